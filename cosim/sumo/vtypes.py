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

Each model's params, their defaults and its builder are its registry entry's
(``cosim.core.vehicles.MODELS``, :class:`~cosim.core.vehicles.VTypeRecipe`):
a registered model with a recipe is a ``cosim.model`` here. A ``cosim.*``
param that is not one of these is an error that names the closest known one.
Plain functions of values (the demand files' or libsumo's): no libsumo here.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from cosim.core.vehicles import LIBRARY, MODELS, ModelSpec, TyreQuarterCar, VehicleModel, VTypeInputs
from cosim.core.vehicles.registry import cell
from cosim.errors import ConfigError, SumoError
from cosim.sumo.library import HEAVY_VCLASSES, LibraryVehicle, Suspension, entry_for

if TYPE_CHECKING:
    from cosim.core.loads import VehicleLoad

__all__ = [
    "HEAVY_VCLASSES",
    "PARAM_PREFIX",
    "SOURCE_DEFAULT",
    "SOURCE_MASS",
    "SOURCE_PARAMS",
    "VehicleType",
    "axles_from_parameters",
    "check_parameter_names",
    "library_model",
    "markdown_table",
    "model_from_parameters",
    "model_params",
    "param_keys",
    "scaled_model",
    "vehicle_type",
    "vtype_models",
]

PARAM_PREFIX = "cosim."
#: The params of the axles (every model reads them).
AXLE_KEYS = ("axles", "axle_loads")
#: ``cosim.model`` when a vType sets suspension params without it.
DEFAULT_MODEL = "quarter-car"
CONTACT_KINDS = ("bilateral", "unilateral")
#: Where a number came from, as summaries and logs say it.
SOURCE_PARAMS = "vType params"
SOURCE_MASS = "SUMO mass"
SOURCE_DEFAULT = "cosim default"


def vtype_models() -> dict[str, ModelSpec]:
    """The registered models a vType's ``cosim.model`` may name (those with a vType recipe), in registry order."""
    return {name: spec for name, spec in MODELS.items() if spec.vtype is not None}


def model_params(spec: ModelSpec) -> tuple[str, ...]:
    """The ``cosim.*`` params (without the prefix) a model reads: ``model``, its suspension (library defaults),
    the axles, ``contact`` (with a tyre) and its others."""
    assert spec.vtype is not None
    params = spec.vtype.parameters
    return ("model", *(p.name for p in params if p.default is LIBRARY), *AXLE_KEYS,
            *(("contact",) if spec.tyre else ()), *(p.name for p in params if p.default is not LIBRARY))


def param_keys() -> tuple[str, ...]:
    """Every ``cosim.*`` param cosim reads (without the prefix), in the order messages list them."""
    specs = list(vtype_models().values())
    params = [p for spec in specs if spec.vtype is not None for p in spec.vtype.parameters]
    return ("model", *dict.fromkeys(p.name for p in params if p.default is LIBRARY), *AXLE_KEYS,
            *(("contact",) if any(spec.tyre for spec in specs) else ()),
            *dict.fromkeys(p.name for p in params if p.default is not LIBRARY))


def markdown_table() -> str:
    """The docs' table of each ``cosim.model`` and the params it reads (docs/own-network.md)."""
    lines = [f"| `{PARAM_PREFIX}model` | the `{PARAM_PREFIX}*` params it reads besides `{PARAM_PREFIX}model`, "
             f"`{PARAM_PREFIX}axles` and `{PARAM_PREFIX}axle_loads` | without `{PARAM_PREFIX}axles` |",
             "|---|---|---|"]
    for name, spec in vtype_models().items():
        assert spec.vtype is not None
        library = [p for p in spec.vtype.parameters if p.default is LIBRARY]
        parts = []
        if library:
            parts.append(", ".join(f"`{PARAM_PREFIX}{p.name}` ({p.unit})" for p in library) +
                         ": the library suspension of the vClass unless given")
        if spec.tyre:
            parts.append(f"`{PARAM_PREFIX}contact` (`bilateral` or `unilateral`)")
        parts += [f"`{PARAM_PREFIX}{p.name}` ({p.unit or 'true or false'}: {p.doc})" for p in spec.vtype.parameters
                  if p.default is not LIBRARY]
        axles = "one body on the library's axles" if spec.vtype.one_body else "one axle at mid-length"
        default = " (the default)" if name == DEFAULT_MODEL else ""
        lines.append(f"| `{name}`{default} | {cell('; '.join(parts) or 'none')} | {axles} |")
    return "\n".join(lines)


