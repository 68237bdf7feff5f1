"""Units in which results are shown to people (summaries, plots, assertion messages); logs stay in SI."""
from __future__ import annotations

#: Display units per sensor quantity: (unit, factor from SI).
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "displacement": ("mm", 1e3),
    "velocity": ("mm/s", 1e3),
    "acceleration": ("m/s^2", 1.0),
    "bending_moment": ("kN m", 1e-3),
    "stress": ("MPa", 1e-6),
    "strain": ("µε", 1e6),
    "shear_stress_xy": ("MPa", 1e-6),
    "shear_stress_xz": ("MPa", 1e-6),
}
#: For a quantity without a display unit: SI, unscaled.
SI = ("SI", 1.0)


def display_unit(quantity: str) -> tuple[str, float]:
    """(unit, factor from SI) in which a sensor quantity is shown; ("SI", 1.0) for an unknown one."""
    return DISPLAY_UNITS.get(quantity, SI)
