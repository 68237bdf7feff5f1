"""The one registry of vehicle models: each model's name, class, parameters and builders (docs/architecture.md).

A :class:`ModelSpec` says everything the layers above the core need to know
about a model: its parameters (:class:`Parameter`: name, unit, default,
constraint, doc), how a scenario's ``[[vehicles]]`` table builds it
(``build``), whether it has a tyre (``contact = "unilateral"``), how a SUMO
vType's ``cosim.*`` params build it (:class:`VTypeRecipe`, or None) and an
example. :func:`register` adds one; :data:`MODELS` holds them by name, in
the order they were registered (the order of every list of models in
messages and docs). The scenario tables (:mod:`cosim.run.tables`), the vType
params (:mod:`cosim.sumo.vtypes`), the logs (:func:`model_from_dict`) and the
docs' tables (:func:`markdown_tables`) all read it.

A registered name is a model class (its ``kind``) or a preset of one
(``golden-car``: a tyre quarter-car with the IRI reference ratios); logs name
the class.
"""
from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from cosim.errors import ConfigError

from .base import KERNEL_KINDS, VehicleModel


class _Sentinel:
    """A default that is not a value."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __repr__(self) -> str:
        return self.name


#: The default of a parameter that must be given.
REQUIRED: Any = _Sentinel("REQUIRED")
#: The default of a vType param taken from the vClass's library suspension (cosim.sumo.library): ``m_w`` as
#: its unsprung share of the gross mass, ``k_v``, ``c_v``, ``k_t``, ``c_t`` per kg of body.
LIBRARY: Any = _Sentinel("LIBRARY")
#: Parameter kinds: a number (float), a flag (true/false), an array of tables (each with ``fields``).
KINDS = ("number", "flag", "tables")


@dataclass(frozen=True)
class Parameter:
    """One parameter of a vehicle model (a ``[[vehicles]]`` key, a vType ``cosim.*`` param, or a key of a table).

    Attributes:
        name: the key.  unit: its SI unit ("" for flags and tables).  doc: what it is, for the docs.
        default: its value when not given, or :data:`REQUIRED` (or :data:`LIBRARY` for a vType param).
        above, at_least: the bound a number must keep (``> above``, ``>= at_least``); the model class
            checks it (a test holds the two together), the table keys of ``tables`` are checked by it.
        note: more of the constraint, in words (e.g. "> 0 with pitch").
        kind: "number", "flag" or "tables" (an array of tables, each with the keys ``fields``).
    """

    name: str
    unit: str
    doc: str
    default: Any = REQUIRED
    above: float | None = None
    at_least: float | None = None
    note: str = ""
    kind: str = "number"
    fields: tuple[Parameter, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ConfigError(f"parameter {self.name}: kind must be one of {', '.join(KINDS)} (got {self.kind!r})")
        if (self.kind == "tables") != bool(self.fields):
            raise ConfigError(f"parameter {self.name}: an array of tables (kind 'tables') and only it has fields")

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    @property
    def constraint(self) -> str:
        """The constraint in words: "> 0", ">= 0", and the note."""
        bound = f"> {self.above:g}" if self.above is not None else \
            f">= {self.at_least:g}" if self.at_least is not None else ""
        return ", ".join(part for part in (bound, self.note) if part)


@dataclass(frozen=True)
class VTypeInputs:
    """What a SUMO vType gives a model's :attr:`VTypeRecipe.build` (plain values; cosim.sumo.vtypes reads them).

    Attributes:
        type_id: the vType id (for messages).  mass: its gross mass, kg.
        values: each param of the recipe: given, else its default (:data:`LIBRARY`: the vClass's suspension
            at this mass), None for an optional one without a default.
        unilateral: ``cosim.contact = unilateral`` (models with a tyre).
        axles: (distance behind the front bumper m, share of the load) per axle, front first.
        length: the vehicle's length, m.
    """

    type_id: str
    mass: float
    values: Mapping[str, Any]
    unilateral: bool
    axles: tuple[tuple[float, float], ...]
    length: float


@dataclass(frozen=True)
class VTypeRecipe:
    """How a vType's ``cosim.*`` params describe a model (docs/sumo.md).

    Attributes:
        parameters: the params it reads besides ``cosim.model``, ``cosim.axles``, ``cosim.axle_loads`` and
            (with a tyre) ``cosim.contact``; kinds "number" and "flag".
        build: the model of the whole vehicle (raises ConfigError for values that are not physical).
        one_body: one model on all the vType's axles (their positions are its contact points), which are the
            library's axles unless ``cosim.axles`` gives them; False: a model carried by each axle (its share),
            one at mid-length unless ``cosim.axles`` gives them.
    """

    parameters: tuple[Parameter, ...]
    build: Callable[[VTypeInputs], VehicleModel]
    one_body: bool = False


@dataclass(frozen=True)
class ModelSpec:
    """A registered vehicle model (module docstring).

    Attributes:
        name: the ``model`` of ``[[vehicles]]`` and ``cosim.model`` of vTypes.
        cls: its class (a :class:`~cosim.core.vehicles.base.VehicleModel`).
        doc: what it is, one paragraph (the docs' table).
        parameters: its ``[[vehicles]]`` keys, in the order the docs and messages list them.
        build: ``build(values, unilateral)``: the model from its keys (defaults filled in; an array of tables
            as a tuple of dicts) and the ``contact`` key; raises ConfigError naming a key in backticks.
        example: a typical instance (tests run every registered model through the compiled step).
        tyre: whether it takes ``contact = "unilateral"``.
        vtype: how a SUMO vType builds it, or None (not available from SUMO).
    """

    name: str
    cls: type[VehicleModel]
    doc: str
    parameters: tuple[Parameter, ...]
    build: Callable[[Mapping[str, Any], bool], VehicleModel]
    example: VehicleModel
    tyre: bool = False
    vtype: VTypeRecipe | None = None
    _by_name: dict[str, Parameter] = field(init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        self._by_name.update({p.name: p for p in self.parameters})

    def parameter(self, name: str) -> Parameter:
        """The parameter called ``name`` (KeyError if it has none)."""
        return self._by_name[name]

    @property
    def names(self) -> tuple[str, ...]:
        """Its parameters' names: required first, then optional (the order of messages)."""
        return tuple(p.name for p in self.parameters if p.required) + \
            tuple(p.name for p in self.parameters if not p.required)

    @property
    def preset(self) -> bool:
        """A preset of another model's class (logs name the class)."""
        return self.name != self.cls.kind


#: Every registered vehicle model by its name, in registration order (``cosim.VEHICLE_MODELS``).
MODELS: dict[str, ModelSpec] = {}


def register(spec: ModelSpec) -> ModelSpec:
    """Add a vehicle model to the registry (once per name).

    Raises:
        ConfigError: the name is taken, or the spec does not describe a usable model.
    """
    if not isinstance(spec, ModelSpec):
        raise ConfigError(f"register: expected a ModelSpec (got {type(spec).__name__})")
    if spec.name in MODELS:
        raise ConfigError(f"vehicle model {spec.name!r} is registered already")
    if not (isinstance(spec.cls, type) and issubclass(spec.cls, VehicleModel)):
        raise ConfigError(f"vehicle model {spec.name}: its class must derive from VehicleModel")
    if not isinstance(spec.example, spec.cls):
        raise ConfigError(f"vehicle model {spec.name}: its example must be a {spec.cls.__name__}")
    if spec.example.kernel_kind not in KERNEL_KINDS:
        raise ConfigError(f"vehicle model {spec.name}: kernel kind {spec.example.kernel_kind} is not one the "
                          f"compiled loop knows ({', '.join(map(str, KERNEL_KINDS))})")
    if spec.cls.kind != spec.name and spec.cls.kind not in MODELS:
        raise ConfigError(f"vehicle model {spec.name}: a preset of {spec.cls.kind!r}, which is not registered")
    MODELS[spec.name] = spec
    return spec


def unregister(name: str) -> None:
    """Remove a vehicle model (and nothing else) from the registry."""
    MODELS.pop(name, None)


@contextlib.contextmanager
def registered(spec: ModelSpec) -> Iterator[ModelSpec]:
    """The model registered for the duration of a ``with`` block (tests)."""
    register(spec)
    try:
        yield spec
    finally:
        unregister(spec.name)


def model_classes() -> dict[str, type[VehicleModel]]:
    """The registered model classes by ``kind`` (the names logs use; presets share their class's)."""
    return {spec.name: spec.cls for spec in MODELS.values() if not spec.preset}


def spec_of(model: VehicleModel) -> ModelSpec:
    """The registry entry of a model's class."""
    spec = MODELS.get(type(model).kind)
    if spec is None:
        raise ConfigError(f"unknown vehicle model {type(model).kind!r} (expected one of: {', '.join(MODELS)})")
    return spec


def model_to_dict(model: VehicleModel) -> dict[str, float | str]:
    """A plain description of a vehicle model (for logs): ``{"model": kind, <parameters as numbers>}``."""
    return {"model": model.kind, **model.record()}


def model_from_dict(data: dict[str, Any]) -> VehicleModel:
    """Rebuild a vehicle model from :func:`model_to_dict`'s output (numbers only; validated)."""
    kind = data.get("model")
    classes = model_classes()
    if kind not in classes:
        raise ConfigError(f"unknown vehicle model {kind!r} (expected one of: {', '.join(classes)})")
    params = {k: v for k, v in data.items() if k != "model"}
    for key, value in params.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ConfigError(f"vehicle model parameter `{key}` must be a number (got {value!r})")
    try:
        return classes[kind].from_record(params)
    except TypeError as exc:
        raise ConfigError(f"vehicle model {kind}: {exc}") from None


# ----------------------------------------------------------------------- docs
#: The lines around a generated table in the docs (a test holds what lies between them equal to the registry).
DOCS_BEGIN = "<!-- generated from the vehicle-model registry (cosim.core.vehicles): do not edit by hand -->"
DOCS_END = "<!-- end of the generated table -->"


def cell(text: str) -> str:
    """Text for a Markdown table cell."""
    return text.replace("|", "\\|").replace("\n", " ")


def parameter_text(p: Parameter) -> str:
    """A parameter as the docs' tables list it: "`c_t` (N s/m, >= 0, default `0.0`)"."""
    kind = {"flag": "boolean", "tables": "array of tables, below"}.get(p.kind, "")
    shown = ""
    if not p.required and p.default is not LIBRARY and p.default is not None:
        value = ("true" if p.default else "false") if isinstance(p.default, bool) else repr(p.default)
        shown = f"default `{value}`"
    what = ", ".join(part for part in (kind, p.unit, p.constraint, shown) if part)
    return f"`{p.name}`" + (f" ({what})" if what else "")


def markdown_tables() -> str:
    """The docs' tables of the registered models' ``[[vehicles]]`` keys (docs/scenario.md)."""
    lines = ["| `model` | parameters | `contact` | what |", "|---|---|---|---|"]
    for spec in MODELS.values():
        params = ", ".join(parameter_text(p) for p in spec.parameters)
        contact = "`bilateral` or `unilateral`" if spec.tyre else "`bilateral`"
        lines.append(f"| `{spec.name}` | {cell(params)} | {contact} | {cell(spec.doc)} |")
    for spec in MODELS.values():
        for p in spec.parameters:
            if p.kind != "tables":
                continue
            lines += ["", f"Each entry of `{p.name}` of `{spec.name}` ({cell(p.doc)}):", "",
                      "| key | unit | default | constraints | what |", "|---|---|---|---|---|"]
            for f in p.fields:
                default = "**required**" if f.required else f"`{f.default!r}`"
                lines.append(f"| `{f.name}` | {f.unit} | {default} | {cell(f.constraint)} | {cell(f.doc)} |")
    return "\n".join(lines)
