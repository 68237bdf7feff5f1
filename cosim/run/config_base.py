"""The validation layer shared by cosim's TOML files (scenarios, studies, datasets).

Pydantic models with ``extra="forbid"`` and strict numbers, and one formatter
that turns pydantic's errors into cosim's one-line messages::

    <file>: <dotted.key>: <what is wrong> (got <value>)

with "did you mean" for misspelled keys and choices. Files build their tables
on :class:`ConfigModel` and raise :class:`Problems` (via :func:`fail`) from
validators; :func:`config_error` formats a ``ValidationError`` for a file, and
:func:`load_config` reads a file's TOML and validates it in one call.
"""
from __future__ import annotations

import difflib
import json
import math
import sys
import types
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, TypeVar, Union, get_args, get_origin, overload

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    Strict,
    ValidationError,
)

from cosim.errors import ConfigError, CosimError

# cosim's one number formatter: "500", "0.1", "-0.3333333333333333", the shortest text that reads back as the same
# number (repr), not %.6g. It writes SUMO files and run ids, which must be exact, and the numbers of messages, where
# a rounded bound can contradict its message ("must be <= 166.667 Hz (got 166.6667)" for 1 / 0.006 s).
from cosim.sumo.files import number_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

#: Top-level sections that later versions add; rejected for now with a clear note.
FUTURE_SECTIONS: dict[str, str] = {}

# --------------------------------------------------------------------------- errors


class Problems(ValueError):
    """Problems found by a validator, each with a key path relative to the value checked."""

    def __init__(self, problems: Sequence[tuple[Sequence[str | int], str]]) -> None:
        super().__init__("; ".join(msg for _, msg in problems))
        self.problems = [(tuple(loc), msg) for loc, msg in problems]


def fail(message: str, *loc: str | int) -> Problems:
    return Problems([(tuple(loc), message)])


def show(value: Any, limit: int = 60) -> str:
    """A TOML-looking rendering of a value for error messages."""
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = json.dumps(value, ensure_ascii=False)
    elif isinstance(value, float):
        text = repr(value) if value == 0 or 1e-4 <= abs(value) < 1e6 else f"{value:.10g}"
    elif isinstance(value, (list, tuple)):
        text = "[" + ", ".join(show(v, limit) for v in value) + "]"
    elif isinstance(value, dict):
        text = "{" + ", ".join(f"{k} = {show(v, limit)}" for k, v in value.items()) + "}"
    else:
        text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def describe(value: Any) -> str:
    """What kind of TOML value was found: 'string "0.005"', 'a table', ..."""
    if isinstance(value, bool):
        return f"boolean {show(value)}"
    if isinstance(value, (int, float)):
        return f"number {show(value)}"
    if isinstance(value, str):
        return f"string {show(value)}"
    if isinstance(value, dict):
        return f"a table {show(value)}"
    if isinstance(value, (list, tuple)):
        return f"an array {show(value)}"
    return f"{type(value).__name__} {show(value)}"


def key_path(loc: tuple[str | int, ...]) -> str:
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += ("." if text else "") + str(part)
    return text or "(top level)"


def _unwrap(annotation: Any) -> Any:
    """Strip Annotated and Optional from a field annotation."""
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin is Union or isinstance(annotation, types.UnionType):
            args = [a for a in get_args(annotation) if a is not type(None)]
            if len(args) != 1:
                return annotation
            annotation = args[0]
        else:
            return annotation


def _keys(model: type[BaseModel]) -> list[str]:
    """The TOML keys of a table: field aliases where given (``class``), else field names."""
    return [field.alias or name for name, field in model.model_fields.items()]


def _field(model: type[BaseModel], key: str) -> Any:
    for name, field in model.model_fields.items():
        if key in (name, field.alias):
            return field
    return None


def _model_at(root: type[BaseModel], loc: tuple[str | int, ...]) -> type[BaseModel] | None:
    """The model class that validates the table at ``loc`` (None if not a table)."""
    annotation: Any = root
    for part in loc:
        annotation = _unwrap(annotation)
        if isinstance(part, int):
            if get_origin(annotation) not in (tuple, list):
                return None
            annotation = get_args(annotation)[0]
            continue
        if not (isinstance(annotation, type) and issubclass(annotation, BaseModel)):
            return None
        field = _field(annotation, part)
        if field is None:
            return None
        annotation = field.annotation
    annotation = _unwrap(annotation)
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None


