"""The study file and its runs: validation, the sweep, run ids and each run's generated inputs.

A study file (TOML, ``docs/studies.md`` documents every key) names a base
scenario and sweep axes; every combination of axis values is one *run*
(:class:`RunTask`), with an id built from its values only (``vph-500_seed-3``)
and every input as text: the run's scenario and its SUMO files with the
sweep's edits (:mod:`cosim.sumo.files`). Nothing here runs anything.
"""
from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import math
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, PlainValidator, Strict, field_validator

from cosim.core.limits import MAX_RUNS
from cosim.core.loads import bundled_sites, load_model
from cosim.core.roughness import ISO_CLASSES as ISO_ROAD_CLASSES
from cosim.errors import ConfigError, CosimError
from cosim.run.config_base import ConfigModel, Name, Positive, Problems, choice, fail, load_config, show
from cosim.run.scenario import ROAD_CLASSES, SUMO_LEVELS, Scenario, list_bundled_scenarios, load_scenario
from cosim.run.tables import SensorConfig
from cosim.study.folder import RUNS_FOLDER, SUMO_FOLDER
from cosim.sumo import (
    SumoSet,
    bundled_networks,
    read_sumo_set,
    set_speed_limit,
    set_truck_share,
    set_vehicles_per_hour,
)
from cosim.sumo.files import number_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "AXES",
    "BUNDLED_LEVELS",
    "DEFAULT_PERCENTILES",
    "FIXED_LOADS",
    "SUMO_AXES",
    "RunTask",
    "Study",
    "error_text",
    "id_part",
    "load_study",
    "number_text",
    "parse_study",
]

ISO_CLASSES = tuple(ISO_ROAD_CLASSES)
#: Bumped when what a run computes changes: older results are then redone.
STUDY_FORMAT = 2
#: Sweep axes in the order they vary (the last fastest) and their labels in run ids.
AXES: dict[str, str] = {
    "sumo_config": "cfg",
    "vehicles_per_hour": "vph",
    "truck_share": "trucks",
    "speed_limit": "vmax",
    "loads": "loads",
    "road_class": "road",
    "seed": "seed",
}
#: Axes that edit the SUMO demand: the base scenario needs [traffic] (or the sumo_config axis).
SUMO_AXES = ("sumo_config", "vehicles_per_hour", "truck_share", "speed_limit", "loads")
#: The ``loads`` axis's value for a run without ``[traffic.loads]``: every vehicle weighs what its vType says.
FIXED_LOADS = "fixed"
#: Bundled demand levels (``sumo_networks/<level>.sumocfg``): the scenario's own list.
BUNDLED_LEVELS = SUMO_LEVELS
DEFAULT_PERCENTILES = (50.0, 95.0, 99.0)
#: Road-profile seed when a random road class is swept without seeds.
DEFAULT_SEED = 1
#: Longest error message kept in a row.
ERROR_LIMIT = 2000


# --------------------------------------------------------------------------- the study file

_Text = Annotated[str, Strict(), Field(min_length=1)]
_Share = Annotated[float, Strict(), Field(ge=0.0, le=1.0)]
_Percent = Annotated[float, Strict(), Field(gt=0.0, le=100.0)]


def _seeds(value: Any) -> tuple[int, ...]:
    """``seeds = [1, 2, 3]`` or a count ``seeds = 3`` (meaning 1, 2, 3)."""
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise fail(f"a count of seeds must be >= 1 (got {value})")
        limit = MAX_RUNS.value()
        if value > limit:  # before the tuple of seeds is built
            raise fail(f"{value:,} seeds is more than the limit of {limit:,} runs for one study; "
                       f"{MAX_RUNS.how_to_raise()}")
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

    name: Name | None = None
    base: _Text
    duration: Positive | None = None
    output: _Text | None = None
    percentiles: tuple[_Percent, ...] = DEFAULT_PERCENTILES
    plots: Annotated[bool, Strict()] = True


