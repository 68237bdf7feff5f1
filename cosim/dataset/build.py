"""Writing a labelled monitoring dataset: one logged run per window and damage case, measured by instruments.

For damage case ``c`` and window ``k`` (``k = 0 ... windows - 1``): the time of
day is ``start + k spacing``, which sets the deck's temperature and so E; the
traffic is the base scenario's with seed ``seed + k`` (the same traffic for
every damage case: paired records); the bridge is the base's with the case's
stiffness loss and support spring. The run is logged to MCAP, its logged
histories are measured by the instruments (:func:`~.sensor_models.measure`,
noise seeded by ``(seed, c, k)``) and become one row of ``dataset.parquet``
with the labels (among them each vehicle's loads: ``vehicle_loads``).
"""
from __future__ import annotations

import copy
import io
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.bridge import build_bridge
from cosim.core.fields import vehicle_of
from cosim.core.section import Material
from cosim.errors import ConfigError
from cosim.log import sensor_series
from cosim.run.logged import run_logged
from cosim.run.outputs import atomic_write, check_new_file
from cosim.run.scenario import Scenario, parse_scenario
from cosim.run.toml_writer import toml_dumps

from .sensor_models import SENSOR_TYPES, measure
from .spec import DamageConfig, Dataset

__all__ = ["DATASET_FILE", "DatasetOutcome", "damaged_bridge", "window_scenario", "write_dataset"]

DATASET_FILE = "dataset.parquet"
LOGS_FOLDER = "logs"


@dataclass(frozen=True)
class DatasetOutcome:
    """What :func:`write_dataset` wrote: the table, its rows (without the signals) and the logs."""

    dataset: Dataset
    table: Path
    rows: list[dict[str, Any]]
    logs: list[Path]
    wall_time: float


def window_scenario(dataset: Dataset, k: int) -> Scenario:
    """The base scenario for window ``k``: the instruments as its sensors, ``window`` s long, traffic seed
    ``seed + k``, its own log and CSV outputs removed."""
    data = copy.deepcopy(dataset.base_data)
    data["sensors"] = [
        {"name": s.name, "x": s.x, "y": s.y, "quantity": SENSOR_TYPES[s.type],
         **({"z": s.z} if s.z is not None else {})}
        for s in dataset.sensors]
    output = data.get("output")
    if isinstance(output, dict):
        output.pop("log", None)
        output.pop("csv", None)
    if "traffic" in data:
        traffic = data["traffic"]
        traffic["seed"] = dataset.seed + k
        traffic["end"] = float(traffic.get("begin", 0.0)) + dataset.window
        if isinstance(data.get("solver"), dict):
            data["solver"].pop("duration", None)
    else:
        data.setdefault("solver", {})["duration"] = dataset.window
    return parse_scenario(toml_dumps(data), f"{dataset.source} (window {k})", base_dir=dataset.base.base_dir)


def damaged_bridge(scenario: Scenario, case: DamageConfig, e_factor: float) -> Any:
    """The scenario's bridge with E and G scaled by ``e_factor`` (temperature) and the damage of ``case``."""
    config = scenario.bridge
    material = scenario.material()
    scaled = Material(E=material.E * e_factor, G=material.G * e_factor, rho=material.rho)
    section = scenario.build_section()
    n_per = config.elements_per_span
    counts = [n_per] * len(config.spans) if isinstance(n_per, int) else list(n_per)
    edges = np.concatenate([[0.0], np.cumsum([[span / n] * n for span, n in zip(config.spans, counts)])])
    centres = 0.5 * (edges[:-1] + edges[1:])
    factors = np.ones(len(centres))
    if case.x is not None:
        factors[(centres >= case.x[0]) & (centres <= case.x[1])] = case.stiffness
        if np.all(factors == 1.0):
            raise ConfigError(f"damage {case.name}: x = {list(case.x)} holds no element's centre; give a longer "
                              "length or more elements")
    springs = [(case.support, case.dof, case.spring)] if case.support is not None and case.spring else []
    with scenario.named("bridge"):
        return build_bridge(spans=config.spans, elements_per_span=config.elements_per_span, material=scaled,
                            section=section, supports=config.supports,
                            damping=config.damping.beam_damping() if config.damping is not None else None,
                            theory=config.theory(), stiffness_factors=factors, support_springs=springs)


