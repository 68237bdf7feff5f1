"""cosim's log messages as Protocol Buffers: the schemas, an encoder of fixed-shape messages, and the decoder.

Every message of a log written by this version is protobuf (Foxglove's
recommended encoding): cosim's own topics in the messages of
``cosim/log/cosim.proto`` (:data:`COSIM_MESSAGES`, the same table
writes that file) and a per-run ``cosim.SensorSample`` with one ``double``
per sensor (:func:`sensor_file`); the 3D scene in Foxglove's own
``foxglove.SceneUpdate`` and ``foxglove.FrameTransform`` (the
``foxglove-schemas-protobuf`` package). Each channel's schema record holds
the serialized ``FileDescriptorSet`` of its message, so Foxglove, the ``mcap``
CLI and any protobuf library read a log as it is.

Field names and units are those of the JSON logs (docs/logs.md), with two
differences a protobuf schema imposes: a sensor whose name is not a protobuf
identifier (``mid.left``) is a field with a plain name (``mid_left``) whose
``json_name`` is the sensor's name (:func:`sensor_fields`), and a vehicle
type's parameters are a list of (``name``, ``number`` or ``integer``) pairs.
:func:`decoder` turns a message back into exactly the dictionary the JSON log
held, so every reader of logs works on both encodings.

Encoding is cosim's own, not the protobuf runtime's: a message of a fixed
shape (a sensor sample, the vehicles on the deck with the same fleet, the
deck of a scene) is encoded once with *holes* (:class:`Hole`) where its
numbers go, and then rendered for many rows of numbers at once with numpy
(:class:`FixedTemplate`): a ``double`` is 8 bytes wherever it is, and an
integer hole (a timestamp) is a varint padded to 5 bytes, so the holes have
fixed offsets. Scalar fields are always written, zeros included (valid
protobuf: a parser reads them as it reads absent ones). benchmarks/README.md
says what this costs against the protobuf runtime and Foxglove's SDK.

Decoding uses the protobuf runtime with cosim's own schemas, never the one
stored in the file (the sensor names of a ``SensorSample`` are taken from it
after it is checked to be cosim's shape): a message that does not parse, or
whose values are not what cosim writes, is a :class:`cosim.errors.LogError`
of one line in :mod:`cosim.log.reader`.
"""
from __future__ import annotations

import functools
import re
import struct
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cosim.core.fields import VEHICLE_FIELDS

from .schemas import (
    TOPIC_EVENTS,
    TOPIC_SCENE,
    TOPIC_SCENE_STATIC,
    TOPIC_SCENE_TRANSFORM,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_LOADS,
    TOPIC_VEHICLE_TYPES,
    TOPIC_VEHICLES,
)

__all__ = ["COSIM_MESSAGES", "ENCODING", "SCHEMA_ENCODING", "TOPIC_MESSAGES", "FixedTemplate", "Hole", "decoder",
           "encode", "number_holes", "proto_text", "schema_data", "sensor_fields", "sensor_file", "spec_of"]

#: The channels' message encoding and the schemas' encoding (MCAP's well-known names).
ENCODING = "protobuf"
SCHEMA_ENCODING = "protobuf"

# FieldDescriptorProto types (descriptor.proto).
DOUBLE, INT64, INT32, FIXED32, BOOL, STRING, MESSAGE, UINT32, ENUM = 1, 3, 5, 7, 8, 9, 11, 13, 14
_TYPE_NAMES = {DOUBLE: "double", INT64: "int64", INT32: "int32", FIXED32: "fixed32", BOOL: "bool",
               STRING: "string", UINT32: "uint32"}

#: The message of each topic (cosim's own, Foxglove's for the scene).
TOPIC_MESSAGES: dict[str, str] = {
    TOPIC_SENSORS: "cosim.SensorSample",
    TOPIC_VEHICLES: "cosim.VehiclesOnDeck",
    TOPIC_EVENTS: "cosim.TrafficEvent",
    TOPIC_STATUS: "cosim.RunStatus",
    TOPIC_TRAFFIC: "cosim.TrafficFrame",
    TOPIC_VEHICLE_TYPES: "cosim.VehicleType",
    TOPIC_VEHICLE_LOADS: "cosim.VehicleLoads",
    TOPIC_SCENE: "foxglove.SceneUpdate",
    TOPIC_SCENE_STATIC: "foxglove.SceneUpdate",
    TOPIC_SCENE_TRANSFORM: "foxglove.FrameTransform",
}

