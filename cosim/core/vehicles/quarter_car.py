"""The paper's quarter-car with perfect wheel-deck contact (docs/theory.md §5.5, §6.4).

Body ``m_v`` on a suspension ``k_v, c_v`` over a wheel ``m_w`` that follows
the deck exactly, ``u_w = N d``; the road profile acts in the suspension,
whose stretch is ``u_v - u_w - r(x_c)``. The wheel's acceleration includes
the moving-contact terms of a vehicle with speed ``v`` and acceleration ``a``::

    u_w'' = n0 . d'' + 2 v n1 . d' + (v^2 n2 + a n1) . d
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from ..jit import compiled
from .base import QUARTER_CAR, VehicleModel, check_non_negative, check_positive
from .registry import LIBRARY, ModelSpec, Parameter, VTypeInputs, VTypeRecipe


@dataclass(frozen=True)
class QuarterCar(VehicleModel):
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
    kind: ClassVar[str] = "quarter-car"
    KIND: ClassVar[int] = QUARTER_CAR

    def __post_init__(self) -> None:
        check_positive("quarter-car", m_v=self.m_v, k_v=self.k_v)
        check_non_negative("quarter-car", m_w=self.m_w, c_v=self.c_v)

    @property
    def total_mass(self) -> float:
        """kg."""
        return float(self.m_v + self.m_w)

    @property
    def body_frequency_hz(self) -> float:
        """Body bounce frequency on a rigid road, Hz."""
        return math.sqrt(self.k_v / self.m_v) / (2 * math.pi)

    def pack(self) -> tuple[float, ...]:
        """Compiled parameters: m_v, m_w, k_v, c_v."""
        return (self.m_v, self.m_w, self.k_v, self.c_v)


#: Its ``[[vehicles]]`` keys (the tyre quarter-car shares them).
M_V = Parameter("m_v", "kg", "body (sprung) mass", above=0.0)
K_V = Parameter("k_v", "N/m", "suspension stiffness", above=0.0)
C_V = Parameter("c_v", "N s/m", "suspension damping", at_least=0.0)
#: Its vType params: the suspension of the vClass's library vehicle unless given (docs/sumo.md).
VTYPE_M_W = Parameter("m_w", "kg", "unsprung (wheel and axle) mass", LIBRARY)
VTYPE_K_V = Parameter("k_v", "N/m", "suspension stiffness", LIBRARY)
VTYPE_C_V = Parameter("c_v", "N s/m", "suspension damping", LIBRARY)


def _from_table(values: Mapping[str, Any], unilateral: bool) -> QuarterCar:
    return QuarterCar(m_v=values["m_v"], m_w=values["m_w"], k_v=values["k_v"], c_v=values["c_v"])


def _from_vtype(vtype: VTypeInputs) -> QuarterCar:
    v = vtype.values
    return QuarterCar(m_v=vtype.mass - v["m_w"], m_w=v["m_w"], k_v=v["k_v"], c_v=v["c_v"])


SPEC = ModelSpec(
    name=QuarterCar.kind, cls=QuarterCar,
    doc="the paper's quarter-car: body `m_v` on a suspension `k_v`, `c_v` over a wheel `m_w` in perfect contact "
        "with the deck; the road profile acts in the suspension",
    parameters=(M_V, Parameter("m_w", "kg", "wheel (unsprung) mass; 0: the classical sprung mass", at_least=0.0),
                K_V, C_V),
    build=_from_table, example=QuarterCar(m_v=8000.0, m_w=1000.0, k_v=4e5, c_v=4e4),
    vtype=VTypeRecipe(parameters=(VTYPE_M_W, VTYPE_K_V, VTYPE_C_V), build=_from_vtype),
)


@compiled
def coefficients(i, p, vstate, pred, v, a, r, r_x, dots, b2, g1, ca, alpha, e0, c0, c1, c2, aux):  # noqa: ANN001, ANN201
    """Deck-force coefficients of vehicle ``i`` (docs/theory.md (6.6)-(6.10)).

    ``e0[i]`` holds ``-(1+alpha) m g`` on entry.
    """
    m_v, m_w, k_v, c_v = p[0, i], p[1, i], p[2, i], p[3, i]
    ub, vb = pred[0, i], pred[1, i]
    w0, w1d, w1v, w2d, w1v1 = dots[0, i], dots[1, i], dots[2, i], dots[3, i], dots[4, i]
    m_hat = k_v * b2 + c_v * g1
    den = m_v + ca * m_hat
    h = 2.0 * v * w1v1 + v * v * w2d + a * w1d
    F0 = k_v * (ub - w0 - r) + c_v * (vb - w1v - v * w1d - v * r_x)
    e0[i] += ca * (m_v * F0 + alpha * m_hat * vstate[6, i]) / den - m_w * h
    c0[i] = m_w + ca * m_v / den * m_hat
    c1[i] = m_w * (2.0 * v * g1 + b2 * a) + ca * m_v / den * c_v * v * b2
    c2[i] = m_w * b2 * v * v
    aux[0, i], aux[1, i], aux[2, i], aux[3, i] = F0, h, den, m_hat


@compiled
def update(i, p, vstate, aux, v, a, n0a, n1a, n2a, b2, g1, ca, alpha):  # noqa: ANN001, ANN201
    """Body and wheel accelerations, suspension force and the deck force once ``a`` is known.

    Returns ``(acc_body, acc_wheel, suspension, tyre, deck, elastic)``: ``deck`` is the force the wheel
    puts on the deck (weight excluded, wheel inertia included), ``elastic`` its non-inertial part (the
    suspension force), which HHT weights.
    """
    m_w, c_v = p[1, i], p[3, i]
    F0, h, den, m_hat = aux[0, i], aux[1, i], aux[2, i], aux[3, i]
    qa = m_hat * n0a + c_v * v * b2 * n1a
    acc_b = -(ca * (F0 - qa) - alpha * vstate[6, i]) / den
    susp = F0 - qa + m_hat * acc_b
    acc_w = n0a + (2.0 * v * g1 + b2 * a) * n1a + b2 * v * v * n2a + h
    return acc_b, acc_w, susp, 0.0, susp - m_w * acc_w, susp
