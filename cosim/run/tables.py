"""The tables of a scenario file besides ``[bridge]``: what loads the bridge, how it is solved, where results go.

``[[sensors]]``, ``[[vehicles]]``, ``[traffic]``, ``[road]``, ``[solver]`` and
``[output]``. Each table checks its own keys and lowers itself to the
:mod:`cosim.core` object it describes (``to_model()``, ``to_scripted()``,
``to_settings()``, ...). ``[bridge]``: :mod:`cosim.run.bridge_tables`; checks
across tables: :class:`cosim.run.scenario.Scenario`. ``docs/scenario.md``
documents every key.
"""
from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from typing import Annotated, Any

from pydantic import (
    ConfigDict,
    Field,
    PlainValidator,
    SerializerFunctionWrapHandler,
    Strict,
    TypeAdapter,
    ValidationError,
    create_model,
    model_serializer,
    model_validator,
)

from cosim.analysis.fatigue import SNCurve, sn_curve, sn_curve_names
from cosim.core.loads import FORMATS
from cosim.core.roughness import ISO_CLASSES
from cosim.core.sensors import SECTION_POINT_QUANTITIES, SENSOR_QUANTITIES, Sensor
from cosim.core.simulation import METHODS, SolverSettings
from cosim.core.traffic import LoadRecord, ScriptedVehicle
from cosim.core.vehicles import MODELS, ModelSpec, Parameter, VehicleModel
from cosim.errors import ConfigError

from .config_base import (
    ConfigModel,
    Name,
    NetPoint,
    NonNegative,
    Number,
    Positive,
    PositiveInt,
    Problems,
    choice,
    choices_message,
    describe,
    fail,
    number_problem,
    problems_of,
    show,
    suggest,
)

__all__ = [
    "BASES",
    "DEFAULT_HHT_ALPHA",
    "DEFAULT_MODAL_MODES",
    "DEFAULT_RATE_HZ",
    "DIRECTIONS",
    "OutputConfig",
    "QUANTITIES",
    "ROAD_CLASSES",
    "RoadConfig",
    "SCHEMES",
    "SUMO_LEVELS",
    "SNCurveConfig",
    "SensorConfig",
    "SolverConfig",
    "LoadsConfig",
    "RECORD_MODELS",
    "RECORD_VIA",
    "RecordLaneConfig",
    "RecordsConfig",
    "TrafficConfig",
    "CONTACTS",
    "VEHICLE_MODELS",
    "VehicleConfig",
    "tyre_models",
    "vehicle_parameters",
]

# --------------------------------------------------------------------------- names

#: Sensor quantities (the core's list: displacement, velocity, acceleration, bending_moment, and the stresses and the
#: strain read at a section point).
QUANTITIES: tuple[str, ...] = SENSOR_QUANTITIES

SCHEMES: tuple[str, ...] = ("newmark", "hht")
BASES: tuple[str, ...] = ("direct", "modal")

#: The vehicle models of ``[[vehicles]]`` (and of vTypes): the one registry, ``cosim.core.vehicles.MODELS``
#: (``cosim.VEHICLE_MODELS``), name -> :class:`~cosim.core.vehicles.ModelSpec` with its parameters.
VEHICLE_MODELS: dict[str, ModelSpec] = MODELS
#: ``contact`` of ``[[vehicles]]``: the tyre holds to the deck, or may leave it (models with a tyre only).
CONTACTS: tuple[str, ...] = ("bilateral", "unilateral")
DIRECTIONS: dict[str, int] = {"+x": 1, "-x": -1}

#: ``[road].class``: an ISO 8608 class, or a smooth road.
ROAD_CLASSES: tuple[str, ...] = (*ISO_CLASSES, "smooth")

#: ``[traffic].sumo_config`` may name one of these bundled demand levels (sumo_networks/<level>.sumocfg).
SUMO_LEVELS: tuple[str, ...] = ("light", "medium", "heavy", "congested")

DEFAULT_HHT_ALPHA = -0.05
DEFAULT_MODAL_MODES = 30
#: Default logging rate of ``[output]``, Hz (every step when dt is longer than its period).
DEFAULT_RATE_HZ = 100.0


# --------------------------------------------------------------------------- tables