# --------------------------------------------------------------------------- cosim's messages


@dataclass(frozen=True)
class FieldDef:
    """A field of cosim's messages: name, number, type, ``"repeated"``, ``"optional"`` (explicit presence) or
    ``"oneof <name>"``, the message it holds, what it means."""

    name: str
    number: int
    type: int
    label: str = ""
    message: str = ""
    comment: str = ""


def _d(name: str, number: int, comment: str = "", label: str = "") -> FieldDef:
    return FieldDef(name, number, DOUBLE, label, "", comment)


def _s(name: str, number: int, comment: str = "", label: str = "") -> FieldDef:
    return FieldDef(name, number, STRING, label, "", comment)


#: cosim's messages (package ``cosim``), in the order of cosim/log/cosim.proto: (name, comment, fields).
COSIM_MESSAGES: tuple[tuple[str, str, tuple[FieldDef, ...]], ...] = (
    ("VehicleOnDeck", "One vehicle (contact point) on the deck: the fields of cosim.core.fields.VEHICLE_FIELDS.",
     tuple(FieldDef(f.name, i + 1, STRING if f.json_type == "string" else DOUBLE, "", "",
                    f"{f.description}, {f.unit}" if f.unit else f.description)
           for i, f in enumerate(VEHICLE_FIELDS))),
    ("VehiclesOnDeck", "/cosim/vehicles: the vehicles on the deck at one logged sample.",
     (_d("t", 1, "simulated time, s"), FieldDef("vehicles", 2, MESSAGE, "repeated", "VehicleOnDeck"))),
    ("TrafficEvent", "/cosim/events: a wheel entered or left the deck, lifted off, touched down or went beside it.",
     (_d("t", 1, "s"), _s("vehicle", 2), _s("event", 3, "entered, left, liftoff, touchdown or offdeck"),
      _d("x", 4, "along the axis, m"), _d("y", 5, "lateral offset (offdeck events), m", "optional"))),
    ("RunStatus", "/cosim/status: the run's state at its start, every 10 s simulated and at its end.",
     (_d("t", 1, "s"), _s("state", 2, "started, running, finished, interrupted or error"),
      _s("message", 3, "", "optional"), _d("progress", 4, "0 to 1", "optional"),
      _d("wall_time", 5, "s", "optional"))),
    ("TrafficFrame", "/cosim/traffic: the vehicles near the deck at one SUMO step (bridge coordinates).",
     (_d("t", 1, "s"), _s("ids", 2, "", "repeated"), _d("x", 3, "m", "repeated"), _d("y", 4, "m", "repeated"),
      _d("speed", 5, "m/s", "repeated"), _d("acceleration", 6, "m/s^2", "repeated"),
      _s("types", 7, "", "repeated"))),
    ("Parameter", "A vehicle model's parameter: a number, or an integer.",
     (_s("name", 1), _d("number", 2, "", "oneof value"), FieldDef("integer", 3, INT64, "oneof value"))),
    ("VehicleModel", "A vehicle model and its parameters (SI units).",
     (_s("model", 1), FieldDef("parameters", 2, MESSAGE, "repeated", "Parameter"))),
    ("VehicleType", "/cosim/vehicle_types: the vehicle model of a SUMO vType, when it first appears.",
     (_d("t", 1, "s"), _s("type", 2), FieldDef("model", 3, MESSAGE, "", "VehicleModel"))),
    ("VehicleLoads", "/cosim/vehicle_loads: what loaded the deck, per vehicle, at its entry onto the deck.",
     (_d("t", 1, "when its first axle came onto the deck, s"), _s("id", 2),
      _s("class", 3, "car, truck-N (N axles), a SUMO vClass or a model's name"),
      _s("lane", 4, "SUMO's lane id or a WIM record's (BTLS) lane number"), _d("speed", 5, "at entry, m/s"),
      _d("gvw", 6, "gross weight, N"), FieldDef("n_axles", 7, INT32),
      _d("axle_loads", 8, "static load of each axle, N, front first", "repeated"),
      _d("axle_spacings", 9, "each axle to the next, m", "repeated"),
      _d("y", 10, "lateral offset of its path on the deck, m (wander included)"),
      _d("wander", 11, "its lateral offset within its lane, m"), _s("source", 12, "where its loads came from"))),
)
_COSIM_FILE = "cosim/log.proto"
_SENSOR_FILE = "cosim/sensors.proto"
_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def sensor_fields(names: Iterable[str]) -> list[str]:
    """The protobuf field name of each sensor: its name when that is an identifier, else the name with every
    other character as ``_`` (and a leading ``s_`` before a digit), made unique (``_2``, ...) and never ``t``."""
    out: list[str] = []
    taken = {"t"}
    for name in names:
        field = name if _IDENTIFIER.match(name) else re.sub(r"[^A-Za-z0-9_]", "_", name)
        if not field or field[0].isdigit():
            field = "s_" + field
        base, k = field, 1
        while field in taken:
            k += 1
            field = f"{base}_{k}"
        taken.add(field)
        out.append(field)
    return out


