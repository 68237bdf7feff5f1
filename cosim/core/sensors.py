"""Virtual sensors on the deck: what they measure and the one row that reads it from the bridge's DOFs.

A sensor reads ``s = r . d`` (or ``r . d'``, ``r . d''``) with ``r`` its row:
the vertical displacement of the deck point ``(x, y)`` (bending and twist,
``w = w_S + (y - y_S) theta_x``, docs/theory.md §1.4), the vertical bending
moment of the section at ``x``, or the strain or a stress at the section
point ``(y, z)`` of the section at ``x`` (docs/theory.md §12). The time
integration, the quasi-static response and the static load cases all use
:func:`sensor_row`; a stress is one more row, so the compiled loop reads it
like any other channel.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cosim.errors import ConfigError

from .checks import finite, one_of
from .element import DeckRow

if TYPE_CHECKING:  # its module loads scipy, which reading a log's sensors does not need
    from .bridge import BridgeModel

#: Sensor quantities and their SI units.
SENSOR_UNITS: dict[str, str] = {
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "bending_moment": "N m",
    "stress": "Pa",
    "strain": "1",
    "shear_stress_xy": "Pa",
    "shear_stress_xz": "Pa",
}
SENSOR_QUANTITIES: tuple[str, ...] = tuple(SENSOR_UNITS)
#: Which time derivative of the bridge's DOFs a quantity reads (0: d, 1: d', 2: d'').
TIME_DERIVATIVE: dict[str, int] = {"displacement": 0, "velocity": 1, "acceleration": 2, "bending_moment": 0,
                                   "stress": 0, "strain": 0, "shear_stress_xy": 0, "shear_stress_xz": 0}
#: Quantities read at a point (y, z) of the section rather than at a deck point (x, y).
SECTION_POINT_QUANTITIES: tuple[str, ...] = ("stress", "strain", "shear_stress_xy", "shear_stress_xz")
#: Shear stress quantities: which component of (tau_xy, tau_xz).
SHEAR_COMPONENT: dict[str, int] = {"shear_stress_xy": 0, "shear_stress_xz": 1}


@dataclass(frozen=True)
class Sensor:
    """A virtual sensor on the deck.

    Args:
        name: channel name.
        x, y: position on the deck, m (y is ignored for the bending moment).
        quantity: displacement (m) | velocity (m/s) | acceleration (m/s^2) of
            the deck point, vertical, twist included; bending_moment (N m,
            sagging positive) of the section at x; stress (normal stress
            sigma_x, Pa, tension positive) | strain (eps_x, 1) |
            shear_stress_xy | shear_stress_xz (Pa) at the section point (y, z)
            of the section at x (docs/theory.md §12).
        z: vertical coordinate of the section point, m, in the frame the
            section is drawn in; required by the section-point quantities.
        omega: the principal sectorial coordinate at (y, z), m^2 (docs/theory.md
            (1.3)), for a section given by constants with warping (``I_w > 0``),
            where cosim has no warping function; a section of plates computes it.
        every: read only at the steps whose index from the run's start (t = 0) is a multiple
            of ``every``, NaN at the others: a drawing that needs a few samples per second
            (the log's 3D scene) then costs a few rows, not one per step.

    Raises:
        ConfigError: an unknown quantity, a non-finite position, z missing, or ``every`` not an integer >= 1.
    """

    name: str
    x: float
    y: float = 0.0
    quantity: str = "displacement"
    z: float | None = None
    omega: float | None = None
    every: int = 1

    def __post_init__(self) -> None:
        if isinstance(self.every, bool) or not isinstance(self.every, int) or self.every < 1:
            raise ConfigError(f"sensor {self.name}: `every` must be an integer >= 1 (got {self.every!r})")
        one_of(self.quantity, SENSOR_QUANTITIES, "quantity", f"sensor {self.name}: ")
        for key in ("x", "y"):
            finite(getattr(self, key), key, f"sensor {self.name}: ", unit="m")
        for key in ("z", "omega"):
            value = getattr(self, key)
            if value is not None:
                finite(value, key, f"sensor {self.name}: ", unit="m")
        if self.on_section:
            if self.z is None:
                raise ConfigError(f"sensor {self.name}: quantity = {self.quantity!r} is read at a point (y, z) of "
                                  "the section: give `z`, m, in the frame the section is drawn in")
        else:
            for key in ("z", "omega"):
                if getattr(self, key) is not None:
                    raise ConfigError(f"sensor {self.name}: `{key}` is only used by the quantities "
                                      f"{', '.join(SECTION_POINT_QUANTITIES)} (got quantity = {self.quantity!r})")

    @property
    def unit(self) -> str:
        """SI unit of the reading."""
        return SENSOR_UNITS[self.quantity]

    @property
    def on_section(self) -> bool:
        """Whether the sensor reads at a point (y, z) of the section (a stress or a strain)."""
        return self.quantity in SECTION_POINT_QUANTITIES


def check_sensor_on(bridge: BridgeModel, sensor: Sensor) -> None:
    """Raise :class:`ConfigError` unless the sensor lies on the bridge (0 <= x <= L; y on the deck, or (y, z) in
    the section for stresses and strains) and the bridge's section can give what it reads."""
    length = bridge.length
    y_min, y_max = bridge.section.deck_y
    tol_x = 1e-9 * length
    tol_y = 1e-9 * max(y_max - y_min, 1.0)
    if not -tol_x <= sensor.x <= length + tol_x:
        raise ConfigError(f"sensor {sensor.name}: `x` must lie on the bridge, 0 <= x <= {length:g} m "
                          f"(got {sensor.x:g}); move the sensor or use this bridge's length")
    if sensor.quantity in SHEAR_COMPONENT:
        _shear_field(bridge, sensor)
    elif sensor.on_section:
        section_point_omega(bridge, sensor)
    elif sensor.quantity != "bending_moment" and not y_min - tol_y <= sensor.y <= y_max + tol_y:
        raise ConfigError(f"sensor {sensor.name}: `y` must lie on the deck, {y_min:g} <= y <= {y_max:g} m "
                          f"(got {sensor.y:g})")


def section_point_omega(bridge: BridgeModel, sensor: Sensor) -> float:
    """The sectorial coordinate at the sensor's point (y, z), m^2 (docs/theory.md §12.3).

    A section of plates interpolates its warping function there (and checks
    that the point lies in the section); a section of constants takes the
    sensor's ``omega``, which it needs when the section warps (``I_w > 0``);
    without warping the bimoment term vanishes and ``omega`` is 0.

    Raises:
        ConfigError: the point is outside the section; or the section is given by
            constants with ``I_w > 0`` and the sensor has no ``omega``; or it has
            one although the plates give it.
    """
    assert sensor.z is not None
    field = bridge.section.stress_field
    if field is not None:
        if sensor.omega is not None:
            raise ConfigError(f"sensor {sensor.name}: `omega` is computed from the section's plates; remove it")
        try:
            return field.omega_at(sensor.y, sensor.z)
        except ConfigError as exc:
            raise ConfigError(f"sensor {sensor.name}: {exc}; give (y, z) in the frame the section's plates are "
                              "drawn in") from None
    if sensor.omega is not None:
        return float(sensor.omega)
    if bridge.section.I_w > 0:
        raise ConfigError(
            f"sensor {sensor.name}: the section is given by constants with warping (I_w > 0), so cosim does not "
            "know its warping function: give `omega`, the principal sectorial coordinate at (y, z) in m^2 "
            "(docs/theory.md §12.3), or describe the section by plates")
    return 0.0


def _shear_field(bridge: BridgeModel, sensor: Sensor) -> np.ndarray:
    """(3, 2) shear stresses per unit St Venant torque, V_y and V_z at the sensor's point."""
    field = bridge.section.stress_field
    if field is None:
        raise ConfigError(f"sensor {sensor.name}: quantity = {sensor.quantity!r} needs the section's shear stress "
                          "field, which only a section of plates has (the constants give no geometry)")
    assert sensor.z is not None
    return field.shear_at(sensor.y, sensor.z)


def sensor_row(bridge: BridgeModel, sensor: Sensor) -> DeckRow:
    """The row of element DOFs the sensor reads (``values[0]``; apply it to d, d' or d'' by :data:`TIME_DERIVATIVE`).

    Stresses and strains (docs/theory.md §12): ``strain`` is the row of
    ``eps_x`` at (y, z); ``stress`` is ``E eps_x`` (uniaxial, the beam theory's
    normal stress); ``shear_stress_xy``/``_xz`` combine the rows of the St Venant
    torque and the two shear forces with the section's stresses per unit force
    at the point.
    """
    q = sensor.quantity
    if q == "bending_moment":
        return bridge.field_row("bending_moment", sensor.x)
    if q in ("stress", "strain"):
        assert sensor.z is not None
        row = bridge.field_row("normal_strain", sensor.x, sensor.y, z=sensor.z,
                               omega=section_point_omega(bridge, sensor))
        if q == "stress":
            return DeckRow(dofs=row.dofs, values=bridge.material.E * row.values)
        return row
    if q in SHEAR_COMPONENT:
        unit = _shear_field(bridge, sensor)[:, SHEAR_COMPONENT[q]]
        rows = [bridge.field_row(name, sensor.x) for name in ("torque_sv", "shear_force_y", "shear_force_z")]
        values = sum(u * r.values for u, r in zip(unit, rows))
        return DeckRow(dofs=rows[0].dofs, values=np.asarray(values))
    return bridge.field_row("w_deck", sensor.x, sensor.y)
