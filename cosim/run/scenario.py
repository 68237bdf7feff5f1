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
import math
import os
import re
import sys
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Callable, Iterator, Union

import numpy as np
from pydantic import (
    Field,
    PlainValidator,
    PrivateAttr,
    Strict,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from cosim.core.bridge import (
    DOF_NAMES,
    SUPPORT_PRESETS,
    BridgeModel,
    ExplicitDamping,
    RayleighDamping,
    build_bridge,
)
from cosim.core.bridge import MODE_KINDS as _BRIDGE_MODE_KINDS
from cosim.core.roughness import (
    ISO_CLASSES,
    RoadProfile,
    iso8608_profile,
    profile_from_csv,
    smooth_road,
)
from cosim.core.section import (
    Material,
    Plate,
    SectionProperties,
    section_from_constants,
    section_from_plates,
)
from cosim.core.simulation import Sensor, SimulationResult, SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel
from cosim.errors import ConfigError, ModelError
from cosim.run.config_base import (
    ConfigModel,
    Interval,
    NetPoint,
    NonNegative,
    Number,
    Point,
    Positive,
    PositiveInt,
    Problems,
    Text,
    choice,
    choices_message,
    config_error,
    describe,
    fail,
    number_problem,
    number_text,
    show,
    suggest,
)

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


def _count_problem(item: Any) -> str | None:
    """Why ``item`` is not an element count (an integer >= 1), or None."""
    if isinstance(item, bool) or not isinstance(item, int):
        return f"expected an integer >= 1, got {describe(item)}"
    if item < 1:
        return f"must be >= 1 (got {item})"
    return None


def _elements_per_span(value: Any) -> int | tuple[int, ...]:
    if isinstance(value, (list, tuple)):
        if not value:
            raise fail("expected an integer or a non-empty array of integers (one per span), got []")
        problems = [((i,), msg) for i, item in enumerate(value) if (msg := _count_problem(item))]
        if problems:
            raise Problems(problems)
        return tuple(value)
    problem = _count_problem(value)
    if problem is not None:
        if isinstance(value, int) and not isinstance(value, bool):
            raise fail(problem)
        raise fail(f"expected an integer >= 1 or an array of them (one per span), got {describe(value)}")
    return value


def _supports(value: Any) -> tuple[str | tuple[str, ...], ...]:
    preset_names = tuple(SUPPORT_PRESETS)
    if not isinstance(value, (list, tuple)):
        raise fail(
            "expected an array with one entry per support line (a preset name or an array of DOF names), "
            f"got {describe(value)}"
        )
    problems: list[tuple[tuple[int, ...], str]] = []
    result: list[str | tuple[str, ...]] = []
    for i, item in enumerate(value):
        if isinstance(item, str):
            if item not in SUPPORT_PRESETS:
                problems.append(((i,), choices_message(item, preset_names, "support preset")))
            result.append(item)
        elif isinstance(item, (list, tuple)):
            seen: set[str] = set()
            for j, dof in enumerate(item):
                if not isinstance(dof, str) or dof not in DOF_NAMES:
                    problems.append(((i, j), choices_message(dof, DOF_NAMES, "DOF name")))
                elif dof in seen:
                    problems.append(((i, j), f"DOF {show(dof)} is listed twice"))
                else:
                    seen.add(dof)
            result.append(tuple(item))
        else:
            problems.append(
                ((i,), f"expected a preset name ({', '.join(preset_names)}) or an array of DOF names "
                       f"({', '.join(DOF_NAMES)}), got {describe(item)}")
            )
    if problems:
        raise Problems(problems)
    return tuple(result)


def _mode_ref(value: Any) -> int | str:
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise fail(f"a mode number is 1-based: must be >= 1 (got {value})")
        return value
    if isinstance(value, str):
        match = _MODE_REF.fullmatch(value)
        if match and match["kind"] in MODE_KINDS and int(match["n"]) >= 1:
            return value
        hint = ""
        if match and match["kind"] not in MODE_KINDS:
            near = suggest(match["kind"], MODE_KINDS)
            hint = f'; did you mean "{near}-{match["n"]}"?' if near else ""
        raise fail(
            f'unknown mode reference {show(value)}{hint} (expected a 1-based mode number or "<kind>-<n>" '
            f"with kind one of: {', '.join(MODE_KINDS)}, e.g. \"vertical-1\")"
        )
    raise fail(f'expected a 1-based mode number or a string like "vertical-1", got {describe(value)}')


ModeRef = Annotated[Union[int, str], PlainValidator(_mode_ref)]
"""A mode: 1-based number in frequency order, or "<kind>-<n>" (n-th mode of that kind)."""


# --------------------------------------------------------------------------- models




class MaterialConfig(ConfigModel):
    """``[bridge.material]``: linear elastic isotropic material (exactly one of G, nu)."""

    E: Positive
    G: Positive | None = None
    nu: Annotated[float, Strict(), Field(gt=-1.0, lt=0.5)] | None = None
    rho: Positive

    @model_validator(mode="after")
    def _one_of_g_nu(self) -> MaterialConfig:
        if self.G is not None and self.nu is not None:
            raise fail(f"give exactly one of G or nu, got both (G = {show(self.G)}, nu = {show(self.nu)})")
        if self.G is None and self.nu is None:
            raise fail("give exactly one of G (shear modulus, Pa) or nu (Poisson's ratio), got neither")
        if self.G is not None:
            nu = self.E / (2.0 * self.G) - 1.0
            if not -1.0 < nu < 0.5:
                raise fail(
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


class PlateConfig(ConfigModel):
    """``[[bridge.section.plates]]``: one thin-walled plate (midline segment + thickness)."""

    start: Point
    end: Point
    thickness: Positive

    @model_validator(mode="after")
    def _nonzero_length(self) -> PlateConfig:
        if self.start == self.end:
            raise fail(f"plate has zero length (end equals start = {show(list(self.start))})", "end")
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


class ConstantsConfig(ConfigModel):
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
                (("deck_y",), f"expected [y_min, y_max] with y_min < y_max (got {show(list(self.deck_y))})")
            )
        if self.I_y * self.I_z - self.I_yz**2 <= 0:
            problems.append(
                (("I_yz",), f"I_y I_z - I_yz^2 must be > 0 (got I_y = {show(self.I_y)}, I_z = {show(self.I_z)}, "
                            f"I_yz = {show(self.I_yz)})")
            )
        if problems:
            raise Problems(problems)
        return self


class SectionConfig(ConfigModel):
    """``[bridge.section]``: exactly one of ``plates`` or ``constants``."""

    mesh_size: Positive | None = None
    plates: tuple[PlateConfig, ...] | None = None
    constants: ConstantsConfig | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> SectionConfig:
        if self.plates is not None and self.constants is not None:
            raise fail("give exactly one of [[bridge.section.plates]] or [bridge.section.constants], got both")
        if self.plates is None and self.constants is None:
            raise fail("give exactly one of [[bridge.section.plates]] or [bridge.section.constants], got neither")
        if self.plates is not None and len(self.plates) == 0:
            raise fail("expected at least one plate, got an empty array", "plates")
        if self.constants is not None and self.mesh_size is not None:
            raise fail("only used with plates (the FE section solver); remove it for constants", "mesh_size")
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


class DampingConfig(ConfigModel):
    """``[bridge.damping]``: Rayleigh damping from two target ratios at two modes, or explicit alpha/beta."""

    ratios: tuple[Annotated[float, Strict(), Field(ge=0.0, lt=1.0)], ...] | None = None
    modes: tuple[ModeRef, ...] | None = None
    alpha: NonNegative | None = None
    beta: NonNegative | None = None

    @field_validator("ratios", "modes")
    @classmethod
    def _two(cls, value: tuple[Any, ...] | None) -> tuple[Any, ...] | None:
        if value is not None and len(value) != 2:
            raise fail(f"expected exactly 2 entries (Rayleigh damping fits two modes), got {len(value)}")
        return value

    @field_validator("modes")
    @classmethod
    def _distinct(cls, value: tuple[Any, ...] | None) -> tuple[Any, ...] | None:
        if value is not None and value[0] == value[1]:
            raise fail(f"the two modes must differ (got {show(value[0])} twice)")
        return value

    @model_validator(mode="after")
    def _one_form(self) -> DampingConfig:
        rayleigh = self.ratios is not None or self.modes is not None
        explicit = self.alpha is not None or self.beta is not None
        if rayleigh and explicit:
            raise fail("give either ratios + modes or alpha + beta, not both")
        if rayleigh and (self.ratios is None or self.modes is None):
            missing = "modes" if self.modes is None else "ratios"
            raise fail("required key is missing (ratios and modes go together)", missing)
        if explicit and (self.alpha is None or self.beta is None):
            missing = "beta" if self.beta is None else "alpha"
            raise fail("required key is missing (alpha and beta go together; write 0.0 for none)", missing)
        if not rayleigh and not explicit:
            raise fail("give ratios + modes or alpha + beta (or remove [bridge.damping] for no damping)")
        return self

    def to_damping(self) -> RayleighDamping | ExplicitDamping:
        """The :mod:`cosim.core.bridge` damping specification."""
        if self.ratios is not None:
            assert self.modes is not None
            return RayleighDamping(ratios=tuple(self.ratios), modes=tuple(self.modes))
        assert self.alpha is not None and self.beta is not None
        return ExplicitDamping(alpha=self.alpha, beta=self.beta)


class BridgeConfig(ConfigModel):
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
            raise fail("expected one or more span lengths, got []")
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
            raise Problems(problems)
        return self

    @property
    def length(self) -> float:
        """Total length, m."""
        return float(sum(self.spans))


class SensorConfig(ConfigModel):
    """``[[sensors]]``: a measured quantity at a deck point."""

    name: Annotated[str, Strict(), Field(pattern=r"^[A-Za-z0-9_.-]+$")]
    x: Number
    y: Number = 0.0
    quantity: Annotated[str, choice(QUANTITIES, "quantity")] = "displacement"




def _speed_profile(value: Any) -> tuple[tuple[float, float], ...]:
    """``profile = [[t, v], ...]``: t from entry (s), starting at 0 and increasing; v >= 0 (m/s)."""
    if not isinstance(value, (list, tuple)) or not value:
        raise fail(f"expected a non-empty array of [t, v] pairs (s, m/s), got {describe(value)}")
    problems: list[tuple[tuple[int, ...], str]] = []
    points: list[tuple[float, float]] = []
    for i, item in enumerate(value):
        if not isinstance(item, (list, tuple)) or len(item) != 2:
            problems.append(((i,), f"expected a pair [t, v] (s, m/s), got {describe(item)}"))
            continue
        bad = [((i, j), msg) for j, v in enumerate(item) if (msg := number_problem(v))]
        if bad:
            problems.extend(bad)
            continue
        t, v = float(item[0]), float(item[1])
        if i == 0 and t != 0.0:
            problems.append(((0, 0), f"the first time must be 0 (time from the vehicle's entry; got {show(item[0])})"))
        elif points and t <= points[-1][0]:
            problems.append(
                ((i, 0), f"times must increase (got {show(item[0])} after {show(points[-1][0])})")
            )
        if v < 0:
            problems.append(((i, 1), f"speed must be >= 0 m/s (got {show(item[1])})"))
        points.append((t, v))
    if problems:
        raise Problems(problems)
    return tuple(points)


SpeedProfile = Annotated[tuple[tuple[float, float], ...], PlainValidator(_speed_profile)]

_CORE_KEY = re.compile(r"`(?P<key>\w+)`\s*(?P<rest>.*)", re.S)


def _rekeyed(exc: ConfigError, keys: tuple[str, ...]) -> Problems:
    """A core-class message ("quarter-car: `m_v` must be ...") as a problem at that key."""
    match = _CORE_KEY.search(str(exc))
    if match and match["key"] in keys:
        return fail(match["rest"].strip(), match["key"])
    return fail(str(exc))


class VehicleConfig(ConfigModel):
    """``[[vehicles]]``: a scripted vehicle, its model and parameters, path, speed and entry time."""

    id: Annotated[str, Strict(), Field(pattern=_NAME_PATTERN)]
    model: Annotated[str, choice(tuple(VEHICLE_MODELS), "vehicle model")]
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
    direction: Annotated[str, choice(tuple(DIRECTIONS), "direction")] = "+x"
    profile: SpeedProfile | None = None

    @model_validator(mode="after")
    def _parameters(self) -> VehicleConfig:
        required, optional = VEHICLE_MODELS[self.model]
        problems: list[tuple[tuple[str | int, ...], str]] = []
        listed = ", ".join((*required, *optional))
        for key in VEHICLE_PARAMETERS:
            if getattr(self, key) is not None and key not in required and key not in optional:
                problems.append(((key,), f"not a parameter of model {show(self.model)} (its parameters: {listed})"))
        for key in required:
            if getattr(self, key) is None:
                problems.append(((key,), f"required key is missing (model {show(self.model)} needs {listed})"))
        if self.speed is not None and self.profile is not None:
            problems.append((("speed",), "give either speed or profile, not both"))
        if self.speed is None and self.profile is None:
            problems.append((("speed",), "required key is missing (give speed, m/s, or a speed profile)"))
        if problems:
            raise Problems(problems)
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


class RoadConfig(ConfigModel):
    """``[road]``: an ISO 8608 class with a seed, a profile file, or a smooth road."""

    road_class: Annotated[str, choice(ROAD_CLASSES, "road class")] | None = Field(default=None, alias="class")
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    profile: Annotated[str, Strict(), Field(min_length=1)] | None = None

    @model_validator(mode="after")
    def _one_form(self) -> RoadConfig:
        if self.road_class is not None and self.profile is not None:
            raise fail(f"give either class or profile, not both (got class = {show(self.road_class)} "
                        f"and profile = {show(self.profile)})")
        if self.random and self.seed is None:
            raise fail(
                f"required key is missing: a random road (class = {show(self.road_class)}) needs a seed "
                "(an integer >= 0) so that it can be reproduced, e.g. seed = 1", "seed"
            )
        if self.seed is not None and not self.random:
            where = f"profile = {show(self.profile)}" if self.profile is not None else (
                f"class = {show(self.road_class)}" if self.road_class is not None else "no class")
            raise fail(f'only used with a random road, class = "A" ... "H" (got {where})', "seed")
        return self

    @property
    def random(self) -> bool:
        """True for an ISO 8608 class (A-H)."""
        return self.road_class is not None and self.road_class in ISO_CLASSES

    @property
    def smooth(self) -> bool:
        """True for a smooth road (``class = "smooth"`` or nothing given)."""
        return not self.random and self.profile is None


class TrafficConfig(ConfigModel):
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
            raise fail(f"must be after begin = {show(self.begin)} s (got {show(self.end)})", "end")
        if self.axis is not None and math.dist(*self.axis) <= 0:
            raise fail("the two axis points must differ", "axis")
        return self

    @property
    def bundled(self) -> bool:
        return self.sumo_config in SUMO_LEVELS


class SolverConfig(ConfigModel):
    """``[solver]``: time integration settings."""

    dt: Positive = 0.005
    scheme: Annotated[str, choice(SCHEMES, "scheme")] = "newmark"
    hht_alpha: Annotated[float, Strict(), Field(ge=-1.0 / 3.0, le=0.0)] | None = None
    basis: Annotated[str, choice(BASES, "basis")] = "direct"
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
            problems.append((("duration",), f"must be >= dt = {show(self.dt)} s (got {show(self.duration)})"))
        if problems:
            raise Problems(problems)
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


class OutputConfig(ConfigModel):
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
            raise fail(
                f"give either rate_hz (logging rate, Hz) or every (keep every N-th step), not both "
                f"(got rate_hz = {show(self.rate_hz)} and every = {self.every})", "every"
            )
        if self.log is not None and not self.log.lower().endswith(".mcap"):
            raise fail(f"the log is an MCAP file: expected a path ending in .mcap (got {show(self.log)})", "log")
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


class Scenario(ConfigModel):
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
                     f"duplicate sensor name {show(sensor.name)} (also sensors[{seen[sensor.name]}])")
                )
            seen.setdefault(sensor.name, i)
            if not -tol_x <= sensor.x <= length + tol_x:
                problems.append(
                    (("sensors", i, "x"), f"must lie on the bridge, 0 <= x <= {length:g} m (got {show(sensor.x)})")
                )
            if not y_min - tol_y <= sensor.y <= y_max + tol_y:
                problems.append(
                    (("sensors", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {show(sensor.y)})")
                )
        if problems:
            raise Problems(problems)
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
                     f"duplicate vehicle id {show(vehicle.id)} (also vehicles[{seen[vehicle.id]}]; "
                     "vehicles without an id are named V1, V2, ... by position)")
                )
            seen.setdefault(vehicle.id, i)
            if not y_min - tol_y <= vehicle.y <= y_max + tol_y:
                problems.append(
                    (("vehicles", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {show(vehicle.y)})")
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
            raise Problems(problems)
        return self

    @model_validator(mode="after")
    def _traffic_fits(self, info: ValidationInfo) -> Scenario:
        traffic = self.traffic
        if traffic is None:
            return self
        if self.vehicles:
            raise fail("give either [traffic] (SUMO) or [[vehicles]] (scripted), not both", "traffic")
        ratio = traffic.step / self.solver.dt
        if abs(ratio - round(ratio)) > 1e-6 * ratio or round(ratio) < 1:
            raise fail(f"SUMO's step must be a whole number of solver steps: step / solver.dt = "
                        f"{number_text(traffic.step)} / {number_text(self.solver.dt)} = {ratio:.6g}", "traffic", "step")
        length = self.bridge.length
        if traffic.axis is not None and abs(math.dist(*traffic.axis) - length) > 1e-3:
            raise fail(f"the axis is {math.dist(*traffic.axis):.6g} m long; it must be the bridge's length, "
                        f"{length:g} m", "traffic", "axis")
        if not traffic.bundled:
            base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
            path = Path(base) / traffic.sumo_config
            if not path.is_file():
                raise fail(f"file not found: {path} (a bundled level: {', '.join(SUMO_LEVELS)}; a relative path "
                            "is relative to the scenario file's folder)", "traffic", "sumo_config")
        return self

    @model_validator(mode="after")
    def _rate_within_steps(self) -> Scenario:
        rate, dt = self.output.rate_hz, self.solver.dt
        if rate is not None and rate * dt > 1.0 + 1e-9:
            raise fail(
                f"must be <= 1 / solver.dt = {number_text(1.0 / dt)} Hz (got {show(rate)}): "
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
            raise fail(
                f"file not found: {path} (a relative path is relative to the scenario file's folder)",
                "road", "profile",
            )
        try:
            road = profile_from_csv(path)
        except ConfigError as exc:
            raise fail(str(exc), "road", "profile") from None
        x_end = road.x0 + road.dx * (road.r.shape[1] - 1)
        length = self.bridge.length
        tol = 1e-6 * max(length, 1.0)
        if road.x0 > tol or x_end < length - tol:
            raise fail(
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
        from cosim.sumo.adapter import (  # only SUMO runs load libsumo
            BridgeAxis,
            SumoTraffic,
        )

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
        raise config_error(source, Scenario, exc) from None


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
    hint = suggest(source, bundled)
    hint_text = f'; did you mean "{hint}"?' if hint else ""
    raise ConfigError(f"{source}: no such scenario file{hint_text} (bundled scenarios: {listed})")