class SNCurveConfig(ConfigModel):
    """``sn_curve = {ds_ref = ..., ...}`` of a stress sensor: a user's S-N curve (Pa, cycles)."""

    ds_ref: Positive
    n_ref: Positive
    m1: Positive
    m2: Positive | None = None
    n_knee: Positive | None = None
    n_cutoff: Positive | None = None

    @model_validator(mode="after")
    def _curve(self) -> SNCurveConfig:
        try:
            self.to_curve("check", 1.0)
        except ConfigError as exc:
            raise fail(str(exc).split(": ", 1)[-1]) from None
        return self

    def to_curve(self, name: str, partial_factor: float) -> SNCurve:
        """The :class:`cosim.analysis.fatigue.SNCurve` (one slope when m2 and n_knee are not given)."""
        return SNCurve(name, self.ds_ref, self.n_ref, self.m1, self.m2 if self.m2 is not None else self.m1,
                       self.n_knee if self.n_knee is not None else self.n_ref, self.n_cutoff, partial_factor)


def _sn_name(value: Any) -> str:
    if not isinstance(value, str) or value not in sn_curve_names():
        raise fail(choices_message(value, sn_curve_names(), "S-N curve") + " (or a table of the curve's constants)")
    return value


class SensorConfig(ConfigModel):
    """``[[sensors]]``: a measured quantity at a deck point, or a stress or strain at a section point."""

    name: Name
    x: Number
    y: Number = 0.0
    z: Number | None = None
    omega: Number | None = None
    quantity: Annotated[str, choice(QUANTITIES, "quantity")] = "displacement"
    sn_curve: Annotated[str, PlainValidator(_sn_name)] | SNCurveConfig | None = None
    partial_factor: Positive = 1.0

    @model_validator(mode="after")
    def _section_point(self) -> SensorConfig:
        on_section = self.quantity in SECTION_POINT_QUANTITIES
        if on_section and self.z is None:
            raise fail(f"required key is missing: quantity = {show(self.quantity)} is read at the section point "
                       "(y, z); give z, m, in the frame the section is drawn in", "z")
        for key in ("z", "omega"):
            if not on_section and getattr(self, key) is not None:
                raise fail(f"only used by the quantities {', '.join(SECTION_POINT_QUANTITIES)} "
                           f"(got quantity = {show(self.quantity)})", key)
        if self.sn_curve is not None and self.quantity not in ("stress", "shear_stress_xy", "shear_stress_xz"):
            raise fail(f"only a stress sensor has an S-N curve (got quantity = {show(self.quantity)})", "sn_curve")
        if self.partial_factor != 1.0 and self.sn_curve is None:
            raise fail("only used with sn_curve", "partial_factor")
        return self

    def curve(self) -> SNCurve | None:
        """The sensor's S-N curve (None without one)."""
        if self.sn_curve is None:
            return None
        if isinstance(self.sn_curve, str):
            return sn_curve(self.sn_curve, self.partial_factor)
        return self.sn_curve.to_curve(f"{self.name} (given)", self.partial_factor)

    def to_sensor(self) -> Sensor:
        """The :class:`cosim.core.sensors.Sensor` this table describes."""
        return Sensor(name=self.name, x=self.x, y=self.y, quantity=self.quantity, z=self.z, omega=self.omega)


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


def vehicle_parameters() -> dict[str, Parameter]:
    """Every registered model's ``[[vehicles]]`` parameters by name, in registry order (a name two models share:
    the first one's)."""
    found: dict[str, Parameter] = {}
    for spec in VEHICLE_MODELS.values():
        for parameter in spec.parameters:
            found.setdefault(parameter.name, parameter)
    return found


def tyre_models() -> tuple[str, ...]:
    """The models that take ``contact = "unilateral"`` (their tyre may leave the deck)."""
    return tuple(name for name, spec in VEHICLE_MODELS.items() if spec.tyre)


def _model_name(value: Any) -> str:
    names = tuple(VEHICLE_MODELS)
    if not isinstance(value, str) or value not in names:
        raise fail(choices_message(value, names, "vehicle model"))
    return value


def _annotation(parameter: Parameter) -> Any:
    """The pydantic type of a key of a table parameter (its bound checked: ``must be > 0 (got -1.0)``)."""
    if parameter.kind == "flag":
        return Annotated[bool, Strict()]
    if parameter.kind == "tables":
        return _tables(parameter)[0]
    if parameter.above is not None:
        return Annotated[float, Strict(), Field(gt=parameter.above)]
    if parameter.at_least is not None:
        return Annotated[float, Strict(), Field(ge=parameter.at_least)]
    return Number


