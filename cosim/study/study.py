"""Traffic-volume studies: a base scenario swept over demand, trucks, speed limit, road and seeds, on Dask.

A study file (TOML, ``docs/studies.md`` documents every key) names a base
scenario and sweep axes; every combination of axis values is one *run*:

- ``sumo_config``: the SUMO demand, a bundled level (light, medium, heavy,
  congested) or the user's own ``.sumocfg``;
- ``vehicles_per_hour``: every ``<flow>`` of the demand gets this rate (the
  bundled demand has one flow per direction: vehicles per hour per direction);
- ``truck_share``: the probabilities of the heavy vTypes (vClass bus, coach,
  truck, trailer) of every ``vTypeDistribution`` are rescaled to sum to this
  share, the light ones to the rest;
- ``speed_limit``: the speed of every lane of the network (internal junction
  lanes aside), m/s;
- ``road_class``: smooth or an ISO 8608 class;
- ``seeds``: Monte Carlo repetitions; SUMO's seed and the road-profile seed
  are both the run's seed.

For every run cosim writes the SUMO files and the scenario it generated into
``<output>/runs/<run id>/``, runs the scenario there into ``run.mcap`` and
reduces it to one row of results (``result.json``): peaks and percentiles per
sensor, RMS, the dynamic amplification factor against a quasi-static run of the
same traffic (:mod:`cosim.core.quasistatic`), vehicle counts, lift-offs, wall time
and status. The rows make ``<output>/results.csv`` and ``results.parquet``;
``<output>/plots/`` gets one PNG per statistic against every swept axis.

Runs are plain functions (:func:`execute_run`) of a :class:`RunTask` that
carries every input as text, executed on a Dask cluster: a local one of worker
processes by default (one libsumo simulation per process), or an existing
scheduler. A run id depends only on its parameter values, and a run whose
``result.json`` matches its inputs and whose log is complete is not run again:
re-running a study resumes it. Nothing here prints.
"""
from __future__ import annotations

import copy
import hashlib
import io
import itertools
import json
import logging
import math
import os
import re
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Annotated, Any, Callable, Sequence

import numpy as np
from pydantic import Field, PlainValidator, Strict, ValidationError, field_validator

from cosim.core.quasistatic import daf, quasi_static
from cosim.core.roughness import ISO_CLASSES as _ISO
from cosim.errors import ConfigError, CosimError
from cosim.log.writer import (
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_TYPES,
    file_is_complete,
    read_log,
    traffic_from_log,
)

ISO_CLASSES = tuple(_ISO)
from cosim.run.config_base import (
    ConfigModel,
    Problems,
    choices_message,
    config_error,
    fail,
    show,
)
from cosim.run.scenario import (
    ROAD_CLASSES,
    SUMO_LEVELS,
    Scenario,
    list_bundled_scenarios,
    load_scenario,
)
from cosim.sumo.adapter import bundled_networks
from cosim.sumo.files import (
    SumoSet,
    number_text,
    read_sumo_set,
    set_speed_limit,
    set_truck_share,
    set_vehicles_per_hour,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "AXES",
    "RunTask",
    "Study",
    "StudyOutcome",
    "execute_run",
    "load_study",
    "parse_study",
    "plot_study",
    "run_study",
    "summary_text",
    "write_table",
]

#: Bumped when what a run computes changes: older results are then redone.
STUDY_FORMAT = 1
#: Sweep axes in the order they vary (the last fastest) and their labels in run ids.
AXES: dict[str, str] = {
    "sumo_config": "cfg",
    "vehicles_per_hour": "vph",
    "truck_share": "trucks",
    "speed_limit": "vmax",
    "road_class": "road",
    "seed": "seed",
}
#: Axes that edit the SUMO demand: the base scenario needs [traffic] (or the sumo_config axis).
SUMO_AXES = ("sumo_config", "vehicles_per_hour", "truck_share", "speed_limit")
#: Bundled demand levels (``sumo_networks/<level>.sumocfg``): the scenario's own list.
BUNDLED_LEVELS = SUMO_LEVELS
DEFAULT_PERCENTILES = (50.0, 95.0, 99.0)
#: Road-profile seed when a random road class is swept without seeds.
DEFAULT_SEED = 1
SUMO_FOLDER = "sumo"
RUNS_FOLDER = "runs"
SCENARIO_FILE = "scenario.toml"
LOG_FILE = "run.mcap"
RESULT_FILE = "result.json"
TABLE_CSV = "results.csv"
TABLE_PARQUET = "results.parquet"
PLOTS_FOLDER = "plots"
#: How long to wait for a remote scheduler to have a worker, s.
WORKER_WAIT = 60.0
#: Longest error message kept in a row.
ERROR_LIMIT = 2000

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- the study file

