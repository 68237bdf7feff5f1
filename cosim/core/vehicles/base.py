"""The vehicle-model interface (:class:`VehicleModel`), its contact points, and the layout of its compiled state.

A vehicle model is a frozen dataclass (parameters in SI units, validated in
``__post_init__``) deriving from :class:`VehicleModel`. What the rest of
cosim asks of it:

- the traffic sources: its contact points (:attr:`VehicleModel.contact_points`,
  each a distance behind the vehicle's reference point and an offset to the
  left of its path): one contact column per point;
- the coupled step (:mod:`cosim.core.coupling`): its compiled kind
  (:attr:`VehicleModel.kernel_kind`), its compiled parameters
  (:meth:`VehicleModel.pack`), its total mass and static axle loads, whether
  its tyres may leave the deck (:attr:`VehicleModel.unilateral`) and, for the
  ``LINEAR`` kind, its matrices (:meth:`VehicleModel.linear_system`);
- the logs: :meth:`VehicleModel.record` and :meth:`VehicleModel.from_record`
  (numbers only);
- the SUMO adapter: :meth:`VehicleModel.scaled` (the share one axle carries).

The compiled block loop calls, for each vehicle, the compiled functions of
its kind (docs/theory.md §6.2-6.5, (6.6)):

- ``coefficients``: from the Newmark predictors, the effective deck force
  ``E_i = e0_i - (c0 n0 + c1 n1 + c2 n2)_i . a`` (linear in the unknown
  bridge acceleration ``a``);
- ``update``: once ``a`` is known, the vehicle's new accelerations and forces.

Compiled state of one contact column (a column of ``vstate``, :data:`STATE_ROWS`):
body u, u', u''; wheel u, u', u''; suspension force; tyre force (the last two
are the HHT ``F_n`` of the vehicle). Parameters: a column of ``params``
(:data:`PARAM_ROWS` rows, the model's :meth:`~VehicleModel.pack` order, zeros after).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import fields, replace
from typing import Any, ClassVar, NamedTuple

import numpy as np

from ..checks import finite

#: Rows of a vehicle's compiled state: body u, u', u''; wheel u, u', u''; suspension force; tyre force.
STATE_ROWS = 8
#: Rows of a vehicle's compiled parameters (the longest ``pack()``).
PARAM_ROWS = 6
#: The kind ids the compiled loop dispatches on (``cosim.core.kernels``): MOVING_FORCE (the weight on each
#: contact, no physics of its own), the two one-contact models with their own compiled physics, and LINEAR:
#: any linear vehicle on tyres, with one or more contacts and bilateral or unilateral contact, given by its
#: matrices (``cosim.core.vehicles.linear``).
MOVING_FORCE, QUARTER_CAR, TYRE_QUARTER_CAR, LINEAR = 0, 1, 2, 3
#: Every kind id the compiled loop knows.
KERNEL_KINDS = (MOVING_FORCE, QUARTER_CAR, TYRE_QUARTER_CAR, LINEAR)


def check_positive(owner: str, **values: float) -> None:
    """Raise ConfigError unless every value is a finite number > 0 (``owner`` names the vehicle or model)."""
    for name, value in values.items():
        finite(value, name, f"{owner}: ", above=0.0)


def check_non_negative(owner: str, **values: float) -> None:
    """Raise ConfigError unless every value is a finite number >= 0."""
    for name, value in values.items():
        finite(value, name, f"{owner}: ", at_least=0.0)


class ContactPoint(NamedTuple):
    """Where a vehicle touches the road, relative to its reference point (its front contact).

    Attributes:
        behind: distance behind the reference point along the path, m (>= 0; the front contact is at 0).
        left: offset to the left of the vehicle's path (looking where it drives), m; 0 on the path.
    """

    behind: float
    left: float = 0.0


#: The contact points of a one-contact model: its reference point itself.
ONE_CONTACT = (ContactPoint(0.0, 0.0),)


class VehicleModel(ABC):
    """The interface of every vehicle model (module docstring; docs/architecture.md, "Adding a vehicle model").

    A model is a frozen dataclass deriving from this class, with the class
    attributes ``kind`` (its name in logs) and ``KIND`` (the compiled kind id,
    one of :data:`KERNEL_KINDS`), and :attr:`total_mass` and :meth:`pack`.
    The rest has defaults for one contact point on the path, bilateral contact
    and no matrices of its own.
    """

    #: The model's name in logs (``/cosim/vehicle_types``) and its registry entry.
    kind: ClassVar[str]
    #: The kind id the compiled loop dispatches on (:data:`KERNEL_KINDS`).
    KIND: ClassVar[int]
    #: Whether its tyres may leave the deck (unilateral contact; LINEAR kind only).
    unilateral: bool = False
    #: Set by ``@dataclass`` on every model (declared so that type checkers know a model is a dataclass).
    __dataclass_fields__: ClassVar[dict[str, Any]]

    @property
    @abstractmethod
    def total_mass(self) -> float:
        """The vehicle's mass, kg."""

    @abstractmethod
    def pack(self) -> tuple[float, ...]:
        """The compiled parameters of each of its contact columns (at most :data:`PARAM_ROWS` numbers)."""

    @property
    def kernel_kind(self) -> int:
        """The kind id the compiled loop dispatches on (``KIND`` unless the model switches kinds)."""
        return self.KIND

    @property
    def contact_points(self) -> tuple[ContactPoint, ...]:
        """Where it touches the road, front first: one contact column each (:class:`ContactPoint`)."""
        return ONE_CONTACT

    @property
    def contacts(self) -> int:
        """How many contact points (columns) it has."""
        return len(self.contact_points)

    @property
    def contact_offsets(self) -> tuple[float, ...]:
        """Each contact point's distance behind the reference point, m."""
        return tuple(p.behind for p in self.contact_points)

    def linear_system(self, gravity: float) -> dict[str, np.ndarray] | None:
        """Its matrices as a linear vehicle on tyres (the LINEAR kind: ``cosim.core.vehicles.linear``), or None.

        Returns ``mv, cv, kv`` (nz, nz), ``b`` (contacts, nz: the vehicle point on each tyre), ``k_t, c_t``
        (contacts,), ``loads`` (the static axle loads, N) and ``obs`` (contacts, nz: the body's motion
        reported above each contact).
        """
        return None

    def static_axle_loads(self, gravity: float) -> np.ndarray:
        """The force on each contact point at rest on a rigid, level road, N (compression positive; sum: the
        weight). One contact carries the weight; a linear vehicle's come from its matrices; a model with
        several contacts and no matrices must say."""
        system = self.linear_system(gravity)
        if system is not None:
            return np.asarray(system["loads"], dtype=float)
        if self.contacts == 1:
            return np.array([self.total_mass * gravity])
        raise NotImplementedError(f"{type(self).__name__}: a model on several contacts without a linear system "
                                  "must define static_axle_loads")

    def record(self) -> dict[str, float]:
        """The model as numbers only (for logs): its dataclass fields."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_record(cls, values: dict[str, Any]) -> VehicleModel:
        """The inverse of :meth:`record` (values already checked to be numbers)."""
        return cls(**values)

    def scaled(self, share: float) -> VehicleModel:
        """The part one of several independent axles carries: its masses, stiffnesses and dampings times
        ``share`` (every number; switches stay). A model with other numbers (lengths) overrides this."""
        numbers = {f.name: getattr(self, f.name) * share for f in fields(self)
                   if isinstance(getattr(self, f.name), float | int) and not isinstance(getattr(self, f.name), bool)}
        return replace(self, **numbers)
