"""Virtual sensors on the deck: what they measure and the one row that reads it from the bridge's DOFs.

A sensor reads ``s = r . d`` (or ``r . d'``, ``r . d''``) with ``r`` its row:
the vertical displacement of the deck point ``(x, y)`` (bending and twist,
``w = w_S + (y - y_S) theta_x``, docs/theory.md §1.4), or the vertical bending
moment of the section at ``x``. The time integration, the quasi-static
response and the static load cases all use :func:`sensor_row`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from cosim.errors import ConfigError

from .bridge import BridgeModel
from .element import DeckRow

#: Sensor quantities and their SI units.
SENSOR_UNITS: dict[str, str] = {
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "bending_moment": "N m",
}
SENSOR_QUANTITIES: tuple[str, ...] = tuple(SENSOR_UNITS)
#: Which time derivative of the bridge's DOFs a quantity reads (0: d, 1: d', 2: d'').
TIME_DERIVATIVE: dict[str, int] = {"displacement": 0, "velocity": 1, "acceleration": 2, "bending_moment": 0}


@dataclass(frozen=True)
class Sensor:
    """A virtual sensor on the deck.

    Args:
        name: channel name.
        x, y: position on the deck, m (y is ignored for the bending moment).
        quantity: displacement (m) | velocity (m/s) | acceleration (m/s^2) of
            the deck point, vertical, twist included; or bending_moment (N m,
            sagging positive) of the section at x.

    Raises:
        ConfigError: an unknown quantity or a non-finite position.
    """

    name: str
    x: float
    y: float = 0.0
    quantity: str = "displacement"

    def __post_init__(self) -> None:
        if self.quantity not in SENSOR_QUANTITIES:
            raise ConfigError(f"sensor {self.name}: `quantity` must be one of {', '.join(SENSOR_QUANTITIES)} "
                              f"(got {self.quantity!r})")
        for key in ("x", "y"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ConfigError(f"sensor {self.name}: `{key}` must be a finite number, m (got {value!r})")

    @property
    def unit(self) -> str:
        """SI unit of the reading."""
        return SENSOR_UNITS[self.quantity]


def check_sensor_on(bridge: BridgeModel, sensor: Sensor) -> None:
    """Raise :class:`ConfigError` unless the sensor lies on the bridge's deck (0 <= x <= L, y on the deck)."""
    length = bridge.length
    y_min, y_max = bridge.section.deck_y
    tol_x = 1e-9 * length
    tol_y = 1e-9 * max(y_max - y_min, 1.0)
    if not -tol_x <= sensor.x <= length + tol_x:
        raise ConfigError(f"sensor {sensor.name}: `x` must lie on the bridge, 0 <= x <= {length:g} m "
                          f"(got {sensor.x:g}); move the sensor or use this bridge's length")
    if sensor.quantity != "bending_moment" and not y_min - tol_y <= sensor.y <= y_max + tol_y:
        raise ConfigError(f"sensor {sensor.name}: `y` must lie on the deck, {y_min:g} <= y <= {y_max:g} m "
                          f"(got {sensor.y:g})")


def sensor_row(bridge: BridgeModel, sensor: Sensor) -> DeckRow:
    """The row of element DOFs the sensor reads (``values[0]``; apply it to d, d' or d'' by :data:`TIME_DERIVATIVE`)."""
    name = "bending_moment" if sensor.quantity == "bending_moment" else "w_deck"
    return bridge.field_row(name, sensor.x, sensor.y)
