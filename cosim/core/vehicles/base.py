"""What every vehicle model shares: parameter checks and the layout of its compiled state.

A vehicle model is a frozen dataclass (parameters in SI units, validated in
``__post_init__``) plus two compiled functions of its module that the block
loop calls for each of its vehicles (docs/theory.md §6.2-6.5, (6.6)):

- ``coefficients``: from the Newmark predictors, the effective deck force
  ``E_i = e0_i - (c0 n0 + c1 n1 + c2 n2)_i . a`` (linear in the unknown
  bridge acceleration ``a``);
- ``update``: once ``a`` is known, the vehicle's new accelerations and forces.

Compiled state of one vehicle (a column of ``vstate``, :data:`STATE_ROWS`):
body u, u', u''; wheel u, u', u''; suspension force; tyre force (the last two
are the HHT ``F_n`` of the vehicle). Parameters: a column of ``params``
(:data:`PARAM_ROWS` rows, the model's :meth:`pack` order, zeros after).
"""
from __future__ import annotations

from typing import ClassVar

from ..checks import finite

#: Rows of a vehicle's compiled state: body u, u', u''; wheel u, u', u''; suspension force; tyre force.
STATE_ROWS = 8
#: Rows of a vehicle's compiled parameters (the longest ``pack()``).
PARAM_ROWS = 6
#: The kind ids the compiled loop dispatches on (see ``cosim.core.vehicles.MODELS``): the three one-contact
#: models with their own compiled physics, and LINEAR: any linear vehicle on tyres, with one or more contacts
#: and bilateral or unilateral contact (``cosim.core.vehicles.linear``).
MOVING_FORCE, QUARTER_CAR, TYRE_QUARTER_CAR, LINEAR = 0, 1, 2, 3


def check_positive(owner: str, **values: float) -> None:
    """Raise ConfigError unless every value is a finite number > 0 (``owner`` names the vehicle or model)."""
    for name, value in values.items():
        finite(value, name, f"{owner}: ", above=0.0)


def check_non_negative(owner: str, **values: float) -> None:
    """Raise ConfigError unless every value is a finite number >= 0."""
    for name, value in values.items():
        finite(value, name, f"{owner}: ", at_least=0.0)


class OneContact:
    """What a one-contact-point model shares: its contact is the vehicle's reference point (no axles behind it)."""

    KIND: ClassVar[int]
    contacts: ClassVar[int] = 1
    contact_offsets: ClassVar[tuple[float, ...]] = (0.0,)

    @property
    def kernel_kind(self) -> int:
        """The kind id the compiled loop dispatches on."""
        return self.KIND
