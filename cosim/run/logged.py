"""Runs with their MCAP logs, and what can be done with a log afterwards.

The command line (:mod:`cosim.cli`) is a thin layer over these functions;
nothing here prints.

- :func:`run_logged`: a scenario's time simulation, streamed into an MCAP log
  that embeds everything needed to run it again (the scenario text, its input
  files, the resolved parameters, section constants and frequencies). Ctrl-C
  or a failing solver still leave a finished log whose last status says why.
- :func:`replay_scenario`: the scenario that re-drives a bridge with a log's
  traffic, either the log's own (bit-identical sensor channels) or another
  scenario's bridge, sensors, road and solver.
- :func:`open_log`, :func:`iter_messages`, :func:`export_csv`,
  :func:`sensor_series`, :func:`compare_sensors`, :func:`plot_sensors`:
  reading logs in a streaming way (constant memory, except for plots), also
  logs cut short by a killed process.
"""
from __future__ import annotations

import contextlib
import csv
import datetime
import io
import json
import math
import os
import platform
import re
import signal
import sys
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from cosim import __version__
from cosim.core.bridge import BridgeModel, ModalResult
from cosim.core.section import SectionProperties
from cosim.core.simulation import SimulationResult, simulate
from cosim.errors import ConfigError, CosimError, LogError, ModelError, SumoError
from cosim.log.reader import read_log, traffic_from_log
from cosim.log.schemas import (
    EVENTS_SCHEMA,
    PROFILE,
    STATUS_SCHEMA,
    TOPIC_EVENTS,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_TYPES,
    TOPIC_VEHICLES,
    VEHICLE_ITEM,
)
from cosim.log.writer import BlockLogger, LogRecorder, TrafficLogger

from .scenario import Scenario, parse_scenario

MAGIC = b"\x89MCAP0\r\n"
SCENARIO_ATTACHMENT = "scenario.toml"
DERIVED_ATTACHMENTS = ("resolved.json", "section.json", "modes.json")
METADATA_NAME = "cosim"
REPLAY_METADATA_NAME = "replay"
LOGGED_MODES = 20
#: How often a "running" status is logged, s of simulated time.
STATUS_EVERY = 10.0
#: Display units per sensor quantity: (unit, factor from SI).
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "displacement": ("mm", 1e3),
    "velocity": ("mm/s", 1e3),
    "acceleration": ("m/s^2", 1.0),
    "bending_moment": ("kN m", 1e-3),
}
SI_UNITS = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2", "bending_moment": "N m"}
#: Scenario keys that name input files (dotted key -> attachment folder for unsafe paths).
INPUT_KEYS = ("road.profile",)

# --------------------------------------------------------------------------- payloads