def check_parameter_names(type_id: str, params: dict[str, str]) -> None:
    """Raise :class:`SumoError` for a ``cosim.*`` param cosim does not know, naming the closest known one."""
    keys = param_keys()
    for key in params:
        if not key.startswith(PARAM_PREFIX):
            continue
        name = key[len(PARAM_PREFIX):]
        if name in keys:
            continue
        near = difflib.get_close_matches(name, keys, n=1, cutoff=0.5)
        hint = f"did you mean `{PARAM_PREFIX}{near[0]}`? " if near else ""
        raise SumoError(f"vType {type_id}: unknown param `{key}` ({hint}cosim reads "
                        f"{', '.join(PARAM_PREFIX + k for k in keys)})")
    model = params.get(PARAM_PREFIX + "model", DEFAULT_MODEL)
    spec = vtype_models().get(model)
    if spec is None:
        return  # an unknown model: the model's own check names it
    allowed = model_params(spec)
    unused = [k for k in params if k.startswith(PARAM_PREFIX) and k[len(PARAM_PREFIX):] not in allowed]
    if unused:  # it would be ignored, silently
        raise SumoError(f"vType {type_id}: param `{unused[0]}` is not used by model {model} (its params: "
                        f"{', '.join(PARAM_PREFIX + k for k in allowed)})")
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


def library_model(suspension: Suspension, mass: float) -> TyreQuarterCar:
    """The suspension set scaled to a vehicle of gross ``mass`` kg."""
    m_v = mass / (1.0 + suspension.m_w)
    return TyreQuarterCar(m_v=m_v, m_w=suspension.m_w * m_v, k_v=suspension.k_v * m_v, c_v=suspension.c_v * m_v,
                          k_t=suspension.k_t * m_v, c_t=suspension.c_t * m_v)


