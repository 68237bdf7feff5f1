"""Replays: a bridge re-driven with the traffic recorded in a log, and two logs' sensors compared.

- :func:`replay_log`: a replay as one call (``cosim replay``): the replay's
  scenario, its logged run and the comparison of its sensors with the log's
  (:class:`ReplayOutcome`).
- :func:`replay_scenario`: the scenario that re-drives a bridge with a log's
  traffic, either the log's own (bit-identical sensor channels) or another
  scenario's bridge, sensors, road and solver; run it with
  :func:`cosim.run.logged.run_logged` and the plan's extras.
- :func:`compare_sensors`: two logs' sensor channels, sample by sample
  (:class:`Comparison`), streaming both.
"""
from __future__ import annotations

import json
import math
import os
import re
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from cosim.errors import ConfigError, LogError
from cosim.log.reader import LogOverview, check_messages, iter_messages, open_log
from cosim.log.replay_source import LoggedTraffic
from cosim.log.schemas import SCENARIO_ATTACHMENT, TOPIC_SENSORS, TOPIC_TRAFFIC
from cosim.sumo.files import FILE_OPTIONS, read_config

from .api import RunStart, log_target
from .config_base import load_config
from .inputs import input_files, scenario_files
from .logged import RunOutcome, run_logged
from .outputs import check_not_input, unique_path
from .scenario import Scenario, load_scenario, parse_scenario
from .toml_writer import get_key, set_key, toml_dumps

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


#: The scenario keys that name input files; a replay takes each from the log's attachments only.
FILE_KEYS: tuple[str, ...] = ("road.profile", "traffic.sumo_config", "traffic.records.file")
#: Attachments that are documents about the run, not its input files.
DERIVED_ATTACHMENTS = frozenset({SCENARIO_ATTACHMENT, "resolved.json", "section.json", "modes.json"})
_DRIVE = re.compile(r"^[A-Za-z]:")


def _safe_name(name: str) -> PurePosixPath | None:
    """``name`` as a relative path inside a folder, or None if it could point anywhere else."""
    if not name or "\\" in name or "\0" in name or _DRIVE.match(name) or len(name) > 1024:
        return None
    pure = PurePosixPath(name)
    if pure.is_absolute() or any(part in ("..", ".", "") for part in name.split("/")):
        return None
    return pure


def _extract(overview: LogOverview, folder: Path) -> tuple[dict[str, str], set[Path]]:
    """Write the log's input files (every attachment but the documents about the run) into ``folder``.

    Returns the "inputs" metadata (dotted key -> attachment name) and the files written.

    Raises:
        LogError: an attachment's name is absolute, has ``..`` or is not a plain relative path; an input
            names a key that is not a file key or an attachment the log does not hold.
    """
    path = overview.path
    written: set[Path] = set()
    for name, data in overview.attachments.items():
        if name in DERIVED_ATTACHMENTS or name.startswith("replay/"):
            continue
        pure = _safe_name(name)
        if pure is None:
            raise LogError(f"{path}: attachment {name[:80]!r} has an unsafe name (absolute, '..' or not a plain "
                           "relative path); a log's input files have relative names")
        target = folder.joinpath(*pure.parts)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        except OSError as exc:
            raise LogError(f"{path}: attachment {name!r} cannot be written to a scratch folder "
                           f"({exc.strerror or exc})") from None
        written.add(target)
    inputs = json.loads(overview.info.get("inputs", "{}"))  # checked by open_log: names -> names
    for key, name in inputs.items():
        if key not in FILE_KEYS:
            raise LogError(f"{path}: the log's inputs name an unknown key {key[:80]!r} (file keys: "
                           f"{', '.join(FILE_KEYS)})")
        if _safe_name(name) is None or folder.joinpath(*PurePosixPath(name).parts) not in written:
            raise LogError(f"{path}: input file {name[:80]!r} ({key}) is missing or has an unsafe name")
    return inputs, written


def _confine(overview: LogOverview, data: dict[str, Any], inputs: dict[str, str], folder: Path,
             written: set[Path]) -> bool:
    """Point every file key of the log's scenario at the log's own attachments, or refuse.

    A crafted log could name ``/home/user/.ssh/id_rsa`` as its network or
    ``/etc/passwd`` as its road profile; a replay reads such keys, and the files
    the embedded SUMO config names, only from the attachments extracted into ``folder``.

    Returns:
        Whether a key was changed (the scenario's text must then be written anew).

    Raises:
        LogError: a file key or a file the SUMO config names is not one of the log's attachments.
    """
    path = overview.path
    changed = False
    for key, name in inputs.items():
        if get_key(data, key) is not None and get_key(data, key) != name:
            set_key(data, key, name)
            changed = True
    for key in FILE_KEYS:
        value = get_key(data, key)
        if value is None:
            continue
        if not isinstance(value, str) or value not in inputs.values():
            raise LogError(f"{path}: the log's scenario names {key} = {str(value)[:80]!r}, which is not one of "
                           "the log's attachments; a replay reads its input files only from the log")
    config_name = get_key(data, "traffic.sumo_config")
    if not isinstance(config_name, str):
        return changed
    config = folder.joinpath(*PurePosixPath(config_name).parts)
    try:
        parsed = read_config(config)
    except ConfigError as exc:
        raise LogError(f"{path}: the log's SUMO config: {exc}") from None
    base = config.parent
    for option in FILE_OPTIONS:
        for _, names in parsed.options(option):
            for name in names:
                _confined_name(path, option, name, base, written)
    return changed


