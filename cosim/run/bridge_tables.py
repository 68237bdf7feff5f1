"""The ``[bridge]`` table of a scenario file and its sub-tables: material, section (plates or constants), damping.

Each table checks its own keys and lowers itself to the :mod:`cosim.core`
object it describes (``to_material()``, ``to_plate()``, ``build()``,
``to_damping()``). The other tables: :mod:`cosim.run.tables`; checks across
tables: :class:`cosim.run.scenario.Scenario`. ``docs/scenario.md`` documents
every key.
"""
from __future__ import annotations

import math
import re
from typing import Annotated, Any, Union

from pydantic import Field, PlainValidator, PrivateAttr, Strict, field_validator, model_validator

from cosim.core.bridge import (
    DOF_NAMES,
    SUPPORT_PRESETS,
    ExplicitDamping,
    RayleighDamping,
)
from cosim.core.bridge import MODE_KINDS as _BRIDGE_MODE_KINDS
from cosim.core.element import BENDING_THEORIES, TORSION_THEORIES, BeamTheory
from cosim.core.modal_bridge import ModalRatios
from cosim.core.modal_deck import ModalDeck
from cosim.core.section import (
    Material,
    Plate,
    SectionProperties,
    section_from_constants,
    section_from_plates,
)

from .config_base import (
    ConfigModel,
    Interval,
    NonNegative,
    Number,
    Point,
    Positive,
    Problems,
    choice,
    choices_message,
    describe,
    fail,
    show,
    suggest,
)

__all__ = [
    "BridgeConfig",
    "ConstantsConfig",
    "DampingConfig",
    "MODE_KINDS",
    "MaterialConfig",
    "PlateConfig",
    "SectionConfig",
]

#: The frames a modes file's points may be given in (docs/modal-decks.md).
MODE_FRAMES: tuple[str, ...] = ("bridge", "network")
#: Keys of a beam bridge, not used with ``modes``.
BEAM_KEYS: tuple[str, ...] = ("spans", "elements_per_span", "material", "section", "supports", "torsion", "bending")

#: Mode kinds a damping mode reference may name ("vertical-1", "torsion-2", ...).
MODE_KINDS: tuple[str, ...] = tuple(_BRIDGE_MODE_KINDS)

_MODE_REF = re.compile(r"(?P<kind>[a-z]+)-(?P<n>[0-9]+)")

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
Ratio = Annotated[float, Strict(), Field(ge=0.0, lt=1.0)]
"""A mode: 1-based number in frequency order, or "<kind>-<n>" (n-th mode of that kind)."""


# --------------------------------------------------------------------------- tables


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
    I_ws: Positive | None = None
    mass_per_length: Positive | None = None
    rotary_inertia: Annotated[bool, Strict()] = True

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

        A plate section solved once is read back from the user's cache folder afterwards
        (:mod:`cosim.run.section_cache`).

        Args:
            nu: Poisson's ratio of the material (the FE solver's shear areas depend on it).
        """
        if self.plates is not None:
            from .section_cache import user_section_cache

            return section_from_plates([p.to_plate() for p in self.plates], nu=nu, mesh_size=self.mesh_size,
                                       store=user_section_cache())
        assert self.constants is not None
        c = self.constants
        keys = ("y_s", "z_s", "A_sy", "A_sz", "I_ws", "mass_per_length")
        optional = {k: getattr(c, k) for k in keys if getattr(c, k) is not None}
        return section_from_constants(
            c.A, c.I_y, c.I_z, c.J, y_c=c.y_c, z_c=c.z_c, I_yz=c.I_yz, I_w=c.I_w, deck_y=c.deck_y,
            rotary_inertia=c.rotary_inertia, **optional
        )


class DampingConfig(ConfigModel):
    """``[bridge.damping]``: Rayleigh damping from two target ratios at two modes, or explicit alpha/beta; on a
    deck given by its modes also ``ratio``: one damping ratio for every mode, or one per mode."""

    ratio: Union[Ratio, tuple[Ratio, ...]] | None = None
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
        if self.ratio is not None:
            if rayleigh or explicit:
                raise fail("give one of ratio (modal damping, a deck given by its modes), ratios + modes or "
                           "alpha + beta, not more", "ratio")
            if isinstance(self.ratio, tuple) and not self.ratio:
                raise fail("expected a damping ratio or one per mode, got []", "ratio")
            return self
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

    def beam_damping(self) -> RayleighDamping | ExplicitDamping:
        """The beam's Rayleigh damping (``ratio`` is refused for beams by :class:`BridgeConfig`)."""
        damping = self.to_damping()
        assert not isinstance(damping, ModalRatios)
        return damping

    def to_damping(self) -> RayleighDamping | ExplicitDamping | ModalRatios:
        """The :mod:`cosim.core.bridge` damping specification (``ratio``: the modal deck's
        :class:`cosim.core.modal_bridge.ModalRatios`)."""
        if self.ratio is not None:
            return ModalRatios(self.ratio)
        if self.ratios is not None:
            assert self.modes is not None
            (z1, z2), (m1, m2) = self.ratios, self.modes  # two of each, checked by the validators
            return RayleighDamping(ratios=(z1, z2), modes=(m1, m2))
        assert self.alpha is not None and self.beta is not None
        return ExplicitDamping(alpha=self.alpha, beta=self.beta)