class SweepSection(ConfigModel):
    """``[sweep]``: the axes; every combination of their values is one run."""

    sumo_config: tuple[_Text, ...] | None = None
    vehicles_per_hour: tuple[Positive, ...] | None = None
    truck_share: tuple[_Share, ...] | None = None
    speed_limit: tuple[Positive, ...] | None = None
    loads: tuple[_Text, ...] | None = None
    road_class: tuple[Annotated[str, choice(ROAD_CLASSES, "road class")], ...] | None = None
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


class FatigueSection(ConfigModel):
    """``[fatigue]``: how a run's damage becomes a damage per year."""

    vehicles_per_year: Positive | None = None


#: Run statistics whose maxima over the seeds can be fitted: the largest value, the largest of -value, |value|.
EXTREME_STATISTICS: dict[str, str] = {"max": "max", "min": "min", "peak": "peak"}


class ExtremesSection(ConfigModel):
    """``[extremes]``: characteristic values from the maxima of the study's seeds (one block per run)."""

    sensors: tuple[_Text, ...] | None = None
    statistic: Annotated[str, choice(tuple(EXTREME_STATISTICS), "statistic")] = "max"
    distribution: Annotated[str, choice(("gumbel", "gev"), "distribution")] = "gumbel"
    return_period: Positive = 1000.0
    confidence: Annotated[float, Strict(), Field(gt=0.0, lt=1.0)] = 0.95
    bootstrap: Annotated[int, Strict(), Field(ge=10, le=10000)] = 200
    seed: Annotated[int, Strict(), Field(ge=0)] = 1


class StudyFile(ConfigModel):
    study: StudySection
    sweep: SweepSection = SweepSection()
    sensors: tuple[SensorConfig, ...] = ()
    fatigue: FatigueSection = FatigueSection()
    extremes: ExtremesSection | None = None


# --------------------------------------------------------------------------- runs


