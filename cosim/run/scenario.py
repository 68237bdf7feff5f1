"""Scenario files: TOML in, frozen and validated configuration objects out.

A scenario describes one bridge (spans, material, cross-section, supports,
damping), its sensors, scripted vehicles, the road surface, the solver
settings and where results go; ``docs/scenario.md`` documents every key with
its unit, default and constraints.

Typical use::

    from cosim.run.scenario import load_scenario

    scenario = load_scenario("paper-double-tee")      # a bundled scenario, or a path
    bridge = scenario.build_bridge()                  # cosim.core.bridge.BridgeModel
    result = scenario.simulate()                      # cosim.core.simulation.SimulationResult

The pieces :meth:`Scenario.simulate` wires together are available one by one:
:meth:`Scenario.build_vehicles` (a :class:`cosim.core.traffic.ScriptedTraffic`),
:meth:`Scenario.build_road` (a :class:`cosim.core.roughness.RoadProfile`),
:meth:`Scenario.solver_settings` and :meth:`Scenario.sensors_core`.

Every problem with a scenario (missing file, TOML syntax, unknown or missing
key, wrong type, non-physical value) raises :class:`cosim.errors.ConfigError`
whose first line names the file and the dotted key, what was expected and what
was found, e.g.::

    paper.toml: bridge.section.plates[0].thickness: must be > 0 (got -0.25)

Numbers are strict: an integer is accepted where a float belongs, a string or a
boolean never is. All objects are frozen; "changing" one means building a new
one (``model_copy(update=...)``).
"""
from __future__ import annotations

import contextlib
import datetime
import difflib
import json
import math
import os
import re
import sys
import types
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Callable, Iterator, Union, get_args, get_origin

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    PrivateAttr,
    Strict,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from cosim.core.bridge import DOF_NAMES, SUPPORT_PRESETS, BridgeModel, ExplicitDamping, RayleighDamping, build_bridge
from cosim.core.bridge import MODE_KINDS as _BRIDGE_MODE_KINDS
from cosim.core.roughness import ISO_CLASSES, RoadProfile, iso8608_profile, profile_from_csv, smooth_road
from cosim.core.section import Material, Plate, SectionProperties, section_from_constants, section_from_plates
from cosim.core.simulation import Sensor, SimulationResult, SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel
from cosim.errors import ConfigError, ModelError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "BridgeConfig",
    "ConstantsConfig",
    "DampingConfig",
    "DOF_NAMES",
    "MODE_KINDS",
    "MaterialConfig",
    "OutputConfig",
    "PlateConfig",
    "QUANTITIES",
    "ROAD_CLASSES",
    "RoadConfig",
    "SUPPORT_PRESETS",
    "Scenario",
    "SectionConfig",
    "SensorConfig",
    "SolverConfig",
    "VEHICLE_MODELS",
    "VehicleConfig",
    "list_bundled_scenarios",
    "load_scenario",
    "parse_scenario",
]

# --------------------------------------------------------------------------- names

#: Mode kinds a damping mode reference may name ("vertical-1", "torsion-2", ...).
MODE_KINDS: tuple[str, ...] = tuple(_BRIDGE_MODE_KINDS)

#: Sensor quantities.
QUANTITIES: tuple[str, ...] = ("displacement", "velocity", "acceleration", "bending_moment")

SCHEMES: tuple[str, ...] = ("newmark", "hht")
BASES: tuple[str, ...] = ("direct", "modal")

#: Vehicle models of ``[[vehicles]]`` and their parameters: name -> (required, optional with default).
VEHICLE_MODELS: dict[str, tuple[tuple[str, ...], dict[str, float]]] = {
    "moving-force": (("mass",), {}),
    "quarter-car": (("m_v", "m_w", "k_v", "c_v"), {}),
    "tyre-quarter-car": (("m_v", "m_w", "k_v", "c_v", "k_t"), {"c_t": 0.0}),
    "golden-car": (("m_v",), {}),
}
VEHICLE_PARAMETERS: tuple[str, ...] = ("mass", "m_v", "m_w", "k_v", "c_v", "k_t", "c_t")
DIRECTIONS: dict[str, int] = {"+x": 1, "-x": -1}

#: ``[road].class``: an ISO 8608 class, or a smooth road.
ROAD_CLASSES: tuple[str, ...] = (*ISO_CLASSES, "smooth")
#: Random road profiles cover the deck plus this margin at both ends, m.
ROAD_MARGIN = 10.0

#: Top-level sections that later versions add; rejected for now with a clear note.
FUTURE_SECTIONS: dict[str, str] = {}

#: ``[traffic].sumo_config`` may name one of these bundled demand levels (sumo_networks/<level>.sumocfg).
SUMO_LEVELS: tuple[str, ...] = ("light", "medium", "heavy", "congested")
#: With SUMO traffic, random road profiles are laid on wheel paths this far apart across the deck, m.
SUMO_PATH_SPACING = 0.5

_MODE_REF = re.compile(r"(?P<kind>[a-z]+)-(?P<n>[0-9]+)")
_NAME_PATTERN = r"^[A-Za-z0-9_.-]+$"

DEFAULT_HHT_ALPHA = -0.05
DEFAULT_MODAL_MODES = 30
#: Without ``solver.duration``, the run lasts until the last vehicle leaves the deck plus this, s.
RING_DOWN = 2.0
DEFAULT_OUTPUT_DIR = "runs"
#: Default logging rate of ``[output]``, Hz (every step when dt is longer than its period).
DEFAULT_RATE_HZ = 100.0


# --------------------------------------------------------------------------- errors


class _Problems(ValueError):
    """Problems found by a validator, each with a key path relative to the value checked."""

    def __init__(self, problems: list[tuple[tuple[str | int, ...], str]]) -> None:
        super().__init__("; ".join(msg for _, msg in problems))
        self.problems = problems


def _fail(message: str, *loc: str | int) -> _Problems:
    return _Problems([(tuple(loc), message)])


def _num(value: float) -> str:
    """A bound for messages: 0 rather than 0.0, -0.333333 rather than 16 digits."""
    value = float(value)
    if value.is_integer():
        return str(int(value))
    return f"{value:.6g}"


def _show(value: Any, limit: int = 60) -> str:
    """A TOML-looking rendering of a value for error messages."""
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = json.dumps(value, ensure_ascii=False)
    elif isinstance(value, float):
        text = repr(value) if value == 0 or 1e-4 <= abs(value) < 1e6 else f"{value:.10g}"
    elif isinstance(value, (list, tuple)):
        text = "[" + ", ".join(_show(v, limit) for v in value) + "]"
    elif isinstance(value, dict):
        text = "{" + ", ".join(f"{k} = {_show(v, limit)}" for k, v in value.items()) + "}"
    else:
        text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe(value: Any) -> str:
    """What kind of TOML value was found: 'string "0.005"', 'a table', ..."""
    if isinstance(value, bool):
        return f"boolean {_show(value)}"
    if isinstance(value, (int, float)):
        return f"number {_show(value)}"
    if isinstance(value, str):
        return f"string {_show(value)}"
    if isinstance(value, dict):
        return f"a table {_show(value)}"
    if isinstance(value, (list, tuple)):
        return f"an array {_show(value)}"
    return f"{type(value).__name__} {_show(value)}"