def _model_spec(type_id: str, params: dict[str, str]) -> ModelSpec:
    """The registry entry ``cosim.model`` names (default quarter-car)."""
    kind = params.get(PARAM_PREFIX + "model", DEFAULT_MODEL).strip()
    models = vtype_models()
    if kind not in models:
        near = difflib.get_close_matches(kind, list(models), n=1)
        hint = f"; did you mean {near[0]}?" if near else ""
        raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}model` must be {', '.join(models)} "
                        f"(got {kind!r}{hint})")
    return models[kind]


def _param_values(type_id: str, spec: ModelSpec, mass: float, suspension: Suspension,
                  params: dict[str, str]) -> dict[str, float | bool | None]:
    """The values of the params the model reads: given, else their default; a library one from ``suspension``
    at ``mass`` (the unsprung mass as its share of the gross mass, the others per kg of body)."""
    assert spec.vtype is not None
    values: dict[str, float | bool | None] = {}
    m_v = mass
    if any(p.name == "m_w" and p.default is LIBRARY for p in spec.vtype.parameters):
        m_w = _number(type_id, params, "m_w")
        m_w = suspension.unsprung_share() * mass if m_w is None else m_w
        m_v = mass - m_w
        if not m_v > 0:
            raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}m_w` = {m_w:g} kg leaves no body mass "
                            f"(mass = {mass:g} kg)")
        values["m_w"] = m_w
    for p in spec.vtype.parameters:
        if p.name in values:
            continue
        if p.kind == "flag":
            values[p.name] = _flag(type_id, params, p.name, p.default)
            continue
        value = _number(type_id, params, p.name)
        if value is None:
            value = getattr(suspension, p.name) * m_v if p.default is LIBRARY else p.default
        values[p.name] = value
    return values


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

    def contact_columns(self) -> list[tuple[str, VehicleModel, float, float]]:
        """(model table key, model, distance behind the front bumper m, offset to the left of the path m) per
        contact column: the type itself for one, ``type#k`` for column k of several.

        Independent axles each get their share of the model (one column each); the contact points of one
        body (a half-car's axles) all name the whole model, which the beam step recognises as one vehicle
        on several contacts, placed from the first axle (a contact on one of the axles: at that axle).
        """
        points = self.model.contact_points
        if len(points) > 1:
            front = self.axles[0][0]
            on_axle = {d - front: d for d, _ in self.axles}
            return [(f"{self.id}#{k}", self.model, on_axle.get(p.behind, front + p.behind), p.left)
                    for k, p in enumerate(points)]
        left = points[0].left
        if len(self.axles) == 1:
            return [(self.id, self.model, self.axles[0][0], left)]
        return [(f"{self.id}#{k}", self.model.scaled(share), d, left) for k, (d, share) in enumerate(self.axles)]

    def axle_models(self) -> list[tuple[str, VehicleModel]]:
        """(model table key, model) per contact column (:meth:`contact_columns`)."""
        return [(key, model) for key, model, _, _ in self.contact_columns()]

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
    own = [k for k in param_keys() if k not in AXLE_KEYS and (PARAM_PREFIX + k) in params]
    spec = _model_spec(type_id, params) if own else None
    if spec is not None and spec.vtype is not None:
        values = _param_values(type_id, spec, gross, entry.suspension, params)
        unilateral = _contact(type_id, params)
        missing = [p.name for p in spec.vtype.parameters if p.default is LIBRARY and p.name not in own]
        sources["suspension"] = SOURCE_PARAMS + (f" + {SOURCE_DEFAULT}" if missing else "")
        details["suspension"] = ", ".join(PARAM_PREFIX + k for k in own) + (
            f"; {', '.join(missing)} from {entry.suspension.name} ({entry.suspension.source})" if missing else "")
    else:
        model: VehicleModel = library_model(entry.suspension, gross)
        sources["suspension"] = f"{SOURCE_DEFAULT}: {entry.suspension.name}"
        details["suspension"] = entry.suspension.source
    if (PARAM_PREFIX + "axles") in params or (PARAM_PREFIX + "axle_loads") in params:
        axles = axles_from_parameters(type_id, length if known else math.inf, params)
        sources["axles"] = SOURCE_PARAMS
        details["axles"] = f"{PARAM_PREFIX}axles, {PARAM_PREFIX}axle_loads"
    elif spec is not None and spec.vtype is not None and not spec.vtype.one_body:
        axles = ((0.5 * length, 1.0),)
        sources["axles"] = SOURCE_PARAMS
        details["axles"] = f"one quarter-car at mid-length (no {PARAM_PREFIX}axles)"
    else:
        axles, scaled = _library_axles(entry, length)
        sources["axles"] = default
        details["axles"] = entry.axles_source + (f"; scaled to the vType's {length:g} m" if scaled else "")
    if spec is not None and spec.vtype is not None:
        try:
            model = spec.vtype.build(VTypeInputs(type_id, gross, values, unilateral, axles, float(length)))
        except ConfigError as exc:
            raise SumoError(f"vType {type_id}: {exc}") from None
    return VehicleType(id=type_id, vclass=vclass, length=float(length), model=model, axles=axles,
                       sources=sources, details=details, library=entry.name, note=note)


def loaded_vehicle_type(vtype: VehicleType, key: str, load: VehicleLoad, front: float, source: str) -> VehicleType:
    """One vehicle of ``vtype`` with its own drawn loads (``load``: a :class:`cosim.core.loads.VehicleLoad`):
    its axles ``front`` m behind the bumper and then at the drawn spacings, each carrying its drawn load, on the
    vType's suspension scaled to the drawn weight (the same frequencies and damping ratios), named ``key``.

    Raises:
        SumoError: the vType's model is one body on its axles (a half-car): its loads are its own.
    """
    if vtype.model.contacts > 1:
        raise SumoError(f"vType {vtype.id}: a half-car's weights come from its own params; map it to \"fixed\" "
                        "in [traffic.loads] vtype_classes")
    mass = load.gross_weight / LOADS_G
    model = vtype.model.scaled(mass / vtype.mass)
    distances = [front]
    for spacing in load.axle_spacings:
        distances.append(distances[-1] + spacing)
    shares = [w / load.gross_weight for w in load.axle_loads]
    return VehicleType(id=key, vclass=vtype.vclass, length=vtype.length, model=model,
                       axles=tuple(zip(distances, shares)),
                       sources={"mass": source, "axles": source, "suspension": vtype.sources.get("suspension", "")},
                       details={"mass": f"drawn for this vehicle from {source}", "axles": f"drawn from {source}",
                                "suspension": f"the vType {vtype.id}'s, scaled to the drawn weight"},
                       library=vtype.library, note=vtype.note)


#: Gravity of the WIM models' weights, m/s^2 (BTLS's, :data:`cosim.core.loads.draws.G`).
LOADS_G = 9.81


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