def suggest(word: str, choices: list[str] | tuple[str, ...]) -> str | None:
    lowered = {c.lower(): c for c in choices}
    if word.lower() in lowered:
        return lowered[word.lower()]
    scored = sorted(
        ((difflib.SequenceMatcher(None, word, c).ratio(), c) for c in choices), reverse=True
    )
    if not scored or scored[0][0] < 0.6:
        return None
    if len(scored) > 1 and scored[1][0] == scored[0][0]:
        return None  # ambiguous: no suggestion rather than a wrong one
    return scored[0][1]


def choices_message(value: Any, choices: tuple[str, ...] | list[str], what: str = "") -> str:
    listed = ", ".join(choices)
    if not isinstance(value, str):
        return f"expected {what or 'a string'}, one of: {listed} (got {describe(value)})"
    hint = suggest(value, choices)
    hint_text = f'; did you mean "{hint}"?' if hint else ""
    return f"unknown {what or 'value'} {show(value)}{hint_text} (expected one of: {listed})"


_TYPE_EXPECTED = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "an integer",
    "string_type": "a string",
    "bool_type": "a boolean",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "dict_type": "a table",
    "tuple_type": "an array",
    "list_type": "an array",
}

_BOUNDS = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}


def _format_one(root: Any, error: dict[str, Any]) -> list[tuple[tuple[str | int, ...], str]]:
    """(key path, message) pairs for one pydantic error (``root``: the model or type validated)."""
    loc: tuple[str | int, ...] = tuple(error["loc"])
    kind = error["type"]
    value = error.get("input")
    ctx = error.get("ctx") or {}

    if kind == "value_error" and isinstance(ctx.get("error"), Problems):
        return [(loc + rel, msg) for rel, msg in ctx["error"].problems]
    if kind in ("value_error", "assertion_error"):
        message = str(ctx.get("error", error["msg"]))
        return [(loc, message)]
    if kind == "extra_forbidden":
        parent = _model_at(root, loc[:-1])
        allowed = _keys(parent) if parent is not None else []
        key = str(loc[-1])
        listed = f"expected one of: {', '.join(allowed)}" if allowed else "no keys expected here"
        if len(loc) == 1 and key in FUTURE_SECTIONS:
            return [(loc,
                     f"not supported yet (planned for a later version: {FUTURE_SECTIONS[key]}; {listed})")]
        hint = suggest(key, allowed)
        hint_text = f'; did you mean "{hint}"?' if hint else ""
        return [(loc, f"unknown key{hint_text} ({listed})")]
    if kind == "missing":
        return [(loc, "required key is missing")]
    if kind in _TYPE_EXPECTED:
        expected = _TYPE_EXPECTED[kind]
        if kind in ("tuple_type", "list_type") and isinstance(value, dict):
            return [(loc, f"expected an array of tables ([[{key_path(loc)}]]), got a single table")]
        if kind in ("model_type", "dict_type") and isinstance(value, (list, tuple)):
            return [(loc, f"expected a table ([{key_path(loc)}]), got {describe(value)}")]
        return [(loc, f"expected {expected}, got {describe(value)}")]
    if kind in _BOUNDS:
        bound = next(iter(ctx.values()))
        return [(loc, f"must be {_BOUNDS[kind]} {number_text(bound)} (got {show(value)})")]
    if kind == "finite_number":
        return [(loc, f"must be a finite number (got {show(value)})")]
    if kind == "too_short":
        return [(loc, f"expected at least {ctx.get('min_length')} item(s), got {ctx.get('actual_length')}")]
    if kind == "too_long":
        return [(loc, f"expected at most {ctx.get('max_length')} item(s), got {ctx.get('actual_length')}")]
    if kind == "string_too_short":
        return [(loc, f"must not be empty (got {show(value)})")]
    if kind == "string_pattern_mismatch":
        return [(loc, f"may contain only letters, digits, '_', '.' and '-' (got {show(value)})")]
    return [(loc, f"{error['msg']} (got {show(value)})")]


def config_error(source: str, root: type[BaseModel], exc: ValidationError) -> ConfigError:
    errors = exc.errors(include_url=False)
    # A misspelt key also makes its correct spelling "missing": report the
    # misspelling (with its suggestion) only.
    suggested: set[tuple[str | int, ...]] = set()
    for error in errors:
        if error["type"] == "extra_forbidden":
            loc = tuple(error["loc"])
            parent = _model_at(root, loc[:-1])
            hint = suggest(str(loc[-1]), _keys(parent)) if parent is not None else None
            if hint is not None:
                suggested.add(loc[:-1] + (hint,))
    lines: list[str] = []
    for error in errors:
        if error["type"] == "missing" and tuple(error["loc"]) in suggested:
            continue
        for loc, message in _format_one(root, dict(error)):
            lines.append(f"{source}: {key_path(loc)}: {message}")
    if len(lines) > 1:
        more = len(lines) - 1
        lines.insert(1, f"({more} more problem{'s' if more > 1 else ''}:)")
    return ConfigError("\n".join(lines))