class BridgeConfig(ConfigModel):
    """``[bridge]``: a straight continuous beam of one or more spans, or a deck given by its modes (``modes``:
    a modes file, docs/modal-decks.md; ``frame``: the frame of its points)."""

    name: Annotated[str, Strict(), Field(min_length=1)] | None = None
    spans: tuple[Positive, ...] = ()
    elements_per_span: Annotated[Union[int, tuple[int, ...]], PlainValidator(_elements_per_span)] = 20
    material: MaterialConfig | None = None
    section: SectionConfig | None = None
    supports: Annotated[tuple[Union[str, tuple[str, ...]], ...], PlainValidator(_supports)] = ()
    damping: DampingConfig | None = None
    torsion: Annotated[str, choice(TORSION_THEORIES, "torsion theory")] = "vlasov"
    bending: Annotated[str, choice(BENDING_THEORIES, "bending theory")] = "timoshenko"
    modes: Annotated[str, Strict(), Field(min_length=1)] | None = None
    frame: Annotated[str, choice(MODE_FRAMES, "frame")] = "bridge"

    #: The modes file's deck once the scenario has read it (:meth:`cosim.run.scenario.Scenario.modal_deck`).
    _deck: ModalDeck | None = PrivateAttr(default=None)
    _axis: tuple[tuple[float, float], tuple[float, float]] | None = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _beam_or_modes(self) -> BridgeConfig:
        if self.modes is not None:
            beam = [k for k in BEAM_KEYS if k in self.model_fields_set]
            if beam:
                raise fail("not used with modes: a deck given by its modes has no spans, section, material, "
                           "supports or beam theory (they are the FE model's); remove it, or remove modes",
                           beam[0])
            return self
        if "frame" in self.model_fields_set:
            raise fail("only used with modes (the frame of a modes file's points)", "frame")
        if self.damping is not None and self.damping.ratio is not None:
            raise fail("a beam's damping is Rayleigh: give ratios + modes or alpha + beta (ratio is the modal "
                       "damping of a deck given by its modes)", "damping", "ratio")
        for key in ("spans", "material", "section", "supports"):
            if key not in self.model_fields_set:
                raise fail("required key is missing (a beam bridge: spans, material, section and supports; or a "
                           "deck given by its modes: modes = \"FILE\")", key)
        if not self.spans:
            raise fail("expected one or more span lengths, got []", "spans")
        return self

    @property
    def is_modal(self) -> bool:
        """Whether the bridge is a deck given by its modes (``modes``)."""
        return self.modes is not None

    def keep_axis(self, axis: tuple[tuple[float, float], tuple[float, float]]) -> None:
        """Keep the axis a network-frame deck was placed on (network coordinates, x = 0 to its end)."""
        self._axis = axis

    @property
    def network_axis(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """The axis in network coordinates a ``frame = "network"`` deck was placed on, else None."""
        return self._axis

    def keep_deck(self, deck: ModalDeck) -> None:
        """Keep the modes file's deck, read (and checked) by the scenario, which knows the file's folder."""
        self._deck = deck

    @property
    def deck(self) -> ModalDeck:
        """The modes file's deck (after validation of a scenario with ``modes``)."""
        if self._deck is None:
            raise ValueError("bridge.modes: the modes file has not been read (validate the scenario)")
        return self._deck

    @property
    def deck_y(self) -> tuple[float, float]:
        """The deck's lateral extent (y_min, y_max), m: the section's, or the modes file's points'."""
        if self.modes is not None:
            y = self.deck.points[:, 1]
            return float(y.min()), float(y.max())
        assert self.section is not None
        return self.section.deck_y

    @property
    def beam_section(self) -> SectionConfig:
        """``[bridge.section]`` of a beam bridge."""
        if self.section is None:
            raise ValueError("bridge.section: a deck given by its modes has no section")
        return self.section

    @property
    def beam_material(self) -> MaterialConfig:
        """``[bridge.material]`` of a beam bridge."""
        if self.material is None:
            raise ValueError("bridge.material: a deck given by its modes has no material")
        return self.material

    @model_validator(mode="after")
    def _counts(self) -> BridgeConfig:
        if self.modes is not None:
            return self
        problems: list[tuple[tuple[str, ...], str]] = []
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
        constants = self.beam_section.constants
        if (self.torsion == "benscoter" and constants is not None and constants.I_w > 0
                and constants.I_ws is None):
            problems.append(
                (("section", "constants", "I_ws"),
                 'required by torsion = "benscoter" when I_w > 0: the warping shear constant in m^4 '
                 "(docs/theory.md §10.2; plates compute it), or use torsion = \"vlasov\"")
            )
        if problems:
            raise Problems(problems)
        return self

    @property
    def length(self) -> float:
        """Total length, m: the spans', or the modes file's deck's extent along x."""
        if self.modes is not None:
            return float(self.deck.points[:, 0].max())
        return float(sum(self.spans))

    def theory(self) -> BeamTheory:
        """The element's torsion and bending theories (:class:`cosim.core.element.BeamTheory`)."""
        return BeamTheory(torsion=self.torsion, bending=self.bending)