def jsonable(value: Any) -> Any:
    """Plain JSON types from numpy scalars/arrays, tuples and dataclass fields (non-finite -> None)."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if hasattr(value, "tolist"):
        return jsonable(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def section_payload(section: SectionProperties) -> dict[str, Any]:
    return jsonable(asdict(section))


def modes_payload(modal: ModalResult) -> list[dict[str, Any]]:
    f_hz = modal.f_hz
    return [
        {
            "n": i + 1,
            "f_hz": float(f_hz[i]),
            "kind": modal.kinds[i],
            "participation": {kind: float(values[i]) for kind, values in modal.participation.items()},
        }
        for i in range(len(f_hz))
    ]


def damping_payload(bridge: BridgeModel) -> dict[str, Any]:
    return {"alpha": float(bridge.alpha), "beta": float(bridge.beta), "note": bridge.damping_note}


# --------------------------------------------------------------------------- TOML out


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)


def _toml_string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)  # shortest round-trip form: the same float reads back
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + "}"
    raise ValueError(f"cannot write {type(value).__name__} values to TOML")


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def toml_dumps(data: dict[str, Any]) -> str:
    """TOML text for the plain data :mod:`tomllib` reads (tables, arrays of tables, numbers, strings).

    ``tomllib.loads(toml_dumps(d)) == d`` for such data; floats keep every bit.
    """
    lines: list[str] = []

    def table(path: list[str], values: dict[str, Any], header: str | None) -> None:
        if header is not None:
            if lines:
                lines.append("")
            lines.append(header)
        for key, value in values.items():
            if not isinstance(value, dict) and not _is_table_array(value):
                lines.append(f"{_toml_key(key)} = {_toml_value(value)}")
        for key, value in values.items():
            name = ".".join(_toml_key(k) for k in [*path, key])
            if isinstance(value, dict):
                table([*path, key], value, f"[{name}]")
            elif _is_table_array(value):
                for item in value:
                    table([*path, key], item, f"[[{name}]]")

    table([], data, None)
    return "\n".join(lines) + "\n"


def _get_key(data: dict[str, Any], dotted: str) -> Any:
    node: Any = data
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _set_key(data: dict[str, Any], dotted: str, value: Any) -> None:
    *parents, last = dotted.split(".")
    node = data
    for part in parents:
        node = node[part]
    node[last] = value


# --------------------------------------------------------------------------- outputs


def check_new_file(path: Path, what: str, force: bool = False) -> None:
    """Fail before any work when ``path`` cannot be created: it exists (without ``force``), is a
    directory, or a file stands where a folder is needed. Missing folders are created later."""
    if path.is_dir():
        raise CosimError(f"{path}: is a directory, expected a file name for the {what}")
    if path.exists() and not force:
        raise CosimError(f"{path}: already exists; refusing to overwrite the {what} (use --force)")
    blocking = next((folder for folder in reversed(path.parents) if folder.exists() and not folder.is_dir()), None)
    if blocking is not None:
        raise CosimError(f"{path}: cannot create the folder for the {what}: {str(blocking)!r} is a file")


def unique_path(path: Path) -> Path:
    """``path``, or ``<stem>-2<suffix>``, ``-3``, ... if it exists (for default names)."""
    if not path.exists():
        return path
    for n in range(2, 10_000):
        candidate = path.with_name(f"{path.stem}-{n}{path.suffix}")
        if not candidate.exists():
            return candidate
    raise CosimError(f"{path}: too many runs with this name in the same second")


def _replace_into(partial: Path, path: Path, what: str) -> None:
    try:
        os.replace(partial, path)
    except OSError as exc:
        partial.unlink(missing_ok=True)
        raise CosimError(f"{path}: cannot write the {what} ({exc.strerror or exc})") from None


# --------------------------------------------------------------------------- running


class RunFailed(ModelError):
    """The time integration failed (e.g. diverged) after the log was created; the log says so.

    Attributes:
        log_path: the finished log, whose last status is "error".
    """

    def __init__(self, message: str, log_path: Path) -> None:
        super().__init__(message)
        self.log_path = log_path



@dataclass(frozen=True)
class InputFile:
    """A file the scenario refers to: its dotted key, the path as written, the file, and its attachment name."""

    key: str
    written: str
    path: Path
    attachment: str


def input_files(scenario: Scenario) -> list[InputFile]:
    """The scenario's input files (now: the road profile), with the names they get in a log.

    A relative path inside the scenario's folder keeps its name (``data/road.csv``);
    any other path is stored as ``inputs/<file name>``.
    """
    found = []
    profile = scenario.road_profile_path
    if profile is not None and scenario.road.profile is not None:
        written = scenario.road.profile
        pure = PurePosixPath(written.replace("\\", "/"))
        safe = not pure.is_absolute() and ".." not in pure.parts and not re.match(r"^[A-Za-z]:", written)
        name = str(pure) if safe else f"inputs/{pure.name}"
        found.append(InputFile("road.profile", written, profile, name))
    sumo_cfg = scenario.sumo_config_path
    if sumo_cfg is not None:
        for path in sumo_input_files(sumo_cfg):
            rel = path.relative_to(sumo_cfg.parent) if path.is_relative_to(sumo_cfg.parent) else Path(path.name)
            # Only the config is a scenario key; the files it names travel along as plain attachments.
            key = "traffic.sumo_config" if path == sumo_cfg else ""
            found.append(InputFile(key, str(path), path, f"sumo/{rel.as_posix()}"))
    return found


def sumo_input_files(config: Path) -> list[Path]:
    """The SUMO config and the net, route and additional files it names (parsed as XML, never run)."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(config).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ConfigError(f"{config}: not a readable SUMO config ({exc})") from None
    files = [config]
    for tag in ("net-file", "route-files", "additional-files"):
        for element in root.iter(tag):
            for name in element.get("value", "").split(","):
                if name.strip():
                    path = (config.parent / name.strip())
                    if path.is_file() and path not in files:
                        files.append(path)
    return files


@dataclass
class RunOutcome:
    """A finished logged run.

    Attributes:
        scenario: what ran.
        log_path: the MCAP log.
        result: extremes and counters of the run (histories are not kept: they are in the log).
        duration: simulated time, s; every: steps per logged sample; rate_hz: logging rate.
        on_deck: vehicle id -> (first, last) time on the deck, s (at every step).
        samples: sensor samples in the log (t = 0 included).
        wall_time: wall time of the whole logged run, s (time stepping and logging).
        log_bytes: size of the finished log.
    """

    scenario: Scenario
    log_path: Path
    result: SimulationResult
    duration: float
    every: int
    rate_hz: float
    on_deck: dict[str, tuple[float, float]]
    samples: int
    wall_time: float
    log_bytes: int


class _DeckTimes:
    """First and last time each vehicle is on the deck (every step; constant memory per vehicle)."""

    def __init__(self) -> None:
        self.spans: dict[str, list[float]] = {}

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001 - the simulate() observer protocol
        if not report.ids:
            return
        on = report.on_deck
        present = np.flatnonzero(on.any(axis=0))
        for j in present.tolist():
            column = on[:, j]
            first = float(times[int(np.argmax(column))])
            last = float(times[len(column) - 1 - int(np.argmax(column[::-1]))])
            span = self.spans.setdefault(report.ids[j], [first, last])
            span[0], span[1] = min(span[0], first), max(span[1], last)


class _Samples:
    def __init__(self) -> None:
        self.count = 0

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001
        self.count += int(np.count_nonzero(keep))


