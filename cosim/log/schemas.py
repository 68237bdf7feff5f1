"""The cosim log format in one place: the MCAP profile, topics, JSON Schemas and record names.

Every message is JSON with a JSON Schema (so Foxglove and the ``mcap`` CLI can
read the logs); log times are integer nanoseconds of *simulated* time. The
writer (:mod:`cosim.log.writer`), the reader (:mod:`cosim.log.reader`) and
everything that exports a log take their names from here.

The vehicle item of ``/cosim/vehicles`` is derived from
:data:`cosim.core.fields.VEHICLE_FIELDS`: its properties, their order and
types follow that list.
"""
from __future__ import annotations

from typing import Any, Iterable

from cosim.core.fields import VEHICLE_FIELDS

#: The MCAP header's profile of a cosim log.
PROFILE = "cosim"
#: The first (and last) eight bytes of an MCAP file.
MAGIC = b"\x89MCAP0\r\n"

TOPIC_SENSORS = "/cosim/sensors"
TOPIC_VEHICLES = "/cosim/vehicles"
TOPIC_EVENTS = "/cosim/events"
TOPIC_STATUS = "/cosim/status"
TOPIC_TRAFFIC = "/cosim/traffic"
TOPIC_VEHICLE_TYPES = "/cosim/vehicle_types"

STATUS_STATES = ("started", "running", "finished", "interrupted", "error")
EVENT_KINDS = ("entered", "left", "liftoff", "touchdown")

#: The metadata record with the run's parameters (version, scenario, dt, sensors, ...).
METADATA_NAME = "cosim"
#: The metadata record of a replay: which log it replayed.
REPLAY_METADATA_NAME = "replay"
#: The attachment holding the scenario's TOML text exactly as it was read.
SCENARIO_ATTACHMENT = "scenario.toml"

_NUMBER = {"type": "number"}


def sensors_schema(names: Iterable[str]) -> dict[str, Any]:
    """Schema of one sensor sample: ``t`` (s) plus one number per sensor (SI unit of its quantity)."""
    names = list(names)
    props: dict[str, Any] = {"t": {"type": "number", "description": "simulated time, s"}}
    for name in names:
        props[name] = _NUMBER
    return {"title": "cosim.SensorSample", "type": "object", "properties": props,
            "required": ["t", *names], "additionalProperties": False}


def _vehicle_property(json_type: str, description: str, unit: str) -> dict[str, Any]:
    if json_type != "number":
        return {"type": json_type}
    return {"type": json_type, "description": f"{description}, {unit}" if unit else description}


#: One vehicle (contact point) on the deck: the fields of :data:`cosim.core.fields.VEHICLE_FIELDS`, in order.
VEHICLE_ITEM: dict[str, Any] = {
    "type": "object",
    "properties": {f.name: _vehicle_property(f.json_type, f.description, f.unit) for f in VEHICLE_FIELDS},
    "required": [f.name for f in VEHICLE_FIELDS],
    "additionalProperties": False,
}
VEHICLES_SCHEMA = {
    "title": "cosim.VehiclesOnDeck", "type": "object",
    "properties": {"t": _NUMBER, "vehicles": {"type": "array", "items": VEHICLE_ITEM}},
    "required": ["t", "vehicles"], "additionalProperties": False,
}
EVENTS_SCHEMA = {
    "title": "cosim.TrafficEvent", "type": "object",
    "properties": {"t": _NUMBER, "vehicle": {"type": "string"}, "event": {"enum": list(EVENT_KINDS)},
                   "x": _NUMBER},
    "required": ["t", "vehicle", "event"], "additionalProperties": False,
}
STATUS_SCHEMA = {
    "title": "cosim.RunStatus", "type": "object",
    "properties": {"t": _NUMBER, "state": {"enum": list(STATUS_STATES)}, "message": {"type": "string"},
                   "progress": _NUMBER, "wall_time": _NUMBER},
    "required": ["t", "state"], "additionalProperties": False,
}
TRAFFIC_SCHEMA = {
    "title": "cosim.TrafficFrame", "type": "object",
    "description": "Vehicles near the deck at one SUMO step (bridge coordinates): what replay re-drives.",
    "properties": {
        "t": _NUMBER,
        "ids": {"type": "array", "items": {"type": "string"}},
        "x": {"type": "array", "items": _NUMBER},
        "y": {"type": "array", "items": _NUMBER},
        "speed": {"type": "array", "items": _NUMBER},
        "acceleration": {"type": "array", "items": _NUMBER},
        "types": {"type": "array", "items": {"type": "string"}},
    },
    "required": ["t", "ids", "x", "y", "speed", "acceleration", "types"], "additionalProperties": False,
}
VEHICLE_TYPE_SCHEMA = {
    "title": "cosim.VehicleType", "type": "object",
    "description": "The vehicle model of a SUMO vType, logged when the type first appears.",
    "properties": {"t": _NUMBER, "type": {"type": "string"},
                   "model": {"type": "object", "properties": {"model": {"type": "string"}},
                             "required": ["model"], "additionalProperties": {"type": "number"}}},
    "required": ["t", "type", "model"], "additionalProperties": False,
}


def topic_schemas(sensor_names: Iterable[str]) -> list[tuple[str, dict[str, Any]]]:
    """Every topic of a log with its schema (whose ``title`` names it), in the order the channels are registered."""
    return [
        (TOPIC_SENSORS, sensors_schema(sensor_names)),
        (TOPIC_VEHICLES, VEHICLES_SCHEMA),
        (TOPIC_EVENTS, EVENTS_SCHEMA),
        (TOPIC_STATUS, STATUS_SCHEMA),
        (TOPIC_TRAFFIC, TRAFFIC_SCHEMA),
        (TOPIC_VEHICLE_TYPES, VEHICLE_TYPE_SCHEMA),
    ]


def to_ns(t: float) -> int:
    """Simulated time in seconds -> integer nanoseconds."""
    return int(round(t * 1e9))
