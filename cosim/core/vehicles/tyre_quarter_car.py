"""Quarter-car with a tyre spring and damper: the wheel is its own DOF (docs/theory.md §5.6, §6.5).

The tyre's stretch is ``u_w - w_deck - r``, so standard vehicle parameter
sets (body, wheel, suspension, tyre) apply directly.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np

from cosim.errors import ConfigError

from ..jit import compiled
from .base import LINEAR, TYRE_QUARTER_CAR, VehicleModel, check_non_negative, check_positive
from .quarter_car import C_V, K_V, M_V, VTYPE_C_V, VTYPE_K_V, VTYPE_M_W
from .registry import LIBRARY, ModelSpec, Parameter, VTypeInputs, VTypeRecipe


@dataclass(frozen=True)
class TyreQuarterCar(VehicleModel):
    """Quarter-car with a tyre spring and damper (wheel as its own DOF).

    Args:
        m_v: body mass, kg.  m_w: wheel mass, kg (> 0).
        k_v, c_v: suspension, N/m and N s/m.
        k_t, c_t: tyre, N/m and N s/m.
        unilateral: the tyre may leave the deck (it carries no tension) and land again;
            False keeps the paper's bilateral contact (a pulling tyre is counted as a lift-off).
    """

    m_v: float
    m_w: float
    k_v: float
    c_v: float
    k_t: float
    c_t: float = 0.0
    unilateral: bool = False
    kind: ClassVar[str] = "tyre-quarter-car"
    KIND: ClassVar[int] = TYRE_QUARTER_CAR

    def __post_init__(self) -> None:
        check_positive("tyre quarter-car", m_v=self.m_v, m_w=self.m_w, k_v=self.k_v, k_t=self.k_t)
        check_non_negative("tyre quarter-car", c_v=self.c_v, c_t=self.c_t)
        if not isinstance(self.unilateral, bool):
            raise ConfigError(f"tyre quarter-car: `unilateral` must be true or false (got {self.unilateral!r})")

    @property
    def kernel_kind(self) -> int:
        """Compiled kind: unilateral contact runs through the linear-vehicle path (the tyre may leave the deck)."""
        return LINEAR if self.unilateral else TYRE_QUARTER_CAR

    def record(self) -> dict[str, float]:
        """The model as numbers only (for logs); ``unilateral`` appears only when set."""
        out = {k: getattr(self, k) for k in ("m_v", "m_w", "k_v", "c_v", "k_t", "c_t")}
        if self.unilateral:
            out["unilateral"] = 1.0
        return out

    @classmethod
    def from_record(cls, values: dict[str, Any]) -> TyreQuarterCar:
        """The inverse of :meth:`record`."""
        params = dict(values)
        params["unilateral"] = bool(params.pop("unilateral", 0.0))
        return cls(**params)

    def linear_system(self, gravity: float) -> dict[str, np.ndarray]:
        """The model as a linear vehicle [body, wheel] (used for unilateral contact)."""
        return tyre_quarter_car_system(self.m_v, self.m_w, self.k_v, self.c_v, self.k_t, self.c_t, gravity)

    @property
    def total_mass(self) -> float:
        """kg."""
        return float(self.m_v + self.m_w)

    def pack(self) -> tuple[float, ...]:
        """Compiled parameters: m_v, m_w, k_v, c_v, k_t, c_t."""
        return (self.m_v, self.m_w, self.k_v, self.c_v, self.k_t, self.c_t)

    @classmethod
    def golden_car(cls, m_v: float) -> TyreQuarterCar:
        """The IRI reference ("golden car") ratios scaled to body mass ``m_v`` (kg).

        k_s/m_s = 63.3 1/s^2, c_s/m_s = 6.0 1/s, k_t/m_s = 653 1/s^2,
        m_u/m_s = 0.15 (Sayers, Gillespie & Queiroz, World Bank TP 45, 1986).
        """
        return cls(m_v=m_v, m_w=0.15 * m_v, k_v=63.3 * m_v, c_v=6.0 * m_v, k_t=653.0 * m_v, c_t=0.0)


#: Its tyre keys (the half-car's axles share them).
K_T = Parameter("k_t", "N/m", "tyre stiffness", above=0.0)
C_T = Parameter("c_t", "N s/m", "tyre damping", 0.0, at_least=0.0)
#: Its vType params beyond the quarter-car's.
VTYPE_K_T = Parameter("k_t", "N/m", "tyre stiffness", LIBRARY)
VTYPE_C_T = Parameter("c_t", "N s/m", "tyre damping", LIBRARY)


def _from_table(values: Mapping[str, Any], unilateral: bool) -> TyreQuarterCar:
    return TyreQuarterCar(m_v=values["m_v"], m_w=values["m_w"], k_v=values["k_v"], c_v=values["c_v"],
                          k_t=values["k_t"], c_t=values["c_t"], unilateral=unilateral)


def from_vtype(vtype: VTypeInputs) -> TyreQuarterCar:
    """The whole vehicle of a vType on one tyre (the half-car shares it among its axles)."""
    v = vtype.values
    return TyreQuarterCar(m_v=vtype.mass - v["m_w"], m_w=v["m_w"], k_v=v["k_v"], c_v=v["c_v"], k_t=v["k_t"],
                          c_t=v["c_t"], unilateral=vtype.unilateral)


def _golden_car(values: Mapping[str, Any], unilateral: bool) -> TyreQuarterCar:
    golden = TyreQuarterCar.golden_car(values["m_v"])
    return replace(golden, unilateral=unilateral) if unilateral else golden


#: Its vType params (the half-car reads them too).
VTYPE_PARAMETERS = (VTYPE_M_W, VTYPE_K_V, VTYPE_C_V, VTYPE_K_T, VTYPE_C_T)

SPEC = ModelSpec(
    name=TyreQuarterCar.kind, cls=TyreQuarterCar,
    doc="the wheel as its own DOF on a tyre spring `k_t` and damper `c_t`; the road profile acts in the tyre",
    parameters=(M_V, Parameter("m_w", "kg", "wheel (unsprung) mass", above=0.0), K_V, C_V, K_T, C_T),
    build=_from_table, example=TyreQuarterCar(m_v=8000.0, m_w=1000.0, k_v=4e5, c_v=4e4, k_t=3e6, c_t=1e4),
    tyre=True, vtype=VTypeRecipe(parameters=VTYPE_PARAMETERS, build=from_vtype),
)
#: A preset: the IRI reference car scaled to its body mass.
GOLDEN_CAR = ModelSpec(
    name="golden-car", cls=TyreQuarterCar,
    doc="a `tyre-quarter-car` with the IRI reference (\"golden car\") ratios scaled to the body mass: "
        "`k_v = 63.3 m_v`, `c_v = 6.0 m_v`, `k_t = 653 m_v`, `m_w = 0.15 m_v`, `c_t = 0`",
    parameters=(M_V,), build=_golden_car, example=TyreQuarterCar.golden_car(300.0), tyre=True,
)


@compiled
def coefficients(i, p, vstate, pred, v, a, r, r_x, dots, b2, g1, ca, alpha, e0, c0, c1, c2, aux):  # noqa: ANN001, ANN201
    """Deck-force coefficients of vehicle ``i`` (docs/theory.md (6.11)-(6.13)).

    ``e0[i]`` holds ``-(1+alpha) m g`` on entry.
    """
    m_v, m_w, k_v, c_v, k_t, c_t = p[0, i], p[1, i], p[2, i], p[3, i], p[4, i], p[5, i]
    ub, vb, uw, vw = pred[0, i], pred[1, i], pred[2, i], pred[3, i]
    w0, w1d, w1v = dots[0, i], dots[1, i], dots[2, i]
    mv = k_v * b2 + c_v * g1
    mt = k_t * b2 + c_t * g1
    S0 = k_v * (ub - uw) + c_v * (vb - vw)
    T0 = k_t * (uw - w0 - r) + c_t * (vw - w1v - v * w1d - v * r_x)
    R1 = -ca * S0 + alpha * vstate[6, i]
    R2 = ca * (S0 - T0) - alpha * (vstate[6, i] - vstate[7, i])
    den = (m_v + ca * mv) * (m_w + ca * mv + ca * mt) - (ca * mv) ** 2
    e0[i] += ca * (T0 + mt * ((m_v + ca * mv) * R2 + ca * mv * R1) / den)
    kappa = ca * (1.0 - ca * mt * (m_v + ca * mv) / den)
    c0[i] = kappa * (k_t * b2 + c_t * g1)
    c1[i] = kappa * c_t * v * b2
    aux[0, i], aux[1, i], aux[2, i], aux[3, i], aux[4, i], aux[5, i] = S0, T0, R1, R2, den, 0.0


@compiled
def update(i, p, vstate, aux, v, a, n0a, n1a, n2a, b2, g1, ca, alpha):  # noqa: ANN001, ANN201
    """Body and wheel accelerations, suspension and tyre forces, and the deck force once ``a`` is known.

    Returns ``(acc_body, acc_wheel, suspension, tyre, deck, elastic)``: only the tyre touches the deck, so
    both the deck force (weight excluded) and its non-inertial part are the tyre force.
    """
    m_v, m_w, k_v, c_v, k_t, c_t = p[0, i], p[1, i], p[2, i], p[3, i], p[4, i], p[5, i]
    S0, T0, R1, R2, den = aux[0, i], aux[1, i], aux[2, i], aux[3, i], aux[4, i]
    mv = k_v * b2 + c_v * g1
    mt = k_t * b2 + c_t * g1
    ta = (k_t * b2 + c_t * g1) * n0a + c_t * v * b2 * n1a
    acc_w = ((m_v + ca * mv) * (R2 + ca * ta) + ca * mv * R1) / den
    acc_b = ((m_w + ca * mv + ca * mt) * R1 + ca * mv * (R2 + ca * ta)) / den
    susp = S0 + mv * (acc_b - acc_w)
    tyre = T0 + mt * acc_w - ta
    return acc_b, acc_w, susp, tyre, tyre, tyre


def tyre_quarter_car_system(m_v: float, m_w: float, k_v: float, c_v: float, k_t: float, c_t: float,
                            gravity: float) -> dict[str, np.ndarray]:
    """The tyre quarter-car as a linear vehicle [body, wheel] (for unilateral contact)."""
    mv = np.diag([m_v, m_w])
    kv = k_v * np.array([[1.0, -1.0], [-1.0, 1.0]])
    cv = c_v * np.array([[1.0, -1.0], [-1.0, 1.0]])
    b = np.array([[0.0, 1.0]])
    obs = np.array([[1.0, 0.0]])
    return {"mv": mv, "cv": cv, "kv": kv, "b": b, "k_t": np.array([k_t]), "c_t": np.array([c_t]),
            "loads": np.array([(m_v + m_w) * gravity]), "obs": obs}
