"""A study's numbers: each run's row of statistics from its log, and the table of all rows.

:func:`run_statistics` reduces a finished run (its result and its log) to
peaks, percentiles, RMS and the dynamic amplification factor against a
quasi-static run of the same traffic (:mod:`cosim.core.quasistatic`) per
sensor, and vehicle counts; :func:`write_table` writes the rows as
``results.csv`` and ``results.parquet``; :func:`plot_study` hands the table to
:func:`cosim.plots.plot_sweep`.
"""
from __future__ import annotations

import io
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.bridge import BridgeModel
from cosim.core.quasistatic import daf, quasi_static
from cosim.core.traffic import FrameTraffic, ScriptedTraffic, vehicle_of
from cosim.run.scenario import Scenario
from cosim.study.folder import TABLE_CSV, TABLE_PARQUET, write_file
from cosim.study.logs import logged_sensors, logged_traffic
from cosim.study.spec import AXES, RunTask, Study, number_text

__all__ = [
    "AXIS_LABELS",
    "base_row",
    "jsonable_row",
    "plot_study",
    "plotted_statistics",
    "run_statistics",
    "table_frame",
    "write_table",
]

#: Columns that hold text; every other column is numeric.
TEXT_COLUMNS = ("error", "heaviest_id", "log", "status", "run_id", "road_class", "sumo_config", "loads")
_FIRST = ("run_id", "status", *AXES, "sumo_seed", "road_seed", "loads_seed", "duration", "steps")
_LAST = ("vehicles", "max_on_deck", "heaviest_kg", "heaviest_id", "liftoff_events", "liftoff_steps",
         "wall_time", "wall_time_total", "log", "error")
#: x-axis label of each swept axis in the plots.
AXIS_LABELS = {
    "sumo_config": "SUMO demand",
    "vehicles_per_hour": "vehicles per hour per direction",
    "truck_share": "truck share",
    "speed_limit": "speed limit [m/s]",
    "loads": "vehicles' loads",
    "road_class": "road class",
    "seed": "seed",
}
#: Plotted columns that are not per sensor: label and display factor.
GLOBAL_STATISTICS = {
    "vehicles": ("vehicles on the deck during the run", 1.0),
    "max_on_deck": ("most vehicles on the deck at once", 1.0),
    "heaviest_kg": ("heaviest vehicle [t]", 1e-3),
    "liftoff_events": ("lift-off events", 1.0),
}


# --------------------------------------------------------------------------- one run's row


def base_row(task: RunTask) -> dict[str, Any]:
    """The row a run starts from: its id, its parameters and ``status = "error"`` until it succeeds."""
    return {"run_id": task.run_id, "status": "error", **task.parameters}


def run_statistics(scenario: Scenario, bridge: Any, outcome: Any, percentiles: Sequence[float],
                   vehicles_per_year: float | None = None) -> dict[str, Any]:
    """Peaks, percentiles, RMS, quasi-static peak and DAF per sensor; fatigue of the stress sensors with an S-N
    curve; vehicle counts of the run; gross weights per vehicle class (``gvw.<class>.count``, ``.mean``,
    ``.sd``, ``.max``, N).

    Args:
        scenario, bridge: what ran.
        outcome: the finished logged run (:class:`cosim.run.logged.RunOutcome`).
        percentiles: of |value| per sensor, in percent.
        vehicles_per_year: the stated traffic volume the damage per year is scaled to (None: the run's traffic
            all year).
    """
    result = outcome.result
    sensors = scenario.sensors_core()
    names = [s.name for s in sensors]
    series = logged_sensors(outcome.log_path, names)
    traffic: FrameTraffic | ScriptedTraffic
    if scenario.traffic is not None:  # the logged SUMO frames (empty ones are not in the log)
        traffic = logged_traffic(outcome.log_path, bridge.length, scenario.traffic.step, until=outcome.duration)
    else:
        traffic = scenario.build_vehicles()
    # A deck given by its modes has no influence lines: no static peak, no DAF (docs/modal-decks.md).
    qs = (quasi_static(bridge, traffic, outcome.duration, scenario.solver.dt, sensors, scenario.solver.gravity)
          if isinstance(bridge, BridgeModel) else None)
    row: dict[str, Any] = {"duration": outcome.duration, "steps": result.steps}
    for name in names:
        lo, hi = result.sensor_min[name], result.sensor_max[name]
        peak = max(abs(lo), abs(hi))
        values = np.abs(series[name])
        row[f"{name}.min"] = lo
        row[f"{name}.max"] = hi
        row[f"{name}.peak"] = peak
        for q in percentiles:
            row[f"{name}.p{number_text(q)}"] = float(np.percentile(values, q)) if len(values) else None
        row[f"{name}.rms"] = float(np.sqrt(np.mean(values**2))) if len(values) else None
        row[f"{name}.static_peak"] = qs.peak[name] if qs is not None else None
        row[f"{name}.daf"] = daf(peak, qs.peak[name]) if qs is not None else None
    # Vehicles, not contact points: a vehicle with its own axles is "id#0", "id#1", ... in result.vehicle_ids.
    vehicles = len({vehicle_of(contact) for contact in result.vehicle_ids})
    for name, fat in outcome.fatigue.items():
        per_year = fat.damage_per_year
        if vehicles_per_year is not None:
            per_year = fat.damage * vehicles_per_year / vehicles if vehicles else None
        row[f"{name}.cycles"] = fat.cycles
        row[f"{name}.damage"] = fat.damage
        row[f"{name}.damage_per_year"] = per_year
        row[f"{name}.equivalent_stress_range"] = fat.equivalent_stress_range
        row[f"{name}.max_stress_range"] = fat.max_stress_range
    for cls, w in result.weights.items():  # gross weights per vehicle class (its loads' records)
        row[f"gvw.{cls}.count"] = w.count
        row[f"gvw.{cls}.mean"] = w.mean
        row[f"gvw.{cls}.sd"] = w.sd
        row[f"gvw.{cls}.max"] = w.high
    row.update({
        "vehicles": vehicles,
        "max_on_deck": result.max_on_deck,
        "heaviest_kg": qs.heaviest if qs is not None else None,
        "heaviest_id": qs.heaviest_id if qs is not None else None,
        "liftoff_events": result.liftoff_events,
        "liftoff_steps": result.liftoff_steps,
        "wall_time": outcome.wall_time,
    })
    return row


