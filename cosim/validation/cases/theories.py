"""Beam theories (docs/theory.md §10): Benscoter torsion, the paper case under both torsions, VBI-2D's beam."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import BeamTheory, build_bridge
from cosim.core.element import DOF_INDEX, NODE_DOFS
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.run.scenario import load_scenario

from ..references import (
    STEEL,
    VBI2D_SPRUNG,
    benscoter_midspan_torque_twist,
    benscoter_torsional_frequencies_hz,
    doubly_symmetric_section,
    midspan_torque_twist,
    sprung_mass_modal_solution,
    torsional_frequencies_hz,
    vbi2d_sprung_case,
)
from ..results import CaseResult, FigureData, StudyResult, Table, format_number, judge
from .common import (
    GRAVITY,
    TOL_BENSCOTER_FREQ,
    TOL_BENSCOTER_STATIC,
    TOL_ORDER_MESH_TIMOSHENKO,
    TOL_VBI2D,
    TOL_VBI2D_PEAK_TIME,
    first_kind,
    observed_orders,
    rel_peak,
    signed_y,
)
from .paper import PAPER_DURATION, PAPER_NODES, PAPER_QC1, PAPER_QC2, PAPER_SPEED, paper_runs

__all__ = [
    "BenscoterFigure",
    "PaperTheoriesFigure",
    "Vbi2dFigure",
    "benscoter_torsion",
    "paper_torsion_theories",
    "vbi2d_sprung_vehicle",
]

# A stocky I-like girder (the Vlasov checks' section) whose warping shear matters: I_ws / I_w = 10 1/m^2.
_STOCKY_I_WS = 2.0e-5


@dataclass(frozen=True)
class BenscoterFigure(FigureData):
    """Benscoter torsion: twist lines (rad), torsional frequencies (Hz) and the mesh convergence of one of them.

    ``closed`` and ``vlasov`` are the closed forms on ``x``, ``fe`` the nodal twists, one per ``warping``.
    """

    static_title: str
    x: npt.NDArray[np.float64]
    warping: tuple[str, ...]
    closed: tuple[npt.NDArray[np.float64], ...]
    vlasov: tuple[npt.NDArray[np.float64], ...]
    nodes_x: npt.NDArray[np.float64]
    fe: tuple[npt.NDArray[np.float64], ...]
    frequency_title: str
    modes: npt.NDArray[np.int64]
    f_vlasov: npt.NDArray[np.float64]
    f_ref: npt.NDArray[np.float64]
    f_fe: npt.NDArray[np.float64]
    n_elements: int
    mesh_label: str
    counts: npt.NDArray[np.int64]
    errors: npt.NDArray[np.float64]
    expected_order: float


def benscoter_torsion() -> StudyResult:
    """Shear-deformable warping (Benscoter) against its closed forms, its frequency equation and in mesh convergence."""
    sec = replace(doubly_symmetric_section(), I_ws=_STOCKY_I_WS)
    theory = BeamTheory(torsion="benscoter")
    E, G = STEEL.E, STEEL.G
    L, T, n_el = 10.0, 1.0e4, 40
    gj, eiw, giws = G * sec.J, E * sec.I_w, G * _STOCKY_I_WS
    file = "benscoter_torsion.png"
    cases = []

    # Static twist under a mid-span torque, warping restrained and free.
    x_fine = np.linspace(0.0, L, 401)
    warpings, closed, vlasov_lines, fes = [], [], [], []
    for warping, supports in (("restrained", ["rigid-end", "rigid-end"]), ("free", ["pinned", "fork"])):
        bridge = build_bridge([L], n_el, STEEL, sec, supports, theory=theory)
        f = np.zeros(bridge.ndof)
        f[NODE_DOFS * (n_el // 2) + DOF_INDEX["theta_x"]] = T
        fe = bridge.static(f=f).field("theta_x", bridge.nodes_x)
        ref = benscoter_midspan_torque_twist(bridge.nodes_x, L, T, gj, eiw, giws, warping)
        vlasov = float(midspan_torque_twist(L / 2, L, T, gj, eiw, warping))
        warpings.append(warping)
        closed.append(benscoter_midspan_torque_twist(x_fine, L, T, gj, eiw, giws, warping))
        vlasov_lines.append(midspan_torque_twist(x_fine, L, T, gj, eiw, warping))
        fes.append(fe)
        ends = "θ = ψ = 0 (rigid end)" if warping == "restrained" else "θ = 0, ψ' = 0 (fork)"
        fe_mid, ref_mid = float(fe[n_el // 2]), float(ref[n_el // 2])
        cases.append(CaseResult(
            name=f"Benscoter torsion, mid-span torque, warping {warping}",
            reference="GJ θ' + G I_ws (θ' - ψ) = T/2, E I_w ψ'' + G I_ws (θ' - ψ) = 0 (Benscoter, J. Appl. Mech. 21, "
                      f"1954), {ends}: hyperbolic closed form of docs/theory.md §10.4",
            metric=f"max over nodes abs(θ_FE - θ_ref) / max abs(θ_ref) ({n_el} elements)",
            error=rel_peak(fe, ref), tolerance=TOL_BENSCOTER_STATIC, figures=(file,),
            details=(f"Mid-span twist: FE {1e3 * fe_mid:.6f} mrad, closed form {1e3 * ref_mid:.6f} mrad, "
                     f"Vlasov {1e3 * vlasov:.6f} mrad ({100 * (ref_mid / vlasov - 1):+.1f} % from the warping "
                     f"shear). Section: J = {sec.J:g} m4, I_w = {sec.I_w:g} m6, I_ws = {sec.I_ws:g} m4, L = {L:g} m.",),
            values={"theta_mid_fe": fe_mid, "theta_mid_ref": ref_mid, "theta_mid_vlasov": vlasov},
        ))

    # Frequencies with fork supports against the frequency equation.
    def torsion_hz(n: int, count: int = 3) -> npt.NDArray[np.float64]:
        return first_kind(build_bridge([L], n, STEEL, sec, ["pinned", "fork"], theory=theory), "torsion", count, 40)

    modes = np.arange(1, 4)
    ref_f = benscoter_torsional_frequencies_hz(modes, L, STEEL, sec)
    vlasov_f = torsional_frequencies_hz(modes, L, STEEL, sec)
    fe_f = torsion_hz(n_el)
    rel = np.abs(fe_f / ref_f - 1)
    rows = tuple((str(n), f"{f:.5f}", f"{r:.5f}", f"{v:.5f}", format_number(e))
                 for n, f, r, v, e in zip(modes, fe_f, ref_f, vlasov_f, rel))
    cases.append(CaseResult(
        name="Benscoter torsional frequencies",
        reference="(G_t k² - ω² ρ I_ps)(E I_w k² + G I_ws - ω² ρ I_w) - (G I_ws k)² = 0, k = nπ/L, G_t = GJ + G I_ws, "
                  "smaller root (docs/theory.md §10.4)",
        metric=f"max over the first 3 torsional modes abs(f_FE / f_ref - 1) ({n_el} elements)",
        error=float(np.max(rel)), tolerance=TOL_BENSCOTER_FREQ, figures=(file,),
        details=(Table(("n", "FE [Hz]", "Benscoter [Hz]", "Vlasov [Hz]", "rel. error"), rows),),
        values={**{f"f{n}_fe": f for n, f in zip(modes, fe_f)}, **{f"f{n}_ref": f for n, f in zip(modes, ref_f)},
                **{f"f{n}_vlasov": f for n, f in zip(modes, vlasov_f)}},
    ))

    # Mesh convergence of the third torsional frequency.
    counts = np.array([5, 10, 20, 40])
    errors = np.array([torsion_hz(int(n))[2] / ref_f[2] - 1.0 for n in counts])
    orders = observed_orders(L / counts, errors)
    cases.append(CaseResult(
        name="Benscoter torsion, mesh convergence",
        reference="Benscoter frequency equation; expected order 2 (constant secondary shear strain per element, "
                  "as the Timoshenko element)",
        metric=f"order shortfall max(0, 2 - min observed order) over {', '.join(map(str, counts))} elements",
        error=max(0.0, 2.0 - float(np.min(orders))) if np.all(errors > 0) else math.inf,
        tolerance=TOL_ORDER_MESH_TIMOSHENKO, figures=(file,),
        details=(Table(("elements", "rel. error"), tuple((str(n), format_number(e)) for n, e in zip(counts, errors))),
                 f"Observed orders: {', '.join(f'{p:.2f}' for p in orders)}."),
        values={"min_order": float(np.min(orders)), "max_order": float(np.max(orders)),
                **{f"error_{n}_elements": e for n, e in zip(counts, errors)}},
    ))
    figure = BenscoterFigure(
        file=file, static_title=f"Torque {T / 1e3:g} kN m at mid-span, L = {L:g} m", x=x_fine, warping=tuple(warpings),
        closed=tuple(closed), vlasov=tuple(vlasov_lines), nodes_x=bridge.nodes_x, fe=tuple(fes),
        frequency_title="Fork supports", modes=modes, f_vlasov=vlasov_f, f_ref=ref_f, f_fe=fe_f, n_elements=n_el,
        mesh_label="third torsional frequency", counts=counts, errors=errors, expected_order=2.0,
    )
    return StudyResult(tuple(cases), (figure,))


@dataclass(frozen=True)
class PaperTheoriesFigure(FigureData):
    """Mid-span histories (m) of the paper case under moving forces, one panel per node, one line per theory.

    ``w[j]`` holds theory ``j``'s histories, one row per node (``node_titles``), at the times ``t[j]``.
    """

    title: str
    node_titles: tuple[str, ...]
    theories: tuple[str, ...]
    torsion_1: tuple[float, ...]  # Hz, per theory
    t: tuple[npt.NDArray[np.float64], ...]
    w: tuple[npt.NDArray[np.float64], ...]
    duration: float


def paper_torsion_theories(dt: float) -> StudyResult:
    """The paper's bridge with Vlasov and with Benscoter torsion: torsional frequencies and moving-force peaks.

    Informational: no published reference for the double-tee with shear-deformable warping.
    """
    scenario = load_scenario("paper-double-tee")
    cfg = scenario.bridge
    damping = cfg.damping.beam_damping() if cfg.damping is not None else None
    section = scenario.build_section()
    theories = ("vlasov", "benscoter")
    results, rows, values = {}, [], {}
    for name in theories:
        bridge = build_bridge(cfg.spans, cfg.elements_per_span, scenario.material(), section, cfg.supports, damping,
                              theory=BeamTheory(torsion=name))
        modal = bridge.modes(12)
        f_t = [f for f, k in zip(modal.f_hz, modal.kinds) if k == "torsion"]
        res = paper_runs(bridge, dt, [("mf", "direct", True)])["mf"]
        results[name] = (f_t, res)
        rows.append((name, f"{f_t[0]:.4f}", f"{f_t[1]:.4f}",
                     *(f"{1e3 * np.min(res[node]):.4f}" for node, _ in PAPER_NODES)))
        values.update({f"torsion1_{name}": f_t[0], f"torsion2_{name}": f_t[1],
                       **{f"min_{node.lower().replace(' ', '')}_{name}": np.min(res[node]) for node, _ in PAPER_NODES}})
    f_v, f_b = results["vlasov"][0][0], results["benscoter"][0][0]
    file = "paper_torsion_theories.png"
    figure = PaperTheoriesFigure(
        file=file,
        title=f"Paper case, moving forces ({PAPER_QC1.total_mass:g} kg, {PAPER_QC2.total_mass:g} kg) at "
              f"{PAPER_SPEED:g} m/s, direct basis",
        node_titles=tuple(f"{node}: mid-span, y = {signed_y(y)} m" for node, y in PAPER_NODES), theories=theories,
        torsion_1=tuple(results[name][0][0] for name in theories),
        t=tuple(results[name][1]["t"] for name in theories),
        w=tuple(np.vstack([results[name][1][node] for node, _ in PAPER_NODES]) for name in theories),
        duration=PAPER_DURATION,
    )
    details = (
        f"Bundled scenario `paper-double-tee` (40 elements, rigid ends: warping restrained; Rayleigh 2 % at "
        f"vertical-1 and torsion-1 of each model) with `torsion` switched; section I_ws = {section.I_ws:.4g} m4 "
        f"(FE warping shear constant, docs/theory.md §10.2). Moving forces as in the paper case, dt = {dt} s.",
        Table(("torsion", "torsion-1 [Hz]", "torsion-2 [Hz]", *(f"{n} peak [mm]" for n, _ in PAPER_NODES)),
              tuple(rows)),
        f"Benscoter lowers the first torsional frequency by {100 * (1 - f_b / f_v):.1f} % ({f_v:.3f} -> {f_b:.3f} Hz).",
    )
    return StudyResult((CaseResult(
        name="Paper case, Vlasov vs Benscoter torsion: frequencies and moving-force peaks (informational)",
        reference="none (the issue quotes a 3D shell model about 10 % below the Vlasov torsion-1, 4.51 Hz)",
        metric="frequencies and peaks only", error=None, tolerance=None, passed=True, figures=(file,),
        details=details, values={**values, "I_ws": float(section.I_ws or math.nan)},
    ),), (figure,))


@dataclass(frozen=True)
class Vbi2dFigure(FigureData):
    """VBI-2D's sprung vehicle: mid-span deflection (m) with the published peak, body acceleration (m/s^2).

    ``a_ref`` is the modal reference at the times ``t``; ``a_fe`` cosim's at ``t_body``.
    """

    title: str
    n_elements: int
    ref_modes: int
    t: npt.NDArray[np.float64]
    w_fe: npt.NDArray[np.float64]
    w_ref: npt.NDArray[np.float64]
    peak_t: float
    peak_w: float
    t_body: npt.NDArray[np.float64]
    a_fe: npt.NDArray[np.float64]
    a_ref: npt.NDArray[np.float64]


def vbi2d_sprung_vehicle(modes: int, rtol: float) -> StudyResult:
    """VBI-2D's verification case 'SprungVeh' on an Euler-Bernoulli beam: its published peak, and a modal ODE.

    Args:
        modes: sine modes of the independent modal reference.
        rtol: relative tolerance of the reference's ODE solve (``atol = 1e-3 rtol``).
    """
    bridge, traffic, crossing = vbi2d_sprung_case()
    p = VBI2D_SPRUNG
    res = simulate(bridge, traffic, crossing, SolverSettings(dt=1e-3, gravity=GRAVITY), [Sensor("mid", p["L"] / 2)])
    w = res.sensors["mid"]
    k = int(np.argmin(w))
    ref_w, ref_a = sprung_mass_modal_solution(res.t, p["L"], p["E"] * p["I"], p["m"], p["m_v"], p["k_v"], 0.0, p["v"],
                                              gravity=GRAVITY, n_modes=modes, rtol=rtol, atol=rtol * 1e-3)
    body = res.vehicle("sprung")
    file = "vbi2d_sprung_mass.png"
    figure = Vbi2dFigure(
        file=file,
        title="VBI-2D 'SprungVeh': 5750 kg on 1.595 MN/m at 25 m/s, L = 25 m, EI = 4.865e10 N m², 18358 kg/m",
        n_elements=bridge.n_elements, ref_modes=modes, t=res.t, w_fe=w, w_ref=ref_w, peak_t=p["peak_t"],
        peak_w=p["peak_w"], t_body=body["t"], a_fe=body["body_acceleration"], a_ref=ref_a,
    )
    w_peak, t_peak = float(w[k]), float(res.t[k])
    k_ref = int(np.argmin(ref_w))
    diff_w = rel_peak(w, ref_w)
    diff_a = rel_peak(np.interp(res.t, body["t"], body["body_acceleration"]), ref_a)
    error = abs(w_peak / p["peak_w"] - 1.0)
    return StudyResult((CaseResult(
        name="VBI-2D sprung vehicle: mid-span peak",
        reference="VBI-2D verification case 'SprungVeh' (D. Cantero, github.com/DanielCanteroNTNU/VBI-2D, "
                  "V01_Analytical_Verification_Examples.m): -0.41855 mm at 0.436 s",
        metric=f"abs(w_peak / w_peak,ref - 1); the peak's time must also lie within {TOL_VBI2D_PEAK_TIME:g} s "
               "of the reference's",
        error=error, tolerance=TOL_VBI2D,
        passed=judge(error, TOL_VBI2D) and abs(t_peak - p["peak_t"]) <= TOL_VBI2D_PEAK_TIME, figures=(file,),
        details=(f"The model of `examples/scenarios/vbi2d-sprung-mass.toml` (bending = \"euler-bernoulli\", "
                 f"mass_per_length = 18358 kg/m, rotary_inertia = false, quarter-car with m_w = 0, 20 elements, "
                 f"dt = 1 ms, entering at x = 0 at t = 0). Peak: "
                 f"cosim {1e3 * w_peak:.5f} mm at {t_peak:.3f} s; VBI-2D -0.41855 mm at 0.436 s; independent modal "
                 f"ODE {1e3 * ref_w.min():.5f} mm at {res.t[k_ref]:.3f} s. Max abs difference to the "
                 f"modal ODE over the crossing: {diff_w:.2e} of its peak (deflection), "
                 f"{diff_a:.2e} (body acceleration).",),
        values={"peak_w": w_peak, "peak_t": t_peak, "peak_w_ref": p["peak_w"], "peak_t_ref": p["peak_t"],
                "peak_w_modal": float(ref_w.min()), "peak_t_modal": float(res.t[k_ref]),
                "modal_difference_w": diff_w, "modal_difference_a": diff_a},
    ),), (figure,))