class _InterruptOnce:
    """Ctrl-C stops the run once; while the log is being finished, further Ctrl-C are held back.

    Installed only over Python's default SIGINT handler, in the main thread.
    """

    def __init__(self) -> None:
        self.closing = False
        self._old: Any = None

    def __enter__(self) -> "_InterruptOnce":
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._old = signal.signal(signal.SIGINT, self._handle)
        return self

    def _handle(self, signum, frame) -> None:  # noqa: ANN001
        if self.closing:
            return
        self.closing = True
        raise KeyboardInterrupt

    def __exit__(self, *exc: object) -> None:
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
            self._old = None


def run_logged(
    scenario: Scenario,
    log_path: Path,
    *,
    force: bool = False,
    bridge: BridgeModel | None = None,
    progress: Callable[[float], None] | None = None,
    replay: dict[str, str] | None = None,
    attachments: dict[str, bytes] | None = None,
    started: datetime.datetime | None = None,
    traffic: Any = None,
    duration: float | None = None,
) -> RunOutcome:
    """Run ``scenario``'s vehicles over its bridge and stream everything into the MCAP log ``log_path``.

    Everything that can fail on bad input (bridge, road, vehicles, modes) is
    built before the log file is created. The log then holds the scenario
    text and input files, ``resolved.json``, ``section.json``, ``modes.json``,
    a "cosim" metadata record, the sensor samples (from t = 0, at rest), the
    vehicles on the deck, traffic events and status messages.

    Args:
        scenario: a scenario with [[vehicles]].
        log_path: the log to write (its folder is created).
        force: overwrite an existing log.
        bridge: the scenario's model, if already built.
        progress: called with the fraction done after every block of steps.
        replay: for a replay, what was replayed (stored as the "replay" metadata record).
        attachments: more documents to store (name -> bytes).
        started: wall-clock start time for the metadata (default now).
        traffic: a traffic source to use instead of the scenario's (replay of logged SUMO frames).
        duration: simulated time instead of the scenario's, s.

    Raises:
        KeyboardInterrupt: Ctrl-C; the log is finished first, with status "interrupted".
        RunFailed: the solution diverged; the log is finished first, with status "error".
        ConfigError, ModelError, LogError: bad input, before the log is created.
    """
    if not scenario.vehicles and scenario.traffic is None and traffic is None:
        raise ConfigError(f"{scenario.source}: the scenario has no [[vehicles]] and no [traffic]: "
                          "nothing to simulate in time")
    started = started or datetime.datetime.now().astimezone()
    if bridge is None:
        bridge = scenario.build_bridge()
    live_sumo = traffic is None and scenario.traffic is not None
    if traffic is None and not live_sumo:
        traffic = scenario.build_vehicles()
    road = scenario.build_road()
    solver = scenario.solver_settings()
    sensors = scenario.sensors_core()
    duration = duration if duration is not None else scenario.duration
    every = scenario.output_every
    rate_hz = scenario.output_rate_hz
    names = [s.name for s in sensors]
    modal = bridge.modes(count=LOGGED_MODES)
    inputs = input_files(scenario)
    files = {}
    for item in inputs:
        try:
            files[item.attachment] = item.path.read_bytes()
        except OSError as exc:
            raise ConfigError(f"{scenario.source}: {item.key}: cannot read {item.path} ({exc.strerror})") from None
    check_new_file(log_path, "log", force)
    meta = {
        "version": __version__,
        "kind": "replay" if replay else "run",
        "scenario": scenario.title,
        "source": scenario.source,
        "started": started.isoformat(timespec="seconds"),
        "dt": repr(solver.dt),
        "scheme": solver.scheme,
        "basis": solver.basis,
        "duration": repr(duration),
        "every": str(every),
        "rate_hz": repr(rate_hz),
        "sensors": json.dumps(names),
        "quantities": json.dumps([s.quantity for s in sensors]),
        "vehicles": json.dumps([v.id for v in scenario.vehicles]),
        "traffic": "sumo" if (live_sumo or scenario.traffic is not None) else (
            "replayed frames" if traffic is not None and not scenario.vehicles else "scripted"),
        "inputs": json.dumps({item.key: item.attachment for item in inputs if item.key}),
        "python": platform.python_version(),
    }
    resolved = {
        "scenario": scenario.model_dump(mode="json", by_alias=True, warnings=False),
        "derived": {"duration": duration, "output_every": every, "rate_hz": rate_hz,
                    "leave_time": jsonable(scenario.leave_time)},
    }
    extremes = _DeckTimes()
    samples = _Samples()
    wall_start = time.perf_counter()
    with _InterruptOnce() as guard, LogRecorder(log_path, names, force=force) as rec:
        rec.attach(SCENARIO_ATTACHMENT, scenario.text, "application/toml")
        for name, data in {**files, **(attachments or {})}.items():
            media = {".csv": "text/csv", ".toml": "application/toml"}.get(Path(name).suffix.lower(),
                                                                          "application/octet-stream")
            rec.attach(name, data, media)
        rec.attach("resolved.json", json.dumps(jsonable(resolved), indent=1), "application/json")
        rec.attach("section.json", json.dumps(section_payload(bridge.section), indent=1), "application/json")
        rec.attach("modes.json", json.dumps({"modes": modes_payload(modal), "damping": damping_payload(bridge)},
                                            indent=1), "application/json")
        rec.metadata(METADATA_NAME, meta)
        if replay:
            rec.metadata(REPLAY_METADATA_NAME, replay)
        rec.status(0.0, "started", f"{scenario.title}: {duration:g} s simulated, dt = {solver.dt:g} s, "
                                   f"logging at {rate_hz:g} Hz", progress=0.0)
        rec.write(TOPIC_SENSORS, 0.0, {"t": 0.0, **{n: 0.0 for n in names}})  # at rest
        try:
            with contextlib.ExitStack() as stack, \
                    BlockLogger(rec, names, duration, status_every=STATUS_EVERY) as logger:
                if live_sumo:  # SUMO starts inside the log: a SUMO failure is the log's final status
                    traffic = stack.enter_context(scenario.build_traffic(frame_sink=TrafficLogger(rec)))
                result = simulate(bridge, logger.paced(traffic), duration, solver=solver, sensors=sensors, road=road,
                                  output_every=every, progress=progress, observers=[extremes, samples, logger],
                                  collect=False)
                guard.closing = True  # a Ctrl-C from here on must not cut the log's ending short
        except KeyboardInterrupt:
            guard.closing = True
            rec.close("interrupted", "interrupted by the user (SIGINT)", wall_time=time.perf_counter() - wall_start)
            raise
        except CosimError as exc:
            guard.closing = True
            try:
                rec.close("error", f"{type(exc).__name__}: {exc}", wall_time=time.perf_counter() - wall_start)
            except (OSError, ValueError, LogError):
                pass  # the log itself failed (e.g. disk full): report the first error
            if isinstance(exc, ModelError):
                raise RunFailed(f"{scenario.source}: {exc}", log_path) from exc
            if isinstance(exc, SumoError) and getattr(traffic, "sumo_steps", 0) > 0:
                raise RunFailed(f"{scenario.source}: {exc}", log_path) from exc  # SUMO failed mid-run
            raise
        wall = time.perf_counter() - wall_start
        rec.close("finished", f"{duration:g} s simulated in {wall:.3g} s", wall_time=wall)
    return RunOutcome(
        scenario=scenario, log_path=log_path, result=result, duration=duration, every=every, rate_hz=rate_hz,
        on_deck={k: (v[0], v[1]) for k, v in extremes.spans.items()}, samples=samples.count + 1,
        wall_time=wall, log_bytes=log_path.stat().st_size,
    )


