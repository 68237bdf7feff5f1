"""Non-uniform (Vlasov) torsion: statics, torsional and coupled lateral-torsional frequencies."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import build_bridge
from cosim.core.element import DOF_INDEX, NODE_DOFS

from ..references import (
    STEEL,
    doubly_symmetric_section,
    lateral_torsional_frequencies_hz,
    midspan_torque_twist,
    monosymmetric_section,
    torsional_frequencies_hz,
)
from ..results import CaseResult, FigureData, StudyResult, Table, format_number
from .common import TOL_FE_40, first_kind, rel_peak

__all__ = [
    "TorsionStaticFigure",
    "lateral_torsional_frequencies",
    "torsion_static",
    "torsional_frequencies",
]


@dataclass(frozen=True)
class TorsionStaticFigure(FigureData):
    """Twist lines (rad): uniform torsion, closed forms and FE nodes for warping free and restrained."""

    title: str
    x: npt.NDArray[np.float64]
    uniform: npt.NDArray[np.float64]
    warping: tuple[str, ...]
    closed: tuple[npt.NDArray[np.float64], ...]
    nodes_x: npt.NDArray[np.float64]
    fe: tuple[npt.NDArray[np.float64], ...]


def torsion_static() -> StudyResult:
    """Non-uniform (Vlasov) torsion under a mid-span torque, warping free and restrained ends."""
    sec = doubly_symmetric_section()
    E, G = STEEL.E, STEEL.G
    L, T, n_el = 10.0, 1.0e4, 40
    x_fine = np.linspace(0.0, L, 401)
    file = "torsion_static.png"
    lam = math.sqrt(G * sec.J / (E * sec.I_w))
    results, closed, fes = [], [], []
    for warping, supports in (("free", ["pinned", "fork"]), ("restrained", ["rigid-end", "rigid-end"])):
        bridge = build_bridge([L], n_el, STEEL, sec, supports)
        f = np.zeros(bridge.ndof)
        f[NODE_DOFS * (n_el // 2) + DOF_INDEX["theta_x"]] = T
        fe = bridge.static(f=f).field("theta_x", bridge.nodes_x)
        ref = midspan_torque_twist(bridge.nodes_x, L, T, G * sec.J, E * sec.I_w, warping)
        results.append((warping, rel_peak(fe, ref), fe[n_el // 2], ref[n_el // 2]))
        closed.append(midspan_torque_twist(x_fine, L, T, G * sec.J, E * sec.I_w, warping))
        fes.append(fe)
    figure = TorsionStaticFigure(
        file=file, title=f"Torque {T / 1e3:g} kN m at mid-span, L = {L:g} m, λL = {lam * L:.2f}",
        x=x_fine, uniform=T * np.minimum(x_fine, L - x_fine) / (2 * G * sec.J), warping=("free", "restrained"),
        closed=tuple(closed), nodes_x=bridge.nodes_x, fe=tuple(fes),
    )
    cases = []
    for warping, error, fe_mid, ref_mid in results:
        ends = "theta = theta'' = 0 (fork)" if warping == "free" else "theta = theta' = 0 (rigid end)"
        cases.append(CaseResult(
            name=f"Non-uniform torsion, warping {warping}",
            reference=f"Vlasov torsion GJ θ' - E I_w θ''' = T/2, {ends}, hyperbolic closed form "
                      "(Kollbrunner & Basler, Torsion in Structures, ch. 4)",
            metric="max over nodes abs(θ_FE - θ_ref) / max abs(θ_ref) (40 elements)",
            error=error, tolerance=TOL_FE_40, figures=(file,),
            details=(f"Mid-span twist: FE {1e3 * fe_mid:.6f} mrad, closed form {1e3 * ref_mid:.6f} mrad "
                     f"(λ = sqrt(GJ / E I_w) = {lam:.4g} 1/m).",),
            values={"theta_mid_fe": fe_mid, "theta_mid_ref": ref_mid, "lambda_L": lam * L},
        ))
    return StudyResult(tuple(cases), (figure,))


def _frequency_case(name: str, reference: str, fe: np.ndarray, ref: np.ndarray, labels: Sequence[str],
                    setup: str, values: dict | None = None) -> CaseResult:
    rel = np.abs(fe / ref - 1)
    rows = [(lab, f"{f:.5f}", f"{r:.5f}", format_number(x)) for lab, f, r, x in zip(labels, fe, ref, rel)]
    return CaseResult(
        name=name, reference=reference, metric=f"max over the {len(fe)} modes abs(f_FE / f_ref - 1)",
        error=float(np.max(rel)), tolerance=TOL_FE_40,
        details=(setup, Table(("mode", "FE [Hz]", "reference [Hz]", "rel. error"), rows)),
        values={**{f"f{i + 1}_fe": f for i, f in enumerate(fe)}, **{f"f{i + 1}_ref": f for i, f in enumerate(ref)},
                **(values or {})},
    )


def torsional_frequencies() -> StudyResult:
    """Torsional frequencies 1-3 with warping, fork supports."""
    sec = doubly_symmetric_section()
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    fe = first_kind(bridge, "torsion", 3, n_modes=40)
    ref = torsional_frequencies_hz(np.arange(1, 4), L, STEEL, sec)
    return StudyResult((_frequency_case(
        "Torsional frequencies with warping",
        "ω² = (GJ k² + E I_w k⁴) / (ρ I_p + ρ I_w k²), k = nπ/L, fork supports (Vlasov; docs/theory.md §8)",
        fe, ref, [f"torsion {n}" for n in range(1, 4)],
        "Doubly symmetric I-like section (J = 1e-6 m4, I_w = 2e-6 m6), L = 10 m, 40 elements, fork supports.",
    ),))


def lateral_torsional_frequencies() -> StudyResult:
    """The first six coupled lateral-torsional frequencies of a mono-symmetric section, fork supports."""
    sec = monosymmetric_section(e_z=0.12)
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    modal = bridge.modes(6)
    ref = lateral_torsional_frequencies_hz(8, L, STEEL, sec)[:6]
    uncoupled = build_bridge([L], 40, STEEL, monosymmetric_section(e_z=0.0), ["pinned", "fork"]).modes(1).f_hz[0]
    shift = modal.f_hz[0] / uncoupled - 1
    setup = (
        f"Mono-symmetric section, shear centre {sec.z_s:g} m above the centroid, L = {L:g} m, 40 elements, fork "
        f"supports. Without the offset the first frequency would be {uncoupled:.4f} Hz "
        f"(coupling moves it by {100 * shift:+.1f} %)."
    )
    return StudyResult((_frequency_case(
        "Coupled lateral-torsional frequencies, mono-symmetric section",
        "2x2 frequency determinant per mode number, sine modes in v and θx (Timoshenko & Gere, Theory of "
        "Elastic Stability; rotary and warping inertia kept)",
        modal.f_hz[:6], ref, [f"{i + 1}: {k}" for i, k in enumerate(modal.kinds[:6])], setup,
        {"f1_uncoupled": uncoupled, "coupling_shift": shift},
    ),))