def _file_proto(name: str, messages: Sequence[tuple[str, str, Sequence[FieldDef]]],
                json_names: dict[tuple[str, str], str] | None = None) -> Any:
    from google.protobuf import descriptor_pb2

    label_of = descriptor_pb2.FieldDescriptorProto
    out = descriptor_pb2.FileDescriptorProto(name=name, package="cosim", syntax="proto3")
    for message_name, _, fields in messages:
        message = out.message_type.add(name=message_name)
        oneofs: list[str] = []
        for f in fields:
            if f.label.startswith("oneof ") and f.label[6:] not in oneofs:
                oneofs.append(f.label[6:])
        for oneof in oneofs:
            message.oneof_decl.add(name=oneof)
        for f in fields:
            field = message.field.add(name=f.name, number=f.number, type=f.type)
            field.label = label_of.LABEL_REPEATED if f.label == "repeated" else label_of.LABEL_OPTIONAL
            if f.message:
                field.type_name = f".cosim.{f.message}"
            json_name = (json_names or {}).get((message_name, f.name))
            if json_name is not None:
                field.json_name = json_name
            if f.label.startswith("oneof "):
                field.oneof_index = oneofs.index(f.label[6:])
            elif f.label == "optional":
                field.proto3_optional = True
                field.oneof_index = len(message.oneof_decl)
                message.oneof_decl.add(name=f"_{f.name}")
    return out


def cosim_file() -> Any:
    """``cosim/log.proto`` (every message but the sensor sample) as a ``FileDescriptorProto``."""
    return _file_proto(_COSIM_FILE, COSIM_MESSAGES)


def _sensor_message(fields: Sequence[str]) -> tuple[str, str, tuple[FieldDef, ...]]:
    return ("SensorSample", "/cosim/sensors: one logged sample: t and one number per sensor (SI units).",
            (_d("t", 1, "simulated time, s"), *(_d(f, i + 2) for i, f in enumerate(fields))))


def sensor_file(names: Sequence[str]) -> Any:
    """``cosim/sensors.proto`` of a run with these sensors: ``cosim.SensorSample`` as a ``FileDescriptorProto``
    (``json_name``: the sensor's name, where the field's differs)."""
    fields = sensor_fields(names)
    message = _sensor_message(fields)
    return _file_proto(_SENSOR_FILE, [message], {("SensorSample", f): n for f, n in zip(fields, names) if f != n})