@functools.cache
def _tables(parameter: Parameter) -> tuple[Any, TypeAdapter]:
    """The pydantic type of an array-of-tables parameter (each table a model of its ``fields``) and its adapter."""
    fields: dict[str, Any] = {f.name: (_annotation(f), ... if f.required else f.default) for f in parameter.fields}
    table = create_model(f"{parameter.name.capitalize()}Table", __base__=ConfigModel, **fields)
    kind = tuple[table, ...]  # type: ignore[valid-type]
    return kind, TypeAdapter(kind)


def _checked(parameter: Parameter, value: Any) -> tuple[Any, list[tuple[tuple[str | int, ...], str]]]:
    """A parameter's value as the model takes it (a float, a bool, a tuple of tables), or its problems."""
    at = (parameter.name,)
    if parameter.kind == "number":
        problem = number_problem(value)
        return (None, [(at, problem)]) if problem else (float(value), [])
    if parameter.kind == "flag":
        return (value, []) if isinstance(value, bool) else (None, [(at, f"expected a boolean, got {describe(value)}")])
    kind, adapter = _tables(parameter)
    try:
        return adapter.validate_python(value), []
    except ValidationError as exc:
        return None, [(at + loc, message) for loc, message in problems_of(kind, exc)]


class VehicleConfig(ConfigModel):
    """``[[vehicles]]``: a scripted vehicle, its model and parameters, path, speed and entry time.

    The model's parameters are those its registry entry lists (``cosim.core.vehicles.MODELS``): checked here
    and kept as the table's other keys (``vehicle.m_v``; :attr:`parameters` with the defaults).
    """

    model_config = ConfigDict(extra="allow", frozen=True, allow_inf_nan=False)

    id: Name
    model: Annotated[str, PlainValidator(_model_name)]
    contact: Annotated[str, choice(CONTACTS, "contact")] = "bilateral"
    y: Number
    speed: Positive | None = None
    entry_time: NonNegative = 0.0
    direction: Annotated[str, choice(tuple(DIRECTIONS), "direction")] = "+x"
    profile: SpeedProfile | None = None

    @model_validator(mode="wrap")
    @classmethod
    def _parameters(cls, data: Any, handler: Callable[[Any], VehicleConfig]) -> VehicleConfig:
        """The vehicle's own keys through pydantic, the model's parameters through the registry; the problems
        of both in the order of the table's keys (its own, with the parameters after ``model``)."""
        if not isinstance(data, dict):
            return handler(data)
        own = set(cls.model_fields)
        known = vehicle_parameters()
        order = ["id", "model", *known, *(k for k in cls.model_fields if k not in ("id", "model"))]
        problems: list[tuple[tuple[str | int, ...], str]] = []
        try:
            vehicle: VehicleConfig | None = handler({k: v for k, v in data.items() if k in own})
        except ValidationError as exc:
            vehicle = None
            problems += problems_of(cls, exc)
        model = data.get("model")
        spec = VEHICLE_MODELS.get(model) if isinstance(model, str) else None
        values: dict[str, Any] = {}
        unknown: list[tuple[tuple[str | int, ...], str]] = []
        hinted = set()
        for key, value in data.items():
            if key in own or value is None:  # None: a key of another model in a scenario dumped by an older cosim
                continue
            parameter = spec.parameter(key) if spec is not None and key in spec.names else known.get(key)
            if parameter is None:
                hint = suggest(str(key), order)
                hinted.add((hint,))
                unknown.append(((key,), f"unknown key{f'; did you mean {show(hint)}?' if hint else ''} "
                                        f"(expected one of: {', '.join(order)})"))
                continue
            checked, found = _checked(parameter, value)
            problems += found
            values[key] = checked
        # A misspelt key also makes its correct spelling "missing": report the misspelling only.
        problems = [p for p in problems if not (p[0] in hinted and p[1] == "required key is missing")]
        problems.sort(key=lambda p: order.index(p[0][0]) if p[0] and p[0][0] in order else len(order))
        if problems or unknown:
            raise Problems(problems + unknown)
        assert vehicle is not None and spec is not None
        ordered = {key: values[key] for key in known if key in values}
        object.__setattr__(vehicle, "__pydantic_extra__", ordered)
        vehicle._check_parameters(spec)
        return vehicle

    @model_serializer(mode="wrap")
    def _dump(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """Every registered parameter after ``model`` (None where not given), as when they were fields."""
        data = handler(self)
        out = {"id": data.pop("id"), "model": data.pop("model")}
        out.update({key: data.pop(key, None) for key in vehicle_parameters()})
        out.update(data)
        return out

    def _check_parameters(self, spec: ModelSpec) -> None:
        """The keys of the model, the speed, the contact and the model itself (the classes check the numbers)."""
        given = self.__pydantic_extra__ or {}
        problems: list[tuple[tuple[str | int, ...], str]] = []
        listed = ", ".join(spec.names)
        for key in given:
            if key not in spec.names:
                problems.append(((key,), f"not a parameter of model {show(self.model)} (its parameters: {listed})"))
        for key in spec.names:
            if spec.parameter(key).required and key not in given:
                problems.append(((key,), f"required key is missing (model {show(self.model)} needs {listed})"))
        if self.speed is not None and self.profile is not None:
            problems.append((("speed",), "give either speed or profile, not both"))
        if self.speed is None and self.profile is None:
            problems.append((("speed",), "required key is missing (give speed, m/s, or a speed profile)"))
        if self.contact == "unilateral" and not spec.tyre:
            problems.append((("contact",), f"unilateral contact needs a tyre: use one of {', '.join(tyre_models())} "
                                           f"(model {show(self.model)} keeps its wheel on the deck)"))
        for parameter in spec.parameters:
            if parameter.kind == "tables" and parameter.name in given and not given[parameter.name]:
                one = parameter.name[:-1] if parameter.name.endswith("s") else parameter.name
                problems.append(((parameter.name,), f"expected at least one {one}, got an empty array"))
        if problems:
            raise Problems(problems)
        try:
            self.to_model()
        except ConfigError as exc:
            raise _rekeyed(exc, tuple(vehicle_parameters())) from None

    @property
    def spec(self) -> ModelSpec:
        """The model's registry entry."""
        return VEHICLE_MODELS[self.model]

    @property
    def parameters(self) -> dict[str, Any]:
        """The model's parameters, defaults filled in, required first (SI units; an array of tables as tables
        with their keys as attributes: a half-car's ``axles[0].distance``)."""
        given = self.__pydantic_extra__ or {}
        spec = self.spec
        return {key: given[key] if key in given else spec.parameter(key).default for key in spec.names}

    def to_model(self) -> VehicleModel:
        """The :mod:`cosim.core.vehicles` model this table describes.

        Raises:
            ConfigError: a non-physical parameter (the vehicle classes check them).
        """
        spec = self.spec
        values = {key: tuple(table.model_dump() for table in value) if spec.parameter(key).kind == "tables"
                  else value for key, value in self.parameters.items()}
        return spec.build(values, self.contact == "unilateral")

    def to_scripted(self, gravity: float = 9.81) -> ScriptedVehicle:
        """The :class:`cosim.core.traffic.ScriptedVehicle` this table describes (its load record at ``gravity``,
        m/s^2: what the log records of it at its entry)."""
        model = self.to_model()
        speed = self.speed if self.speed is not None else 0.0
        entry_speed = self.profile[0][1] if self.profile else speed
        return ScriptedVehicle(
            id=self.id,
            model=model,
            y=self.y,
            speed=speed,
            entry_time=self.entry_time,
            direction=DIRECTIONS[self.direction],
            profile=self.profile or (),
            load=LoadRecord.of_model(self.id, model, self.y, entry_speed, gravity),
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


#: Lateral wander of ``[traffic.loads]``: EN 1991-2 §4.6.1 Figure 4.6, none, or a normal distribution's sd (m).
WANDERS: tuple[str, ...] = ("en1991-2", "none")
#: What ``vtype_classes`` may give a vType besides truck classes (axle counts 2-5): the light distribution, or
#: the vType's own weights.
VTYPE_CLASS_WORDS: tuple[str, ...] = ("car", "fixed")


def _wander(value: Any) -> str | float:
    """``wander = "en1991-2" | "none" | <sd, m>``."""
    if isinstance(value, str) and value in WANDERS:
        return value
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and 0 < value <= 1.0:
        return float(value)
    raise fail(f"expected {', '.join(WANDERS)} or the standard deviation of a normal wander, a number > 0 and "
               f"<= 1 m (got {describe(value)})")


def _vtype_class(value: Any) -> tuple[int, ...] | str:
    """A vType's classes: a list of axle counts (2-5), "car" or "fixed"."""
    if isinstance(value, str) and value in VTYPE_CLASS_WORDS:
        return value
    if isinstance(value, (list, tuple)) and value and all(
            isinstance(c, int) and not isinstance(c, bool) and 2 <= c <= 5 for c in value):
        return tuple(sorted(set(value)))
    raise fail(f"expected a list of truck classes (axle counts 2 to 5, e.g. [4, 5]), \"car\" (the light "
               f"distribution) or \"fixed\" (the vType's own weights); got {describe(value)}")


class LoadsConfig(ConfigModel):
    """``[traffic.loads]``: every vehicle's weight and axles drawn from a WIM-calibrated model (docs/loads.md)."""

    model: Annotated[str, Strict(), Field(min_length=1)]
    seed: Annotated[int, Strict(), Field(ge=0)]
    vtype_classes: dict[Annotated[str, Strict(), Field(min_length=1)],
                        Annotated[tuple[int, ...] | str, PlainValidator(_vtype_class)]] = {}
    wander: Annotated[str | float, PlainValidator(_wander)] = "en1991-2"


#: ``[traffic.records] via``: each record driven at its recorded time, lane and speed without SUMO, or inserted
#: into ``[traffic] sumo_config``'s network.
RECORD_VIA: tuple[str, ...] = ("scripted", "sumo")
#: ``[traffic.records] model`` (``via = "scripted"``): each axle a tyre quarter-car on cosim's library suspension
#: scaled to its load, or a constant force (the pure load comparisons of BTLS and influence lines).
RECORD_MODELS: tuple[str, ...] = ("tyre-quarter-car", "moving-force")
DEFAULT_RECORD_MODEL = "tyre-quarter-car"


class RecordLaneConfig(ConfigModel):
    """One entry of ``[traffic.records] lanes``: a lane of the file (BTLS's number), its wheel path, its way."""

    lane: PositiveInt
    y: Number
    direction: Annotated[str, choice(tuple(DIRECTIONS), "direction")]


class RecordsConfig(ConfigModel):
    """``[traffic.records]``: a WIM record file as the traffic (docs/loads.md#records-as-traffic)."""

    file: Annotated[str, Strict(), Field(min_length=1)]
    format: Annotated[str, choice(tuple(FORMATS), "record format")]
    lanes: tuple[RecordLaneConfig, ...]
    via: Annotated[str, choice(RECORD_VIA, "via")]
    model: Annotated[str, choice(RECORD_MODELS, "model")] | None = None
    wander: Annotated[str | float, PlainValidator(_wander)] = "none"
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    begin: NonNegative = 0.0
    end: Positive | None = None

    @model_validator(mode="after")
    def _consistent(self) -> RecordsConfig:
        problems: list[tuple[tuple[str | int, ...], str]] = []
        if not self.lanes:
            problems.append((("lanes",), "expected at least one lane, e.g. lanes = [{lane = 1, y = -1.875, "
                                         "direction = \"+x\"}]"))
        seen: dict[int, int] = {}
        for i, lane in enumerate(self.lanes):
            if lane.lane in seen:
                twice = f"lane {lane.lane} is given twice (also lanes[{seen[lane.lane]}])"
                problems.append((("lanes", i, "lane"), f"{twice}; give each of the file's lanes once"))
            seen.setdefault(lane.lane, i)
        if self.model is not None and self.via != "scripted":
            problems.append((("model",), f'only used with via = "scripted" (got via = {show(self.via)}: SUMO\'s '
                                         "vehicles carry the library suspension of their vType's vClass)"))
        if self.wander != "none" and self.seed is None:
            problems.append((("seed",), f"required key is missing: wander = {show(self.wander)} is drawn per vehicle "
                                        "and needs a seed (an integer >= 0) so that it can be reproduced, "
                                        "e.g. seed = 1"))
        if self.seed is not None and self.wander == "none":
            problems.append((("seed",), 'only used with a wander (wander = "en1991-2" or a standard deviation, m; '
                                        'got wander = "none")'))
        if self.end is not None and self.end <= self.begin:
            problems.append((("end",), f"must be after begin = {show(self.begin)} s (got {show(self.end)})"))
        if problems:
            raise Problems(problems)
        return self

    @property
    def axle_model(self) -> str:
        """The axles' model (``via = "scripted"``), the default filled in."""
        return self.model if self.model is not None else DEFAULT_RECORD_MODEL

    @property
    def window_end(self) -> float:
        """``end``, or inf: the whole file."""
        return self.end if self.end is not None else math.inf


#: ``[traffic]`` keys of a SUMO run: not to be given without ``sumo_config``.
SUMO_KEYS: tuple[str, ...] = ("step", "begin", "end", "seed", "axis", "edges", "loads")


class TrafficConfig(ConfigModel):
    """``[traffic]``: vehicles from a SUMO simulation (``sumo_config``), or from a WIM record file
    (``[traffic.records]``: driven as recorded, or inserted into the SUMO network), instead of scripted
    ``[[vehicles]]``."""

    sumo_config: Annotated[str, Strict(), Field(min_length=1)] | None = None
    step: Positive = 0.05
    begin: NonNegative = 0.0
    end: Positive = 600.0
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    axis: tuple[NetPoint, NetPoint] | None = None
    edges: tuple[Annotated[str, Strict(), Field(min_length=1)], ...] = ()
    loads: LoadsConfig | None = None
    records: RecordsConfig | None = None

    @model_validator(mode="after")
    def _times(self) -> TrafficConfig:
        if self.sumo_config is None:
            if self.records is None:
                raise fail("required key is missing: give sumo_config (a SUMO simulation: a bundled level, "
                           f"{', '.join(SUMO_LEVELS)}, or a .sumocfg) or a [traffic.records] table (a WIM record file)",
                           "sumo_config")
            if self.records.via == "sumo":
                raise fail('required key is missing: records with via = "sumo" are inserted into a SUMO network: '
                           'give sumo_config, or drive them as recorded with via = "scripted"', "sumo_config")
            given = [k for k in SUMO_KEYS if k in self.model_fields_set]
            if given:
                raise fail('only used with sumo_config (SUMO traffic); records with via = "scripted" run without '
                           "SUMO: their window is [traffic.records] begin and end", given[0])
            return self
        if self.records is not None and self.records.via == "scripted":
            raise fail('records with via = "scripted" run without SUMO: remove sumo_config (and the other SUMO keys), '
                       'or insert them into the network with via = "sumo"', "records", "via")
        if self.end <= self.begin:
            raise fail(f"must be after begin = {show(self.begin)} s (got {show(self.end)})", "end")
        if self.axis is not None and math.dist(*self.axis) <= 0:
            raise fail("the two axis points must differ", "axis")
        return self

    @property
    def sumo(self) -> bool:
        """Whether SUMO runs (``sumo_config`` given)."""
        return self.sumo_config is not None

    @property
    def scripted_records(self) -> RecordsConfig | None:
        """The records driven as recorded, without SUMO (``via = "scripted"``), or None."""
        return self.records if self.records is not None and self.records.via == "scripted" else None

    @property
    def bundled(self) -> bool:
        return self.sumo_config in SUMO_LEVELS


class SolverConfig(ConfigModel):
    """``[solver]``: time integration settings; ``method``: dynamic, or quasi-static (the static response at
    every step: no inertia, no vehicle dynamics, no roughness)."""

    method: Annotated[str, choice(METHODS, "method")] = "dynamic"
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
            method=self.method,
        )


#: The largest exaggeration of the 3D scene: a millimetre drawn as a kilometre.
MAX_SCENE_EXAGGERATION = 1e6


def _scene(value: Any) -> bool | float:
    """``scene = true | false | <exaggeration>``: the 3D scene on or off, or on with this exaggeration."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)) and math.isfinite(value) and 0 < value <= MAX_SCENE_EXAGGERATION:
        return float(value)
    raise fail("expected true, false or the deck displacement's exaggeration in the 3D scene, a number > 0 and "
               f"<= {MAX_SCENE_EXAGGERATION:g} (got {describe(value)})")


class OutputConfig(ConfigModel):
    """``[output]``: where the run's MCAP log (and an optional sensor CSV) go, the logging rate, the 3D scene.

    The rate is ``rate_hz`` (default :data:`DEFAULT_RATE_HZ`) or, for
    compatibility, ``every`` (keep every N-th step); not both. ``scene``: the
    log's 3D scene (:mod:`cosim.log.scene`) on or off, or on with a chosen
    exaggeration; unset, it is on for runs of at most an hour.
    """

    log: Annotated[str, Strict(), Field(min_length=1)] | None = None
    rate_hz: Positive | None = None
    every: PositiveInt | None = None
    csv: Annotated[str, Strict(), Field(min_length=1)] | None = None
    scene: Annotated[bool | float, PlainValidator(_scene)] | None = None

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