def jsonable_row(row: dict[str, Any]) -> dict[str, Any]:
    """Plain JSON types, non-finite numbers as None: what result.json stores and the table reads."""
    out = {}
    for key, value in row.items():
        if isinstance(value, (np.floating, np.integer)):
            value = value.item()
        if isinstance(value, float) and not math.isfinite(value):
            value = None
        out[key] = value
    return json.loads(json.dumps(out))


# --------------------------------------------------------------------------- the table


def table_frame(rows: list[dict[str, Any]]):  # noqa: ANN201 - pandas is imported lazily
    """The rows as a pandas DataFrame: run id and status first, the axes, statistics, then counts and files."""
    import pandas as pd

    keys: dict[str, None] = {"run_id": None, "status": None}
    for row in rows:
        keys.update(dict.fromkeys(row))
    first = [k for k in _FIRST if k in keys]
    last = [k for k in _LAST if k in keys]
    middle = [k for k in keys if k not in first and k not in last]
    columns = first + middle + last
    frame = pd.DataFrame([{k: row.get(k) for k in columns} for row in rows], columns=columns)
    for name in TEXT_COLUMNS:
        if name in frame:
            frame[name] = frame[name].fillna("").astype(str)
    for name in columns:
        if frame[name].dtype == object and name not in TEXT_COLUMNS:
            frame[name] = pd.to_numeric(frame[name], errors="coerce")
    return frame


def write_table(rows: list[dict[str, Any]], output: Path) -> tuple[Path, Path]:
    """``results.csv`` and ``results.parquet`` in ``output``: one row per run, SI units."""
    frame = table_frame(rows)
    csv_path, parquet_path = output / TABLE_CSV, output / TABLE_PARQUET
    text = io.StringIO()
    frame.to_csv(text, index=False)
    write_file(csv_path, text.getvalue())
    data = io.BytesIO()
    frame.to_parquet(data, index=False)
    write_file(parquet_path, data.getvalue())
    return csv_path, parquet_path


# --------------------------------------------------------------------------- plots


def plotted_statistics(study: Study, frame: Any) -> list[tuple[str, str, float]]:
    """(column, label, display factor) of every statistic plotted: each sensor's peak, RMS and DAF, and counts."""
    from cosim.run.units import DISPLAY_UNITS

    out = []
    for sensor in study.all_sensors:
        unit, factor = DISPLAY_UNITS.get(sensor.quantity, ("SI", 1.0))
        for stat, label, scale in (("damage_per_year", "Miner damage per year", 1.0),
                                   ("equivalent_stress_range", "equivalent stress range [MPa]", 1e-6)):
            column = f"{sensor.name}.{stat}"
            if column in frame and np.isfinite(frame[column].to_numpy(dtype=float)).any():
                out.append((column, f"{sensor.name}: {label}", scale))
        for stat, what in (("peak", "peak |value|"), ("rms", "RMS"), ("daf", "DAF")):
            column = f"{sensor.name}.{stat}"
            if column not in frame or not np.isfinite(frame[column].to_numpy(dtype=float)).any():
                continue
            if stat == "daf":
                out.append((column, f"{sensor.name}: dynamic amplification factor", 1.0))
            else:
                out.append((column, f"{sensor.name}: {what} [{unit}]", factor))
    for column, (label, factor) in GLOBAL_STATISTICS.items():
        if column in frame:
            out.append((column, label, factor))
    return out


def plot_study(rows: list[dict[str, Any]], study: Study, folder: Path) -> list[Path]:
    """One PNG per statistic (``<folder>/<column>.png``) with a panel per swept axis (failed runs left out).

    See :func:`cosim.plots.plot_sweep` for what a panel shows.
    """
    from cosim.plots import plot_sweep

    frame = table_frame(rows)
    ok = frame[frame["status"] == "ok"] if len(frame) else frame
    ticks = {"sumo_config": {v: study.sumo_label(v) for v in study.axes.get("sumo_config", ())},
             "loads": {v: study.loads_label(v) for v in study.axes.get("loads", ())}}
    return plot_sweep(ok, study.axes, plotted_statistics(study, ok), folder, title=study.name,
                      axis_labels=AXIS_LABELS, tick_labels=ticks)