def proto_text(messages: Sequence[tuple[str, str, Sequence[FieldDef]]] = COSIM_MESSAGES) -> str:
    """The ``.proto`` source of ``messages`` (cosim/log/cosim.proto is this text)."""
    lines = ['// cosim\'s log messages (docs/logs.md). Written by cosim.log.proto.proto_text: edit the table there.',
             'syntax = "proto3";', "", "package cosim;", ""]
    for name, comment, fields in messages:
        lines += [f"// {comment}", f"message {name} {{"]
        oneofs: dict[str, list[FieldDef]] = {}
        for f in fields:
            if f.label.startswith("oneof "):
                oneofs.setdefault(f.label[6:], []).append(f)
        done: set[str] = set()
        for f in fields:
            kind = f.message or _TYPE_NAMES[f.type]
            note = f"  // {f.comment}" if f.comment else ""
            if f.label.startswith("oneof "):
                oneof = f.label[6:]
                if oneof in done:
                    continue
                done.add(oneof)
                lines.append(f"  oneof {oneof} {{")
                for g in oneofs[oneof]:
                    lines.append(f"    {g.message or _TYPE_NAMES[g.type]} {g.name} = {g.number};")
                lines.append("  }")
                continue
            label = f"{f.label} " if f.label in ("repeated", "optional") else ""
            lines.append(f"  {label}{kind} {f.name} = {f.number};{note}")
        lines += ["}", ""]
    lines += ["// /cosim/sensors: cosim.SensorSample, made for each run (its channel's schema, cosim/sensors.proto):",
              "//   message SensorSample { double t = 1; double <first sensor> = 2; double <second sensor> = 3; ... }",
              "// t in s, then one double per sensor in the run's order (SI units); a sensor whose name is not a",
              "// protobuf identifier is a field named with `_` for each other character, its json_name the name.", ""]
    return "\n".join(lines)


def _file_set(files: Sequence[Any]) -> bytes:
    from google.protobuf import descriptor_pb2

    return descriptor_pb2.FileDescriptorSet(file=list(files)).SerializeToString()


def _foxglove_files(descriptor: Any) -> list[Any]:
    """The ``FileDescriptorProto`` of a message's file and of every file it imports, imports first."""
    from google.protobuf import descriptor_pb2

    out: list[Any] = []
    seen: set[str] = set()

    def visit(file: Any) -> None:
        if file.name in seen:
            return
        seen.add(file.name)
        for dependency in file.dependencies:
            visit(dependency)
        proto = descriptor_pb2.FileDescriptorProto()
        file.CopyToProto(proto)
        out.append(proto)

    visit(descriptor.file)
    return out


@functools.cache
def _foxglove_classes() -> dict[str, Any]:
    from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

    return {"foxglove.SceneUpdate": SceneUpdate, "foxglove.FrameTransform": FrameTransform}


def schema_data(message: str, sensor_names: Sequence[str] = ()) -> bytes:
    """The schema record's data of ``message`` (a ``FileDescriptorSet``: its file and the files it imports)."""
    if message == "cosim.SensorSample":
        return _file_set([sensor_file(sensor_names)])
    if message.startswith("cosim."):
        return _cosim_schema()
    return _file_set(_foxglove_files(_foxglove_classes()[message].DESCRIPTOR))


@functools.lru_cache(maxsize=1)
def _cosim_schema() -> bytes:
    return _file_set([cosim_file()])


# --------------------------------------------------------------------------- specs: what the encoder walks

_VARINTS = (INT64, INT32, UINT32, ENUM, BOOL)
#: Keys of the time fields, as cosim's JSON scene (and Foxglove's JSON schemas) name them.
_TIME_KEYS = {"google.protobuf.Timestamp": ("sec", "nsec"), "google.protobuf.Duration": ("sec", "nsec")}


@dataclass(frozen=True)
class FieldSpec:
    key: str  # the dictionary key (the field name; the sensor's name; "sec"/"nsec" in times)
    attribute: str  # the field's name in the protobuf runtime's message
    number: int
    kind: int  # DOUBLE, FIXED32, STRING, MESSAGE or a varint type
    repeated: bool
    presence: bool  # explicit presence (optional, oneof, or a message field): absent keys are not written
    message: MessageSpec | None


@dataclass(frozen=True)
class MessageSpec:
    name: str
    fields: tuple[FieldSpec, ...]


