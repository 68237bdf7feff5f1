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

from collections.abc import Iterable
from typing import Any

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
#: What loaded the deck: one message per vehicle at its entry (class, weights, axles, lane, path, source).
TOPIC_VEHICLE_LOADS = "/cosim/vehicle_loads"
#: The 3D scene (Foxglove's own schemas): the deck, its vehicles and sensors at the scene rate ...
TOPIC_SCENE = "/cosim/scene"
#: ... what does not move (the deck at rest, the approaches, the sensors' names), once at t = 0 ...
TOPIC_SCENE_STATIC = "/cosim/scene/static"
#: ... and the frame the scene is drawn in (bridge axes) placed in the viewer's world, once at t = 0.
TOPIC_SCENE_TRANSFORM = "/cosim/scene/transform"

STATUS_STATES = ("started", "running", "finished", "interrupted", "error")
#: A wheel entered or left the deck, lifted off or touched down again, or went beside the deck's surface over its
#: length ("offdeck": it loads nothing while there; the event carries its lateral y too).
EVENT_KINDS = ("entered", "left", "liftoff", "touchdown", "offdeck")

#: The metadata record with the run's parameters (version, scenario, dt, sensors, ...).
METADATA_NAME = "cosim"
#: The metadata record of a replay: which log it replayed.
REPLAY_METADATA_NAME = "replay"
#: The attachment holding the scenario's TOML text exactly as it was read.
SCENARIO_ATTACHMENT = "scenario.toml"
#: The attachment holding the Foxglove layout made for the run (:mod:`cosim.log.layout`).
LAYOUT_ATTACHMENT = "foxglove_layout.json"
#: The scene's frames: entities are drawn in ``bridge`` (cosim's axes: x from the first support, y left, z up);
#: ``world`` has its origin at the middle of the bridge, where a 3D viewer's camera looks first.
SCENE_FRAME = "bridge"
WORLD_FRAME = "world"

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
    "properties": {"t": _NUMBER, "vehicle": {"type": "string"}, "event": {"type": "string", "enum": list(EVENT_KINDS)},
                   "x": _NUMBER, "y": {"type": "number", "description": "lateral offset (offdeck events), m"}},
    "required": ["t", "vehicle", "event"], "additionalProperties": False,
}
STATUS_SCHEMA = {
    "title": "cosim.RunStatus", "type": "object",
    "properties": {"t": _NUMBER, "state": {"type": "string", "enum": list(STATUS_STATES)},
                   "message": {"type": "string"}, "progress": _NUMBER, "wall_time": _NUMBER},
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
_NUMBERS = {"type": "array", "items": _NUMBER}
VEHICLE_LOADS_SCHEMA = {
    "title": "cosim.VehicleLoads", "type": "object",
    "description": "What loaded the deck, per vehicle, at its entry onto the deck (SI units).",
    "properties": {
        "t": {"type": "number", "description": "when its first axle came onto the deck, s"},
        "id": {"type": "string"},
        "class": {"type": "string", "description": "car, truck-N (N axles), a SUMO vClass or a model's name"},
        "lane": {"type": "string", "description": "SUMO's lane id or a WIM record's (BTLS) lane number"},
        "speed": {"type": "number", "description": "at entry, m/s"},
        "gvw": {"type": "number", "description": "gross weight, N"},
        "n_axles": {"type": "integer"},
        "axle_loads": {**_NUMBERS, "description": "static load of each axle, N, front first"},
        "axle_spacings": {**_NUMBERS, "description": "each axle to the next, m"},
        "y": {"type": "number", "description": "lateral offset of its path on the deck, m (wander included)"},
        "wander": {"type": "number", "description": "its lateral offset within its lane, m"},
        "source": {"type": "string", "description": "where its loads came from"},
    },
    "required": ["t", "id", "class", "lane", "speed", "gvw", "n_axles", "axle_loads", "axle_spacings", "y",
                 "wander", "source"],
    "additionalProperties": False,
}
VEHICLE_TYPE_SCHEMA = {
    "title": "cosim.VehicleType", "type": "object",
    "description": "The vehicle model of a SUMO vType, logged when the type first appears.",
    "properties": {"t": _NUMBER, "type": {"type": "string"},
                   "model": {"type": "object", "properties": {"model": {"type": "string"}},
                             "required": ["model"], "additionalProperties": {"type": "number"}}},
    "required": ["t", "type", "model"], "additionalProperties": False,
}



# --------------------------------------------------------------------------- Foxglove's schemas (the 3D scene)
#
# The scene topics use Foxglove's own message schemas, so that its 3D panel draws them: the names and
# fields of foxglove.SceneUpdate and foxglove.FrameTransform (their JSON Schemas: github.com/foxglove/
# foxglove-sdk, schemas/jsonschema/), JSON encoding. Written here as the subset cosim writes (the primitives
# it draws), with a "type" on every property as Foxglove's JSON-Schema parser needs (enumerations as
# integers), and stricter than Foxglove's (no other fields) because the reader checks every message.


def _fox(title: str, properties: dict[str, Any], description: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {"title": title, "type": "object"}
    if description:
        out["description"] = description
    out["properties"] = properties
    out["additionalProperties"] = False
    return out


def _array(items: dict[str, Any]) -> dict[str, Any]:
    return {"type": "array", "items": items}


_INTEGER = {"type": "integer"}
_BOOLEAN = {"type": "boolean"}
_STRING = {"type": "string"}
_TIME = _fox("time", {"sec": _INTEGER, "nsec": _INTEGER}, "seconds and nanoseconds (simulated time)")
_DURATION = _fox("duration", {"sec": _INTEGER, "nsec": _INTEGER})
_VECTOR3 = _fox("foxglove.Vector3", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER})
_QUATERNION = _fox("foxglove.Quaternion", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER, "w": _NUMBER})
_POSE = _fox("foxglove.Pose", {"position": _VECTOR3, "orientation": _QUATERNION})
_COLOR = _fox("foxglove.Color", {"r": _NUMBER, "g": _NUMBER, "b": _NUMBER, "a": _NUMBER}, "RGBA, each 0 to 1")
_PRIMITIVES: dict[str, dict[str, Any]] = {
    "arrows": _fox("foxglove.ArrowPrimitive", {
        "pose": _POSE, "shaft_length": _NUMBER, "shaft_diameter": _NUMBER, "head_length": _NUMBER,
        "head_diameter": _NUMBER, "color": _COLOR}, "an arrow along the +x axis of its pose, tail at the position"),
    "cubes": _fox("foxglove.CubePrimitive", {"pose": _POSE, "size": _VECTOR3, "color": _COLOR}),
    "spheres": _fox("foxglove.SpherePrimitive", {"pose": _POSE, "size": _VECTOR3, "color": _COLOR}),
    "cylinders": _fox("foxglove.CylinderPrimitive", {
        "pose": _POSE, "size": _VECTOR3, "bottom_scale": _NUMBER, "top_scale": _NUMBER, "color": _COLOR}),
    "lines": _fox("foxglove.LinePrimitive", {
        "type": {"type": "integer", "description": "0 LINE_STRIP, 1 LINE_LOOP, 2 LINE_LIST"},
        "pose": _POSE, "thickness": _NUMBER, "scale_invariant": _BOOLEAN, "points": _array(_VECTOR3),
        "color": _COLOR, "colors": _array(_COLOR), "indices": _array(_INTEGER)}),
    "triangles": _fox("foxglove.TriangleListPrimitive", {
        "pose": _POSE, "points": _array(_VECTOR3), "color": _COLOR, "colors": _array(_COLOR),
        "indices": _array(_INTEGER)}),
    "texts": _fox("foxglove.TextPrimitive", {
        "pose": _POSE, "billboard": _BOOLEAN, "font_size": _NUMBER, "scale_invariant": _BOOLEAN, "color": _COLOR,
        "text": _STRING}),
}
_SCENE_ENTITY = _fox("foxglove.SceneEntity", {
    "timestamp": _TIME, "frame_id": _STRING, "id": _STRING, "lifetime": _DURATION, "frame_locked": _BOOLEAN,
    "metadata": _array(_fox("foxglove.KeyValuePair", {"key": _STRING, "value": _STRING})),
    **{name: _array(item) for name, item in _PRIMITIVES.items()},
}, "a visual element of the scene; an entity replaces the earlier one of the same id on its topic")
_SCENE_DELETION = _fox("foxglove.SceneEntityDeletion", {
    "timestamp": _TIME, "type": {"type": "integer", "description": "0 MATCHING_ID, 1 ALL"}, "id": _STRING})