def id_part(text: str) -> str:
    """``text`` with every character not allowed in a run id or a file name replaced by ``_``."""
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
        vehicles_per_year: the stated traffic volume a run's fatigue damage is scaled to (None: the
            run's traffic all year).
    """

    run_id: str
    folder: str
    parameters: dict[str, Any]
    scenario_text: str
    files: dict[str, bytes]
    fingerprint: str
    percentiles: tuple[float, ...] = DEFAULT_PERCENTILES
    error: str | None = None
    vehicles_per_year: float | None = None


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
    sensors: tuple[SensorConfig, ...] = ()
    sensor_data: tuple[dict[str, Any], ...] = ()
    vehicles_per_year: float | None = None
    extremes: ExtremesSection | None = None

    @property
    def all_sensors(self) -> tuple[SensorConfig, ...]:
        """The base scenario's sensors and the study's own ``[[sensors]]``, in that order."""
        return tuple(self.base.sensors) + self.sensors

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
            elif name == "loads":
                text = self.loads_label(value)
            elif isinstance(value, str):
                text = value
            else:
                text = number_text(value)
            parts.append(f"{AXES[name]}-{id_part(text)}")
        return "_".join(parts)

    def sumo_label(self, value: str) -> str:
        """How run ids and plots name a ``sumo_config`` value: its level or file stem (plus a hash if ambiguous)."""
        stem = value if value in BUNDLED_LEVELS else Path(value).name.removesuffix(".sumocfg")
        values = self.axes.get("sumo_config", ())
        stems = [v if v in BUNDLED_LEVELS else Path(v).name.removesuffix(".sumocfg") for v in values]
        if stems.count(stem) > 1:
            stem += "-" + hashlib.sha1(value.encode()).hexdigest()[:6]
        return stem

    def loads_label(self, value: str) -> str:
        """How run ids and plots name a ``loads`` value: ``fixed``, the site's name or the folder's (plus a hash if
        ambiguous)."""
        values = self.axes.get("loads", ())
        stems = [_loads_stem(v) for v in values]
        stem = _loads_stem(value)
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
            body, files, seeds, error = "", {}, {}, error_text(exc)
        recorded.update(seeds)
        # The fingerprint covers what the run computes from: not where the study or its base file lie.
        digest = hashlib.sha256()
        digest.update(f"cosim-study-{STUDY_FORMAT}\n{body}\n{self.percentiles}\n{error}\n"
                      f"{self.vehicles_per_year}\n".encode())
        for name in sorted(files):
            digest.update(name.encode() + b"\0" + hashlib.sha256(files[name]).digest())
        described = ", ".join(f"{k} = {v}" for k, v in params.items()) or "the base scenario as it is"
        header = (f"# Run {run_id} of study {self.name} ({self.source}), generated by cosim study from "
                  f"{self.base.source}: {described}\n")
        return RunTask(run_id, str(folder), recorded, header + body if body else "", files, digest.hexdigest(),
                       self.percentiles, error, self.vehicles_per_year)

    # ---------------------------------------------------------------- generation
    def _generate(self, params: dict[str, Any]) -> tuple[str, dict[str, bytes], dict[str, Any]]:
        """The run's scenario TOML (without its header comment), its input files, and the seeds used."""
        data = copy.deepcopy(self.base_data)
        if self.sensor_data:  # the study's own sensors join the base's
            data["sensors"] = list(data.get("sensors") or []) + [dict(d) for d in self.sensor_data]
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
        # [bridge] modes: the modes file (or CSV folder) goes into the run's folder, as a road profile does
        bridge = data.get("bridge")
        if isinstance(bridge, dict) and isinstance(bridge.get("modes"), str):
            source = self.base_dir / bridge["modes"]
            name = f"inputs/{Path(bridge['modes']).name}"
            if source.is_dir():
                for item in sorted(source.iterdir()):
                    if item.is_file():
                        files[f"{name}/{item.name}"] = item.read_bytes()
            else:
                files[name] = source.read_bytes()
            data["bridge"] = {**bridge, "modes": name}
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
            sumo = self.sumo_sets[str(value)]
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
            # [traffic.loads]: the loads axis keeps or removes it (and names its model); the seed is the run's
            loads = traffic.get("loads")
            if params.get("loads") == FIXED_LOADS:
                loads = None
            elif "loads" in params:
                model, site_files = _site_files(params["loads"], self.study_dir)
                loads = {**(loads or {}), "model": model}
                files.update(site_files)
            elif isinstance(loads, dict):
                model, site_files = _site_files(str(loads["model"]), self.base_dir)
                loads = {**loads, "model": model}
                files.update(site_files)
            traffic.pop("loads", None)
            if isinstance(loads, dict):
                if seed is not None:
                    loads["seed"] = seed
                traffic["loads"] = loads
                seeds["loads_seed"] = loads.get("seed")
            if self.duration is not None:
                traffic["end"] = float(traffic.get("begin", 0.0)) + self.duration
                solver = data.get("solver")
                if isinstance(solver, dict) and "duration" in solver:
                    solver["duration"] = self.duration
            data["traffic"] = traffic
            seeds["sumo_seed"] = traffic.get("seed")
        elif self.duration is not None:
            data.setdefault("solver", {})["duration"] = self.duration
        from cosim.run.toml_writer import toml_dumps

        return toml_dumps(data), files, seeds


def _loads_stem(value: str) -> str:
    """A ``loads`` value's short name: ``fixed``, a bundled site's name, or a folder's name."""
    if value == FIXED_LOADS or value.lower() in {site.lower() for site in bundled_sites()}:
        return value
    return Path(value).name or value


def _site_files(model: str, folder: Path) -> tuple[str, dict[str, bytes]]:
    """A run's ``[traffic.loads] model`` and the files it needs: a bundled site as it is; a folder of parameter
    files (relative to ``folder``) copied into the run's ``inputs/loads/<name>/`` (its ``.csv`` files)."""
    if model.lower() in {site.lower() for site in bundled_sites()}:
        return model, {}
    source = Path(model) if Path(model).is_absolute() else folder / model
    target = f"inputs/loads/{id_part(source.name) or 'site'}"
    files = {f"{target}/{path.name}": path.read_bytes() for path in sorted(source.iterdir())
             if path.is_file() and path.suffix.lower() == ".csv"}
    return target, files


