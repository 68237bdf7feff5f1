"""Replays: a bridge re-driven with the traffic recorded in a log, and two logs' sensors compared.

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
import sys
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from cosim.errors import LogError
from cosim.log.reader import LogOverview, iter_messages, open_log, read_traffic
from cosim.log.schemas import SCENARIO_ATTACHMENT, TOPIC_SENSORS, TOPIC_TRAFFIC

from .inputs import input_files
from .scenario import Scenario, parse_scenario
from .toml_writer import get_key, set_key, toml_dumps

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


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
              "log_started": overview.info.get("started", ""), "log_status": overview.status_word}
    sumo = bool(overview.counts.get(TOPIC_TRAFFIC)) or "traffic" in logged
    if other is None:
        inputs = _extract(overview, folder)
        data = tomllib.loads(text)
        changed = False
        for key, name in inputs.items():
            if get_key(data, key) != name:
                set_key(data, key, name)
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
            set_key(data, item.key, item.attachment)
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
    # Frames are logged only while vehicles are near the deck: pad to the logged run's end, or,
    # for a cut-off log, to the last time the log reached.
    duration = min(duration, overview.end_time) if overview.end_time > 0 else duration
    traffic, frames = read_traffic(overview.path, plan.scenario.bridge.length, step, until=duration)
    record["traffic"] = f"{frames} logged SUMO frames"
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
