"""The moving force: a constant vertical force ``m g`` travelling with the vehicle (the classical benchmark).

No inertia and no suspension: its compiled functions are the block loop's
defaults (``E = -m g`` on the deck), so it needs none of its own.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .base import MOVING_FORCE, OneContact, check_positive


@dataclass(frozen=True)
class MovingForce(OneContact):
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
