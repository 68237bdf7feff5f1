"""The moving force: a constant vertical force ``m g`` travelling with the vehicle (the classical benchmark).

No inertia and no suspension: its compiled functions are the block loop's
defaults (``E = -m g`` on the deck), so it needs none of its own.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from .base import MOVING_FORCE, VehicleModel, check_positive
from .registry import ModelSpec, Parameter, VTypeInputs, VTypeRecipe


@dataclass(frozen=True)
class MovingForce(VehicleModel):
    """A constant vertical force ``mass * g`` moving with the vehicle.

    Args:
        mass: total mass, kg.
    """

    mass: float
    kind: ClassVar[str] = "moving-force"
    KIND: ClassVar[int] = MOVING_FORCE

    def __post_init__(self) -> None:
        check_positive("moving force", mass=self.mass)

    @property
    def total_mass(self) -> float:
        """kg."""
        return float(self.mass)

    def pack(self) -> tuple[float, ...]:
        """Compiled parameters: none."""
        return ()


def _from_table(values: Mapping[str, Any], unilateral: bool) -> MovingForce:
    return MovingForce(mass=values["mass"])


def _from_vtype(vtype: VTypeInputs) -> MovingForce:
    return MovingForce(vtype.mass)


SPEC = ModelSpec(
    name=MovingForce.kind, cls=MovingForce,
    doc="a constant force `mass * g`, no inertia (the classical benchmark)",
    parameters=(Parameter("mass", "kg", "the vehicle's mass", above=0.0),),
    build=_from_table, example=MovingForce(9000.0),
    vtype=VTypeRecipe(parameters=(), build=_from_vtype),
)