# --------------------------------------------------------------------------- reading


@dataclass
class LogOverview:
    """What a log holds, without its messages.

    Attributes:
        path: the file.
        complete: finished with its summary and footer (False: cut short, read up to its last chunk).
        library: who wrote it.
        metadata: name -> {key: value}.
        attachments: name -> bytes.
        counts: topic -> messages.
        end_time: log time of the last message, s (simulated time reached).
        final_status: the last /cosim/status message, or None.
        sensor_names: the sensor channels (from the metadata or the sensor schema).
    """

    path: Path
    complete: bool
    library: str = ""
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    end_time: float = 0.0
    final_status: dict | None = None
    sensor_names: list[str] = field(default_factory=list)
    quantities: list[str] = field(default_factory=list)
    size: int = 0

    @property
    def truncated(self) -> bool:
        return not self.complete

    @property
    def info(self) -> dict[str, str]:
        """The "cosim" metadata record."""
        return self.metadata.get(METADATA_NAME, {})



def _open_bytes(path: Path) -> Any:
    try:
        fh = open(path, "rb")
    except OSError as exc:
        raise LogError(f"{path}: cannot read ({exc.strerror})") from None
    if fh.read(8) != MAGIC:
        fh.close()
        raise LogError(f"{path}: not an MCAP file")
    fh.seek(0)
    return fh


def _is_complete(fh: Any) -> bool:
    fh.seek(0, os.SEEK_END)
    size = fh.tell()
    if size < 16:
        fh.seek(0)
        return False
    fh.seek(-8, os.SEEK_END)
    complete = fh.read(8) == MAGIC
    fh.seek(0)
    return complete


def _corrupt(path: Path, exc: BaseException) -> LogError:
    return LogError(f"{path}: corrupt MCAP file ({type(exc).__name__}: {exc})")


def _records(path: Path, fh: Any, complete: bool) -> Iterator[tuple[str, Any]]:
    """Every record of the file in order ("header", "channel", "schema", "message", "attachment",
    "metadata"); a cut-off file ends quietly after its last complete record, damage inside raises."""
    from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema
    from mcap.stream_reader import CRCValidationError, StreamReader

    reader = StreamReader(fh, validate_crcs=True)
    try:
        for record in reader.records:
            if isinstance(record, Message):
                yield "message", record
            elif isinstance(record, Channel):
                yield "channel", record
            elif isinstance(record, Schema):
                yield "schema", record
            elif isinstance(record, Attachment):
                yield "attachment", record
            elif isinstance(record, Metadata):
                yield "metadata", record
            elif isinstance(record, Header):
                yield "header", record
    except CRCValidationError as exc:
        raise _corrupt(path, exc) from None
    except LogError:
        raise
    except Exception as exc:  # noqa: BLE001 - a cut-off file ends in a partial record
        if complete:
            raise _corrupt(path, exc) from None