def _check_loads(values: tuple[str, ...], base_data: dict[str, Any], base: Scenario, study_dir: Path,
                 source: str) -> None:
    """Each ``loads`` value: ``fixed``, or a site or folder that reads, with ``[traffic.loads]`` in the base."""
    sites = bundled_sites()
    has_loads = isinstance((base_data.get("traffic") or {}).get("loads"), dict)
    for i, value in enumerate(values):
        if value == FIXED_LOADS:
            continue
        where = f"{source}: sweep.loads[{i}]"
        path = Path(value) if Path(value).is_absolute() else study_dir / value
        if value.lower() not in {site.lower() for site in sites} and not path.is_dir():
            close = difflib.get_close_matches(value.lower(), [FIXED_LOADS, *(s.lower() for s in sites)], n=1)
            hint = ""
            if close:
                hint = "; did you mean " + (f'"{close[0]}"' if close[0] == FIXED_LOADS else
                                            f'"{next(s for s in sites if s.lower() == close[0])}"') + "?"
            raise ConfigError(
                f"{where}: {value!r} is neither \"{FIXED_LOADS}\" (the vTypes' own weights), a bundled site "
                f"({', '.join(sites)}) nor a folder of BTLS parameter files (relative to the study file){hint}")
        if not has_loads:
            raise ConfigError(
                f"{where}: {value!r} draws each vehicle's loads, which needs the base scenario's [traffic.loads] "
                f"(its seed, vtype_classes and wander are kept, the value replaces its model), but {base.source} "
                f"has none; add one (docs/scenario.md) or sweep only \"{FIXED_LOADS}\"")
        try:
            load_model(value, study_dir)
        except ConfigError as exc:
            raise ConfigError(f"{where}: {exc}") from None


def error_text(exc: BaseException) -> str:
    """What a row records of a failure: the message (with the exception's type unless it is cosim's), bounded."""
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
    raw = load_config(text, source)  # its [[sensors]] tables join each run's scenario as written
    parsed = load_config(raw, source, StudyFile)
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
    runs = math.prod(len(values) for values in axes.values())
    MAX_RUNS.check(runs, f"{source}: sweep", " x ".join(f"{len(v)} {axis}" for axis, v in axes.items()))
    has_traffic = "traffic" in base_data
    if "vehicles" in base_data or not has_traffic:
        for axis in SUMO_AXES:
            if axis in axes:
                raise ConfigError(
                    f"{source}: sweep.{axis}: needs SUMO traffic, but the base scenario {base.source} has "
                    f"{'[[vehicles]]' if base_data.get('vehicles') else 'no [traffic]'}; give a base with "
                    "[traffic] (docs/studies.md)")
    if "loads" in axes:
        _check_loads(axes["loads"], base_data, base, study_dir, source)
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
    base_names = {sensor.name for sensor in base.sensors}
    for i, sensor in enumerate(parsed.sensors):
        if sensor.name in base_names:
            raise ConfigError(f"{source}: sensors[{i}].name: the base scenario {base.source} already has a sensor "
                              f"{sensor.name!r}; give this one another name")
    if parsed.extremes is not None:
        known = [s.name for s in base.sensors] + [s.name for s in parsed.sensors]
        for i, sensor_name in enumerate(parsed.extremes.sensors or ()):
            if sensor_name not in known:
                raise ConfigError(f"{source}: extremes.sensors[{i}]: no sensor {sensor_name!r} "
                                  f"(the study has {', '.join(known) or 'no sensors'})")
    out = Path(output) if output is not None else Path(sec.output or f"studies/{name}")
    return Study(
        name=name, source=source, text=text, base=base, base_data=base_data, base_dir=scenario_dir,
        study_dir=study_dir, duration=sec.duration, output=out.resolve(), axes=axes,
        percentiles=tuple(sec.percentiles), plots=sec.plots, sumo_sets=sumo_sets,
        sensors=tuple(parsed.sensors), sensor_data=tuple(raw.get("sensors") or ()),
        vehicles_per_year=parsed.fatigue.vehicles_per_year, extremes=parsed.extremes,
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

