"""Vehicle models behind one interface: moving force, quarter-car (rigid contact), quarter-car with tyre.

All three are "one contact point" models. Displacements are measured from the
static equilibrium of the vehicle on a rigid, smooth road; gravity acts as a
constant load ``(m_v + m_w) g`` on the deck. The contact force ``P`` is the
force the wheel presses on the deck (compression positive); ``P < 0`` means
the wheel would lift off: it is counted and reported, the contact is kept
(bilateral), as in the paper.

- :class:`MovingForce`: ``P = m g``, no inertia (the classical benchmark).
- :class:`QuarterCar`: the paper's model (Fig. 2). Body ``m_v`` on a
  suspension ``k_v, c_v`` over a wheel ``m_w`` that follows the deck exactly,
  ``u_w = N_bar d``; the road profile acts in the suspension, whose stretch is
  ``u_v - u_w - r(x_c)``.
- :class:`TyreQuarterCar`: the wheel is its own DOF on a tyre ``k_t, c_t``
  whose stretch is ``u_w - w_deck - r``, so standard parameter sets apply.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

from cosim.errors import ConfigError


def _positive(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ConfigError(f"{owner}: `{name}` must be a finite number > 0 (got {value!r})")


def _non_negative(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise ConfigError(f"{owner}: `{name}` must be a finite number >= 0 (got {value!r})")


@dataclass(frozen=True)
class MovingForce:
    """A constant vertical force ``mass * g`` moving with the vehicle.

    Args:
        mass: total mass, kg.
    """

    mass: float
    kind = "moving-force"

    def __post_init__(self) -> None:
        _positive("moving force", mass=self.mass)

    @property
    def total_mass(self) -> float:
        return float(self.mass)


@dataclass(frozen=True)
class QuarterCar:
    """The paper's quarter-car with perfect wheel-deck contact.

    Args:
        m_v: body (sprung) mass, kg.
        m_w: wheel (unsprung) mass, kg; 0 gives the classical sprung mass.
        k_v: suspension stiffness, N/m.
        c_v: suspension damping, N s/m.
    """

    m_v: float
    m_w: float
    k_v: float
    c_v: float
    kind = "quarter-car"

    def __post_init__(self) -> None:
        _positive("quarter-car", m_v=self.m_v, k_v=self.k_v)
        _non_negative("quarter-car", m_w=self.m_w, c_v=self.c_v)

    @property
    def total_mass(self) -> float:
        return float(self.m_v + self.m_w)

    @property
    def body_frequency_hz(self) -> float:
        """Body bounce frequency on a rigid road, Hz."""
        return math.sqrt(self.k_v / self.m_v) / (2 * math.pi)


@dataclass(frozen=True)
class TyreQuarterCar:
    """Quarter-car with a tyre spring and damper (wheel as its own DOF).

    Args:
        m_v: body mass, kg.  m_w: wheel mass, kg (> 0).
        k_v, c_v: suspension, N/m and N s/m.
        k_t, c_t: tyre, N/m and N s/m.
    """

    m_v: float
    m_w: float
    k_v: float
    c_v: float
    k_t: float
    c_t: float = 0.0
    kind = "tyre-quarter-car"

    def __post_init__(self) -> None:
        _positive("tyre quarter-car", m_v=self.m_v, m_w=self.m_w, k_v=self.k_v, k_t=self.k_t)
        _non_negative("tyre quarter-car", c_v=self.c_v, c_t=self.c_t)

    @property
    def total_mass(self) -> float:
        return float(self.m_v + self.m_w)

    @classmethod
    def golden_car(cls, m_v: float) -> "TyreQuarterCar":
        """The IRI reference ("golden car") ratios scaled to body mass ``m_v`` (kg).

        k_s/m_s = 63.3 1/s^2, c_s/m_s = 6.0 1/s, k_t/m_s = 653 1/s^2,
        m_u/m_s = 0.15 (Sayers, Gillespie & Queiroz, World Bank TP 45, 1986).
        """
        return cls(m_v=m_v, m_w=0.15 * m_v, k_v=63.3 * m_v, c_v=6.0 * m_v, k_t=653.0 * m_v, c_t=0.0)


VehicleModel = Union[MovingForce, QuarterCar, TyreQuarterCar]
MODEL_NAMES = ("moving-force", "quarter-car", "tyre-quarter-car")


def model_to_dict(model: VehicleModel) -> dict[str, float | str]:
    """A plain description of a vehicle model (for logs): ``{"model": kind, <parameters>}``."""
    from dataclasses import asdict

    return {"model": model.kind, **asdict(model)}


def model_from_dict(data: dict) -> VehicleModel:
    """Rebuild a vehicle model from :func:`model_to_dict`'s output (numbers only; validated)."""
    kinds = {"moving-force": MovingForce, "quarter-car": QuarterCar, "tyre-quarter-car": TyreQuarterCar}
    kind = data.get("model")
    if kind not in kinds:
        raise ConfigError(f"unknown vehicle model {kind!r} (expected one of: {', '.join(kinds)})")
    params = {k: v for k, v in data.items() if k != "model"}
    for key, value in params.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ConfigError(f"vehicle model parameter `{key}` must be a number (got {value!r})")
    try:
        return kinds[kind](**params)
    except TypeError as exc:
        raise ConfigError(f"vehicle model {kind}: {exc}") from None
