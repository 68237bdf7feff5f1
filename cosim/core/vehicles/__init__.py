"""Vehicle models behind one registry (docs/theory.md §5).

Every model is "one contact point" today: its displacements are measured
from its static equilibrium on a rigid, smooth road, gravity acts as the
constant load ``m g`` on the deck, and the contact force ``P`` is the force
the wheel presses on the deck (compression positive). ``P < 0`` means the
wheel would lift off: it is counted and reported; the contact is kept
(bilateral), as in the paper.

- :class:`MovingForce`: ``P = m g``, no inertia (the classical benchmark).
- :class:`QuarterCar`: the paper's model (rigid wheel-deck contact).
- :class:`TyreQuarterCar`: the wheel on a tyre spring and damper (bilateral, or
  unilateral: the tyre may leave the deck and land again).
- :class:`HalfCar`: a body that bounces and pitches on any number of axles
  (:class:`Axle`), one contact point per axle (an axle group).

Adding a model: a module here with the frozen dataclass (``kind`` name,
``KIND`` id from :mod:`.base`, ``pack()``, ``total_mass``) and its compiled
``coefficients``/``update``; its entry in :data:`MODELS`; its branch in the
block loop's dispatch (``cosim.core.kernels``); and its tests
(``tests/unit/test_vehicles.py`` runs every registered model through the
compiled step).
"""
from __future__ import annotations

from dataclasses import asdict
from typing import Any, Union

from cosim.errors import ConfigError

from .base import PARAM_ROWS, STATE_ROWS
from .half_car import Axle, HalfCar
from .moving_force import MovingForce
from .quarter_car import QuarterCar
from .tyre_quarter_car import TyreQuarterCar

VehicleModel = Union[MovingForce, QuarterCar, TyreQuarterCar, HalfCar]

#: Every vehicle model by its name (the ``model`` key of scenarios and logs).
MODELS: dict[str, type] = {cls.kind: cls for cls in (MovingForce, QuarterCar, TyreQuarterCar, HalfCar)}
MODEL_NAMES: tuple[str, ...] = tuple(MODELS)

__all__ = [
    "Axle",
    "HalfCar",
    "MODELS",
    "MODEL_NAMES",
    "PARAM_ROWS",
    "STATE_ROWS",
    "MovingForce",
    "QuarterCar",
    "TyreQuarterCar",
    "VehicleModel",
    "model_from_dict",
    "model_to_dict",
]


def model_to_dict(model: VehicleModel) -> dict[str, float | str]:
    """A plain description of a vehicle model (for logs): ``{"model": kind, <parameters as numbers>}``."""
    record = model.record() if hasattr(model, "record") else asdict(model)
    return {"model": model.kind, **record}


def model_from_dict(data: dict[str, Any]) -> VehicleModel:
    """Rebuild a vehicle model from :func:`model_to_dict`'s output (numbers only; validated)."""
    kind = data.get("model")
    if kind not in MODELS:
        raise ConfigError(f"unknown vehicle model {kind!r} (expected one of: {', '.join(MODELS)})")
    params = {k: v for k, v in data.items() if k != "model"}
    for key, value in params.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ConfigError(f"vehicle model parameter `{key}` must be a number (got {value!r})")
    try:
        cls = MODELS[kind]
        return cls.from_record(params) if hasattr(cls, "from_record") else cls(**params)
    except TypeError as exc:
        raise ConfigError(f"vehicle model {kind}: {exc}") from None