def _path(loc: tuple[str | int, ...]) -> str:
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


def _suggest(word: str, choices: list[str] | tuple[str, ...]) -> str | None:
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


def _choices_message(value: Any, choices: tuple[str, ...] | list[str], what: str = "") -> str:
    listed = ", ".join(choices)
    if not isinstance(value, str):
        return f"expected {what or 'a string'}, one of: {listed} (got {_describe(value)})"
    hint = _suggest(value, choices)
    hint_text = f'; did you mean "{hint}"?' if hint else ""
    return f"unknown {what or 'value'} {_show(value)}{hint_text} (expected one of: {listed})"


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


def _format_one(root: type[BaseModel], error: dict[str, Any]) -> list[tuple[str, str]]:
    """(dotted key, message) pairs for one pydantic error."""
    loc: tuple[str | int, ...] = tuple(error["loc"])
    kind = error["type"]
    value = error.get("input")
    ctx = error.get("ctx") or {}

    if kind == "value_error" and isinstance(ctx.get("error"), _Problems):
        return [(_path(loc + rel), msg) for rel, msg in ctx["error"].problems]
    if kind in ("value_error", "assertion_error"):
        message = str(ctx.get("error", error["msg"]))
        return [(_path(loc), message)]
    if kind == "extra_forbidden":
        parent = _model_at(root, loc[:-1])
        allowed = _keys(parent) if parent is not None else []
        key = str(loc[-1])
        listed = f"expected one of: {', '.join(allowed)}" if allowed else "no keys expected here"
        if len(loc) == 1 and key in FUTURE_SECTIONS:
            return [(_path(loc), f"not supported yet (planned for a later version: {FUTURE_SECTIONS[key]}; {listed})")]
        hint = _suggest(key, allowed)
        hint_text = f'; did you mean "{hint}"?' if hint else ""
        return [(_path(loc), f"unknown key{hint_text} ({listed})")]
    if kind == "missing":
        return [(_path(loc), "required key is missing")]
    if kind in _TYPE_EXPECTED:
        expected = _TYPE_EXPECTED[kind]
        if kind in ("tuple_type", "list_type") and isinstance(value, dict):
            return [(_path(loc), f"expected an array of tables ([[{_path(loc)}]]), got a single table")]
        if kind in ("model_type", "dict_type") and isinstance(value, (list, tuple)):
            return [(_path(loc), f"expected a table ([{_path(loc)}]), got {_describe(value)}")]
        return [(_path(loc), f"expected {expected}, got {_describe(value)}")]
    if kind in _BOUNDS:
        bound = next(iter(ctx.values()))
        return [(_path(loc), f"must be {_BOUNDS[kind]} {_num(bound)} (got {_show(value)})")]
    if kind == "finite_number":
        return [(_path(loc), f"must be a finite number (got {_show(value)})")]
    if kind == "too_short":
        return [(_path(loc), f"expected at least {ctx.get('min_length')} item(s), got {ctx.get('actual_length')}")]
    if kind == "too_long":
        return [(_path(loc), f"expected at most {ctx.get('max_length')} item(s), got {ctx.get('actual_length')}")]
    if kind == "string_too_short":
        return [(_path(loc), f"must not be empty (got {_show(value)})")]
    if kind == "string_pattern_mismatch":
        return [(_path(loc), f"may contain only letters, digits, '_', '.' and '-' (got {_show(value)})")]
    return [(_path(loc), f"{error['msg']} (got {_show(value)})")]


def _config_error(source: str, root: type[BaseModel], exc: ValidationError) -> ConfigError:
    errors = exc.errors(include_url=False)
    # A misspelt key also makes its correct spelling "missing": report the
    # misspelling (with its suggestion) only.
    suggested: set[tuple[str | int, ...]] = set()
    for error in errors:
        if error["type"] == "extra_forbidden":
            loc = tuple(error["loc"])
            parent = _model_at(root, loc[:-1])
            hint = _suggest(str(loc[-1]), _keys(parent)) if parent is not None else None
            if hint is not None:
                suggested.add(loc[:-1] + (hint,))
    lines: list[str] = []
    for error in errors:
        if error["type"] == "missing" and tuple(error["loc"]) in suggested:
            continue
        for key, message in _format_one(root, error):
            lines.append(f"{source}: {key}: {message}")
    if len(lines) > 1:
        more = len(lines) - 1
        lines.insert(1, f"({more} more problem{'s' if more > 1 else ''}:)")
    return ConfigError("\n".join(lines))


# --------------------------------------------------------------------------- field types

Number = Annotated[float, Strict()]
"""A float; integers are accepted, strings and booleans are not."""
Positive = Annotated[float, Strict(), Field(gt=0)]
NonNegative = Annotated[float, Strict(), Field(ge=0)]
PositiveInt = Annotated[int, Strict(), Field(ge=1)]
Text = Annotated[str, Strict()]


