"""Checking what a log holds before it is used: decoded messages against cosim's own JSON Schemas.

A log is untrusted input (people send logs to each other), so every message
the reader hands out is checked against the schema cosim writes for its topic
(:mod:`cosim.log.schemas`), never against the schema stored in the file. A
message that does not match is a :class:`cosim.errors.LogError` of one line
naming the topic, the field and what was found; numbers must also be finite.

The checks are compiled from the schema dictionaries once per topic: a log
holds up to millions of messages, and a general JSON Schema validator costs
tens of microseconds per message where these closures cost one or two. They
understand exactly the keywords cosim's schemas use (``type``, ``properties``,
``required``, ``additionalProperties``, ``items``, ``enum``); the tests check
them against the ``jsonschema`` package on random messages.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from .schemas import (
    EVENTS_SCHEMA,
    FRAME_TRANSFORM_SCHEMA,
    SCENE_UPDATE_SCHEMA,
    STATUS_SCHEMA,
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
    TRAFFIC_SCHEMA,
    VEHICLE_LOADS_SCHEMA,
    VEHICLE_TYPE_SCHEMA,
    VEHICLES_SCHEMA,
)

__all__ = ["Check", "compile_schema", "message_check"]

#: A compiled check: None when the value matches, else what is wrong (``"vehicles[2].x: expected ..."``).
Check = Callable[[Any], "str | None"]


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _where(path: str, name: str | int) -> str:
    if isinstance(name, int):
        return f"{path}[{name}]"
    return f"{path}.{name}" if path else name


def _is_number(value: Any) -> bool:
    return (type(value) is float and math.isfinite(value)) or (type(value) is int)


_TYPES: dict[str, Callable[[Any], bool]] = {
    "number": _is_number,
    "integer": lambda v: type(v) is int or (type(v) is float and v.is_integer()),
    "string": lambda v: type(v) is str,
    "boolean": lambda v: type(v) is bool,
    "object": lambda v: type(v) is dict,
    "array": lambda v: type(v) is list,
    "null": lambda v: v is None,
}
_EXPECTED = {"number": "a finite number", "integer": "an integer", "string": "a string", "boolean": "a boolean",
             "object": "an object", "array": "an array", "null": "null"}


def compile_schema(schema: dict[str, Any], path: str = "") -> Callable[[Any, str], str | None]:
    """A function ``check(value, path)`` for ``schema``: None if ``value`` matches, else the first problem.

    Raises:
        ValueError: the schema uses a keyword this compiler does not understand (a programming error).
    """
    known = {"type", "properties", "required", "additionalProperties", "items", "enum", "title", "description"}
    unknown = set(schema) - known
    if unknown:
        raise ValueError(f"unsupported schema keyword(s): {', '.join(sorted(unknown))}")
    steps: list[Callable[[Any, str], str | None]] = []
    if "type" in schema:
        kind = schema["type"]
        test = _TYPES[kind]
        expected = _EXPECTED[kind]

        def check_type(value: Any, where: str) -> str | None:
            return None if test(value) else f"{where or 'the message'}: expected {expected}, got {_shown(value)}"

        steps.append(check_type)
    if "enum" in schema:
        choices = list(schema["enum"])

        def check_enum(value: Any, where: str) -> str | None:
            if any(type(value) is type(c) and value == c for c in choices):
                return None
            return f"{where or 'the message'}: expected one of {', '.join(map(str, choices))}, got {_shown(value)}"

        steps.append(check_enum)
    if any(k in schema for k in ("properties", "required", "additionalProperties")):
        props = {name: compile_schema(sub) for name, sub in schema.get("properties", {}).items()}
        required = list(schema.get("required", []))
        extra = schema.get("additionalProperties", True)
        extra_check = compile_schema(extra) if isinstance(extra, dict) else None

        def check_object(value: Any, where: str) -> str | None:
            if type(value) is not dict:
                return None  # "type" says what it must be
            for name in required:
                if name not in value:
                    return f"{_where(where, name)}: missing"
            for name, item in value.items():
                sub = props.get(name)
                if sub is not None:
                    problem = sub(item, _where(where, name))
                elif extra is False:
                    problem = f"{_where(where, name)}: not a field of this topic"
                elif extra_check is not None:
                    problem = extra_check(item, _where(where, name))
                else:
                    problem = None
                if problem is not None:
                    return problem
            return None

        steps.append(check_object)
    if "items" in schema:
        item_check = compile_schema(schema["items"])

        def check_items(value: Any, where: str) -> str | None:
            if type(value) is not list:
                return None
            for i, item in enumerate(value):
                problem = item_check(item, _where(where, i))
                if problem is not None:
                    return problem
            return None

        steps.append(check_items)

    def check(value: Any, where: str = path) -> str | None:
        for step in steps:
            problem = step(value, where)
            if problem is not None:
                return problem
        return None

    return check


def _sensor_check(value: Any) -> str | None:
    """A sensor sample: ``t`` and any sensor channels, every value a finite number (names: checked by users)."""
    if type(value) is not dict:
        return f"the message: expected an object, got {_shown(value)}"
    if "t" not in value:
        return "t: missing"
    for name, item in value.items():
        if not ((type(item) is float and math.isfinite(item)) or type(item) is int):
            return f"{name}: expected a finite number, got {_shown(item)}"
    return None


_COMPILED: dict[str, Callable[..., str | None]] = {
    TOPIC_SENSORS: _sensor_check,
    TOPIC_VEHICLES: compile_schema(VEHICLES_SCHEMA),
    TOPIC_EVENTS: compile_schema(EVENTS_SCHEMA),
    TOPIC_STATUS: compile_schema(STATUS_SCHEMA),
    TOPIC_TRAFFIC: compile_schema(TRAFFIC_SCHEMA),
    TOPIC_VEHICLE_TYPES: compile_schema(VEHICLE_TYPE_SCHEMA),
    TOPIC_VEHICLE_LOADS: compile_schema(VEHICLE_LOADS_SCHEMA),
    TOPIC_SCENE: compile_schema(SCENE_UPDATE_SCHEMA),
    TOPIC_SCENE_STATIC: compile_schema(SCENE_UPDATE_SCHEMA),
    TOPIC_SCENE_TRANSFORM: compile_schema(FRAME_TRANSFORM_SCHEMA),
}


def message_check(topic: str) -> Callable[..., str | None] | None:
    """The check of a cosim topic's messages, or None for a topic cosim does not write (not read either)."""
    return _COMPILED.get(topic)