_NAME = Annotated[str, Strict(), Field(pattern=r"^[A-Za-z0-9_.-]+$")]
_Text = Annotated[str, Strict(), Field(min_length=1)]
_Positive = Annotated[float, Strict(), Field(gt=0)]
_Share = Annotated[float, Strict(), Field(ge=0.0, le=1.0)]
_Percent = Annotated[float, Strict(), Field(gt=0.0, le=100.0)]


def _road_class(value: Any) -> str:
    if not isinstance(value, str) or value not in ROAD_CLASSES:
        raise fail(choices_message(value, ROAD_CLASSES, "road class"))
    return value


def _seeds(value: Any) -> tuple[int, ...]:
    """``seeds = [1, 2, 3]`` or a count ``seeds = 3`` (meaning 1, 2, 3)."""
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise fail(f"a count of seeds must be >= 1 (got {value})")
        return tuple(range(1, value + 1))
    if not isinstance(value, (list, tuple)):
        raise fail(f"expected an array of integers >= 0 (or a count), got {show(value)}")
    problems = []
    for i, item in enumerate(value):
        if isinstance(item, bool) or not isinstance(item, int) or item < 0:
            problems.append(((i,), f"expected an integer >= 0, got {show(item)}"))
    if problems:
        raise Problems(problems)
    return tuple(value)


class StudySection(ConfigModel):
    """``[study]``: what to run and where the results go."""

    name: _NAME | None = None
    base: _Text
    duration: _Positive | None = None
    output: _Text | None = None
    percentiles: tuple[_Percent, ...] = DEFAULT_PERCENTILES
    plots: Annotated[bool, Strict()] = True


class SweepSection(ConfigModel):
    """``[sweep]``: the axes; every combination of their values is one run."""

    sumo_config: tuple[_Text, ...] | None = None
    vehicles_per_hour: tuple[_Positive, ...] | None = None
    truck_share: tuple[_Share, ...] | None = None
    speed_limit: tuple[_Positive, ...] | None = None
    road_class: tuple[Annotated[str, PlainValidator(_road_class)], ...] | None = None
    seeds: Annotated[tuple[int, ...], PlainValidator(_seeds)] | None = None

    @field_validator("*")
    @classmethod
    def _non_empty_unique(cls, value: Any) -> Any:
        if value is None:
            return value
        if len(value) == 0:
            raise fail("expected at least one value (remove the key to keep the base scenario's)")
        seen: dict[Any, int] = {}
        for i, item in enumerate(value):
            if item in seen:
                raise fail(f"value {show(item)} is listed twice (at {seen[item]} and {i})")
            seen[item] = i
        return value


class StudyFile(ConfigModel):
    study: StudySection
    sweep: SweepSection = SweepSection()


# --------------------------------------------------------------------------- SUMO inputs



# --------------------------------------------------------------------------- runs


