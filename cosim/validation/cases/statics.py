"""Statics and frequencies of deep beams against the Timoshenko closed forms."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import PointLoad, build_bridge

from ..references import (
    STEEL,
    cantilever_tip_load_deflection,
    euler_bernoulli_ss_frequency_hz,
    rectangle_section,
    ss_point_load_deflection,
    timoshenko_ss_frequency_hz,
)
from ..results import CaseResult, FigureData, StudyResult, Table, format_number
from .common import TOL_FREQ_TIMOSHENKO, TOL_NODAL_EXACT, first_kind, rel_peak

__all__ = [
    "TimoshenkoStaticFigure",
    "timoshenko_frequencies",
    "timoshenko_static",
]


@dataclass(frozen=True)
class TimoshenkoStaticFigure(FigureData):
    """Closed-form deflection lines and FE nodal values (m): simply supported (two loads) and cantilever."""

    ss_title: str
    ss_loads: tuple[float, ...]  # a / L
    ss_x: npt.NDArray[np.float64]
    ss_closed: tuple[npt.NDArray[np.float64], ...]
    ss_nodes_x: npt.NDArray[np.float64]
    ss_fe: tuple[npt.NDArray[np.float64], ...]
    cantilever_title: str
    cantilever_x: npt.NDArray[np.float64]
    cantilever_closed: npt.NDArray[np.float64]
    cantilever_bending_only: npt.NDArray[np.float64]
    cantilever_nodes_x: npt.NDArray[np.float64]
    cantilever_fe: npt.NDArray[np.float64]


def timoshenko_static() -> StudyResult:
    """Static deflection of a deep simply supported beam and a cantilever, bending and shear."""
    E, G = STEEL.E, STEEL.G
    file = "timoshenko_static.png"

    # Simply supported deep beam (L/h = 5), point load at a = 0.5 L and 0.3 L.
    sec = rectangle_section(0.3, 1.2)
    L, P = 6.0, -2.0e5
    bridge = build_bridge([L], 20, STEEL, sec, ["pinned", "fork"])
    x_fine = np.linspace(0.0, L, 301)
    errors, rows, closed, fes, values = [], [], [], [], {}
    loads = (0.5, 0.3)
    for a_over_l in loads:
        a = a_over_l * L
        fe = bridge.static([PointLoad(a, 0.0, P)]).field("w", bridge.nodes_x)
        ref = ss_point_load_deflection(bridge.nodes_x, a, L, P, E * sec.I_y, G * sec.A_sz)
        errors.append(rel_peak(fe, ref))
        shear = P * a * (L - a) / (G * sec.A_sz * L)
        ref_a = float(ss_point_load_deflection(a, a, L, P, E * sec.I_y, G * sec.A_sz))
        fe_a = fe[np.argmin(np.abs(bridge.nodes_x - a))]
        rows.append((f"{a_over_l:g}", f"{1e3 * fe_a:.6f}", f"{1e3 * ref_a:.6f}", f"{100 * shear / ref_a:.1f} %",
                     format_number(errors[-1])))
        values.update({f"w_fe_at_{a_over_l:g}L": fe_a, f"w_ref_at_{a_over_l:g}L": ref_a,
                       f"shear_share_at_{a_over_l:g}L": shear / ref_a})
        closed.append(ss_point_load_deflection(x_fine, a, L, P, E * sec.I_y, G * sec.A_sz))
        fes.append(fe)

    # Cantilever with a tip load.
    Lc, Pc = 4.0, -1.0e5
    cbridge = build_bridge([Lc], 8, STEEL, sec, ["fixed", "free"])
    fe_c = cbridge.static([PointLoad(Lc, 0.0, Pc)]).field("w", cbridge.nodes_x)
    ref_c = cantilever_tip_load_deflection(cbridge.nodes_x, Lc, Pc, E * sec.I_y, G * sec.A_sz)
    error_c = rel_peak(fe_c, ref_c)
    xc = np.linspace(0.0, Lc, 201)
    figure = TimoshenkoStaticFigure(
        file=file,
        ss_title="Simply supported, L = 6 m, 0.3 x 1.2 m, P = 200 kN", ss_loads=loads, ss_x=x_fine,
        ss_closed=tuple(closed), ss_nodes_x=bridge.nodes_x, ss_fe=tuple(fes),
        cantilever_title="Cantilever, L = 4 m, 0.3 x 1.2 m, tip load 100 kN", cantilever_x=xc,
        cantilever_closed=cantilever_tip_load_deflection(xc, Lc, Pc, E * sec.I_y, G * sec.A_sz),
        cantilever_bending_only=cantilever_tip_load_deflection(xc, Lc, Pc, E * sec.I_y, np.inf),
        cantilever_nodes_x=cbridge.nodes_x, cantilever_fe=fe_c,
    )
    tip = float(ref_c[-1])
    shear_c = Pc * Lc / (G * sec.A_sz) / tip
    cases = (
        CaseResult(
            name="Timoshenko static deflection, simply supported",
            reference="P b x (L^2 - b^2 - x^2)/(6 EI L) + P b x/(kGA L) (Gere & Timoshenko, Mechanics of Materials)",
            metric="max over nodes abs(w_FE - w_ref) / max abs(w_ref), loads at 0.5 L and 0.3 L (20 elements)",
            error=max(errors), tolerance=TOL_NODAL_EXACT, figures=(file,),
            details=(Table(("a / L", "FE at load [mm]", "closed form [mm]", "shear share", "error"), rows),),
            values=values,
        ),
        CaseResult(
            name="Timoshenko static deflection, cantilever",
            reference="P x^2 (3L - x)/(6 EI) + P x/(kGA) (Timoshenko & Gere)",
            metric="max over nodes abs(w_FE - w_ref) / max abs(w_ref) (8 elements)",
            error=error_c, tolerance=TOL_NODAL_EXACT, figures=(file,),
            details=(f"Tip deflection: FE {1e3 * fe_c[-1]:.6f} mm, closed form {1e3 * tip:.6f} mm "
                     f"(shear part {100 * shear_c:.1f} %).",),
            values={"w_tip_fe": fe_c[-1], "w_tip_ref": tip, "shear_share": shear_c},
        ),
    )
    return StudyResult(cases, (figure,))


def timoshenko_frequencies() -> StudyResult:
    """Vertical frequencies 1-4 of a deep simply supported beam against the Timoshenko frequency equation."""
    sec = rectangle_section(0.3, 0.8)
    L = 6.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    n = np.arange(1, 5)
    fe = first_kind(bridge, "vertical", 4, n_modes=30)
    ref = timoshenko_ss_frequency_hz(n, L, STEEL, sec)
    euler = euler_bernoulli_ss_frequency_hz(n, L, STEEL.E * sec.I_y, STEEL.rho * sec.A)
    rel = np.abs(fe / ref - 1)
    rows = [(str(k), f"{f:.5f}", f"{r:.5f}", f"{e:.5f}", format_number(x))
            for k, f, r, e, x in zip(n, fe, ref, euler, rel)]
    return StudyResult((CaseResult(
        name="Timoshenko frequencies, simply supported",
        reference="frequency equation of the simply supported Timoshenko beam (Han, Benaroya & Wei, JSV 225, 1999)",
        metric="max over modes 1-4 abs(f_FE / f_ref - 1)",
        error=float(np.max(rel)), tolerance=TOL_FREQ_TIMOSHENKO,
        details=("Deep beam L = 6 m, 0.3 x 0.8 m steel, 40 elements, pinned / fork.",
                 Table(("n", "FE [Hz]", "Timoshenko [Hz]", "Euler-Bernoulli [Hz]", "rel. error"), rows)),
        values={**{f"f{k}_fe": f for k, f in zip(n, fe)}, **{f"f{k}_ref": f for k, f in zip(n, ref)},
                **{f"f{k}_euler_bernoulli": f for k, f in zip(n, euler)}},
    ),))