def _spec(descriptor: Any, keys: dict[str, str] | None = None, seen: dict[str, MessageSpec] | None = None
          ) -> MessageSpec:
    seen = {} if seen is None else seen
    name = descriptor.full_name
    if name in seen:
        return seen[name]
    fields = []
    times = _TIME_KEYS.get(name)
    for i, f in enumerate(sorted(descriptor.fields, key=lambda f: f.number)):
        sub = _spec(f.message_type, None, seen) if f.type == MESSAGE else None
        key = times[i] if times else (keys or {}).get(f.name, f.name)
        repeated = f.is_repeated if hasattr(f, "is_repeated") else f.label == 3
        presence = f.containing_oneof is not None or f.type == MESSAGE
        fields.append(FieldSpec(key, f.name, f.number, f.type, repeated, presence, sub))
    out = MessageSpec(name, tuple(fields))
    seen[name] = out
    return out


@functools.cache
def _cosim_pool() -> Any:
    from google.protobuf import descriptor_pool

    pool = descriptor_pool.DescriptorPool()
    pool.Add(cosim_file())
    return pool


@functools.lru_cache(maxsize=64)
def _sensor_pool(names: tuple[str, ...]) -> Any:
    from google.protobuf import descriptor_pool

    pool = descriptor_pool.DescriptorPool()
    pool.Add(sensor_file(names))
    return pool


@functools.lru_cache(maxsize=64)
def spec_of(message: str, sensor_names: tuple[str, ...] = ()) -> MessageSpec:
    """What the encoder walks for ``message`` (the sensor sample of ``sensor_names``)."""
    if message == "cosim.SensorSample":
        descriptor = _sensor_pool(sensor_names).FindMessageTypeByName(message)
        return _spec(descriptor, dict(zip(sensor_fields(sensor_names), sensor_names)))
    if message.startswith("cosim."):
        return _spec(_cosim_pool().FindMessageTypeByName(message))
    return _spec(_foxglove_classes()[message].DESCRIPTOR)


# --------------------------------------------------------------------------- encoding


class Hole:
    """Where a number of a fixed-shape message goes (:class:`FixedTemplate`): column ``index`` of its rows."""

    __slots__ = ("index",)

    def __init__(self, index: int) -> None:
        self.index = index


def number_holes(value: Any, marker: Any) -> tuple[Any, int]:
    """``value`` with each ``marker`` replaced by a :class:`Hole` numbered in the order JSON would write them
    (dictionaries in their order, depth first); returns it and the number of holes."""
    count = 0

    def walk(v: Any) -> Any:
        nonlocal count
        if v is marker or (isinstance(v, str) and isinstance(marker, str) and v == marker):
            count += 1
            return Hole(count - 1)
        if isinstance(v, dict):
            return {k: walk(item) for k, item in v.items()}
        if isinstance(v, list | tuple):
            return [walk(item) for item in v]
        return v

    return walk(value), count


_PADDED = b"\x80\x80\x80\x80\x00"  # a varint hole: 5 bytes, whatever the value (up to 2^35 - 1)
_DOUBLE = struct.Struct("<d")
_FIXED32 = struct.Struct("<I")


def varint(value: int) -> bytes:
    """``value`` as a protobuf varint (a negative one as its 64-bit two's complement)."""
    return _varint(value)


