"""MCAP logs of cosim runs: the format (:mod:`.schemas`), the writer (:mod:`.writer`), the reader (:mod:`.reader`,
over the bounded MCAP record parser :mod:`.records`) and the replay's traffic source (:mod:`.replay_source`).

Every message is JSON with a JSON Schema, so Foxglove and the ``mcap`` CLI can
read the logs. Log times are integer nanoseconds of *simulated* time. The
scenario, the resolved parameters, section constants, frequencies and every
input file are stored as attachments and metadata, so a log alone is enough
to run it again.

The names below load on first use (PEP 562): importing :mod:`.schemas` (topics, record names) loads
neither mcap nor numpy, so the command line's help can show them.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .reader import (
        LogContents,
        LogOverview,
        file_is_complete,
        iter_messages,
        open_log,
        read_log,
        sensor_series,
    )
    from .replay_source import read_traffic, traffic_from_log
    from .schemas import (
        EVENT_KINDS,
        METADATA_NAME,
        PROFILE,
        REPLAY_METADATA_NAME,
        SCENARIO_ATTACHMENT,
        STATUS_STATES,
        TOPIC_EVENTS,
        TOPIC_SENSORS,
        TOPIC_STATUS,
        TOPIC_TRAFFIC,
        TOPIC_VEHICLE_TYPES,
        TOPIC_VEHICLES,
    )
    from .writer import BlockLogger, LogRecorder, TrafficLogger

#: Public name -> the module of this package that defines it.
_EXPORTS: dict[str, str] = {
    **dict.fromkeys(("LogContents", "LogOverview", "file_is_complete", "iter_messages", "open_log", "read_log",
                     "sensor_series"), "reader"),
    **dict.fromkeys(("read_traffic", "traffic_from_log"), "replay_source"),
    **dict.fromkeys(("EVENT_KINDS", "METADATA_NAME", "PROFILE", "REPLAY_METADATA_NAME", "SCENARIO_ATTACHMENT",
                     "STATUS_STATES", "TOPIC_EVENTS", "TOPIC_SENSORS", "TOPIC_STATUS", "TOPIC_TRAFFIC",
                     "TOPIC_VEHICLE_TYPES", "TOPIC_VEHICLES"), "schemas"),
    **dict.fromkeys(("BlockLogger", "LogRecorder", "TrafficLogger"), "writer"),
}

__all__ = [
    "BlockLogger",
    "EVENT_KINDS",
    "LogContents",
    "LogOverview",
    "LogRecorder",
    "METADATA_NAME",
    "PROFILE",
    "REPLAY_METADATA_NAME",
    "SCENARIO_ATTACHMENT",
    "STATUS_STATES",
    "TOPIC_EVENTS",
    "TOPIC_SENSORS",
    "TOPIC_STATUS",
    "TOPIC_TRAFFIC",
    "TOPIC_VEHICLES",
    "TOPIC_VEHICLE_TYPES",
    "TrafficLogger",
    "file_is_complete",
    "iter_messages",
    "open_log",
    "read_log",
    "read_traffic",
    "sensor_series",
    "traffic_from_log",
]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
