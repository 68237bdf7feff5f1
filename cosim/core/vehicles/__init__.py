"""Vehicle models: one interface, one registry (docs/theory.md §5, §11; docs/architecture.md).

Every model derives from :class:`VehicleModel` (:mod:`.base`): its contact
points (a distance behind its reference point and an offset to the left of
its path each), compiled kind, mass, static axle loads, compiled parameters,
record for logs, unilateral contact or not, and optional linear matrices.
Displacements are measured from static equilibrium on a rigid, smooth road,
gravity acts as the constant static axle loads on the deck, and a contact
force ``P`` is the force a wheel presses on the deck (compression positive).
``P < 0`` means the wheel would lift off: it is counted and reported; the
contact is kept (bilateral, as in the paper) unless the model's tyres may
leave the deck (unilateral).

- :class:`MovingForce`: ``P = m g``, no inertia (the classical benchmark).
- :class:`QuarterCar`: the paper's model (rigid wheel-deck contact).
- :class:`TyreQuarterCar`: the wheel on a tyre spring and damper (bilateral, or
  unilateral: the tyre may leave the deck and land again); ``golden-car`` is
  its preset with the IRI reference ratios.
- :class:`HalfCar`: a body that bounces and pitches on any number of axles
  (:class:`Axle`), one contact point per axle (an axle group).

Each model's module defines its class and its registry entry (``SPEC``:
:class:`ModelSpec`, :mod:`.registry`); they are registered here, in the order
every list of models shows them. Adding a model: docs/architecture.md,
"Adding a vehicle model".
"""
from __future__ import annotations

from . import half_car, moving_force, quarter_car, tyre_quarter_car
from .base import (
    KERNEL_KINDS,
    LINEAR,
    MOVING_FORCE,
    PARAM_ROWS,
    QUARTER_CAR,
    STATE_ROWS,
    TYRE_QUARTER_CAR,
    ContactPoint,
    VehicleModel,
    check_non_negative,
    check_positive,
)
from .half_car import Axle, HalfCar
from .moving_force import MovingForce
from .quarter_car import QuarterCar
from .registry import (
    LIBRARY,
    MODELS,
    REQUIRED,
    ModelSpec,
    Parameter,
    VTypeInputs,
    VTypeRecipe,
    markdown_tables,
    model_classes,
    model_from_dict,
    model_to_dict,
    register,
    registered,
    spec_of,
    unregister,
)
from .tyre_quarter_car import TyreQuarterCar

for _spec in (moving_force.SPEC, quarter_car.SPEC, tyre_quarter_car.SPEC, tyre_quarter_car.GOLDEN_CAR,
              half_car.SPEC):
    register(_spec)
del _spec

__all__ = [
    "Axle",
    "ContactPoint",
    "HalfCar",
    "KERNEL_KINDS",
    "LIBRARY",
    "LINEAR",
    "MODELS",
    "MOVING_FORCE",
    "ModelSpec",
    "MovingForce",
    "PARAM_ROWS",
    "Parameter",
    "QUARTER_CAR",
    "QuarterCar",
    "REQUIRED",
    "STATE_ROWS",
    "TYRE_QUARTER_CAR",
    "TyreQuarterCar",
    "VTypeInputs",
    "VTypeRecipe",
    "VehicleModel",
    "check_non_negative",
    "check_positive",
    "markdown_tables",
    "model_classes",
    "model_from_dict",
    "model_to_dict",
    "register",
    "registered",
    "spec_of",
    "unregister",
]
