"""TOML out: the writer :mod:`tomllib` lacks, and dotted keys into nested tables.

Scenarios are rewritten as TOML when a replay merges two of them, when a study
varies one, and when a scripted test builds one from tables.
"""
from __future__ import annotations

import json
import math
import re
from typing import Any

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


def get_key(data: dict[str, Any], dotted: str) -> Any:
    """The value at a dotted key (``"road.profile"``) of nested tables, or None if a part is missing."""
    node: Any = data
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def set_key(data: dict[str, Any], dotted: str, value: Any) -> None:
    """Set the value at a dotted key of nested tables (its parent tables must exist)."""
    *parents, last = dotted.split(".")
    node = data
    for part in parents:
        node = node[part]
    node[last] = value
