"""MCAP logs of cosim runs: the format (:mod:`.schemas`), the writer (:mod:`.writer`), the reader (:mod:`.reader`,
over the bounded MCAP record parser :mod:`.records`) and the replay's traffic source (:mod:`.replay_source`).

Every message is JSON with a JSON Schema, so Foxglove and the ``mcap`` CLI can
read the logs. Log times are integer nanoseconds of *simulated* time. The
scenario, the resolved parameters, section constants, frequencies and every
input file are stored as attachments and metadata, so a log alone is enough
to run it again.
"""
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