def _pair(value: Any, names: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise _fail(f"expected an array of 2 numbers [{names}], got {_describe(value)}")
    problems = []
    for i, item in enumerate(value):
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            problems.append(((i,), f"expected a number, got {_describe(item)}"))
        elif not math.isfinite(item):
            problems.append(((i,), f"must be a finite number (got {_show(item)})"))
    if problems:
        raise _Problems(problems)
    return (float(value[0]), float(value[1]))


Point = Annotated[tuple[float, float], PlainValidator(lambda v: _pair(v, "y, z"))]
"""A section point (y, z) in metres."""
Interval = Annotated[tuple[float, float], PlainValidator(lambda v: _pair(v, "min, max"))]
NetPoint = Annotated[tuple[float, float], PlainValidator(lambda v: _pair(v, "x, y"))]
"""A point (x, y) in SUMO network coordinates, m."""


def _choice(choices: tuple[str, ...], what: str):  # noqa: ANN202 - returns a validator
    def check(value: Any) -> str:
        if not isinstance(value, str) or value not in choices:
            raise _fail(_choices_message(value, choices, what))
        return value

    return PlainValidator(check)


def _count_problem(item: Any) -> str | None:
    """Why ``item`` is not an element count (an integer >= 1), or None."""
    if isinstance(item, bool) or not isinstance(item, int):
        return f"expected an integer >= 1, got {_describe(item)}"
    if item < 1:
        return f"must be >= 1 (got {item})"
    return None


def _elements_per_span(value: Any) -> int | tuple[int, ...]:
    if isinstance(value, (list, tuple)):
        if not value:
            raise _fail("expected an integer or a non-empty array of integers (one per span), got []")
        problems = [((i,), msg) for i, item in enumerate(value) if (msg := _count_problem(item))]
        if problems:
            raise _Problems(problems)
        return tuple(value)
    problem = _count_problem(value)
    if problem is not None:
        if isinstance(value, int) and not isinstance(value, bool):
            raise _fail(problem)
        raise _fail(f"expected an integer >= 1 or an array of them (one per span), got {_describe(value)}")
    return value


def _supports(value: Any) -> tuple[str | tuple[str, ...], ...]:
    preset_names = tuple(SUPPORT_PRESETS)
    if not isinstance(value, (list, tuple)):
        raise _fail(
            "expected an array with one entry per support line (a preset name or an array of DOF names), "
            f"got {_describe(value)}"
        )
    problems: list[tuple[tuple[int, ...], str]] = []
    result: list[str | tuple[str, ...]] = []
    for i, item in enumerate(value):
        if isinstance(item, str):
            if item not in SUPPORT_PRESETS:
                problems.append(((i,), _choices_message(item, preset_names, "support preset")))
            result.append(item)
        elif isinstance(item, (list, tuple)):
            seen: set[str] = set()
            for j, dof in enumerate(item):
                if not isinstance(dof, str) or dof not in DOF_NAMES:
                    problems.append(((i, j), _choices_message(dof, DOF_NAMES, "DOF name")))
                elif dof in seen:
                    problems.append(((i, j), f"DOF {_show(dof)} is listed twice"))
                else:
                    seen.add(dof)
            result.append(tuple(item))
        else:
            problems.append(
                ((i,), f"expected a preset name ({', '.join(preset_names)}) or an array of DOF names "
                       f"({', '.join(DOF_NAMES)}), got {_describe(item)}")
            )
    if problems:
        raise _Problems(problems)
    return tuple(result)


def _mode_ref(value: Any) -> int | str:
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise _fail(f"a mode number is 1-based: must be >= 1 (got {value})")
        return value
    if isinstance(value, str):
        match = _MODE_REF.fullmatch(value)
        if match and match["kind"] in MODE_KINDS and int(match["n"]) >= 1:
            return value
        hint = ""
        if match and match["kind"] not in MODE_KINDS:
            near = _suggest(match["kind"], MODE_KINDS)
            hint = f'; did you mean "{near}-{match["n"]}"?' if near else ""
        raise _fail(
            f'unknown mode reference {_show(value)}{hint} (expected a 1-based mode number or "<kind>-<n>" '
            f"with kind one of: {', '.join(MODE_KINDS)}, e.g. \"vertical-1\")"
        )
    raise _fail(f'expected a 1-based mode number or a string like "vertical-1", got {_describe(value)}')


ModeRef = Annotated[Union[int, str], PlainValidator(_mode_ref)]
"""A mode: 1-based number in frequency order, or "<kind>-<n>" (n-th mode of that kind)."""


# --------------------------------------------------------------------------- models


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class MaterialConfig(_Model):
    """``[bridge.material]``: linear elastic isotropic material (exactly one of G, nu)."""

    E: Positive
    G: Positive | None = None
    nu: Annotated[float, Strict(), Field(gt=-1.0, lt=0.5)] | None = None
    rho: Positive

    @model_validator(mode="after")
    def _one_of_g_nu(self) -> MaterialConfig:
        if self.G is not None and self.nu is not None:
            raise _fail(f"give exactly one of G or nu, got both (G = {_show(self.G)}, nu = {_show(self.nu)})")
        if self.G is None and self.nu is None:
            raise _fail("give exactly one of G (shear modulus, Pa) or nu (Poisson's ratio), got neither")
        if self.G is not None:
            nu = self.E / (2.0 * self.G) - 1.0
            if not -1.0 < nu < 0.5:
                raise _fail(
                    f"E and G imply nu = E/(2 G) - 1 = {nu:.4g}, outside the isotropic range (-1, 0.5)", "G"
                )
        return self

    @property
    def shear_modulus(self) -> float:
        """G in Pa, given or from ``E / (2 (1 + nu))``."""
        if self.G is not None:
            return self.G
        assert self.nu is not None
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def poisson(self) -> float:
        """Poisson's ratio, given or from ``E / (2 G) - 1``."""
        if self.nu is not None:
            return self.nu
        return self.E / (2.0 * self.shear_modulus) - 1.0

    def to_material(self) -> Material:
        """The :class:`cosim.core.section.Material` this table describes."""
        return Material(E=self.E, G=self.shear_modulus, rho=self.rho)


class PlateConfig(_Model):
    """``[[bridge.section.plates]]``: one thin-walled plate (midline segment + thickness)."""

    start: Point
    end: Point
    thickness: Positive

    @model_validator(mode="after")
    def _nonzero_length(self) -> PlateConfig:
        if self.start == self.end:
            raise _fail(f"plate has zero length (end equals start = {_show(list(self.start))})", "end")
        return self

    @property
    def y_range(self) -> tuple[float, float]:
        """Lateral extent of the plate's rectangle (midline +- thickness/2), m."""
        (y1, z1), (y2, z2) = self.start, self.end
        length = math.hypot(y2 - y1, z2 - z1)
        half = 0.5 * self.thickness * abs(z2 - z1) / length  # y-part of the normal offset
        return (min(y1, y2) - half, max(y1, y2) + half)

    def to_plate(self) -> Plate:
        """The :class:`cosim.core.section.Plate` this table describes."""
        return Plate(start=self.start, end=self.end, thickness=self.thickness)


class ConstantsConfig(_Model):
    """``[bridge.section.constants]``: explicit section constants (SI units)."""

    A: Positive
    I_y: Positive
    I_z: Positive
    J: Positive
    y_c: Number = 0.0
    z_c: Number = 0.0
    I_yz: Number = 0.0
    y_s: Number | None = None
    z_s: Number | None = None
    I_w: NonNegative = 0.0
    A_sy: Positive | None = None
    A_sz: Positive | None = None
    deck_y: Interval

    @model_validator(mode="after")
    def _consistent(self) -> ConstantsConfig:
        problems = []
        if not self.deck_y[0] < self.deck_y[1]:
            problems.append(
                (("deck_y",), f"expected [y_min, y_max] with y_min < y_max (got {_show(list(self.deck_y))})")
            )
        if self.I_y * self.I_z - self.I_yz**2 <= 0:
            problems.append(
                (("I_yz",), f"I_y I_z - I_yz^2 must be > 0 (got I_y = {_show(self.I_y)}, I_z = {_show(self.I_z)}, "
                            f"I_yz = {_show(self.I_yz)})")
            )
        if problems:
            raise _Problems(problems)
        return self


class SectionConfig(_Model):
    """``[bridge.section]``: exactly one of ``plates`` or ``constants``."""

    mesh_size: Positive | None = None
    plates: tuple[PlateConfig, ...] | None = None
    constants: ConstantsConfig | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> SectionConfig:
        if self.plates is not None and self.constants is not None:
            raise _fail("give exactly one of [[bridge.section.plates]] or [bridge.section.constants], got both")
        if self.plates is None and self.constants is None:
            raise _fail("give exactly one of [[bridge.section.plates]] or [bridge.section.constants], got neither")
        if self.plates is not None and len(self.plates) == 0:
            raise _fail("expected at least one plate, got an empty array", "plates")
        if self.constants is not None and self.mesh_size is not None:
            raise _fail("only used with plates (the FE section solver); remove it for constants", "mesh_size")
        return self

    @property
    def deck_y(self) -> tuple[float, float]:
        """Lateral extent (y_min, y_max) of the deck, m: the plates' outline, or ``constants.deck_y``."""
        if self.constants is not None:
            return self.constants.deck_y
        assert self.plates is not None
        ranges = [p.y_range for p in self.plates]
        return (min(r[0] for r in ranges), max(r[1] for r in ranges))

    def build(self, nu: float) -> SectionProperties:
        """Section constants: from the plates (FE section solver) or the given constants.

        Args:
            nu: Poisson's ratio of the material (the FE solver's shear areas depend on it).
        """
        if self.plates is not None:
            return section_from_plates([p.to_plate() for p in self.plates], nu=nu, mesh_size=self.mesh_size)
        assert self.constants is not None
        c = self.constants
        optional = {k: getattr(c, k) for k in ("y_s", "z_s", "A_sy", "A_sz") if getattr(c, k) is not None}
        return section_from_constants(
            c.A, c.I_y, c.I_z, c.J, y_c=c.y_c, z_c=c.z_c, I_yz=c.I_yz, I_w=c.I_w, deck_y=c.deck_y, **optional
        )


class DampingConfig(_Model):
    """``[bridge.damping]``: Rayleigh damping from two target ratios at two modes, or explicit alpha/beta."""

    ratios: tuple[Annotated[float, Strict(), Field(ge=0.0, lt=1.0)], ...] | None = None
    modes: tuple[ModeRef, ...] | None = None
    alpha: NonNegative | None = None
    beta: NonNegative | None = None

    @field_validator("ratios", "modes")
    @classmethod
    def _two(cls, value: tuple[Any, ...] | None) -> tuple[Any, ...] | None:
        if value is not None and len(value) != 2:
            raise _fail(f"expected exactly 2 entries (Rayleigh damping fits two modes), got {len(value)}")
        return value

    @field_validator("modes")
    @classmethod
    def _distinct(cls, value: tuple[Any, ...] | None) -> tuple[Any, ...] | None:
        if value is not None and value[0] == value[1]:
            raise _fail(f"the two modes must differ (got {_show(value[0])} twice)")
        return value

    @model_validator(mode="after")
    def _one_form(self) -> DampingConfig:
        rayleigh = self.ratios is not None or self.modes is not None
        explicit = self.alpha is not None or self.beta is not None
        if rayleigh and explicit:
            raise _fail("give either ratios + modes or alpha + beta, not both")
        if rayleigh and (self.ratios is None or self.modes is None):
            missing = "modes" if self.modes is None else "ratios"
            raise _fail("required key is missing (ratios and modes go together)", missing)
        if explicit and (self.alpha is None or self.beta is None):
            missing = "beta" if self.beta is None else "alpha"
            raise _fail("required key is missing (alpha and beta go together; write 0.0 for none)", missing)
        if not rayleigh and not explicit:
            raise _fail("give ratios + modes or alpha + beta (or remove [bridge.damping] for no damping)")
        return self

    def to_damping(self) -> RayleighDamping | ExplicitDamping:
        """The :mod:`cosim.core.bridge` damping specification."""
        if self.ratios is not None:
            assert self.modes is not None
            return RayleighDamping(ratios=tuple(self.ratios), modes=tuple(self.modes))
        assert self.alpha is not None and self.beta is not None
        return ExplicitDamping(alpha=self.alpha, beta=self.beta)


class BridgeConfig(_Model):
    """``[bridge]``: a straight continuous beam of one or more spans."""

    name: Annotated[str, Strict(), Field(min_length=1)] | None = None
    spans: tuple[Positive, ...]
    elements_per_span: Annotated[Union[int, tuple[int, ...]], PlainValidator(_elements_per_span)] = 20
    material: MaterialConfig
    section: SectionConfig
    supports: Annotated[tuple[Union[str, tuple[str, ...]], ...], PlainValidator(_supports)]
    damping: DampingConfig | None = None

    @field_validator("spans")
    @classmethod
    def _some_spans(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if not value:
            raise _fail("expected one or more span lengths, got []")
        return value

    @model_validator(mode="after")
    def _counts(self) -> BridgeConfig:
        problems = []
        n = len(self.spans)
        if isinstance(self.elements_per_span, tuple) and len(self.elements_per_span) != n:
            problems.append(
                (("elements_per_span",), f"expected one entry per span ({n}), got {len(self.elements_per_span)}")
            )
        if len(self.supports) != n + 1:
            problems.append(
                (("supports",), f"expected {n + 1} entries (one per support line: len(spans) + 1), "
                                f"got {len(self.supports)}")
            )
        if problems:
            raise _Problems(problems)
        return self

    @property
    def length(self) -> float:
        """Total length, m."""
        return float(sum(self.spans))


class SensorConfig(_Model):
    """``[[sensors]]``: a measured quantity at a deck point."""

    name: Annotated[str, Strict(), Field(pattern=r"^[A-Za-z0-9_.-]+$")]
    x: Number
    y: Number = 0.0
    quantity: Annotated[str, _choice(QUANTITIES, "quantity")] = "displacement"


def _number_problem(item: Any) -> str | None:
    if isinstance(item, bool) or not isinstance(item, (int, float)):
        return f"expected a number, got {_describe(item)}"
    if not math.isfinite(item):
        return f"must be a finite number (got {_show(item)})"
    return None


def _speed_profile(value: Any) -> tuple[tuple[float, float], ...]:
    """``profile = [[t, v], ...]``: t from entry (s), starting at 0 and increasing; v >= 0 (m/s)."""
    if not isinstance(value, (list, tuple)) or not value:
        raise _fail(f"expected a non-empty array of [t, v] pairs (s, m/s), got {_describe(value)}")
    problems: list[tuple[tuple[int, ...], str]] = []
    points: list[tuple[float, float]] = []
    for i, item in enumerate(value):
        if not isinstance(item, (list, tuple)) or len(item) != 2:
            problems.append(((i,), f"expected a pair [t, v] (s, m/s), got {_describe(item)}"))
            continue
        bad = [((i, j), msg) for j, v in enumerate(item) if (msg := _number_problem(v))]
        if bad:
            problems.extend(bad)
            continue
        t, v = float(item[0]), float(item[1])
        if i == 0 and t != 0.0:
            problems.append(((0, 0), f"the first time must be 0 (time from the vehicle's entry; got {_show(item[0])})"))
        elif points and t <= points[-1][0]:
            problems.append(
                ((i, 0), f"times must increase (got {_show(item[0])} after {_show(points[-1][0])})")
            )
        if v < 0:
            problems.append(((i, 1), f"speed must be >= 0 m/s (got {_show(item[1])})"))
        points.append((t, v))
    if problems:
        raise _Problems(problems)
    return tuple(points)


SpeedProfile = Annotated[tuple[tuple[float, float], ...], PlainValidator(_speed_profile)]

_CORE_KEY = re.compile(r"`(?P<key>\w+)`\s*(?P<rest>.*)", re.S)


def _rekeyed(exc: ConfigError, keys: tuple[str, ...]) -> _Problems:
    """A core-class message ("quarter-car: `m_v` must be ...") as a problem at that key."""
    match = _CORE_KEY.search(str(exc))
    if match and match["key"] in keys:
        return _fail(match["rest"].strip(), match["key"])
    return _fail(str(exc))


class VehicleConfig(_Model):
    """``[[vehicles]]``: a scripted vehicle, its model and parameters, path, speed and entry time."""

    id: Annotated[str, Strict(), Field(pattern=_NAME_PATTERN)]
    model: Annotated[str, _choice(tuple(VEHICLE_MODELS), "vehicle model")]
    mass: Number | None = None
    m_v: Number | None = None
    m_w: Number | None = None
    k_v: Number | None = None
    c_v: Number | None = None
    k_t: Number | None = None
    c_t: Number | None = None
    y: Number
    speed: Positive | None = None
    entry_time: NonNegative = 0.0
    direction: Annotated[str, _choice(tuple(DIRECTIONS), "direction")] = "+x"
    profile: SpeedProfile | None = None

    @model_validator(mode="after")
    def _parameters(self) -> VehicleConfig:
        required, optional = VEHICLE_MODELS[self.model]
        problems: list[tuple[tuple[str | int, ...], str]] = []
        listed = ", ".join((*required, *optional))
        for key in VEHICLE_PARAMETERS:
            if getattr(self, key) is not None and key not in required and key not in optional:
                problems.append(((key,), f"not a parameter of model {_show(self.model)} (its parameters: {listed})"))
        for key in required:
            if getattr(self, key) is None:
                problems.append(((key,), f"required key is missing (model {_show(self.model)} needs {listed})"))
        if self.speed is not None and self.profile is not None:
            problems.append((("speed",), "give either speed or profile, not both"))
        if self.speed is None and self.profile is None:
            problems.append((("speed",), "required key is missing (give speed, m/s, or a speed profile)"))
        if problems:
            raise _Problems(problems)
        try:
            self.to_model()
        except ConfigError as exc:
            raise _rekeyed(exc, VEHICLE_PARAMETERS) from None
        return self

    @property
    def parameters(self) -> dict[str, float]:
        """The model's parameters, defaults filled in (SI units)."""
        required, optional = VEHICLE_MODELS[self.model]
        values = {key: getattr(self, key) for key in required}
        values.update({key: getattr(self, key) if getattr(self, key) is not None else default
                       for key, default in optional.items()})
        return values

    def to_model(self) -> VehicleModel:
        """The :mod:`cosim.core.vehicles` model this table describes.

        Raises:
            ConfigError: a non-physical parameter (the vehicle classes check them).
        """
        p = self.parameters
        if self.model == "moving-force":
            return MovingForce(mass=p["mass"])
        if self.model == "quarter-car":
            return QuarterCar(m_v=p["m_v"], m_w=p["m_w"], k_v=p["k_v"], c_v=p["c_v"])
        if self.model == "tyre-quarter-car":
            return TyreQuarterCar(m_v=p["m_v"], m_w=p["m_w"], k_v=p["k_v"], c_v=p["c_v"], k_t=p["k_t"], c_t=p["c_t"])
        return TyreQuarterCar.golden_car(p["m_v"])

    def to_scripted(self) -> ScriptedVehicle:
        """The :class:`cosim.core.traffic.ScriptedVehicle` this table describes."""
        return ScriptedVehicle(
            id=self.id,
            model=self.to_model(),
            y=self.y,
            speed=self.speed if self.speed is not None else 0.0,
            entry_time=self.entry_time,
            direction=DIRECTIONS[self.direction],
            profile=self.profile or (),
        )


class RoadConfig(_Model):
    """``[road]``: an ISO 8608 class with a seed, a profile file, or a smooth road."""

    road_class: Annotated[str, _choice(ROAD_CLASSES, "road class")] | None = Field(default=None, alias="class")
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    profile: Annotated[str, Strict(), Field(min_length=1)] | None = None

    @model_validator(mode="after")
    def _one_form(self) -> RoadConfig:
        if self.road_class is not None and self.profile is not None:
            raise _fail(f"give either class or profile, not both (got class = {_show(self.road_class)} "
                        f"and profile = {_show(self.profile)})")
        if self.random and self.seed is None:
            raise _fail(
                f"required key is missing: a random road (class = {_show(self.road_class)}) needs a seed "
                "(an integer >= 0) so that it can be reproduced, e.g. seed = 1", "seed"
            )
        if self.seed is not None and not self.random:
            where = f"profile = {_show(self.profile)}" if self.profile is not None else (
                f"class = {_show(self.road_class)}" if self.road_class is not None else "no class")
            raise _fail(f'only used with a random road, class = "A" ... "H" (got {where})', "seed")
        return self

    @property
    def random(self) -> bool:
        """True for an ISO 8608 class (A-H)."""
        return self.road_class is not None and self.road_class in ISO_CLASSES

    @property
    def smooth(self) -> bool:
        """True for a smooth road (``class = "smooth"`` or nothing given)."""
        return not self.random and self.profile is None


class TrafficConfig(_Model):
    """``[traffic]``: vehicles from a SUMO simulation (instead of scripted ``[[vehicles]]``)."""

    sumo_config: Annotated[str, Strict(), Field(min_length=1)]
    step: Positive = 0.05
    begin: NonNegative = 0.0
    end: Positive = 600.0
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    axis: tuple[NetPoint, NetPoint] | None = None
    edges: tuple[Annotated[str, Strict(), Field(min_length=1)], ...] = ()

    @model_validator(mode="after")
    def _times(self) -> TrafficConfig:
        if self.end <= self.begin:
            raise _fail(f"must be after begin = {_show(self.begin)} s (got {_show(self.end)})", "end")
        if self.axis is not None and math.dist(*self.axis) <= 0:
            raise _fail("the two axis points must differ", "axis")
        return self

    @property
    def bundled(self) -> bool:
        return self.sumo_config in SUMO_LEVELS


class SolverConfig(_Model):
    """``[solver]``: time integration settings."""

    dt: Positive = 0.005
    scheme: Annotated[str, _choice(SCHEMES, "scheme")] = "newmark"
    hht_alpha: Annotated[float, Strict(), Field(ge=-1.0 / 3.0, le=0.0)] | None = None
    basis: Annotated[str, _choice(BASES, "basis")] = "direct"
    modes: PositiveInt | None = None
    cutoff_hz: Positive | None = None
    duration: Positive | None = None
    gravity: NonNegative = 9.81

    @model_validator(mode="before")
    @classmethod
    def _scheme_defaults(cls, data: Any) -> Any:
        if isinstance(data, dict):
            data = dict(data)
            if data.get("scheme") == "hht":
                data.setdefault("hht_alpha", DEFAULT_HHT_ALPHA)
            if data.get("basis") == "modal" and "cutoff_hz" not in data:
                data.setdefault("modes", DEFAULT_MODAL_MODES)
        return data

    @model_validator(mode="after")
    def _relevant(self) -> SolverConfig:
        problems = []
        if self.hht_alpha is not None and self.scheme != "hht":
            problems.append((("hht_alpha",), f'only used with scheme = "hht" (got scheme = "{self.scheme}")'))
        for key in ("modes", "cutoff_hz"):
            if getattr(self, key) is not None and self.basis != "modal":
                problems.append(((key,), f'only used with basis = "modal" (got basis = "{self.basis}")'))
        if self.basis == "modal" and self.modes is not None and self.cutoff_hz is not None:
            problems.append((("cutoff_hz",), "give either modes or cutoff_hz for the modal basis, not both"))
        if self.duration is not None and self.duration < self.dt:
            problems.append((("duration",), f"must be >= dt = {_show(self.dt)} s (got {_show(self.duration)})"))
        if problems:
            raise _Problems(problems)
        return self

    def to_settings(self) -> SolverSettings:
        """The :class:`cosim.core.simulation.SolverSettings` this table describes."""
        return SolverSettings(
            dt=self.dt,
            scheme=self.scheme,
            hht_alpha=self.hht_alpha if self.hht_alpha is not None else DEFAULT_HHT_ALPHA,
            basis=self.basis,
            modes=self.modes,
            cutoff_hz=self.cutoff_hz,
            gravity=self.gravity,
        )


class OutputConfig(_Model):
    """``[output]``: where the run's MCAP log (and an optional sensor CSV) go, and the logging rate.

    The rate is ``rate_hz`` (default :data:`DEFAULT_RATE_HZ`) or, for
    compatibility, ``every`` (keep every N-th step); not both.
    """

    log: Annotated[str, Strict(), Field(min_length=1)] | None = None
    rate_hz: Positive | None = None
    every: PositiveInt | None = None
    csv: Annotated[str, Strict(), Field(min_length=1)] | None = None

    @model_validator(mode="after")
    def _one_rate(self) -> OutputConfig:
        if self.rate_hz is not None and self.every is not None:
            raise _fail(
                f"give either rate_hz (logging rate, Hz) or every (keep every N-th step), not both "
                f"(got rate_hz = {_show(self.rate_hz)} and every = {self.every})", "every"
            )
        if self.log is not None and not self.log.lower().endswith(".mcap"):
            raise _fail(f"the log is an MCAP file: expected a path ending in .mcap (got {_show(self.log)})", "log")
        return self

    def decimation(self, dt: float) -> int:
        """Steps per logged sample: ``every``, else ``round(1 / (rate_hz dt))`` (at least 1)."""
        if self.every is not None:
            return self.every
        rate = self.rate_hz if self.rate_hz is not None else DEFAULT_RATE_HZ
        return max(1, int(round(1.0 / (rate * dt))))


def _leave_time(vehicle: ScriptedVehicle, length: float) -> float:
    """When ``vehicle`` leaves a deck of ``length`` m, s from the start (inf if it stops on the deck)."""
    end = ScriptedTraffic((vehicle,), length).end_time()
    if math.isfinite(end) or not vehicle.profile:
        return end
    # The profile ends at 0 m/s: the vehicle stops; on the deck, or after leaving it?
    t_last = vehicle.profile[-1][0]
    if float(vehicle.distance(t_last)[0]) <= length:
        return math.inf
    lo, hi = 0.0, t_last  # distance is non-decreasing (speeds >= 0): bisect for distance = length
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if float(vehicle.distance(mid)[0]) > length:
            hi = mid
        else:
            lo = mid
        if hi - lo <= 1e-9 * max(t_last, 1.0):
            break
    return vehicle.entry_time + hi


def _file_name(text: str) -> str:
    """``text`` with anything but letters, digits, '_', '.' and '-' replaced by '_'."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", text) or "scenario"


class Scenario(_Model):
    """A validated scenario: the bridge, its sensors, scripted vehicles, road, solver and output settings.

    Build one with :func:`load_scenario` (file or bundled name) or
    :func:`parse_scenario` (TOML text). ``source`` is where it came from and
    ``text`` the raw TOML, kept for logs.
    """

    name: Annotated[str, Strict(), Field(min_length=1)] | None = None
    description: Text = ""
    bridge: BridgeConfig
    sensors: tuple[SensorConfig, ...] = ()
    vehicles: tuple[VehicleConfig, ...] = ()
    traffic: TrafficConfig | None = None
    road: RoadConfig = RoadConfig()
    solver: SolverConfig = SolverConfig()
    output: OutputConfig = OutputConfig()

    _source: str = PrivateAttr(default="<scenario>")
    _text: str = PrivateAttr(default="")
    _base_dir: str = PrivateAttr(default=".")

    def model_post_init(self, context: Any) -> None:  # noqa: D102
        if isinstance(context, dict):
            self._source = str(context.get("source", self._source))
            self._text = str(context.get("text", self._text))
            self._base_dir = str(context.get("base_dir", self._base_dir))

    @model_validator(mode="before")
    @classmethod
    def _default_vehicle_ids(cls, data: Any) -> Any:
        """Vehicles without an ``id`` are "V1", "V2", ... by their position."""
        if isinstance(data, dict) and isinstance(data.get("vehicles"), list):
            data = dict(data)
            data["vehicles"] = [
                {"id": f"V{i + 1}", **item} if isinstance(item, dict) and "id" not in item else item
                for i, item in enumerate(data["vehicles"])
            ]
        return data

    @model_validator(mode="after")
    def _sensors_on_deck(self) -> Scenario:
        problems: list[tuple[tuple[str | int, ...], str]] = []
        length = self.bridge.length
        y_min, y_max = self.bridge.section.deck_y
        tol_x = 1e-9 * length
        tol_y = 1e-9 * max(y_max - y_min, 1.0)
        seen: dict[str, int] = {}
        for i, sensor in enumerate(self.sensors):
            if sensor.name in seen:
                problems.append(
                    (("sensors", i, "name"),
                     f"duplicate sensor name {_show(sensor.name)} (also sensors[{seen[sensor.name]}])")
                )
            seen.setdefault(sensor.name, i)
            if not -tol_x <= sensor.x <= length + tol_x:
                problems.append(
                    (("sensors", i, "x"), f"must lie on the bridge, 0 <= x <= {length:g} m (got {_show(sensor.x)})")
                )
            if not y_min - tol_y <= sensor.y <= y_max + tol_y:
                problems.append(
                    (("sensors", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {_show(sensor.y)})")
                )
        if problems:
            raise _Problems(problems)
        return self

    @model_validator(mode="after")
    def _vehicles_fit(self) -> Scenario:
        problems: list[tuple[tuple[str | int, ...], str]] = []
        y_min, y_max = self.bridge.section.deck_y
        tol_y = 1e-9 * max(y_max - y_min, 1.0)
        seen: dict[str, int] = {}
        for i, vehicle in enumerate(self.vehicles):
            if vehicle.id in seen:
                problems.append(
                    (("vehicles", i, "id"),
                     f"duplicate vehicle id {_show(vehicle.id)} (also vehicles[{seen[vehicle.id]}]; "
                     "vehicles without an id are named V1, V2, ... by position)")
                )
            seen.setdefault(vehicle.id, i)
            if not y_min - tol_y <= vehicle.y <= y_max + tol_y:
                problems.append(
                    (("vehicles", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {_show(vehicle.y)})")
                )
        if self.vehicles and self.solver.duration is None and not problems:
            length = self.bridge.length
            for i, vehicle in enumerate(self.vehicles):
                scripted = vehicle.to_scripted()
                if math.isinf(_leave_time(scripted, length)):
                    s_stop = float(scripted.distance(scripted.profile[-1][0])[0])
                    x_stop = s_stop if scripted.direction > 0 else length - s_stop
                    problems.append(
                        (("solver", "duration"),
                         f"required key is missing: vehicles[{i}] ({vehicle.id}) stops on the deck at "
                         f"x = {x_stop:g} m (its speed profile ends at 0 m/s), so the run has no natural end; "
                         "give the simulated time in s")
                    )
                    break
        if problems:
            raise _Problems(problems)
        return self

    @model_validator(mode="after")
    def _traffic_fits(self, info: ValidationInfo) -> Scenario:
        traffic = self.traffic
        if traffic is None:
            return self
        if self.vehicles:
            raise _fail("give either [traffic] (SUMO) or [[vehicles]] (scripted), not both", "traffic")
        ratio = traffic.step / self.solver.dt
        if abs(ratio - round(ratio)) > 1e-6 * ratio or round(ratio) < 1:
            raise _fail(f"SUMO's step must be a whole number of solver steps: step / solver.dt = "
                        f"{_num(traffic.step)} / {_num(self.solver.dt)} = {ratio:.6g}", "traffic", "step")
        length = self.bridge.length
        if traffic.axis is not None and abs(math.dist(*traffic.axis) - length) > 1e-3:
            raise _fail(f"the axis is {math.dist(*traffic.axis):.6g} m long; it must be the bridge's length, "
                        f"{length:g} m", "traffic", "axis")
        if not traffic.bundled:
            base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
            path = Path(base) / traffic.sumo_config
            if not path.is_file():
                raise _fail(f"file not found: {path} (a bundled level: {', '.join(SUMO_LEVELS)}; a relative path "
                            "is relative to the scenario file's folder)", "traffic", "sumo_config")
        return self

    @model_validator(mode="after")
    def _rate_within_steps(self) -> Scenario:
        rate, dt = self.output.rate_hz, self.solver.dt
        if rate is not None and rate * dt > 1.0 + 1e-9:
            raise _fail(
                f"must be <= 1 / solver.dt = {_num(1.0 / dt)} Hz (got {_show(rate)}): "
                "the log samples the solver's steps, it cannot be faster than them", "output", "rate_hz"
            )
        return self

    @model_validator(mode="after")
    def _road_file(self, info: ValidationInfo) -> Scenario:
        if self.road.profile is None:
            return self
        base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
        path = Path(base) / self.road.profile
        if not path.is_file():
            raise _fail(
                f"file not found: {path} (a relative path is relative to the scenario file's folder)",
                "road", "profile",
            )
        try:
            road = profile_from_csv(path)
        except ConfigError as exc:
            raise _fail(str(exc), "road", "profile") from None
        x_end = road.x0 + road.dx * (road.r.shape[1] - 1)
        length = self.bridge.length
        tol = 1e-6 * max(length, 1.0)
        if road.x0 > tol or x_end < length - tol:
            raise _fail(
                f"{path}: the profile covers {road.x0:g} <= x <= {x_end:g} m; it must cover the deck, "
                f"0 <= x <= {length:g} m", "road", "profile",
            )
        return self

    @property
    def source(self) -> str:
        """Where the scenario came from: the file path as given, or the bundled scenario's name."""
        return self._source

    @property
    def text(self) -> str:
        """The raw TOML text the scenario was read from."""
        return self._text

    @property
    def title(self) -> str:
        """The scenario's name, or the file's stem when it has none."""
        if self.name:
            return self.name
        return Path(self._source).stem or self._source

    def material(self) -> Material:
        """The bridge's :class:`cosim.core.section.Material`."""
        return self.bridge.material.to_material()

    def build_section(self) -> SectionProperties:
        """The bridge's section constants (runs the FE section solver for plates).

        Raises:
            ConfigError, ModelError: the section cannot be built (e.g. plates that do
                not touch); the message names the scenario and ``bridge.section``.
        """
        with self._named("bridge.section"):
            return self.bridge.section.build(nu=self.bridge.material.poisson)

    def build_bridge(self) -> BridgeModel:
        """The finite-element bridge model (:func:`cosim.core.bridge.build_bridge`).

        Raises:
            ConfigError, ModelError: the section or the model cannot be built (e.g. a
                damping mode that the model does not have); the message names the
                scenario and the table.
        """
        bridge = self.bridge
        section = self.build_section()
        with self._named("bridge"):
            return build_bridge(
                spans=bridge.spans,
                elements_per_span=bridge.elements_per_span,
                material=self.material(),
                section=section,
                supports=bridge.supports,
                damping=bridge.damping.to_damping() if bridge.damping is not None else None,
            )

    @property
    def road_profile_path(self) -> Path | None:
        """The road profile file (``road.profile`` resolved against the scenario's folder), or None."""
        if self.road.profile is None:
            return None
        return Path(self._base_dir) / self.road.profile

    @property
    def csv_path(self) -> Path | None:
        """The extra sensor CSV, ``output.csv`` (relative to the current folder), or None."""
        return Path(self.output.csv) if self.output.csv is not None else None

    @property
    def log_path(self) -> Path | None:
        """The MCAP log of a run, ``output.log`` (relative to the current folder), or None for the default."""
        return Path(self.output.log) if self.output.log is not None else None

    def default_log_path(self, started: datetime.datetime | None = None, suffix: str = "") -> Path:
        """``runs/<title><suffix>-<YYYYmmdd-HHMMSS>.mcap`` (relative to the current folder)."""
        stamp = (started or datetime.datetime.now()).strftime("%Y%m%d-%H%M%S")
        return Path(DEFAULT_OUTPUT_DIR) / f"{_file_name(self.title)}{suffix}-{stamp}.mcap"

    @property
    def output_every(self) -> int:
        """Solver steps per logged sample (``[output]`` rate_hz or every, with ``solver.dt``)."""
        return self.output.decimation(self.solver.dt)

    @property
    def output_rate_hz(self) -> float:
        """The logging rate actually used, Hz: ``1 / (output_every * dt)``."""
        return 1.0 / (self.output_every * self.solver.dt)

    @property
    def leave_time(self) -> float | None:
        """When the last scripted vehicle leaves the deck, s (inf if one stops on it; None without vehicles)."""
        if not self.vehicles:
            return None
        length = self.bridge.length
        return max(_leave_time(v.to_scripted(), length) for v in self.vehicles)

    @property
    def duration(self) -> float:
        """Simulated time, s: ``solver.duration``, default :attr:`leave_time` + 2 s.

        Raises:
            ConfigError: no ``solver.duration`` and no vehicles to take it from.
        """
        if self.solver.duration is not None:
            return self.solver.duration
        if self.traffic is not None:
            return self.traffic.end - self.traffic.begin
        leave = self.leave_time
        if leave is None:
            raise ConfigError(
                f"{self._source}: solver.duration: required key is missing "
                "(without [[vehicles]] there is no default simulated time)"
            )
        return leave + RING_DOWN

    def build_vehicles(self) -> ScriptedTraffic:
        """The scripted vehicles as a :class:`cosim.core.traffic.ScriptedTraffic` on this bridge's length."""
        with self._named("vehicles"):
            return ScriptedTraffic(tuple(v.to_scripted() for v in self.vehicles), self.bridge.length)

    def wheel_paths(self) -> tuple[float, ...]:
        """Lateral offsets with a road profile of their own, sorted, m.

        Scripted vehicles: their distinct offsets. SUMO traffic: paths every
        0.5 m across the deck (a wheel uses the nearest), since lanes and
        lateral positions come from SUMO. Otherwise ``(0.0,)``.
        """
        if self.traffic is not None:
            y_min, y_max = self.bridge.section.deck_y
            n = int(math.floor((y_max - y_min) / SUMO_PATH_SPACING)) + 1
            return tuple(float(v) for v in y_min + SUMO_PATH_SPACING * np.arange(n))
        return tuple(sorted({v.y for v in self.vehicles})) or (0.0,)

    @property
    def sumo_config_path(self) -> Path | None:
        """The SUMO config of ``[traffic]`` (a bundled level or a file relative to the scenario), or None."""
        if self.traffic is None:
            return None
        if self.traffic.bundled:
            from cosim.sumo.adapter import bundled_networks

            return bundled_networks() / f"{self.traffic.sumo_config}.sumocfg"
        return Path(self._base_dir) / self.traffic.sumo_config

    def build_traffic(self, frame_sink: Callable[..., None] | None = None) -> Any:
        """The traffic source: :class:`cosim.sumo.adapter.SumoTraffic` (not started) for ``[traffic]``, else the
        scripted vehicles (:meth:`build_vehicles`).

        Args:
            frame_sink: with SUMO, called with every frame (e.g. to log it).
        """
        if self.traffic is None:
            return self.build_vehicles()
        from cosim.sumo.adapter import BridgeAxis, SumoTraffic  # only SUMO runs load libsumo

        t = self.traffic
        length = self.bridge.length
        axis = BridgeAxis(*t.axis) if t.axis is not None else BridgeAxis((0.0, 0.0), (length, 0.0))
        y_min, y_max = self.bridge.section.deck_y
        path = self.sumo_config_path
        assert path is not None
        with self._named("traffic"):
            return SumoTraffic(path, axis, step=t.step, begin=t.begin, end=t.end, edges=t.edges or None,
                               seed=t.seed, half_width=max(abs(y_min), abs(y_max)), frame_sink=frame_sink)

    def build_road(self) -> RoadProfile:
        """The road profile, one wheel path per distinct vehicle offset (:meth:`wheel_paths`).

        A random class covers -10 m <= x <= L + 10 m (L the bridge length) with
        independent profiles per path, all drawn from ``road.seed``; a profile
        file is used on every path; no ``[road]`` or ``class = "smooth"`` is a
        smooth road.
        """
        road = self.road
        paths = self.wheel_paths()
        with self._named("road"):
            if road.random:
                assert road.road_class is not None and road.seed is not None
                return iso8608_profile(
                    road.road_class, road.seed, -ROAD_MARGIN, self.bridge.length + ROAD_MARGIN, path_y=paths
                )
            path = self.road_profile_path
            if path is None:
                return smooth_road()
            one = profile_from_csv(path)
            n = len(paths)
            return RoadProfile(
                path_y=paths, x0=one.x0, dx=one.dx,
                r=np.repeat(one.r, n, axis=0), r_x=np.repeat(one.r_x, n, axis=0),
                description=f"{one.description} on {n} path(s)",
            )

    def solver_settings(self) -> SolverSettings:
        """The :class:`cosim.core.simulation.SolverSettings` of ``[solver]``."""
        return self.solver.to_settings()

    def sensors_core(self) -> list[Sensor]:
        """The ``[[sensors]]`` as :class:`cosim.core.simulation.Sensor` objects."""
        return [Sensor(name=s.name, x=s.x, y=s.y, quantity=s.quantity) for s in self.sensors]

    def simulate(
        self,
        progress: Callable[[float], None] | None = None,
        *,
        bridge: BridgeModel | None = None,
    ) -> SimulationResult:
        """Run the scenario: bridge, scripted vehicles, road, solver and sensors into :func:`cosim.core.simulation.simulate`.

        Args:
            progress: called with the fraction done from time to time.
            bridge: the model from :meth:`build_bridge`, if already built.

        Returns:
            The sensor and vehicle time histories, sampled every :attr:`output_every` steps.

        Raises:
            ConfigError: the scenario cannot be run as given (e.g. no duration).
            ModelError: the model cannot be built, or the solution diverges.
        """
        if bridge is None:
            bridge = self.build_bridge()
        traffic = self.build_traffic()
        road = self.build_road()
        duration = self.duration
        solver = self.solver_settings()
        sensors = self.sensors_core()
        try:
            with contextlib.ExitStack() as stack:
                if hasattr(traffic, "start"):  # SUMO: one simulation, closed whatever happens
                    stack.enter_context(traffic)
                return simulate(
                    bridge, traffic, duration, solver=solver, sensors=sensors, road=road,
                    output_every=self.output_every, progress=progress,
                )
        except (ConfigError, ModelError) as exc:
            raise type(exc)(f"{self._source}: {exc}") from exc

    @contextlib.contextmanager
    def _named(self, key: str) -> Iterator[None]:
        """Prefix errors of the numerical core with this scenario's source and ``key``."""
        try:
            yield
        except (ConfigError, ModelError) as exc:
            raise type(exc)(f"{self._source}: {key}: {exc}") from exc


# --------------------------------------------------------------------------- loading

_BUNDLED_PACKAGE = "cosim"
_BUNDLED_DIR = "scenarios"


def list_bundled_scenarios() -> list[str]:
    """Names of the scenarios shipped with cosim (usable wherever a scenario path is)."""
    folder = resources.files(_BUNDLED_PACKAGE).joinpath(_BUNDLED_DIR)
    if not folder.is_dir():
        return []
    return sorted(item.name[: -len(".toml")] for item in folder.iterdir() if item.name.endswith(".toml"))


def parse_scenario(
    text: str, source: str = "<scenario>", base_dir: str | os.PathLike[str] = "."
) -> Scenario:
    """Validate scenario TOML text.

    Args:
        text: the TOML document.
        source: how to name it in error messages (usually the file path).
        base_dir: the folder relative paths in the scenario (``road.profile``)
            are resolved against: the scenario file's folder.

    Raises:
        ConfigError: syntax error, unknown/missing key, wrong type or non-physical value.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: TOML syntax error: {exc}") from None
    try:
        context = {"source": source, "text": text, "base_dir": os.fspath(base_dir)}
        return Scenario.model_validate(data, context=context)
    except ValidationError as exc:
        raise _config_error(source, Scenario, exc) from None


def load_scenario(path_or_name: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario.

    Args:
        path_or_name: a path to a ``.toml`` file, or the name of a bundled scenario
            (see :func:`list_bundled_scenarios`), e.g. ``"paper-double-tee"``.

    Returns:
        The frozen, validated :class:`Scenario`.

    Raises:
        ConfigError: the file is missing or unreadable, or its content is invalid.
    """
    source = os.fspath(path_or_name)
    path = Path(source)
    if path.is_file():
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"{source}: cannot read scenario file ({exc})") from None
        return parse_scenario(text, source, base_dir=path.parent)
    bundled = list_bundled_scenarios()
    if source in bundled:
        folder = resources.files(_BUNDLED_PACKAGE).joinpath(_BUNDLED_DIR)
        resource = folder.joinpath(f"{source}.toml")
        return parse_scenario(resource.read_text(encoding="utf-8"), source, base_dir=str(folder))
    if path.is_dir():
        raise ConfigError(f"{source}: is a directory, expected a scenario .toml file")
    listed = ", ".join(bundled) or "none"
    hint = _suggest(source, bundled)
    hint_text = f'; did you mean "{hint}"?' if hint else ""
    raise ConfigError(f"{source}: no such scenario file{hint_text} (bundled scenarios: {listed})")