def _id_part(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", text)


@dataclass(frozen=True)
class RunTask:
    """Everything one run needs, as plain data: what a Dask worker receives.

    Attributes:
        run_id: deterministic from the parameter values.
        folder: absolute path of ``<output>/runs/<run_id>`` (the output folder
            must be reachable at this path from every worker).
        parameters: the swept values of this run (axis name -> value), plus
            ``sumo_seed`` and ``road_seed`` when they apply.
        scenario_text: the run's scenario (TOML), written as ``scenario.toml``.
        files: relative path in the run folder -> content (SUMO files, a road profile).
        fingerprint: hash of every input; a stored result with another fingerprint is stale.
        percentiles: of |value| per sensor, in percent.
        error: why the run could not even be generated (e.g. a broken route file); it is then
            recorded as failed without running.
    """

    run_id: str
    folder: str
    parameters: dict[str, Any]
    scenario_text: str
    files: dict[str, bytes]
    fingerprint: str
    percentiles: tuple[float, ...] = DEFAULT_PERCENTILES
    error: str | None = None


@dataclass(frozen=True)
class Study:
    """A validated study: the base scenario, the axes and where results go.

    Build one with :func:`load_study` or :func:`parse_study`.
    """

    name: str
    source: str
    text: str
    base: Scenario
    base_data: dict[str, Any]
    base_dir: Path
    study_dir: Path
    duration: float | None
    output: Path
    axes: dict[str, tuple[Any, ...]]
    percentiles: tuple[float, ...]
    plots: bool
    sumo_sets: dict[str, SumoSet | ConfigError] = field(default_factory=dict)

    @property
    def uses_sumo(self) -> bool:
        return "traffic" in self.base_data or "sumo_config" in self.axes

    @property
    def swept(self) -> list[str]:
        """Axis names in run-id order."""
        return list(self.axes)

    def combinations(self) -> list[dict[str, Any]]:
        """Every combination of axis values, the last axis varying fastest."""
        names = self.swept
        return [dict(zip(names, combo)) for combo in itertools.product(*(self.axes[n] for n in names))]

    def run_id(self, params: dict[str, Any]) -> str:
        """``vph-500_trucks-0.1_seed-3``: the run's folder name, from its parameter values."""
        if not params:
            return "base"
        parts = []
        for name, value in params.items():
            if name == "sumo_config":
                text = self.sumo_label(value)
            elif isinstance(value, str):
                text = value
            else:
                text = number_text(value)
            parts.append(f"{AXES[name]}-{_id_part(text)}")
        return "_".join(parts)

    def sumo_label(self, value: str) -> str:
        stem = value if value in BUNDLED_LEVELS else Path(value).name.removesuffix(".sumocfg")
        values = self.axes.get("sumo_config", ())
        stems = [v if v in BUNDLED_LEVELS else Path(v).name.removesuffix(".sumocfg") for v in values]
        if stems.count(stem) > 1:
            stem += "-" + hashlib.sha1(value.encode()).hexdigest()[:6]
        return stem

    def tasks(self) -> list[RunTask]:
        """The runs of the study, in sweep order."""
        return [self.task(params) for params in self.combinations()]

    def task(self, params: dict[str, Any]) -> RunTask:
        """The :class:`RunTask` of one combination (generation problems become its ``error``)."""
        run_id = self.run_id(params)
        folder = self.output / RUNS_FOLDER / run_id
        recorded = dict(params)
        try:
            body, files, seeds = self._generate(params)
            error = None
        except (CosimError, OSError, ValueError) as exc:
            body, files, seeds, error = "", {}, {}, _error_text(exc)
        recorded.update(seeds)
        # The fingerprint covers what the run computes from: not where the study or its base file lie.
        digest = hashlib.sha256()
        digest.update(f"cosim-study-{STUDY_FORMAT}\n{body}\n{self.percentiles}\n{error}\n".encode())
        for name in sorted(files):
            digest.update(name.encode() + b"\0" + hashlib.sha256(files[name]).digest())
        described = ", ".join(f"{k} = {v}" for k, v in params.items()) or "the base scenario as it is"
        header = (f"# Run {run_id} of study {self.name} ({self.source}), generated by cosim study from "
                  f"{self.base.source}: {described}\n")
        return RunTask(run_id, str(folder), recorded, header + body if body else "", files, digest.hexdigest(),
                       self.percentiles, error)

    # ---------------------------------------------------------------- generation
    def _generate(self, params: dict[str, Any]) -> tuple[str, dict[str, bytes], dict[str, Any]]:
        """The run's scenario TOML (without its header comment), its input files, and the seeds used."""
        data = copy.deepcopy(self.base_data)
        files: dict[str, bytes] = {}
        seeds: dict[str, Any] = {}
        seed = params.get("seed")
        # [output]: the log goes where the study says; no extra CSV.
        output = data.get("output")
        if isinstance(output, dict):
            output.pop("log", None)
            output.pop("csv", None)
            if not output:
                data.pop("output")
        # [road]
        road = dict(data.get("road") or {})
        if "road_class" in params:
            cls = params["road_class"]
            road = {"class": cls}
            if cls in ISO_CLASSES:
                road["seed"] = seed if seed is not None else int((data.get("road") or {}).get("seed", DEFAULT_SEED))
        elif seed is not None and road.get("class") in ISO_CLASSES:
            road["seed"] = seed
        if road.get("profile"):
            source = self.base_dir / road["profile"]
            name = f"inputs/{Path(road['profile']).name}"
            files[name] = source.read_bytes()
            road["profile"] = name
        if road:
            data["road"] = road
        if road.get("class") in ISO_CLASSES:
            seeds["road_seed"] = road.get("seed")
        # [traffic] or [[vehicles]]
        if self.uses_sumo:
            traffic = dict(data.get("traffic") or {})
            value = params.get("sumo_config", traffic.get("sumo_config"))
            sumo = self.sumo_sets[value]
            if isinstance(sumo, ConfigError):
                raise sumo
            if "vehicles_per_hour" in params:
                sumo = set_vehicles_per_hour(sumo, params["vehicles_per_hour"])
            if "truck_share" in params:
                sumo = set_truck_share(sumo, params["truck_share"])
            if "speed_limit" in params:
                sumo = set_speed_limit(sumo, params["speed_limit"])
            for name, content in sumo.files.items():
                files[f"{SUMO_FOLDER}/{name}"] = content
            traffic["sumo_config"] = f"{SUMO_FOLDER}/{sumo.config}"
            if seed is not None:
                traffic["seed"] = seed
            if self.duration is not None:
                traffic["end"] = float(traffic.get("begin", 0.0)) + self.duration
                solver = data.get("solver")
                if isinstance(solver, dict) and "duration" in solver:
                    solver["duration"] = self.duration
            data["traffic"] = traffic
            seeds["sumo_seed"] = traffic.get("seed")
        elif self.duration is not None:
            data.setdefault("solver", {})["duration"] = self.duration
        from cosim.run.logged import toml_dumps

        return toml_dumps(data), files, seeds


def _error_text(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    if not isinstance(exc, CosimError):
        text = f"{type(exc).__name__}: {text}"
    return text[:ERROR_LIMIT]


def parse_study(text: str, source: str = "<study>", base_dir: str | os.PathLike[str] = ".",
                output: str | os.PathLike[str] | None = None) -> Study:
    """Validate study TOML text and load its base scenario and SUMO configs.

    Args:
        text: the TOML document.
        source: how to name it in error messages (the file path).
        base_dir: the study file's folder (``study.base`` and ``sweep.sumo_config`` paths are relative to it).
        output: the output folder instead of ``study.output`` (relative to the current folder).

    Raises:
        ConfigError: the study file is malformed, its base scenario or a SUMO config cannot be
            read, or an axis does not fit the base scenario (e.g. ``vehicles_per_hour`` without
            SUMO traffic). Messages name the file and the key.
    """
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: TOML syntax error: {exc}") from None
    try:
        parsed = StudyFile.model_validate(raw)
    except ValidationError as exc:
        raise config_error(source, StudyFile, exc) from None
    study_dir = Path(base_dir)
    sec = parsed.study
    base_path = study_dir / sec.base
    try:
        if base_path.is_file() or sec.base not in list_bundled_scenarios():
            base = load_scenario(base_path)  # a file next to the study (a missing one: its error)
        else:
            base = load_scenario(sec.base)
    except ConfigError as exc:
        raise ConfigError(f"{source}: study.base: {exc}") from None
    base_data = tomllib.loads(base.text)
    scenario_dir = base_path.parent if base_path.is_file() else _bundled_scenarios_dir()
    name = sec.name or (Path(source).stem if source != "<study>" else base.title)
    axes: dict[str, tuple[Any, ...]] = {}
    sweep = parsed.sweep
    for axis in AXES:
        values = getattr(sweep, "seeds" if axis == "seed" else axis)
        if values is not None:
            axes[axis] = tuple(values)
    has_traffic = "traffic" in base_data
    if "vehicles" in base_data or not has_traffic:
        for axis in SUMO_AXES:
            if axis in axes:
                raise ConfigError(
                    f"{source}: sweep.{axis}: needs SUMO traffic, but the base scenario {base.source} has "
                    f"{'[[vehicles]]' if base_data.get('vehicles') else 'no [traffic]'}; give a base with "
                    "[traffic] (docs/studies.md)")
    sumo_sets: dict[str, SumoSet | ConfigError] = {}
    if has_traffic and "vehicles" not in base_data:
        configs: list[tuple[str, Path, str]] = []
        if "sumo_config" in axes:
            for i, value in enumerate(axes["sumo_config"]):
                configs.append((value, _config_path(value, study_dir, f"{source}: sweep.sumo_config[{i}]"),
                                f"sweep.sumo_config[{i}]"))
        else:
            value = (base_data.get("traffic") or {}).get("sumo_config")
            if not isinstance(value, str):
                raise ConfigError(f"{base.source}: traffic.sumo_config: required key is missing")
            configs.append((value, _config_path(value, scenario_dir, f"{base.source}: traffic.sumo_config"),
                            "traffic.sumo_config"))
        for value, path, key in configs:
            label = value if value in BUNDLED_LEVELS else path.stem
            try:
                sumo_sets[value] = read_sumo_set(path, label)
            except ConfigError as exc:  # broken content: those runs fail, the others go on
                sumo_sets[value] = ConfigError(f"{key}: {exc}")
    out = Path(output) if output is not None else Path(sec.output or f"studies/{name}")
    return Study(
        name=name, source=source, text=text, base=base, base_data=base_data, base_dir=scenario_dir,
        study_dir=study_dir, duration=sec.duration, output=out.resolve(), axes=axes,
        percentiles=tuple(sec.percentiles), plots=sec.plots, sumo_sets=sumo_sets,
    )


def _bundled_scenarios_dir() -> Path:
    from importlib import resources

    return Path(str(resources.files("cosim").joinpath("scenarios")))


def _config_path(value: str, folder: Path, where: str) -> Path:
    if value in BUNDLED_LEVELS:
        return bundled_networks() / f"{value}.sumocfg"
    path = Path(value) if Path(value).is_absolute() else folder / value
    if not path.is_file():
        raise ConfigError(f"{where}: file not found: {path} (a bundled level is one of "
                          f"{', '.join(BUNDLED_LEVELS)}; a path is relative to the file that names it)")
    return path


def load_study(path: str | os.PathLike[str], output: str | os.PathLike[str] | None = None) -> Study:
    """Load and validate a study file (see :func:`parse_study`).

    Raises:
        ConfigError: the file is missing or unreadable, or its content is invalid.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise ConfigError(f"{path}: cannot read the study file ({reason})") from None
    return parse_study(text, str(path), base_dir=path.parent, output=output)


# --------------------------------------------------------------------------- one run (on a worker)


def _write(path: Path, data: bytes | str) -> None:
    """Write through a temporary file, so a reader never sees half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".part")
    if isinstance(data, str):
        data = data.encode("utf-8")
    partial.write_bytes(data)
    os.replace(partial, path)


def _base_row(task: RunTask) -> dict[str, Any]:
    return {"run_id": task.run_id, "status": "error", **task.parameters}


def _sensor_statistics(scenario: Scenario, bridge: Any, outcome: Any, percentiles: Sequence[float]
                       ) -> dict[str, Any]:
    """Peaks, percentiles, RMS, quasi-static peak and DAF per sensor; vehicle counts of the run."""
    from cosim.run.logged import sensor_series

    result = outcome.result
    sensors = scenario.sensors_core()
    names = [s.name for s in sensors]
    _, series = sensor_series(outcome.log_path, names)
    contents = read_log(outcome.log_path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
    if scenario.traffic is not None:  # the logged SUMO frames (empty ones are not in the log)
        traffic = traffic_from_log(contents, bridge.length, scenario.traffic.step, until=outcome.duration)
    else:
        traffic = scenario.build_vehicles()
    qs = quasi_static(bridge, traffic, outcome.duration, scenario.solver.dt, sensors, scenario.solver.gravity)
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
        row[f"{name}.static_peak"] = qs.peak[name]
        row[f"{name}.daf"] = daf(peak, qs.peak[name])
    row.update({
        "vehicles": len(result.vehicle_ids),
        "max_on_deck": result.max_on_deck,
        "heaviest_kg": qs.heaviest,
        "heaviest_id": qs.heaviest_id,
        "liftoff_events": result.liftoff_events,
        "liftoff_steps": result.liftoff_steps,
        "wall_time": outcome.wall_time,
    })
    return row


def _jsonable_row(row: dict[str, Any]) -> dict[str, Any]:
    """Plain JSON types, non-finite numbers as None: what result.json stores and the table reads."""
    out = {}
    for key, value in row.items():
        if isinstance(value, (np.floating, np.integer)):
            value = value.item()
        if isinstance(value, float) and not math.isfinite(value):
            value = None
        out[key] = value
    return json.loads(json.dumps(out))


def execute_run(task: RunTask) -> dict[str, Any]:
    """Run one study run in this process and return its row of results (also stored as ``result.json``).

    Writes the task's files and ``scenario.toml`` into ``task.folder``, runs the
    scenario into ``run.mcap`` (replacing one left by an interrupted attempt),
    then reduces the log to the row. Any failure is recorded in the row
    (``status = "error"``, ``error`` = the message); it never raises, except for
    Ctrl-C.
    """
    started = time.perf_counter()
    folder = Path(task.folder)
    row = _base_row(task)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / RESULT_FILE).unlink(missing_ok=True)
        if task.error is not None:
            raise ConfigError(task.error)
        for name, content in task.files.items():
            pure = PurePosixPath(name)
            if pure.is_absolute() or ".." in pure.parts:
                raise ConfigError(f"unsafe file name in the run's inputs: {name!r}")
            _write(folder.joinpath(*pure.parts), content)
        _write(folder / SCENARIO_FILE, task.scenario_text)
        scenario = load_scenario(folder / SCENARIO_FILE)
        bridge = scenario.build_bridge()
        from cosim.run.logged import run_logged

        outcome = run_logged(scenario, folder / LOG_FILE, force=True, bridge=bridge)
        row.update(_sensor_statistics(scenario, bridge, outcome, task.percentiles))
        row["status"] = "ok"
        row["error"] = ""
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # noqa: BLE001 - a failing run is recorded, the study goes on
        row["status"] = "error"
        row["error"] = _error_text(exc)
        if not isinstance(exc, CosimError):
            log.debug("run %s failed:\n%s", task.run_id, traceback.format_exc())
    row["wall_time_total"] = time.perf_counter() - started
    row["log"] = f"{RUNS_FOLDER}/{task.run_id}/{LOG_FILE}"
    row = _jsonable_row(row)
    try:
        _write(folder / RESULT_FILE, json.dumps({"fingerprint": task.fingerprint, "row": row}, indent=1))
    except OSError as exc:
        row["status"] = "error"
        row["error"] = _error_text(exc)
    return row


def finished_row(task: RunTask) -> dict[str, Any] | None:
    """The stored row of a run that need not run again: status ok, same inputs, complete log; else None."""
    folder = Path(task.folder)
    try:
        stored = json.loads((folder / RESULT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(stored, dict) or stored.get("fingerprint") != task.fingerprint:
        return None
    row = stored.get("row")
    if not isinstance(row, dict) or row.get("status") != "ok":
        return None
    if not file_is_complete(folder / LOG_FILE):
        return None
    return row


# --------------------------------------------------------------------------- the whole study


@dataclass
class StudyOutcome:
    """What :func:`run_study` did.

    Attributes:
        study: the study.
        rows: one row per run, in sweep order.
        ran: run ids executed now; skipped: run ids whose stored results were reused.
        failed: run ids whose status is "error".
        table_csv, table_parquet: the results table.
        plots: the PNG files written.
        wall_time: s, the whole study (cluster start-up included).
        workers: how many workers ran the runs (0: in this process).
    """

    study: Study
    rows: list[dict[str, Any]]
    ran: list[str]
    skipped: list[str]
    failed: list[str]
    table_csv: Path
    table_parquet: Path
    plots: list[Path]
    wall_time: float
    workers: int

    def table(self):  # noqa: ANN201 - pandas is imported lazily
        """The results as a pandas DataFrame (the rows of ``results.csv``)."""
        return _frame(self.rows)


Progress = Callable[[int, int, "dict[str, Any] | None"], None]


def summary_text(outcome: StudyOutcome) -> str:
    """What a study did, for the command line to print: runs, workers, files, failures."""
    study = outcome.study
    rows = outcome.rows
    axes = ", ".join(f"{a} ({len(v)})" for a, v in study.axes.items()) or "none (the base scenario once)"
    if outcome.ran:
        where = f"on {outcome.workers} worker{'s' if outcome.workers != 1 else ''}" if outcome.workers \
            else "in this process"
        done = f"{len(outcome.ran)} run now {where}, {len(outcome.skipped)} reused from earlier"
    else:
        done = "all reused from earlier (nothing to run; --redo runs them again)"
    lines = [
        f"Study: {study.name} ({study.source}), base {study.base.source}",
        f"Axes: {axes}",
        f"Runs: {len(rows)}: {done}, {len(outcome.failed)} failed",
        f"Wall time: {outcome.wall_time:.3g} s",
        f"Table: {outcome.table_csv} and {outcome.table_parquet.name} ({len(rows)} rows)",
    ]
    if outcome.plots:
        lines.append(f"Plots: {len(outcome.plots)} PNG in {outcome.plots[0].parent}")
    if outcome.failed:
        lines.append("Failed runs (their logs and scenarios are in runs/<run id>/):")
        for row in rows:
            if row.get("status") != "ok":
                first = (row.get("error") or "unknown error").strip().splitlines()[0]
                lines.append(f"  {row['run_id']}: {first}")
    return "\n".join(lines)


def default_workers() -> int:
    """Worker processes of a local cluster by default: the CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def run_study(
    study: Study,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
    redo: bool = False,
    plots: bool | None = None,
) -> StudyOutcome:
    """Run every run of ``study`` that has no up-to-date result, then write the table and plots.

    Args:
        study: from :func:`load_study`.
        workers: size of the local Dask cluster (default: one per CPU, at most one per
            run); 0 runs one after another in this process, without Dask.
        scheduler: address of an existing Dask scheduler (``tcp://host:8786``) instead
            of a local cluster; its workers need cosim installed and the output folder
            at the same path.
        progress: called with (runs done, runs in total, the row just finished or None)
            at the start and after every run.
        redo: run every run again, even those with up-to-date results.
        plots: write the plots (default: ``study.plots``).

    Returns:
        The rows, what ran and what was reused, and the files written.

    Raises:
        KeyboardInterrupt: Ctrl-C; the table of the runs finished so far is written first.
        CosimError: the output folder cannot be written, or the scheduler cannot be reached.
    """
    started = time.perf_counter()
    output = study.output
    try:
        output.mkdir(parents=True, exist_ok=True)
        _write(output / "study.toml", study.text)
    except OSError as exc:
        raise CosimError(f"{output}: cannot write the study's output folder ({exc.strerror or exc})") from None
    tasks = study.tasks()
    rows: dict[str, dict[str, Any]] = {}
    todo: list[RunTask] = []
    for task in tasks:
        stored = None if redo else finished_row(task)
        if stored is not None:
            rows[task.run_id] = stored
        else:
            todo.append(task)
    skipped = [t.run_id for t in tasks if t.run_id in rows]
    total = len(tasks)
    if progress is not None:
        progress(len(rows), total, None)

    def finished(row: dict[str, Any]) -> None:
        rows[row["run_id"]] = row
        if progress is not None:
            progress(len(rows), total, row)

    used = 0
    try:
        if todo:
            if workers == 0 and scheduler is None:
                for task in todo:
                    finished(execute_run(task))
            else:
                used = _run_on_dask(study, todo, workers, scheduler, finished)
    except KeyboardInterrupt:
        # Runs that finished on a worker but whose result had not come back yet count too.
        for task in todo:
            if task.run_id not in rows and (stored := finished_row(task)) is not None:
                rows[task.run_id] = stored
        write_table([rows[t.run_id] for t in tasks if t.run_id in rows], output)
        raise
    ordered = [rows[t.run_id] for t in tasks]
    csv_path, parquet_path = write_table(ordered, output)
    pngs = plot_study(ordered, study, output / PLOTS_FOLDER) if (study.plots if plots is None else plots) else []
    return StudyOutcome(
        study=study, rows=ordered, ran=[t.run_id for t in todo], skipped=skipped,
        failed=[r["run_id"] for r in ordered if r.get("status") != "ok"],
        table_csv=csv_path, table_parquet=parquet_path, plots=pngs,
        wall_time=time.perf_counter() - started, workers=used,
    )


def _run_on_dask(study: Study, todo: list[RunTask], workers: int | None, scheduler: str | None,
                 finished: Callable[[dict[str, Any]], None]) -> int:
    """Submit the runs to a Dask cluster and hand every row to ``finished`` as it arrives; returns the workers."""
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    try:
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout="20s")
            except (OSError, TimeoutError) as exc:
                raise CosimError(f"--scheduler {scheduler}: cannot connect to the Dask scheduler ({exc})") from None
            try:
                client.wait_for_workers(1, timeout=WORKER_WAIT)
            except TimeoutError:
                client.close()
                raise CosimError(f"--scheduler {scheduler}: the scheduler has no workers (waited {WORKER_WAIT:g} s; "
                                 "start some with: dask worker ADDRESS --nthreads 1)") from None
        else:
            n = min(workers or default_workers(), len(todo))
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=logging.ERROR)
            client = Client(cluster)
    except BaseException:
        if cluster is not None:
            cluster.close()
        raise
    try:
        n_workers = len(client.scheduler_info(n_workers=-1).get("workers", {})) if scheduler else \
            len(cluster.workers)  # type: ignore[union-attr]
        by_key: dict[str, RunTask] = {}
        futures = []
        for task in todo:
            key = f"cosim-run-{study.name}-{task.run_id}-{task.fingerprint[:12]}"
            future = client.submit(execute_run, task, key=key, pure=False, retries=0)
            by_key[future.key] = task
            futures.append(future)
        try:
            for future in as_completed(futures):
                task = by_key[future.key]
                try:
                    row = future.result()
                except Exception as exc:  # noqa: BLE001 - e.g. the worker died (KilledWorker)
                    row = _lost_row(task, exc)
                finished(row)
        except BaseException:
            client.cancel(futures)
            raise
        return n_workers
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _lost_row(task: RunTask, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose worker failed without returning one (recorded by the caller)."""
    row = _base_row(task)
    row["error"] = f"the Dask worker failed: {_error_text(exc)}"
    row["log"] = f"{RUNS_FOLDER}/{task.run_id}/{LOG_FILE}"
    row = _jsonable_row(row)
    try:
        _write(Path(task.folder) / RESULT_FILE, json.dumps({"fingerprint": task.fingerprint, "row": row}, indent=1))
    except OSError:
        pass
    return row


# --------------------------------------------------------------------------- table and plots

_FIRST = ("run_id", "status", *AXES, "sumo_seed", "road_seed", "duration", "steps")
_LAST = ("vehicles", "max_on_deck", "heaviest_kg", "heaviest_id", "liftoff_events", "liftoff_steps",
         "wall_time", "wall_time_total", "log", "error")


def _frame(rows: list[dict[str, Any]]):  # noqa: ANN202
    import pandas as pd

    keys: dict[str, None] = {"run_id": None, "status": None}
    for row in rows:
        keys.update(dict.fromkeys(row))
    first = [k for k in _FIRST if k in keys]
    last = [k for k in _LAST if k in keys]
    middle = [k for k in keys if k not in first and k not in last]
    columns = first + middle + last
    frame = pd.DataFrame([{k: row.get(k) for k in columns} for row in rows], columns=columns)
    for name in ("error", "heaviest_id", "log", "status", "run_id", "road_class", "sumo_config"):
        if name in frame:
            frame[name] = frame[name].fillna("").astype(str)
    for name in columns:
        if frame[name].dtype == object and name not in ("error", "heaviest_id", "log", "status", "run_id",
                                                        "road_class", "sumo_config"):
            frame[name] = pd.to_numeric(frame[name], errors="coerce")
    return frame


def write_table(rows: list[dict[str, Any]], output: Path) -> tuple[Path, Path]:
    """``results.csv`` and ``results.parquet`` in ``output``: one row per run, SI units."""
    frame = _frame(rows)
    csv_path, parquet_path = output / TABLE_CSV, output / TABLE_PARQUET
    buffer = io.StringIO()
    frame.to_csv(buffer, index=False)
    _write(csv_path, buffer.getvalue())
    partial = parquet_path.with_name(parquet_path.name + ".part")
    frame.to_parquet(partial, index=False)
    os.replace(partial, parquet_path)
    return csv_path, parquet_path


_AXIS_LABELS = {
    "sumo_config": "SUMO demand",
    "vehicles_per_hour": "vehicles per hour per direction",
    "truck_share": "truck share",
    "speed_limit": "speed limit [m/s]",
    "road_class": "road class",
    "seed": "seed",
}
_GLOBAL_STATS = {
    "vehicles": ("vehicles on the deck during the run", 1.0),
    "max_on_deck": ("most vehicles on the deck at once", 1.0),
    "heaviest_kg": ("heaviest vehicle [t]", 1e-3),
    "liftoff_events": ("lift-off events", 1.0),
}
MAX_GROUPS = 6


def _statistics(study: Study, frame) -> list[tuple[str, str, float]]:  # noqa: ANN001
    """(column, label, display factor) of every plotted statistic."""
    from cosim.run.logged import DISPLAY_UNITS

    out = []
    for sensor in study.base.sensors:
        unit, factor = DISPLAY_UNITS.get(sensor.quantity, ("SI", 1.0))
        for stat, what in (("peak", "peak |value|"), ("rms", "RMS"), ("daf", "DAF")):
            column = f"{sensor.name}.{stat}"
            if column not in frame or not np.isfinite(frame[column].to_numpy(dtype=float)).any():
                continue
            if stat == "daf":
                out.append((column, f"{sensor.name}: dynamic amplification factor", 1.0))
            else:
                out.append((column, f"{sensor.name}: {what} [{unit}]", factor))
    for column, (label, factor) in _GLOBAL_STATS.items():
        if column in frame:
            out.append((column, label, factor))
    return out


def plot_study(rows: list[dict[str, Any]], study: Study, folder: Path) -> list[Path]:
    """One PNG per statistic (``<folder>/<column>.png``) with a panel per swept axis.

    Each panel shows the statistic against the axis: the mean over the seeds
    (a line per combination of the other axes, or one line over all runs when
    they are many), the spread across seeds (min-max band) and every run as a
    dot. Failed runs are left out. With seeds as the only axis, the statistic
    is drawn against the seed.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    frame = _frame(rows)
    ok = frame[frame["status"] == "ok"] if len(frame) else frame
    folder.mkdir(parents=True, exist_ok=True)
    varied = [a for a in study.axes if a != "seed" and len(study.axes[a]) > 1]
    panels = varied or (["seed"] if "seed" in study.axes else [])
    written: list[Path] = []
    if not panels or ok.empty:
        return written
    for column, label, factor in _statistics(study, ok):
        fig = Figure(figsize=(4.2 * len(panels) + 0.6, 3.6), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(1, len(panels), squeeze=False)[0]
        for ax, axis in zip(axes, panels):
            _panel(ax, ok, study, axis, [a for a in varied if a != axis], column, factor)
            ax.set_xlabel(_AXIS_LABELS[axis])
            ax.grid(True, linewidth=0.4, alpha=0.6)
        axes[0].set_ylabel(label, fontsize=9)
        seeds = len(study.axes.get("seed", (None,)))
        fig.suptitle(f"{study.name}: {len(ok)} runs, {seeds} seed{'s' if seeds > 1 else ''} each "
                     "(mean, min-max, every run)", fontsize=9)
        path = folder / f"{_id_part(column)}.png"
        partial = path.with_name(path.stem + ".part.png")
        fig.savefig(partial, dpi=100)
        os.replace(partial, path)
        written.append(path)
    return written


def _panel(ax, ok, study: Study, axis: str, others: list[str], column: str, factor: float) -> None:  # noqa: ANN001
    values = list(study.axes[axis])
    numeric = all(isinstance(v, (int, float)) for v in values)
    positions = {v: (float(v) if numeric else float(i)) for i, v in enumerate(values)}
    groups: list[tuple[str, Any]] = []
    if others:
        keys = list(itertools.product(*(study.axes[o] for o in others)))
        if len(keys) <= MAX_GROUPS:
            for key in keys:
                mask = np.ones(len(ok), dtype=bool)
                for o, v in zip(others, key):
                    mask &= (ok[o] == v).to_numpy()
                groups.append((", ".join(f"{o} = {v}" for o, v in zip(others, key)), ok[mask]))
        else:
            groups.append(("all runs", ok))
    else:
        groups.append(("", ok))
    for label, sub in groups:
        xs, mean, lo, hi = [], [], [], []
        for v in values:
            y = sub[sub[axis] == v][column].to_numpy(dtype=float) * factor
            y = y[np.isfinite(y)]
            if not len(y):
                continue
            xs.append(positions[v])
            mean.append(y.mean())
            lo.append(y.min())
            hi.append(y.max())
            ax.plot(np.full(len(y), positions[v]), y, ".", color="0.45", markersize=3)
        if not xs:
            continue
        line, = ax.plot(xs, mean, "o-", linewidth=1.2, markersize=4, label=label or None)
        if axis != "seed":
            ax.fill_between(xs, lo, hi, color=line.get_color(), alpha=0.18, linewidth=0)
    if not numeric:
        ax.set_xticks([positions[v] for v in values], [str(v if axis != "sumo_config" else study.sumo_label(v))
                                                     for v in values])
    if any(label for label, _ in groups):
        ax.legend(fontsize=7)