SCENE_UPDATE_SCHEMA = _fox("foxglove.SceneUpdate", {
    "deletions": _array(_SCENE_DELETION), "entities": _array(_SCENE_ENTITY)},
    "an update to the entities displayed in a 3D scene")
FRAME_TRANSFORM_SCHEMA = _fox("foxglove.FrameTransform", {
    "timestamp": _TIME, "parent_frame_id": _STRING, "child_frame_id": _STRING, "translation": _VECTOR3,
    "rotation": _QUATERNION}, "the child frame's origin and orientation in the parent frame")


def topic_schemas(sensor_names: Iterable[str], scene: bool = False) -> list[tuple[str, dict[str, Any]]]:
    """Every topic of a log with its schema (whose ``title`` names it), in the order the channels are registered;
    with ``scene``, the 3D scene's topics too."""
    topics = [
        (TOPIC_SENSORS, sensors_schema(sensor_names)),
        (TOPIC_VEHICLES, VEHICLES_SCHEMA),
        (TOPIC_EVENTS, EVENTS_SCHEMA),
        (TOPIC_STATUS, STATUS_SCHEMA),
        (TOPIC_TRAFFIC, TRAFFIC_SCHEMA),
        (TOPIC_VEHICLE_TYPES, VEHICLE_TYPE_SCHEMA),
        (TOPIC_VEHICLE_LOADS, VEHICLE_LOADS_SCHEMA),
    ]
    if scene:
        topics += [(TOPIC_SCENE, SCENE_UPDATE_SCHEMA), (TOPIC_SCENE_STATIC, SCENE_UPDATE_SCHEMA),
                   (TOPIC_SCENE_TRANSFORM, FRAME_TRANSFORM_SCHEMA)]
    return topics


def to_ns(t: float) -> int:
    """Simulated time in seconds -> integer nanoseconds."""
    return int(round(t * 1e9))