def _decode(path: Path, topic: str, data: bytes) -> dict:
    try:
        value = json.loads(data)
    except (ValueError, UnicodeDecodeError):
        raise LogError(f"{path}: a message on {topic} is not valid JSON") from None
    if not isinstance(value, dict):
        raise LogError(f"{path}: a message on {topic} is not a JSON object")
    return value


def open_log(path: str | os.PathLike[str]) -> LogOverview:
    """Read a log's metadata, attachments, message counts and final status (not the messages).

    A finished log is read through its summary, and the CRC of every chunk is
    checked; a log cut short is read record by record up to its last complete
    chunk. Either way in constant memory (besides the attachments).

    Raises:
        LogError: missing, not MCAP, not a cosim log, or damaged (e.g. a CRC that does not match).
    """
    path = Path(path)
    with _open_bytes(path) as fh:
        complete = _is_complete(fh)
        fh.seek(0, os.SEEK_END)
        out = LogOverview(path=path, complete=complete, size=fh.tell())
        fh.seek(0)
        if complete:
            profile, sensor_schema = _overview_from_summary(path, fh, out)
        else:
            profile, sensor_schema = _overview_from_records(path, fh, out)
    if profile is None:
        raise LogError(f"{path}: an MCAP file whose header cannot be read")
    if profile != PROFILE:
        raise LogError(f"{path}: an MCAP file, but not a cosim log (profile {profile!r})")
    info = out.info
    try:
        out.sensor_names = json.loads(info["sensors"]) if "sensors" in info else []
        out.quantities = json.loads(info["quantities"]) if "quantities" in info else []
    except ValueError:
        raise LogError(f"{path}: malformed cosim metadata (sensors)") from None
    if not out.sensor_names and sensor_schema is not None:
        try:
            props = json.loads(sensor_schema).get("properties", {})
        except ValueError:
            props = {}
        out.sensor_names = [name for name in props if name != "t"]
    if len(out.quantities) != len(out.sensor_names):
        out.quantities = ["" for _ in out.sensor_names]
    return out


def _overview_from_records(path: Path, fh: Any, out: LogOverview) -> tuple[str | None, bytes | None]:
    channels: dict[int, str] = {}
    schemas: dict[int, bytes] = {}
    sensor_schema: bytes | None = None
    profile = None
    for kind, record in _records(path, fh, False):
        if kind == "message":
            topic = channels.get(record.channel_id)
            if topic is None:
                continue
            out.counts[topic] = out.counts.get(topic, 0) + 1
            out.end_time = max(out.end_time, record.log_time / 1e9)
            if topic == TOPIC_STATUS:
                out.final_status = _decode(path, topic, record.data)
        elif kind == "channel":
            channels[record.id] = record.topic
            if record.topic == TOPIC_SENSORS:
                sensor_schema = schemas.get(record.schema_id)
        elif kind == "schema":
            schemas[record.id] = record.data
        elif kind == "attachment":
            out.attachments[record.name] = record.data
        elif kind == "metadata":
            out.metadata[record.name] = dict(record.metadata)
        elif kind == "header":
            profile = record.profile
            out.library = record.library
    return profile, sensor_schema


def _overview_from_summary(path: Path, fh: Any, out: LogOverview) -> tuple[str | None, bytes | None]:
    import struct

    from mcap.data_stream import ReadDataStream
    from mcap.reader import make_reader
    from mcap.records import Chunk, Message
    from mcap.stream_reader import (
        CRCValidationError,
        breakup_chunk,
        get_chunk_data_stream,
    )

    try:
        reader = make_reader(fh, validate_crcs=True)
        header = reader.get_header()
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            raise ValueError("no summary section")
        topics = {cid: ch.topic for cid, ch in summary.channels.items()}
        stats = summary.statistics
        for cid, count in stats.channel_message_counts.items():
            if cid in topics and count:
                out.counts[topics[cid]] = count
        end_time = stats.message_end_time
        status_ids = {cid for cid, topic in topics.items() if topic == TOPIC_STATUS}
        last_status: tuple[int, int, bytes] | None = None
        for index in summary.chunk_indexes:  # every chunk's CRC, without parsing its messages
            fh.seek(index.chunk_start_offset)
            head = fh.read(9)
            if len(head) != 9 or head[0] != 0x06:
                raise ValueError(f"no chunk record at offset {index.chunk_start_offset}")
            (length,) = struct.unpack("<Q", head[1:])
            chunk = Chunk.read(ReadDataStream(io.BytesIO(fh.read(length))))
            if index.message_end_time < end_time:
                get_chunk_data_stream(chunk, validate_crc=True)
                continue
            for record in breakup_chunk(chunk, validate_crc=True):  # the last chunk(s): the final status
                if isinstance(record, Message) and record.channel_id in status_ids:
                    key = (record.log_time, record.sequence, record.data)
                    if last_status is None or key[:2] >= last_status[:2]:
                        last_status = key
        if last_status is not None:
            out.final_status = _decode(path, TOPIC_STATUS, last_status[2])
        for att in reader.iter_attachments():
            out.attachments[att.name] = att.data
        for meta in reader.iter_metadata():
            out.metadata[meta.name] = dict(meta.metadata)
    except LogError:
        raise
    except (CRCValidationError, Exception) as exc:  # noqa: BLE001 - anything wrong in a finished file is damage
        raise _corrupt(path, exc) from None
    out.end_time = end_time / 1e9
    sensor_schema = None
    for ch in summary.channels.values():
        if ch.topic == TOPIC_SENSORS and ch.schema_id in summary.schemas:
            sensor_schema = summary.schemas[ch.schema_id].data
    return header.profile, sensor_schema