def problems_of(root: Any, exc: ValidationError) -> list[tuple[tuple[str | int, ...], str]]:
    """A pydantic error as (key path, message) problems (for :class:`Problems`): what :func:`config_error` says,
    for a validator that validates part of its value itself (``root``: the model or type it validated)."""
    return [problem for error in exc.errors(include_url=False) for problem in _format_one(root, dict(error))]


_Model = TypeVar("_Model", bound=BaseModel)


@overload
def load_config(document: str | Mapping[str, Any], source: str, model: None = None, *,
                context: dict[str, Any] | None = None, error: type[CosimError] = ConfigError) -> dict[str, Any]: ...


@overload
def load_config(document: str | Mapping[str, Any], source: str, model: type[_Model], *,
                context: dict[str, Any] | None = None, error: type[CosimError] = ConfigError) -> _Model: ...


def load_config(
    document: str | Mapping[str, Any], source: str, model: type[_Model] | None = None, *,
    context: dict[str, Any] | None = None, error: type[CosimError] = ConfigError,
) -> _Model | dict[str, Any]:
    """A TOML document's tables, validated as ``model`` when one is given: the one TOML-to-config loader.

    Scenarios, studies and datasets read their files through it, and so do a
    replay (the scenario a log embeds) and ``cosim.testing`` (TOML text as a base).

    Args:
        document: TOML text, or the tables already read from it (then only validated).
        source: how messages name the document: the file's path, ``"<scenario>"``, ...
        model: the file's :class:`ConfigModel`; None returns the tables as read.
        context: pydantic's validation context, for validators that need the file
            (the scenario's source, text and folder).
        error: what a TOML syntax error raises: :class:`ConfigError`, or
            :class:`~cosim.errors.LogError` for the scenario a log embeds (a damaged log).

    Raises:
        ConfigError: ``<source>: TOML syntax error: <what> (at line L, column C)`` (as ``error``),
            or the model's problems, one line per key (:func:`config_error`).
    """
    if isinstance(document, str):
        try:
            data = tomllib.loads(document)
        except tomllib.TOMLDecodeError as exc:
            raise error(f"{source}: TOML syntax error: {exc}") from None
    else:
        data = dict(document)
    if model is None:
        return data
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        raise config_error(source, model, exc) from None


# --------------------------------------------------------------------------- field types

Number = Annotated[float, Strict()]
"""A float; integers are accepted, strings and booleans are not."""
Positive = Annotated[float, Strict(), Field(gt=0)]
NonNegative = Annotated[float, Strict(), Field(ge=0)]
PositiveInt = Annotated[int, Strict(), Field(ge=1)]
Text = Annotated[str, Strict()]
Name = Annotated[str, Strict(), Field(pattern=r"^[A-Za-z0-9_.-]+$")]
"""A name that can be part of a file name or a run id (a mismatch's message lists the characters allowed)."""


def number_pair(value: Any, names: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise fail(f"expected an array of 2 numbers [{names}], got {describe(value)}")
    problems = []
    for i, item in enumerate(value):
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            problems.append(((i,), f"expected a number, got {describe(item)}"))
        elif not math.isfinite(item):
            problems.append(((i,), f"must be a finite number (got {show(item)})"))
    if problems:
        raise Problems(problems)
    return (float(value[0]), float(value[1]))


Point = Annotated[tuple[float, float], PlainValidator(lambda v: number_pair(v, "y, z"))]
"""A section point (y, z) in metres."""
Interval = Annotated[tuple[float, float], PlainValidator(lambda v: number_pair(v, "min, max"))]
NetPoint = Annotated[tuple[float, float], PlainValidator(lambda v: number_pair(v, "x, y"))]
"""A point (x, y) in SUMO network coordinates, m."""


def choice(choices: tuple[str, ...], what: str) -> PlainValidator:
    """A validator (``Annotated[str, choice(...)]``): one of ``choices``, else "unknown <what> ...", with a hint."""

    def check(value: Any) -> str:
        if not isinstance(value, str) or value not in choices:
            raise fail(choices_message(value, choices, what))
        return value

    return PlainValidator(check)




class ConfigModel(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def number_problem(item: Any) -> str | None:
    if isinstance(item, bool) or not isinstance(item, (int, float)):
        return f"expected a number, got {describe(item)}"
    if not math.isfinite(item):
        return f"must be a finite number (got {show(item)})"
    return None
