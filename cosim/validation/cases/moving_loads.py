"""Moving loads: a constant force (Fryba's series) and a sprung mass (Yang & Yau) crossing a beam."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import MovingForce

from ..references import STEEL, YANG_YAU, fryba_midspan_deflection, sprung_mass_modal_solution, yang_yau_case
from ..results import CaseResult, FigureData, StudyResult
from .common import GRAVITY, TOL_FRYBA, TOL_SPRUNG, euler_bernoulli_bridge, rel_peak

__all__ = [
    "FrybaFigure",
    "SprungMassFigure",
    "fryba_moving_force",
    "sprung_mass",
]


@dataclass(frozen=True)
class FrybaFigure(FigureData):
    """Mid-span deflection (m) against the load position v t / L, one panel per speed parameter."""

    basis: str
    ref_modes: int
    speed_parameters: tuple[float, ...]
    speeds: tuple[float, ...]
    position: tuple[npt.NDArray[np.float64], ...]
    w_fe: tuple[npt.NDArray[np.float64], ...]
    w_ref: tuple[npt.NDArray[np.float64], ...]
    w_static: float


def fryba_moving_force(steps: int, basis: str = "direct", modes: int | None = None) -> StudyResult:
    """A constant force crossing a simply supported beam at speed parameters 0.1 and 0.5 (Fryba's series).

    Args:
        steps: time steps per crossing.
        basis: ``"direct"`` (the report) or ``"modal"`` (with ``modes``, a verification test).
        modes: modes of the modal basis.
    """
    bridge, sec = euler_bernoulli_bridge()
    L = bridge.length
    EI, m = STEEL.E * sec.I_y, STEEL.rho * sec.A
    f1 = np.pi / (2 * L**2) * np.sqrt(EI / m)
    P = 1e5
    ref_modes = 80
    static = -P * L**3 / (48 * EI)
    file = "fryba_moving_force.png" if basis == "direct" else f"fryba_moving_force_{basis}.png"
    label = "" if basis == "direct" else f", {basis} basis ({modes} modes)"
    cases, speeds, positions, fes, refs = [], [], [], [], []
    for speed_parameter in (0.1, 0.5):
        v = speed_parameter * 2 * f1 * L  # alpha = v / (2 f1 L)
        traffic = ScriptedTraffic((ScriptedVehicle("F", MovingForce(P / GRAVITY), 0.0, v),), L)
        T = L / v
        settings = SolverSettings(dt=T / steps, basis=basis, modes=modes, gravity=GRAVITY)
        res = simulate(bridge, traffic, T, settings, [Sensor("mid", L / 2)])
        ref = fryba_midspan_deflection(res.t, L, v, P, EI, m, ref_modes)
        w = res.sensors["mid"]
        error = rel_peak(w, ref)
        fe_min, ref_min = float(np.min(w)), float(np.min(ref))
        speeds.append(v)
        positions.append(res.t * v / L)
        fes.append(w)
        refs.append(ref)
        cases.append(CaseResult(
            name=f"Moving force (Fryba), α = {speed_parameter:g}{label}",
            reference="modal series for a constant force crossing an undamped simply supported beam "
                      "(Fryba, Vibration of Solids and Structures under Moving Loads, 1972, ch. 1)",
            metric=f"max abs(w_FE - w_ref) / max abs(w_ref) at mid-span while the force is on the beam "
                   f"({steps} steps, 40 elements)",
            error=error, tolerance=TOL_FRYBA, figures=(file,),
            details=(f"v = {v:.2f} m/s; peak: FE {1e3 * fe_min:.4f} mm, series {1e3 * ref_min:.4f} mm, "
                     f"dynamic amplification {ref_min / static:.3f}.",),
            values={"speed": v, "min_fe": fe_min, "min_ref": ref_min, "w_static": static},
        ))
    figure = FrybaFigure(file=file, basis=basis, ref_modes=ref_modes, speed_parameters=(0.1, 0.5),
                         speeds=tuple(speeds), position=tuple(positions), w_fe=tuple(fes), w_ref=tuple(refs),
                         w_static=static)
    return StudyResult(tuple(cases), (figure,))


@dataclass(frozen=True)
class SprungMassFigure(FigureData):
    """Mid-span deflection (m) and body acceleration (m/s^2): FE and the modal reference."""

    title: str
    ref_modes: int
    t: npt.NDArray[np.float64]
    w_fe: npt.NDArray[np.float64]
    w_ref: npt.NDArray[np.float64]
    t_body: npt.NDArray[np.float64]
    a_fe: npt.NDArray[np.float64]
    a_ref: npt.NDArray[np.float64]


def sprung_mass(steps: int, modes: int, rtol: float) -> StudyResult:
    """Yang & Yau's sprung mass against an independent modal solution.

    Args:
        steps: time steps of the FE run over the crossing.
        modes: sine modes of the reference.
        rtol: relative tolerance of the reference's ODE solve (``atol = 1e-3 rtol``).
    """
    # Yang & Yau (1997): L 25 m, EI 2.943e10 N m2, m 2303 kg/m, sprung mass 5750 kg, k 1.595e6 N/m, 100 km/h.
    bridge, traffic, T = yang_yau_case()
    L, EI, m, m_v, k_v, c_v, v = (YANG_YAU[k] for k in ("L", "EI", "m", "m_v", "k_v", "c_v", "v"))
    res = simulate(bridge, traffic, T, SolverSettings(dt=T / steps, gravity=GRAVITY), [Sensor("mid", L / 2)])
    w_ref, acc_ref = sprung_mass_modal_solution(res.t, L, EI, m, m_v, k_v, c_v, v, gravity=GRAVITY,
                                                n_modes=modes, rtol=rtol, atol=rtol * 1e-3)
    body = res.vehicle("S")
    acc_on_deck = np.interp(body["t"], res.t, acc_ref)
    w = res.sensors["mid"]
    file = "sprung_mass.png"
    figure = SprungMassFigure(
        file=file, title="Sprung mass (5750 kg, 1.595 MN/m) at 27.78 m/s on a 25 m simply supported beam",
        ref_modes=modes, t=res.t, w_fe=w, w_ref=w_ref, t_body=body["t"], a_fe=body["body_acceleration"],
        a_ref=acc_on_deck,
    )
    reference = (
        "independent modal solution of the continuous beam with the sprung mass, solve_ivp DOP853 "
        "(benchmark of Yang & Yau, J. Struct. Eng. 1997; Biggs)"
    )
    setup = f"{steps} steps, 40 elements; reference {modes} modes, rtol {rtol:g}"
    a_fe_peak, a_ref_peak = float(np.max(np.abs(body["body_acceleration"]))), float(np.max(np.abs(acc_on_deck)))
    cases = (
        CaseResult(
            name="Moving sprung mass: mid-span deflection", reference=reference,
            metric=f"max abs(w_FE - w_ref) / max abs(w_ref) ({setup})",
            error=rel_peak(w, w_ref), tolerance=TOL_SPRUNG, figures=(file,),
            details=(f"Peak deflection: FE {1e3 * w.min():.4f} mm, reference {1e3 * w_ref.min():.4f} mm.",),
            values={"min_fe": w.min(), "min_ref": w_ref.min()},
        ),
        CaseResult(
            name="Moving sprung mass: body acceleration", reference=reference,
            metric=f"max abs(a_FE - a_ref) / max abs(a_ref) while on the beam ({setup})",
            error=rel_peak(body["body_acceleration"], acc_on_deck), tolerance=TOL_SPRUNG, figures=(file,),
            details=(f"Peak body acceleration: FE {a_fe_peak:.4f} m/s2, reference {a_ref_peak:.4f} m/s2.",),
            values={"peak_fe": a_fe_peak, "peak_ref": a_ref_peak},
        ),
    )
    return StudyResult(cases, (figure,))