def _varint(value: int) -> bytes:
    value = int(value)
    if value < 0:
        value += 1 << 64
    out = bytearray()
    while value > 0x7F:
        out.append((value & 0x7F) | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def _tag(number: int, wire: int) -> bytes:
    return _varint(number << 3 | wire)


def _scalar(kind: int, value: Any, out: bytearray, holes: list[tuple[int, int, int]]) -> None:
    if isinstance(value, Hole):
        holes.append((value.index, len(out), kind))
        out += bytes(8) if kind == DOUBLE else _PADDED
    elif kind == DOUBLE:
        out += _DOUBLE.pack(float(value))
    elif kind == FIXED32:
        out += _FIXED32.pack(int(value))
    elif kind == BOOL:
        out.append(1 if value else 0)
    else:
        out += _varint(int(value))


def _wire(kind: int) -> int:
    return 1 if kind == DOUBLE else 5 if kind == FIXED32 else 2 if kind in (STRING, MESSAGE) else 0


def _embed(number: int, body: bytearray, body_holes: list[tuple[int, int, int]], out: bytearray,
           holes: list[tuple[int, int, int]]) -> None:
    out += _tag(number, 2) + _varint(len(body))
    base = len(out)
    holes.extend((index, base + at, kind) for index, at, kind in body_holes)
    out += body


def _encode(spec: MessageSpec, value: dict[str, Any], out: bytearray, holes: list[tuple[int, int, int]]) -> None:
    for f in spec.fields:
        if f.key not in value:
            continue
        v = value[f.key]
        if v is None:
            continue
        if f.repeated:
            if f.kind == MESSAGE:
                assert f.message is not None
                for item in v:
                    body: bytearray = bytearray()
                    inner: list[tuple[int, int, int]] = []
                    _encode(f.message, item, body, inner)
                    _embed(f.number, body, inner, out, holes)
            elif f.kind == STRING:
                tag = _tag(f.number, 2)
                for item in v:
                    data = item.encode()
                    out += tag + _varint(len(data)) + data
            elif len(v):  # packed numbers
                body = bytearray()
                inner = []
                for item in v:
                    _scalar(f.kind, item, body, inner)
                _embed(f.number, body, inner, out, holes)
        elif f.kind == MESSAGE:
            assert f.message is not None
            body = bytearray()
            inner = []
            _encode(f.message, v, body, inner)
            _embed(f.number, body, inner, out, holes)
        elif f.kind == STRING:
            data = v.encode()
            out += _tag(f.number, 2) + _varint(len(data)) + data
        else:
            out += _tag(f.number, _wire(f.kind))
            _scalar(f.kind, v, out, holes)


def encode(spec: MessageSpec, value: dict[str, Any]) -> bytes:
    """``value`` (keyed as the JSON message) as a protobuf message of ``spec``."""
    out = bytearray()
    holes: list[tuple[int, int, int]] = []
    _encode(spec, value, out, holes)
    if holes:
        raise ValueError("encode: a Hole in a message to encode whole (use FixedTemplate)")
    return bytes(out)


def _padded_varints(values: np.ndarray) -> np.ndarray:
    """(rows, k) non-negative integers as 5-byte varints, (rows, k, 5) bytes."""
    v = np.clip(np.rint(values), 0, (1 << 35) - 1).astype(np.int64)
    out = np.empty(v.shape + (5,), dtype=np.uint8)
    for k in range(4):
        out[..., k] = ((v >> (7 * k)) & 0x7F) | 0x80
    out[..., 4] = (v >> 28) & 0x7F
    return out


#: Numbers drawn in the scene are clipped to this magnitude, m (no picture of a bridge comes near it).
LARGEST_DRAWN = 1e12


class FixedTemplate:
    """A message of a fixed shape with :class:`Hole` s where its numbers go, rendered for many rows at once.

    Args:
        spec: the message's spec; value: the message (keyed as JSON), with ``Hole(k)`` for column ``k``.
        decimals: ``double`` holes are rounded to this many decimals (None: written as they are).
        suffix: bytes appended to every rendered message.
    """

    def __init__(self, spec: MessageSpec, value: dict[str, Any], decimals: int | None = None) -> None:
        out = bytearray()
        holes: list[tuple[int, int, int]] = []
        _encode(spec, value, out, holes)
        self.data = bytes(out)
        self.holes = len(holes)
        if sorted(index for index, _, _ in holes) != list(range(len(holes))):
            raise ValueError("FixedTemplate: holes must be numbered 0, 1, ... once each")
        self.decimals = decimals
        by_index = sorted(holes)
        self._double_columns = np.array([i for i, _, kind in by_index if kind == DOUBLE], dtype=np.int64)
        self._double_at = np.array([at for _, at, kind in by_index if kind == DOUBLE], dtype=np.int64)
        self._varint_columns = np.array([i for i, _, kind in by_index if kind != DOUBLE], dtype=np.int64)
        self._varint_at = np.array([at for _, at, kind in by_index if kind != DOUBLE], dtype=np.int64)
        self._template = np.frombuffer(self.data, dtype=np.uint8)
        # One row: struct pieces between the holes, in the order of their offsets.
        order = sorted(holes, key=lambda h: h[1])
        fmt, position = ["<"], 0
        for _, at, kind in order:
            fmt.append(f"{at - position}s" + ("d" if kind == DOUBLE else "5s"))
            position = at + (8 if kind == DOUBLE else 5)
        fmt.append(f"{len(self.data) - position}s")
        self._row = struct.Struct("".join(fmt))
        self._pieces = [self.data[a:b] for a, b in zip([0, *[at + (8 if k == DOUBLE else 5) for _, at, k in order]],
                                                          [*[at for _, at, _ in order], len(self.data)])]
        self._row_order = [(index, kind) for index, _, kind in order]

    def _doubles(self, values: np.ndarray) -> np.ndarray:
        if self.decimals is None:
            return values
        return np.round(np.clip(values, -LARGEST_DRAWN, LARGEST_DRAWN), self.decimals) + 0.0

    def render_bytes(self, values: np.ndarray) -> tuple[bytes, int]:
        """The messages of every row of ``values`` (rows, holes) one after another, and the length of each."""
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 2 or values.shape[1] != self.holes:
            raise ValueError(f"FixedTemplate.render: expected (rows, {self.holes}) numbers, got {values.shape}")
        rows, size = values.shape[0], len(self.data)
        out = np.empty((rows, size), dtype=np.uint8)
        out[:] = self._template
        if len(self._double_at):
            doubles = np.ascontiguousarray(self._doubles(values[:, self._double_columns]), dtype="<f8")
            out[:, self._double_at[:, None] + np.arange(8)] = doubles.view(np.uint8).reshape(rows, -1, 8)
        if len(self._varint_at):
            out[:, self._varint_at[:, None] + np.arange(5)] = _padded_varints(values[:, self._varint_columns])
        return out.tobytes(), size

    def render(self, values: np.ndarray) -> list[bytes]:
        """One message per row of ``values`` (rows, holes)."""
        data, size = self.render_bytes(values)
        return [data[i:i + size] for i in range(0, len(data), size)]

    def row(self, values: Sequence[float]) -> bytes:
        """One message from a row of Python numbers (``struct``, for a message written alone)."""
        args: list[Any] = []
        rounded = self.decimals
        for piece, (index, kind) in zip(self._pieces, self._row_order):
            args.append(piece)
            x = values[index]
            if kind == DOUBLE:
                args.append(float(x) if rounded is None else round(min(max(float(x), -LARGEST_DRAWN),
                                                                       LARGEST_DRAWN), rounded) + 0.0)
            else:
                n = min(max(int(x), 0), (1 << 35) - 1)
                args.append(((n & 0x7F | 0x80) | (n >> 7 & 0x7F | 0x80) << 8 | (n >> 14 & 0x7F | 0x80) << 16
                             | (n >> 21 & 0x7F | 0x80) << 24 | (n >> 28 & 0x7F) << 32).to_bytes(5, "little"))
        args.append(self._pieces[-1])
        return self._row.pack(*args)


def length_delimited(number: int, data: bytes) -> bytes:
    """A length-delimited field (a message or a string) of field ``number``."""
    return _tag(number, 2) + _varint(len(data)) + data


def vehicle_type_wire(message: dict[str, Any]) -> dict[str, Any]:
    """A ``/cosim/vehicle_types`` message (JSON's shape: ``model`` an object of numbers) in the wire's."""
    model = message["model"]
    parameters = [{"name": k, "integer": v} if type(v) is int else {"name": k, "number": v}
                  for k, v in model.items() if k != "model"]
    return {**message, "model": {"model": model["model"], "parameters": parameters}}


# --------------------------------------------------------------------------- decoding


class SchemaProblem(ValueError):
    """A channel's schema is not the one cosim writes for its topic."""


def _sensor_names_from_schema(data: bytes) -> tuple[str, ...]:
    """The sensor names of a ``cosim.SensorSample`` schema, which must have cosim's shape: ``double t = 1`` and
    one ``double`` per sensor, numbered from 2 on."""
    from google.protobuf import descriptor_pb2
    from google.protobuf.message import DecodeError

    try:
        files = descriptor_pb2.FileDescriptorSet.FromString(data).file
    except (DecodeError, RecursionError):
        raise SchemaProblem("its schema is not a protobuf FileDescriptorSet") from None
    found = [m for f in files if f.package == "cosim" for m in f.message_type if m.name == "SensorSample"]
    if len(found) != 1:
        raise SchemaProblem("its schema does not define cosim.SensorSample")
    fields = list(found[0].field)
    label = descriptor_pb2.FieldDescriptorProto
    if not fields or fields[0].name != "t" or any(
            f.type != DOUBLE or f.number != i + 1 or f.label == label.LABEL_REPEATED or f.type_name
            for i, f in enumerate(fields)):
        raise SchemaProblem("its schema is not cosim's (t = 1, then one double per sensor)")
    names = tuple(f.json_name if f.HasField("json_name") else f.name for f in fields[1:])
    if len(set(names)) != len(names) or any(not n or n == "t" for n in names) or \
            [f.name for f in fields[1:]] != sensor_fields(names):
        raise SchemaProblem("its schema's sensor names are not cosim's")
    return names


def _to_dict(message: Any, spec: MessageSpec, foxglove: bool) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for f in spec.fields:
        value = getattr(message, f.attribute)
        if f.repeated:
            if f.kind == MESSAGE:
                assert f.message is not None
                if not value and foxglove:
                    continue
                out[f.key] = [_to_dict(item, f.message, foxglove) for item in value]
            else:
                if not value and foxglove:
                    continue
                out[f.key] = list(value)
        elif f.presence and not message.HasField(f.attribute):
            continue
        elif f.kind == MESSAGE:
            assert f.message is not None
            out[f.key] = _to_dict(value, f.message, foxglove)
        else:
            out[f.key] = value
    if spec.name == "cosim.VehicleModel":
        model: dict[str, Any] = {"model": out["model"]}
        for p in out["parameters"]:
            model[p["name"]] = p.get("number", p.get("integer", 0.0))
        return model
    return out


def decoder(message: str, schema: bytes) -> Callable[[bytes], dict[str, Any]]:
    """A function from a message's bytes to the dictionary the JSON log held (cosim's schema for ``message``;
    the sensor names from ``schema``, checked).

    The function raises ``google.protobuf.message.DecodeError`` for bytes that do not parse.

    Raises:
        SchemaProblem: ``schema`` does not have the shape cosim writes (sensor samples).
    """
    from google.protobuf import message_factory

    if message == "cosim.SensorSample":
        names = _sensor_names_from_schema(schema)
        return _sensor_decoder(names)
    if message.startswith("cosim."):
        descriptor = _cosim_pool().FindMessageTypeByName(message)
        cls = message_factory.GetMessageClass(descriptor)
        spec = spec_of(message)
        parse = cls.FromString
        return lambda data: _to_dict(parse(data), spec, False)
    cls = _foxglove_classes()[message]
    spec = spec_of(message)
    parse = cls.FromString
    return lambda data: _to_dict(parse(data), spec, True)


@functools.lru_cache(maxsize=16)
def _sensor_decoder(names: tuple[str, ...]) -> Callable[[bytes], dict[str, Any]]:
    from google.protobuf import message_factory

    cls = message_factory.GetMessageClass(_sensor_pool(names).FindMessageTypeByName("cosim.SensorSample"))
    parse = cls.FromString
    keys = ("t", *names)
    attributes = ("t", *sensor_fields(names))
    getter = __import__("operator").attrgetter(*attributes)

    def decode(data: bytes) -> dict[str, Any]:
        values = getter(parse(data))
        return dict(zip(keys, values))

    return decode
