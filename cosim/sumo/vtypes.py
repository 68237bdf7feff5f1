"""What a SUMO vType is for the beam: its vehicle model, its axles, and where each number came from.

A vType may set SUMO's own ``mass`` (kg, the gross weight) and ``param``
entries prefixed ``cosim.``: the suspension (``cosim.model``, ``cosim.m_w``,
``cosim.k_v``, ``cosim.c_v``, ``cosim.k_t``, ``cosim.c_t``), the axles
(``cosim.axles``, ``cosim.axle_loads``), the tyre contact (``cosim.contact``:
``bilateral`` or ``unilateral``, tyre models only) and, for
``cosim.model = half-car``, the body (``cosim.pitch``: true/false,
``cosim.i_b``: pitch inertia, kg m^2). The rules:

- **neither** ``mass`` nor ``cosim.*``: cosim's library vehicle of its vClass
  (:mod:`cosim.sumo.library`): gross mass, axles and a tyre quarter-car per
  axle, each with its source; SUMO's default masses are never used;
- ``mass`` only: the library vehicle at that mass (its axles and suspension);
- ``cosim.*`` suspension params: a ``cosim.model`` (default ``quarter-car``)
  with the params given; a missing one comes from the library's suspension of
  the vClass at the vType's mass (``mass``, else the library's); without
  ``cosim.axles``, one quarter-car at mid-length (as the params describe one);
- ``cosim.axles`` with ``cosim.axle_loads``: those axles, each carrying its
  share of the masses, springs and dampers;
- ``cosim.model = half-car``: one body on all the axles (the library's axles
  unless ``cosim.axles`` are given): per axle its share of the wheel mass,
  suspension and tyre; the body's centre of gravity where the axle loads put
  it (sum of share x distance, so a two-axle body carries exactly the shares),
  pitch inertia ``cosim.i_b`` or that of a uniform body as long as the vehicle
  (m_b L^2 / 12).

A ``cosim.*`` param that is not one of these is an error that names the
closest known one. Plain functions of values (the demand files' or
libsumo's): no libsumo here.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import asdict, dataclass

from cosim.core.vehicles import Axle, HalfCar, MovingForce, QuarterCar, TyreQuarterCar, VehicleModel
from cosim.errors import ConfigError, SumoError
from cosim.sumo.library import LibraryVehicle, Suspension, entry_for

__all__ = [
    "HEAVY_VCLASSES",
    "PARAM_KEYS",
    "PARAM_PREFIX",
    "SOURCE_DEFAULT",
    "SOURCE_MASS",
    "SOURCE_PARAMS",
    "VehicleType",
    "axles_from_parameters",
    "check_parameter_names",
    "half_car_model",
    "model_from_parameters",
    "scaled_model",
    "vehicle_type",
]

PARAM_PREFIX = "cosim."
#: The vType params cosim reads (without the prefix).
PARAM_KEYS = ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads", "contact", "pitch", "i_b")
#: The params that describe the suspension itself (not the axles).
SUSPENSION_KEYS = ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "contact", "pitch", "i_b")
MODEL_KINDS = ("quarter-car", "tyre-quarter-car", "half-car", "moving-force")
CONTACT_KINDS = ("bilateral", "unilateral")
#: SUMO vehicle classes that count as trucks (a study's ``truck_share``).
HEAVY_VCLASSES = ("bus", "coach", "truck", "trailer")
#: Where a number came from, as summaries and logs say it.
SOURCE_PARAMS = "vType params"
SOURCE_MASS = "SUMO mass"
SOURCE_DEFAULT = "cosim default"


def check_parameter_names(type_id: str, params: dict[str, str]) -> None:
    """Raise :class:`SumoError` for a ``cosim.*`` param cosim does not know, naming the closest known one."""
    for key in params:
        if not key.startswith(PARAM_PREFIX):
            continue
        name = key[len(PARAM_PREFIX):]
        if name in PARAM_KEYS:
            continue
        near = difflib.get_close_matches(name, PARAM_KEYS, n=1, cutoff=0.5)
        hint = f"did you mean `{PARAM_PREFIX}{near[0]}`? " if near else ""
        raise SumoError(f"vType {type_id}: unknown param `{key}` ({hint}cosim reads "
                        f"{', '.join(PARAM_PREFIX + k for k in PARAM_KEYS)})")
    model = params.get(PARAM_PREFIX + "model", "quarter-car")
    allowed = MODEL_PARAMS.get(model)
    if allowed is None:
        return  # an unknown model: the model's own check names it
    unused = [k for k in params if k.startswith(PARAM_PREFIX) and k[len(PARAM_PREFIX):] not in allowed]
    if unused:  # it would be ignored, silently
        raise SumoError(f"vType {type_id}: param `{unused[0]}` is not used by model {model} (its params: "
                        f"{', '.join(PARAM_PREFIX + k for k in allowed)})")


#: The ``cosim.*`` params each vehicle model uses (any other is an error: it would be ignored).
MODEL_PARAMS: dict[str, tuple[str, ...]] = {
    "quarter-car": ("model", "m_w", "k_v", "c_v", "axles", "axle_loads"),
    "tyre-quarter-car": ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads", "contact"),
    "half-car": ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads", "contact", "pitch", "i_b"),
    "moving-force": ("model", "axles", "axle_loads"),
}


def _number(type_id: str, params: dict[str, str], key: str) -> float | None:
    text = params.get(PARAM_PREFIX + key)
    if text is None or text.strip() == "":
        return None
    try:
        value = float(text)
    except ValueError:
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}{key}` must be a number (got {text!r})") from None
    if not math.isfinite(value):
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}{key}` must be a finite number (got {text!r})")
    return value


def _contact(type_id: str, params: dict[str, str]) -> bool:
    """``cosim.contact``: True for a tyre that may leave the deck."""
    text = params.get(PARAM_PREFIX + "contact", "bilateral").strip()
    if text not in CONTACT_KINDS:
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}contact` must be bilateral or unilateral "
                        f"(got {text!r})")
    return text == "unilateral"


def _flag(type_id: str, params: dict[str, str], key: str, default: bool) -> bool:
    text = params.get(PARAM_PREFIX + key)
    if text is None:
        return default
    value = text.strip().lower()
    if value not in ("true", "false", "1", "0"):
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}{key}` must be true or false (got {text!r})")
    return value in ("true", "1")


def half_car_model(type_id: str, quarter: TyreQuarterCar, axles: tuple[tuple[float, float], ...], length: float,
                   params: dict[str, str]) -> HalfCar:
    """One body on the vType's axles: per axle its share of ``quarter`` (the whole vehicle's suspension).

    Args:
        quarter: the whole vehicle as one tyre quarter-car (masses kg, springs N/m, dampers N s/m).
        axles: (distance behind the front bumper m, share of the load) per axle.
        length: the vehicle's length, m (the default pitch inertia: a uniform body as long as the vehicle).
        params: the vType's params (``cosim.pitch``, ``cosim.i_b``, ``cosim.contact``).

    Raises:
        SumoError: a param is not valid, or the body is not physical (a pitching body on one axle).
    """
    front = axles[0][0]
    pitch = _flag(type_id, params, "pitch", len(axles) > 1)
    i_b = _number(type_id, params, "i_b")
    m_b = quarter.m_v
    try:
        return HalfCar(
            m_b=m_b, i_b=m_b * length**2 / 12.0 if i_b is None else i_b,
            cg=sum(share * (d - front) for d, share in axles),  # the axle loads' resultant: the shares hold
            axles=tuple(Axle(distance=d - front, m_w=share * quarter.m_w, k_s=share * quarter.k_v,
                             c_s=share * quarter.c_v, k_t=share * quarter.k_t, c_t=share * quarter.c_t)
                        for d, share in axles),
            pitch=pitch, unilateral=_contact(type_id, params))
    except ConfigError as exc:
        raise SumoError(f"vType {type_id}: {exc}") from None


def _library_model(suspension: Suspension, mass: float) -> TyreQuarterCar:
    """The suspension set scaled to a vehicle of gross ``mass`` kg."""
    m_v = mass / (1.0 + suspension.m_w)
    return TyreQuarterCar(m_v=m_v, m_w=suspension.m_w * m_v, k_v=suspension.k_v * m_v, c_v=suspension.c_v * m_v,
                          k_t=suspension.k_t * m_v, c_t=suspension.c_t * m_v)


def _param_model(type_id: str, mass: float, suspension: Suspension, params: dict[str, str]) -> VehicleModel:
    """The model the ``cosim.*`` suspension params describe; a missing one from ``suspension`` at ``mass``."""
    kind = params.get(PARAM_PREFIX + "model", "quarter-car").strip()
    if kind not in MODEL_KINDS:
        near = difflib.get_close_matches(kind, MODEL_KINDS, n=1)
        hint = f"; did you mean {near[0]}?" if near else ""
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}model` must be {', '.join(MODEL_KINDS)} "
                        f"(got {kind!r}{hint})")
    if kind == "moving-force":
        return MovingForce(mass)
    m_w = _number(type_id, params, "m_w")
    m_w = suspension.unsprung_share() * mass if m_w is None else m_w
    m_v = mass - m_w
    if not m_v > 0:
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}m_w` = {m_w:g} kg leaves no body mass (mass = {mass:g} kg)")

    def given(key: str, ratio: float) -> float:
        value = _number(type_id, params, key)
        return ratio * m_v if value is None else value

    k_v, c_v = given("k_v", suspension.k_v), given("c_v", suspension.c_v)
    unilateral = _contact(type_id, params)
    try:
        if kind == "quarter-car":
            return QuarterCar(m_v=m_v, m_w=m_w, k_v=k_v, c_v=c_v)
        # a half-car is first the whole vehicle on one tyre; vehicle_type shares it among the axles
        return TyreQuarterCar(m_v=m_v, m_w=m_w, k_v=k_v, c_v=c_v, k_t=given("k_t", suspension.k_t),
                              c_t=given("c_t", suspension.c_t), unilateral=unilateral)
    except ConfigError as exc:
        raise SumoError(f"vType {type_id}: {exc}") from None


def axles_from_parameters(type_id: str, length: float, params: dict[str, str]) -> tuple[tuple[float, float], ...]:
    """The vType's axles as (distance behind the front bumper m, share of the load), or one at mid-length.

    ``cosim.axles`` lists the distances (m, space-separated), ``cosim.axle_loads``
    the shares of the vehicle's weight and suspension (summing to 1).

    Raises:
        SumoError: the lists do not match, are not numbers, or are not physical.
    """
    spacing = params.get(PARAM_PREFIX + "axles", "").split()
    loads = params.get(PARAM_PREFIX + "axle_loads", "").split()
    if not spacing and not loads:
        return ((0.5 * length, 1.0),)
    try:
        where = [float(v) for v in spacing]
        share = [float(v) for v in loads]
    except ValueError:
        raise SumoError(f"vType {type_id}: params `{PARAM_PREFIX}axles` and `{PARAM_PREFIX}axle_loads` must be "
                        "space-separated numbers") from None
    if len(where) != len(share):
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axles` has {len(where)} value(s), "
                        f"`{PARAM_PREFIX}axle_loads` {len(share)}: give one load share per axle")
    if any(not 0.0 <= d <= length for d in where):
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axles` must lie on the vehicle, 0 to {length:g} m "
                        f"behind the front bumper (got {' '.join(spacing)})")
    if any(not f > 0 for f in share) or abs(sum(share) - 1.0) > 1e-6:
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axle_loads` must be positive and sum to 1 "
                        f"(got {' '.join(loads)})")
    return tuple(zip(where, share))


def scaled_model(model: VehicleModel, share: float) -> VehicleModel:
    """The part of ``model`` carried by one axle (:meth:`~cosim.core.vehicles.VehicleModel.scaled`)."""
    return model.scaled(share)


@dataclass(frozen=True)
class VehicleType:
    """A vType as the beam sees it.

    Attributes:
        id: the vType id; vclass: its SUMO vehicle class; length: m.
        model: the whole vehicle's model (gross mass, suspension, tyre).
        axles: (distance behind the front bumper m, share of the load) per axle.
        sources: where each part came from: ``mass``, ``suspension``, ``axles`` ->
            "vType params", "SUMO mass" (the vType's ``mass``), "cosim default: <library vehicle>"
            (or "vType params + cosim default" for a suspension given in part).
        details: the same parts with the params read or the library's sources cited.
        library: the library vehicle of its vClass; note: why it is a stand-in, if it is.
    """

    id: str
    vclass: str
    length: float
    model: VehicleModel
    axles: tuple[tuple[float, float], ...]
    sources: dict[str, str]
    details: dict[str, str]
    library: str
    note: str = ""

    @property
    def mass(self) -> float:
        return float(self.model.total_mass)

    def axle_models(self) -> list[tuple[str, VehicleModel]]:
        """(model table key, model) per axle: the type itself for one axle, ``type#k`` for axle k of several.

        Independent axles each get their share of the model; the axles of one body (a half-car) all
        name the whole model, which the beam step recognises as one vehicle on several contacts.
        """
        if len(self.axles) == 1:
            return [(self.id, self.model)]
        if getattr(self.model, "contacts", 1) > 1:
            return [(f"{self.id}#{k}", self.model) for k in range(len(self.axles))]
        return [(f"{self.id}#{k}", scaled_model(self.model, share)) for k, (_, share) in enumerate(self.axles)]

    def summary(self) -> dict:
        """A plain description (for logs and summaries)."""
        return {"type": self.id, "vclass": self.vclass, "model": self.model.kind, "mass": self.mass,
                "length": self.length, "axles": [d for d, _ in self.axles], "axle_loads": [s for _, s in self.axles],
                "sources": dict(self.sources), "details": dict(self.details), "library": self.library,
                "note": self.note, "parameters": asdict(self.model)}

    def line(self) -> str:
        """One line for summaries: model, gross mass, axles, and where each came from."""
        n = len(self.axles)
        axles = f"{n} axle{'s' if n > 1 else ''}" + (
            f" at {', '.join(f'{d:.2f}' for d, _ in self.axles)} m" if n > 1 else " at mid-length")
        text = (f"{self.model.kind}, {self.mass:.0f} kg ({self.sources['mass']}), {axles} ({self.sources['axles']}), "
                f"suspension: {self.sources['suspension']}")
        return text + (f"; {self.note}" if self.note else "")


def vehicle_type(type_id: str, vclass: str, length: float | None, mass: float | None,
                 params: dict[str, str]) -> VehicleType:
    """The :class:`VehicleType` of a vType (the rules: this module's docstring).

    Args:
        type_id: the vType id; vclass: its vClass; length: its length, m, or None when not known yet
            (a vType without ``length`` before SUMO runs: the library vehicle's length stands in, and
            ``cosim.axles`` are checked against the vehicle's length once SUMO gives it).
        mass: the vType's own ``mass`` attribute, kg, or None when it sets none
            (SUMO's default for the vClass is then never used).
        params: its ``param`` entries (only ``cosim.*`` ones are read).

    Raises:
        SumoError: an unknown ``cosim.*`` param, a param that is not a number, or values that are not physical.
    """
    check_parameter_names(type_id, params)
    if length is not None and not (isinstance(length, (int, float)) and math.isfinite(length) and length > 0):
        raise SumoError(f"vType {type_id}: `length` must be > 0 m (got {length})")
    if mass is not None and not (math.isfinite(mass) and mass > 0):
        raise SumoError(f"vType {type_id}: `mass` must be > 0 kg (got {mass:g})")
    entry, note = entry_for(vclass)
    known = length is not None
    length = float(length) if length is not None else entry.length
    default = f"{SOURCE_DEFAULT}: {entry.name}"
    gross = entry.mass if mass is None else float(mass)
    sources = {"mass": default if mass is None else SOURCE_MASS}
    details = {"mass": entry.mass_source if mass is None else "the vType's mass attribute"}
    own = [k for k in SUSPENSION_KEYS if (PARAM_PREFIX + k) in params]
    if own:
        model = _param_model(type_id, gross, entry.suspension, params)
        missing = [k for k in ("m_w", "k_v", "c_v") if k not in own]
        if model.kind == "tyre-quarter-car":  # (a half-car too, until its axles are known)
            missing += [k for k in ("k_t", "c_t") if k not in own]
        if model.kind == "moving-force":
            missing = []
        sources["suspension"] = SOURCE_PARAMS + (f" + {SOURCE_DEFAULT}" if missing else "")
        details["suspension"] = ", ".join(PARAM_PREFIX + k for k in own) + (
            f"; {', '.join(missing)} from {entry.suspension.name} ({entry.suspension.source})" if missing else "")
    else:
        model = _library_model(entry.suspension, gross)
        sources["suspension"] = f"{SOURCE_DEFAULT}: {entry.suspension.name}"
        details["suspension"] = entry.suspension.source
    if (PARAM_PREFIX + "axles") in params or (PARAM_PREFIX + "axle_loads") in params:
        axles = axles_from_parameters(type_id, length if known else math.inf, params)
        sources["axles"] = SOURCE_PARAMS
        details["axles"] = f"{PARAM_PREFIX}axles, {PARAM_PREFIX}axle_loads"
    elif own and params.get(PARAM_PREFIX + "model", "").strip() != "half-car":
        axles = ((0.5 * length, 1.0),)
        sources["axles"] = SOURCE_PARAMS
        details["axles"] = f"one quarter-car at mid-length (no {PARAM_PREFIX}axles)"
    else:
        axles, scaled = _library_axles(entry, length)
        sources["axles"] = default
        details["axles"] = entry.axles_source + (f"; scaled to the vType's {length:g} m" if scaled else "")
    if own and params.get(PARAM_PREFIX + "model", "").strip() == "half-car":
        assert isinstance(model, TyreQuarterCar)
        model = half_car_model(type_id, model, axles, length, params)
    return VehicleType(id=type_id, vclass=vclass, length=float(length), model=model, axles=axles,
                       sources=sources, details=details, library=entry.name, note=note)


def _library_axles(entry: LibraryVehicle, length: float) -> tuple[tuple[tuple[float, float], ...], bool]:
    where, scaled = entry.axles_for(length)
    return tuple(zip(where, entry.loads)), scaled


def model_from_parameters(type_id: str, mass: float | None, vclass: str, params: dict[str, str],
                          length: float = 5.0) -> VehicleModel:
    """The whole vehicle's model of a vType (:func:`vehicle_type`'s ``model``).

    Raises:
        SumoError: a param is unknown or not a number, or the parameters are not physical.
    """
    return vehicle_type(type_id, vclass, length, mass, params).model