def _first_vertical_hz(bridge: Any) -> float:
    modal = bridge.modes(count=12)
    kinds = [i for i, d in enumerate(modal.dominant) if d == "vertical"]
    return float(modal.f_hz[kinds[0]]) if kinds else float("nan")


def _vehicle_loads(log: Path) -> list[dict[str, Any]]:
    """Each vehicle that came onto the deck in a window: its loads as the log records them (``/cosim/vehicle_loads``:
    t (s), id, class, lane, speed (m/s), gvw (N), axle_loads (N), axle_spacings (m), y and wander (m), source)."""
    from cosim.log import iter_messages
    from cosim.log.schemas import TOPIC_VEHICLE_LOADS

    return [{k: v for k, v in message.items() if k != "n_axles"}
            for _, message in iter_messages(log, [TOPIC_VEHICLE_LOADS])]


def write_dataset(dataset: Dataset, *, force: bool = False,
                  progress: Callable[[int, int], None] | None = None) -> DatasetOutcome:
    """Run every window of every damage case and write ``<output>/dataset.parquet`` and the logs.

    Raises:
        CosimError: the table exists (without ``force``) or a window cannot run; nothing is left half-written.
    """
    import pandas as pd

    started = time.perf_counter()
    table_path = dataset.output / DATASET_FILE
    check_new_file(table_path, "dataset", force)
    total = len(dataset.damage) * dataset.windows
    rows: list[dict[str, Any]] = []
    signals: list[dict[str, Any]] = []
    logs: list[Path] = []
    scenarios = [window_scenario(dataset, k) for k in range(dataset.windows)]  # every input checked first
    names = [s.name for s in dataset.sensors]
    for c, case in enumerate(dataset.damage):
        for k, scenario in enumerate(scenarios):
            seconds = dataset.start + k * dataset.spacing
            temperature = dataset.temperature_at(seconds)
            e_factor = dataset.e_factor(temperature)
            bridge = damaged_bridge(scenario, case, e_factor)
            log = dataset.output / LOGS_FOLDER / case.name / f"window-{k:04d}.mcap"
            outcome = run_logged(scenario, log, force=force, bridge=bridge)
            t, series = sensor_series(log, names)
            rng = np.random.default_rng([dataset.seed, c, k])
            measured = {s.name: measure(series[s.name], outcome.rate_hz, s.rate_hz, s.noise, s.resolution, rng)
                        for s in dataset.sensors}
            row = {
                "window": k, "case": case.name, "damaged": case.x is not None or case.support is not None,
                "damage_x_start": case.x[0] if case.x else None, "damage_x_end": case.x[1] if case.x else None,
                "stiffness_factor": case.stiffness, "support": case.support, "support_dof":
                    case.dof if case.support is not None else None, "support_spring": case.spring,
                "seed": dataset.seed + k, "time_of_day": seconds % 86400.0, "temperature": temperature,
                "e_factor": e_factor, "f1_hz": _first_vertical_hz(bridge), "duration": outcome.duration,
                # Vehicles, not contact points ("id#0", "id#1", ... for a vehicle's own axles), as a study counts.
                "vehicles": len({vehicle_of(c) for c in outcome.result.vehicle_ids}),
                "max_on_deck": outcome.result.max_on_deck,
                "log": str(log.relative_to(dataset.output)),
                "vehicle_loads": _vehicle_loads(log),
            }
            rows.append(row)
            signals.append({**row, **{f"{n}.rate_hz": s.rate_hz for n, s in zip(names, dataset.sensors)},
                            **{n: measured[n].tolist() for n in names}})
            logs.append(log)
            if progress is not None:
                progress(len(rows), total)
    frame = pd.DataFrame(signals)
    data = io.BytesIO()
    frame.to_parquet(data, index=False)
    with atomic_write(table_path, "dataset") as partial:
        partial.write_bytes(data.getvalue())
    with atomic_write(dataset.output / "dataset.toml", "dataset file") as partial:
        partial.write_text(dataset.text, encoding="utf-8")
    with atomic_write(dataset.output / "labels.json", "labels") as partial:
        partial.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return DatasetOutcome(dataset=replace(dataset), table=table_path, rows=rows, logs=logs,
                          wall_time=time.perf_counter() - started)