def _confined_name(path: Path, option: str, name: str, base: Path, written: set[Path]) -> None:
    """Refuse a file named by the log's SUMO config unless it is one of the attachments written."""
    pure = _safe_name(name)
    target = Path(os.path.normpath(base.joinpath(*pure.parts))) if pure is not None else None
    if target is None or target not in written:
        raise LogError(f"{path}: the log's SUMO config names {option} {name[:80]!r}, which is not one of the "
                       "log's attachments; a replay reads its input files only from the log")


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


def covered_time(overview: LogOverview) -> float:
    """The simulated time a log covers, s: its last message's time, but no more than its sensor samples span.

    A genuine log has a sample every ``every * dt``; a crafted one cannot claim
    days of simulated time with a handful of messages.
    """
    info = overview.info
    try:
        span = overview.counts.get(TOPIC_SENSORS, 0) * int(float(info["every"])) * float(info["dt"])
    except KeyError:
        span = overview.end_time
    return min(overview.end_time, span)


def replay_scenario(log: str | os.PathLike[str], folder: Path, other: Scenario | None = None) -> ReplayPlan:
    """The scenario of a replay, with its input files written into ``folder`` (a scratch folder).

    Without ``other``: the log's own scenario (parsed from its embedded text,
    never executed), every input file taken from the log's attachments. With
    ``other``: ``other``'s bridge, sensors, road, solver and output with the
    log's traffic: its ``[[vehicles]]``, or, for SUMO traffic, the logged SUMO
    frames (positions along the original bridge's axis; SUMO itself is not run
    again), read from the log as the replay goes. The log is checked whole
    first (checksums, every message it will use against its schema), so a
    damaged or crafted log is refused before anything is written.

    Raises:
        LogError: the log is unreadable, damaged, has no scenario, or names input files it does not hold.
        ConfigError: the log's traffic does not fit ``other``'s bridge (e.g. a wheel path off its deck).
    """
    overview = open_log(log)
    text = _scenario_text(overview)
    source = f"{overview.path} ({SCENARIO_ATTACHMENT})"
    logged = load_config(text, source, error=LogError)  # not TOML: the log is damaged
    record = {"log": str(overview.path), "log_scenario": overview.info.get("scenario", ""),
              "log_started": overview.info.get("started", ""), "log_status": overview.status_word}
    logged_traffic: dict[str, Any] = logged["traffic"] if isinstance(logged.get("traffic"), dict) else {}
    sumo = bool(overview.counts.get(TOPIC_TRAFFIC)) or "sumo_config" in logged_traffic
    records = not sumo and "records" in logged_traffic  # WIM records driven as recorded: run again from the file
    check_messages(overview.path, [TOPIC_SENSORS])  # the traffic frames: LoggedTraffic.check below
    covered = covered_time(overview)
    duration: float | None = None
    if other is None:
        inputs, written = _extract(overview, folder)
        data = tomllib.loads(text)
        changed = _confine(overview, data, inputs, folder, written)
        scenario = parse_scenario(toml_dumps(data) if changed else text, source, base_dir=folder)
        for item in input_files(scenario):  # every file the run will embed: one of the log's own
            if Path(os.path.normpath(item.path)) not in written:
                raise LogError(f"{overview.path}: the log's scenario needs {item.path.name!r} ({item.key or 'SUMO'}), "
                               "which is not one of the log's attachments")
        record["scenario"] = "the log's own"
        plan = ReplayPlan(scenario, overview, True, record)
        if not sumo and scenario.duration > covered > 0:
            duration = covered  # a log cut short: its own traffic replays only as far as it reached
    else:
        if not sumo and not records and not logged.get("vehicles"):
            raise LogError(f"{overview.path}: the log's scenario has no [[vehicles]] and no [traffic]: "
                           "no traffic to replay")
        data = tomllib.loads(other.text)
        data.pop("traffic", None)
        data.pop("vehicles", None)
        if records:  # the same file, from the log's attachments
            inputs, _ = _extract(overview, folder)
            name = inputs.get("traffic.records.file")
            if name is None:
                raise LogError(f"{overview.path}: the log's scenario names a record file the log does not hold")
            data["traffic"] = logged_traffic
            set_key(data, "traffic.records.file", name)
        elif not sumo:
            data["vehicles"] = logged["vehicles"]
        for item in input_files(other):
            if not item.key or item.key.startswith("traffic."):
                continue
            target = folder.joinpath(*PurePosixPath(item.attachment).parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(item.path.read_bytes())
            set_key(data, item.key, item.attachment)
        merged = toml_dumps(data)
        scenario = parse_scenario(merged, f"{other.source} with the traffic of {overview.path}", base_dir=folder)
        record["scenario"] = other.source
        attachments = {"replay/bridge-scenario.toml": other.text.encode(),
                       "replay/traffic-scenario.toml": text.encode()}
        plan = ReplayPlan(scenario, overview, False, record, attachments)
    if not sumo:
        return ReplayPlan(plan.scenario, overview, plan.own, record, plan.attachments, None, duration)
    try:
        step = float(logged["traffic"].get("step", 0.05))
    except (KeyError, ValueError, TypeError, AttributeError):
        step = math.nan
    if not (math.isfinite(step) and step > 0):
        raise LogError(f"{overview.path}: the log's scenario has no valid traffic.step")
    # Frames are logged only while vehicles are near the deck: pad to the logged run's end, or,
    # for a cut-off log, to the last time the log reached.
    duration = min(float(overview.info.get("duration", covered)), covered)
    if not duration > 0:
        raise LogError(f"{overview.path}: the log covers no simulated time: nothing to replay")
    traffic = LoggedTraffic(overview.path, plan.scenario.bridge.length, step, until=duration)
    record["traffic"] = f"{traffic.check()} logged SUMO frames"
    return ReplayPlan(plan.scenario, overview, plan.own, record, plan.attachments, traffic, duration)


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


@dataclass(frozen=True)
class ReplayOutcome:
    """A finished replay: what was replayed, the replay's run and its sensors against the log's.

    Attributes:
        log: the log replayed.
        plan: the replay's scenario and what is recorded about it (:func:`replay_scenario`).
        start: the replay's run as it started (its bridge, log and duration).
        outcome: the replay's finished run (its log is ``outcome.log_path``).
        comparison: the sensors of the log against the replay's (:func:`compare_sensors`).
    """

    log: Path
    plan: ReplayPlan
    start: RunStart
    outcome: RunOutcome
    comparison: Comparison

    @property
    def own(self) -> bool:
        """Whether the log's own scenario ran again (its sensor channels must then be identical)."""
        return self.plan.own


def replay_log(
    log: str | os.PathLike[str],
    scenario: str | os.PathLike[str] | Scenario | None = None,
    *,
    out: str | os.PathLike[str] | None = None,
    force: bool = False,
    checked: Callable[[ReplayPlan], None] | None = None,
    ready: Callable[[RunStart], None] | None = None,
    progress: Callable[[float], None] | None = None,
) -> ReplayOutcome:
    """Re-drive a bridge with the traffic of ``log`` into a new log, and compare its sensors with the log's.

    Without ``scenario`` the log's own scenario runs again (its sensor channels should come out identical,
    bit for bit); with one, that scenario's bridge, sensors, road and solver take the log's traffic
    (:func:`replay_scenario`). The replay's log goes to ``out``, else
    ``runs/<scenario name>-replay-<YYYYmmdd-HHMMSS>.mcap``; the input files the replay needs are written
    into a scratch folder that is removed afterwards.

    Args:
        log: the log to replay.
        scenario: the scenario (or its file or bundled name) whose bridge to drive, or None for the log's own.
        out: the replay's log (.mcap).
        force: overwrite ``out`` if it exists.
        checked: called with the replay's plan once the log, the scenario and ``out`` are checked, before the
            bridge is built.
        ready: called when the bridge is built, just before the time stepping.
        progress: called with the fraction done after every block of time steps.

    Raises:
        LogError, ConfigError, CosimError: a log that cannot be replayed, traffic that does not fit the bridge,
            an output that may not be written (before anything is written).
        RunInterrupted, RunFailed: as :func:`cosim.run.logged.run_logged`.
    """
    other = scenario if scenario is None or isinstance(scenario, Scenario) else load_scenario(scenario)
    log = Path(log)
    with tempfile.TemporaryDirectory(prefix="cosim-replay-") as scratch:
        plan = replay_scenario(log, Path(scratch), other)
        try:
            replayed = plan.scenario
            log_path = log_target(out, unique_path(replayed.default_log_path(suffix="-replay")), force)
            check_not_input(log_path, "replay's log", [("the log it replays", log),
                                                       *(scenario_files(other) if other is not None else [])])
            if checked is not None:
                checked(plan)
            bridge = replayed.build_bridge()
            duration = plan.duration if plan.duration is not None else replayed.duration
            start = RunStart(replayed, bridge, log_path, duration)
            if ready is not None:
                ready(start)
            outcome = run_logged(replayed, log_path, force=force, bridge=bridge, progress=progress,
                                 replay=plan.record, attachments=plan.attachments, traffic=plan.traffic,
                                 duration=plan.duration)
        finally:
            if plan.traffic is not None:
                plan.traffic.close()
    return ReplayOutcome(log, plan, start, outcome, compare_sensors(log, log_path))