def iter_messages(path: str | os.PathLike[str], topics: Iterable[str]) -> Iterator[tuple[str, dict]]:
    """The decoded messages on ``topics``, in file order (chunk by chunk: constant memory).

    A log cut short yields what it holds up to its last complete chunk.
    """
    path = Path(path)
    wanted = set(topics)
    with _open_bytes(path) as fh:
        complete = _is_complete(fh)
        channels: dict[int, str] = {}
        for kind, record in _records(path, fh, complete):
            if kind == "channel":
                channels[record.id] = record.topic
            elif kind == "message":
                topic = channels.get(record.channel_id)
                if topic in wanted:
                    yield topic, _decode(path, topic, record.data)


def sensor_series(path: str | os.PathLike[str], names: Sequence[str] | None = None
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log as arrays (t, {name: values}), sorted by time."""
    overview_names = open_log(path).sensor_names
    names = list(names) if names is not None else overview_names
    t: list[float] = []
    columns: dict[str, list[float]] = {n: [] for n in names}
    for _, msg in iter_messages(path, [TOPIC_SENSORS]):
        t.append(msg["t"])
        for n in names:
            columns[n].append(msg[n])
    order = np.argsort(np.asarray(t), kind="stable")
    return np.asarray(t)[order], {n: np.asarray(v, dtype=float)[order] for n, v in columns.items()}


# --------------------------------------------------------------------------- export


EXPORT_TOPICS = (TOPIC_SENSORS, TOPIC_VEHICLES, TOPIC_EVENTS, TOPIC_STATUS)
VEHICLE_COLUMNS = ("t", *VEHICLE_ITEM["properties"])
EVENT_COLUMNS = tuple(EVENTS_SCHEMA["properties"])
STATUS_COLUMNS = tuple(STATUS_SCHEMA["properties"])


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return str(value)


def export_csv(log: str | os.PathLike[str], out: str | os.PathLike[str], topic: str = TOPIC_SENSORS,
               force: bool = False) -> tuple[int, list[str]]:
    """Write one topic of a log as CSV (SI units, a header row); returns (rows, columns).

    ``/cosim/sensors``: ``t,<sensor names>``; ``/cosim/vehicles``: one row per
    vehicle per sample; events and status: one row per message. Written through
    a temporary file, so a failure leaves no half file.
    """
    log, out = Path(log), Path(out)
    overview = open_log(log)
    if topic not in EXPORT_TOPICS:
        present = ", ".join(t for t in EXPORT_TOPICS if overview.counts.get(t))
        raise CosimError(f"--topic {topic}: not an exportable topic (this log has: {present})")
    if topic == TOPIC_SENSORS:
        columns = ["t", *overview.sensor_names]
    elif topic == TOPIC_VEHICLES:
        columns = list(VEHICLE_COLUMNS)
    elif topic == TOPIC_EVENTS:
        columns = list(EVENT_COLUMNS)
    else:
        columns = list(STATUS_COLUMNS)
    check_new_file(out, "CSV", force)
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(out.name + ".part")
    rows = 0
    try:
        with open(partial, "w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(columns)
            for _, msg in iter_messages(log, [topic]):
                if topic == TOPIC_VEHICLES:
                    for vehicle in msg["vehicles"]:
                        writer.writerow([_cell(msg["t"]), *(_cell(vehicle.get(c)) for c in columns[1:])])
                        rows += 1
                else:
                    writer.writerow([_cell(msg.get(c)) for c in columns])
                    rows += 1
    except OSError as exc:
        partial.unlink(missing_ok=True)
        raise CosimError(f"{out}: cannot write the CSV ({exc.strerror or exc})") from None
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
    _replace_into(partial, out, "CSV")
    return rows, columns


# --------------------------------------------------------------------------- replay


def _extract(overview: LogOverview, folder: Path) -> dict[str, str]:
    """Write the log's input files into ``folder``; returns dotted key -> attachment name."""
    try:
        inputs = json.loads(overview.info.get("inputs", "{}"))
    except ValueError:
        raise LogError(f"{overview.path}: malformed cosim metadata (inputs)") from None
    for key, name in inputs.items():
        pure = PurePosixPath(name)
        if pure.is_absolute() or ".." in pure.parts or name not in overview.attachments:
            raise LogError(f"{overview.path}: input file {name!r} ({key}) is missing or has an unsafe name")
        target = folder.joinpath(*pure.parts)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(overview.attachments[name])
    return inputs


def _scenario_text(overview: LogOverview) -> str:
    raw = overview.attachments.get(SCENARIO_ATTACHMENT)
    if raw is None:
        raise LogError(f"{overview.path}: the log has no embedded {SCENARIO_ATTACHMENT} (not written by cosim run?)")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise LogError(f"{overview.path}: its {SCENARIO_ATTACHMENT} is not UTF-8 text") from None


@dataclass(frozen=True)
class ReplayPlan:
    """What a replay runs: the scenario, the log it came from, and what to record about it."""

    scenario: Scenario
    overview: LogOverview
    own: bool
    record: dict[str, str]
    attachments: dict[str, bytes] = field(default_factory=dict)
    traffic: Any = None  # the logged SUMO frames, for a log whose traffic came from SUMO
    duration: float | None = None


def replay_scenario(log: str | os.PathLike[str], folder: Path, other: Scenario | None = None) -> ReplayPlan:
    """The scenario of a replay, with its input files written into ``folder`` (a scratch folder).

    Without ``other``: the log's own scenario (parsed from its embedded text,
    never executed). With ``other``: ``other``'s bridge, sensors, road, solver
    and output with the log's traffic: its ``[[vehicles]]``, or, for SUMO
    traffic, the logged SUMO frames (positions along the original bridge's
    axis; SUMO itself is not run again).

    Raises:
        LogError: the log is unreadable or has no scenario.
        ConfigError: the log's traffic does not fit ``other``'s bridge (e.g. a wheel path off its deck).
    """
    overview = open_log(log)
    text = _scenario_text(overview)
    source = f"{overview.path} ({SCENARIO_ATTACHMENT})"
    try:
        logged = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise LogError(f"{source}: TOML syntax error: {exc}") from None
    record = {"log": str(overview.path), "log_scenario": overview.info.get("scenario", ""),
              "log_started": overview.info.get("started", ""), "log_status": status_word(overview)}
    sumo = bool(overview.counts.get(TOPIC_TRAFFIC)) or "traffic" in logged
    if other is None:
        inputs = _extract(overview, folder)
        data = tomllib.loads(text)
        changed = False
        for key, name in inputs.items():
            if _get_key(data, key) != name:
                _set_key(data, key, name)
                changed = True
        scenario = parse_scenario(toml_dumps(data) if changed else text, source, base_dir=folder)
        record["scenario"] = "the log's own"
        plan = ReplayPlan(scenario, overview, True, record)
    else:
        if not sumo and not logged.get("vehicles"):
            raise LogError(f"{overview.path}: the log's scenario has no [[vehicles]] and no [traffic]: "
                           "no traffic to replay")
        data = tomllib.loads(other.text)
        data.pop("traffic", None)
        data.pop("vehicles", None)
        if not sumo:
            data["vehicles"] = logged["vehicles"]
        for item in input_files(other):
            if not item.key or item.key.startswith("traffic."):
                continue
            target = folder.joinpath(*PurePosixPath(item.attachment).parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(item.path.read_bytes())
            _set_key(data, item.key, item.attachment)
        merged = toml_dumps(data)
        scenario = parse_scenario(merged, f"{other.source} with the traffic of {overview.path}", base_dir=folder)
        record["scenario"] = other.source
        attachments = {"replay/bridge-scenario.toml": other.text.encode(),
                       "replay/traffic-scenario.toml": text.encode()}
        plan = ReplayPlan(scenario, overview, False, record, attachments)
    if not sumo:
        return plan
    try:
        duration = float(overview.info["duration"])
        step = float(logged["traffic"].get("step", 0.05))
    except (KeyError, ValueError, TypeError, AttributeError):
        raise LogError(f"{overview.path}: malformed cosim metadata (duration or traffic step)") from None
    contents = read_log(overview.path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
    # Frames are logged only while vehicles are near the deck: pad to the logged run's end, or,
    # for a cut-off log, to the last time the log reached.
    duration = min(duration, overview.end_time) if overview.end_time > 0 else duration
    traffic = traffic_from_log(contents, plan.scenario.bridge.length, step, until=duration)
    record["traffic"] = f"{len(contents.messages.get(TOPIC_TRAFFIC, []))} logged SUMO frames"
    return ReplayPlan(plan.scenario, overview, plan.own, record, plan.attachments, traffic, duration)


def status_word(overview: LogOverview) -> str:
    """The log's final state, e.g. "finished", or "running (truncated)" for a log cut short."""
    status = overview.final_status or {}
    return str(status.get("state", "unknown")) + ("" if overview.complete else " (truncated)")


@dataclass(frozen=True)
class Comparison:
    """Sensor channels of two logs compared sample by sample.

    Attributes:
        names: the channels both logs have.
        samples_a, samples_b: sensor samples in each log.
        compared: samples compared (the common part: a log cut short has fewer).
        identical: every compared sample has the same time and exactly the same floats.
        max_abs_diff: per shared channel, the largest difference (SI units).
        extremes_a, extremes_b: per channel of each log, (min, max) over all its samples.
    """

    names: list[str]
    samples_a: int
    samples_b: int
    compared: int
    identical: bool
    max_abs_diff: dict[str, float]
    extremes_a: dict[str, tuple[float, float]]
    extremes_b: dict[str, tuple[float, float]]


def compare_sensors(log_a: str | os.PathLike[str], log_b: str | os.PathLike[str]) -> Comparison:
    """Compare the sensor channels of two logs, streaming both (constant memory)."""
    names_a, names_b = open_log(log_a).sensor_names, open_log(log_b).sensor_names
    names = [n for n in names_a if n in names_b]
    diff = {n: 0.0 for n in names}
    extremes: list[dict[str, list[float]]] = [{n: [math.inf, -math.inf] for n in names_a},
                                              {n: [math.inf, -math.inf] for n in names_b}]
    counts = [0, 0]
    compared, identical = 0, True
    streams = [iter_messages(log_a, [TOPIC_SENSORS]), iter_messages(log_b, [TOPIC_SENSORS])]
    while True:
        items = [next(stream, None) for stream in streams]
        if items[0] is None and items[1] is None:
            break
        for i, item in enumerate(items):
            if item is None:
                continue
            counts[i] += 1
            msg = item[1]
            for n, lo_hi in extremes[i].items():
                value = msg.get(n)
                if isinstance(value, (int, float)):
                    lo_hi[0], lo_hi[1] = min(lo_hi[0], value), max(lo_hi[1], value)
        if items[0] is None or items[1] is None:
            continue
        a, b = items[0][1], items[1][1]
        compared += 1
        if a.get("t") != b.get("t"):
            identical = False
            continue
        for n in names:
            if a[n] != b[n]:
                identical = False
                diff[n] = max(diff[n], abs(a[n] - b[n]))

    def fixed(ext: dict[str, list[float]]) -> dict[str, tuple[float, float]]:
        return {n: (lo, hi) if lo <= hi else (0.0, 0.0) for n, (lo, hi) in ext.items()}

    return Comparison(names, counts[0], counts[1], compared, identical and compared > 0 and bool(names), diff,
                      fixed(extremes[0]), fixed(extremes[1]))


# --------------------------------------------------------------------------- plot


def plot_sensors(log: str | os.PathLike[str], out: str | os.PathLike[str], names: Sequence[str] | None = None,
                 force: bool = False) -> list[str]:
    """Draw the time histories of sensors of a log into ``out`` (one subplot each); returns their names."""
    overview = open_log(log)
    available = overview.sensor_names
    if not available:
        raise CosimError(f"{log}: the log has no sensor channels to plot")
    chosen = list(names) if names else list(available)
    unknown = [n for n in chosen if n not in available]
    if unknown:
        raise CosimError(f"{log}: no sensor {', '.join(unknown)} in this log (sensors: {', '.join(available)})")
    out = Path(out)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    suffix = out.suffix.lower().lstrip(".")
    if suffix not in FigureCanvasAgg.get_supported_filetypes():
        raise CosimError(f"{out}: unsupported file type for the plot (expected .png, .pdf, .svg, ...)")
    check_new_file(out, "plot", force)
    t, series = sensor_series(log, chosen)
    quantity = dict(zip(available, overview.quantities))
    fig = Figure(figsize=(9.0, 1.9 * len(chosen) + 0.9), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(chosen), 1, sharex=True, squeeze=False)[:, 0]
    for ax, name in zip(axes, chosen):
        unit, factor = DISPLAY_UNITS.get(quantity.get(name, ""), ("SI", 1.0))
        ax.plot(t, series[name] * factor, linewidth=0.8)
        ax.set_ylabel(f"{name}\n[{unit}]", fontsize=9)
        ax.grid(True, linewidth=0.4, alpha=0.6)
    axes[-1].set_xlabel("t [s]")
    title = overview.info.get("scenario", Path(log).stem)
    status = status_word(overview)
    fig.suptitle(f"{title} — {Path(log).name} ({status})", fontsize=10)
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        fig.savefig(out, dpi=110)
    except (OSError, ValueError) as exc:
        raise CosimError(f"{out}: cannot write the plot ({exc})") from None
    return chosen


def load_attachment_json(overview: LogOverview, name: str) -> Any:
    """A JSON attachment of the log, or None."""
    raw = overview.attachments.get(name)
    if raw is None:
        return None
    try:
        return json.loads(raw)
    except ValueError:
        return None


__all__ = [
    "Comparison",
    "LogOverview",
    "ReplayPlan",
    "RunFailed",
    "RunOutcome",
    "check_new_file",
    "compare_sensors",
    "export_csv",
    "input_files",
    "iter_messages",
    "open_log",
    "plot_sensors",
    "replay_scenario",
    "run_logged",
    "sensor_series",
    "toml_dumps",
    "unique_path",
]
