"""The element's optional theories (docs/theory.md §10) against closed forms and a published benchmark.

Benscoter torsion (shear-deformable warping) against its static closed form
and its frequency equation, with the observed mesh-convergence rate;
Euler-Bernoulli bending with a given mass per length against the classical
beam; the VBI-2D sprung-vehicle case against its published peak. Each test
names its reference and states its tolerance.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from _beams import STEEL, doubly_symmetric

import cosim
from cosim import testing as ct
from cosim.core.bridge import BeamTheory, PointLoad, build_bridge
from cosim.core.element import DOF_INDEX
from cosim.core.section import section_from_constants
from cosim.run.scenario import load_scenario
from cosim.validation.references import (
    VBI2D_SPRUNG,
    benscoter_midspan_torque_twist,
    benscoter_torsional_frequencies_hz,
    euler_bernoulli_ss_frequency_hz,
    midspan_torque_twist,
    torsional_frequencies_hz,
)

EXAMPLES = Path(cosim.__file__).resolve().parents[1] / "examples" / "scenarios"
E, G = STEEL.E, STEEL.G
BENSCOTER = BeamTheory(torsion="benscoter")
# The doubly symmetric I-like section of the Vlasov checks with a warping shear constant small enough
# that secondary torsion matters (a stocky girder; I_ws/I_w = 10 1/m^2, an I-section of flange width ~1 m).
STOCKY = replace(doubly_symmetric(), I_ws=2.0e-5)

# Tolerances. The interdependent (theta_x, psi) interpolation is exact for E I_w and G I_ws alone, but GJ makes
# the exact solution hyperbolic: nodal values converge at O(h^2), 40 elements give 2.7e-5 (restrained ends).
BENSCOTER_STATIC_40 = 5e-5
# Frequencies of the first three torsional modes, 40 elements (measured 2e-6, 7e-5, 4e-4): O(h^2) in the constant
# secondary shear strain per element, as the Timoshenko element with shear flexibility.
BENSCOTER_FREQ_40 = 5e-4
EB_NODAL_EXACT = 1e-9  # Hermite cubics are exact at the nodes for point loads
EB_FREQ_40 = 2e-4  # consistent-mass Hermite beam, 40 elements, first four modes (O(h^4))
VBI2D_PEAK_REL = 5e-3  # the tolerance: 0.5 % of the published peak


def _torque_at_midspan(bridge, T):
    f = np.zeros(bridge.ndof)
    f[7 * (bridge.n_elements // 2) + DOF_INDEX["theta_x"]] = T
    return bridge.static(f=f).field("theta_x", bridge.nodes_x)


# ------------------------------------------------------------- Benscoter statics
@pytest.mark.parametrize("warping, supports", [("restrained", ["rigid-end", "rigid-end"]),
                                               ("free", ["pinned", "fork"])])
def test_benscoter_twist_under_a_midspan_torque_matches_the_closed_form(warping, supports):
    L, T = 10.0, 1.0e4
    bridge = build_bridge([L], 40, STEEL, STOCKY, supports, theory=BENSCOTER)
    fe = _torque_at_midspan(bridge, T)
    # GJ theta' + G I_ws (theta' - psi) = T/2, E I_w psi'' + G I_ws (theta' - psi) = 0 (Benscoter 1954), solved in
    # closed form in docs/theory.md §10.4 (psi = 0 at restrained ends, psi' = 0 at forks, psi(L/2) = 0).
    ref = benscoter_midspan_torque_twist(bridge.nodes_x, L, T, G * STOCKY.J, E * STOCKY.I_w, G * STOCKY.I_ws, warping)
    assert np.max(np.abs(fe - ref)) / np.max(np.abs(ref)) < BENSCOTER_STATIC_40
    # The warping shear matters here: Vlasov (psi = theta_x') is stiffer by several per cent.
    vlasov = midspan_torque_twist(L / 2, L, T, G * STOCKY.J, E * STOCKY.I_w, warping)
    assert ref[20] > 1.02 * vlasov


def test_benscoter_static_twist_converges_at_second_order():
    L, T = 10.0, 1.0e4
    errors = []
    for n_el in (10, 20, 40):
        bridge = build_bridge([L], n_el, STEEL, STOCKY, ["rigid-end", "rigid-end"], theory=BENSCOTER)
        ref = benscoter_midspan_torque_twist(bridge.nodes_x, L, T, G * STOCKY.J, E * STOCKY.I_w, G * STOCKY.I_ws,
                                             "restrained")
        errors.append(np.max(np.abs(_torque_at_midspan(bridge, T) - ref)) / np.max(np.abs(ref)))
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(rates > 1.8), rates


# ---------------------------------------------------------- Benscoter frequencies
def _torsion_frequencies(bridge, count=3):
    modal = bridge.modes(40)
    return np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == "torsion"])[:count]


def test_benscoter_torsional_frequencies_match_the_frequency_equation():
    L = 10.0
    fe = _torsion_frequencies(build_bridge([L], 40, STEEL, STOCKY, ["pinned", "fork"], theory=BENSCOTER))
    # theta = sin(kx), psi = cos(kx): (G_t k^2 - w^2 rho I_ps)(E I_w k^2 + G I_ws - w^2 rho I_w) - (G I_ws k)^2 = 0,
    # smaller root (docs/theory.md §10.4; the torsional analogue of Han, Benaroya & Wei 1999).
    ref = benscoter_torsional_frequencies_hz(np.arange(1, 4), L, STEEL, STOCKY)
    np.testing.assert_allclose(fe, ref, rtol=BENSCOTER_FREQ_40)
    vlasov = torsional_frequencies_hz(np.arange(1, 4), L, STEEL, STOCKY)
    assert ref[2] < 0.95 * vlasov[2], "secondary torsion must lower the higher torsional modes noticeably"


def test_benscoter_frequencies_converge_at_second_order():
    L = 10.0
    ref = benscoter_torsional_frequencies_hz(3, L, STEEL, STOCKY)
    errors = np.array([_torsion_frequencies(build_bridge([L], n, STEEL, STOCKY, ["pinned", "fork"],
                                                         theory=BENSCOTER))[2] - ref for n in (10, 20, 40)])
    assert np.all(errors > 0), "consistent mass converges from above"
    rates = np.log2(errors[:-1] / errors[1:])
    assert np.all((rates > 1.9) & (rates < 2.3)), rates


def test_the_paper_bridge_benscoter_torsion_frequency_is_lower_and_mesh_converged():
    """The bundled double-tee (rigid ends, warping restrained): Benscoter lowers torsion-1; 40 elements suffice."""
    scenario = ct.scenario("paper-double-tee", bridge={"torsion": "benscoter"})
    section = scenario.build_section()
    assert section.I_ws == pytest.approx(8.35, rel=0.01)  # FE warping shear constant, m^4 (docs/theory.md §10.5)
    f40 = _torsion_frequencies(scenario.build_bridge(), 1)[0]
    fine = ct.scenario("paper-double-tee", bridge={"torsion": "benscoter", "elements_per_span": 80})
    f80 = _torsion_frequencies(fine.build_bridge(), 1)[0]
    vlasov = _torsion_frequencies(load_scenario("paper-double-tee").build_bridge(), 1)[0]
    assert abs(f40 / f80 - 1) < 1e-3
    assert 0.90 * vlasov < f40 < 0.97 * vlasov


# --------------------------------------------------------------- Euler-Bernoulli
def _eb_beam(n_el=40, L=20.0):
    section = section_from_constants(A=2.0, I_y=0.8, I_z=5.0, J=1.0, mass_per_length=6000.0, rotary_inertia=False,
                                     deck_y=(-2.0, 2.0))
    theory = BeamTheory(bending="euler-bernoulli")
    return build_bridge([L], n_el, STEEL, section, ["pinned", "fork"], theory=theory), section


def test_euler_bernoulli_deflection_is_exact_at_the_load():
    bridge, section = _eb_beam(n_el=10)
    L, a, P = bridge.length, 6.0, -1.0e5
    d = bridge.static([PointLoad(a, 0.0, P)]).deck_displacement(a, 0.0)
    # P a^2 b^2 / (3 E I L) (Gere & Timoshenko, Mechanics of Materials): no shear deflection.
    assert d == pytest.approx(P * a**2 * (L - a) ** 2 / (3 * E * section.I_y * L), rel=EB_NODAL_EXACT)


def test_euler_bernoulli_frequencies_with_a_mass_per_length():
    bridge, section = _eb_beam()
    modal = bridge.modes(20)
    fe = np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == "vertical"])[:4]
    # f_n = (n pi / L)^2 sqrt(E I / m) / (2 pi) with the given m (no rho A, no rotary inertia, no shear).
    ref = euler_bernoulli_ss_frequency_hz(np.arange(1, 5), bridge.length, E * section.I_y, 6000.0)
    np.testing.assert_allclose(fe, ref, rtol=EB_FREQ_40)
    assert np.all(fe > ref), "consistent mass converges from above"


# ------------------------------------------------------------------------ VBI-2D
def test_the_vbi2d_sprung_vehicle_case_within_half_a_percent():
    """examples/scenarios/vbi2d-sprung-mass.toml against VBI-2D's verification case "SprungVeh".

    Reference: D. Cantero, VBI-2D (github.com/DanielCanteroNTNU/VBI-2D), V01_Analytical_Verification_Examples.m: 5750 kg
    body on 1.595e6 N/m (no wheel mass, no damper) at 25 m/s on a 25 m beam (E I = 3.5e10 x 1.3901 N m2,
    18358 kg/m), entering at x = 0 at t = 0; mid-span peak -0.41855 mm at 0.436 s.
    """
    res = ct.run(EXAMPLES / "vbi2d-sprung-mass.toml")
    w = res.channels["mid"]
    k = int(np.argmin(w))
    assert w[k] == pytest.approx(VBI2D_SPRUNG["peak_w"], rel=VBI2D_PEAK_REL)
    assert res.t[k] == pytest.approx(VBI2D_SPRUNG["peak_t"], abs=0.005)
    # The model is the reference's: the span's first frequency is the classical one.
    f1 = res.frequencies(1)[0]
    ref = euler_bernoulli_ss_frequency_hz(1, 25.0, VBI2D_SPRUNG["E"] * VBI2D_SPRUNG["I"], VBI2D_SPRUNG["m"])
    assert f1 == pytest.approx(float(ref), rel=1e-4)


def test_the_example_file_and_the_validation_case_are_one_model():
    """cosim validate builds the VBI-2D case through the Python API; it must be the example file's model."""
    from cosim.validation.references import vbi2d_sprung_case

    api, _, _ = vbi2d_sprung_case()
    from_file = load_scenario(EXAMPLES / "vbi2d-sprung-mass.toml").build_bridge()
    assert (api.K != from_file.K).nnz == 0 and (api.M != from_file.M).nnz == 0
    assert api.theory == from_file.theory and api.section == replace(from_file.section, source=api.section.source)


# ----------------------------------------------------------- one deck row per theory
THEORIES = [BeamTheory(), BENSCOTER, BeamTheory(bending="euler-bernoulli"),
            BeamTheory(torsion="benscoter", bending="euler-bernoulli")]


@pytest.mark.parametrize("theory", THEORIES, ids=lambda t: f"{t.torsion}-{t.bending}")
def test_the_deck_row_is_the_elements_own_for_every_theory(theory):
    """The contact row (5.1) of the compiled loop, the vectorised and the scalar rows, and the deflected shape agree.

    The loop reads the per-element coefficients of BridgeModel.deck_coefficients and the DOFs of
    element.DECK_POINT_DOFS; with Benscoter torsion the twist is the interdependent field of §10.3.
    """
    from cosim.core import kernels
    from cosim.core.element import DECK_POINT_DOFS, NODE_DOFS

    section = replace(doubly_symmetric(), y_s=0.05, z_s=0.1, I_ws=2.0e-5)  # S off C: twist and bending coupled
    bridge = build_bridge([10.0, 6.0], [8, 5], STEEL, section, ["rigid-end", "fork", "warping-restrained"],
                          theory=theory)
    res = bridge.static([PointLoad(4.1, 0.25, -1e5), PointLoad(12.3, -0.2, -5e4)])
    x = np.array([0.7, 4.1, 9.99, 12.3, 15.6])
    y = np.array([0.25, -0.3, 0.1, -0.2, 0.3])
    c_w, c_t, _ = bridge.deck_coefficients
    deck = kernels.DeckArrays(bridge.nodes_x, np.ascontiguousarray(c_w), np.ascontiguousarray(c_t),
                              float(section.y_s), float(bridge.length), np.array(DECK_POINT_DOFS, dtype=np.int64),
                              NODE_DOFS)
    elems, vals, geo = np.zeros(len(x), dtype=np.int64), np.zeros((len(x), 3, 14)), np.zeros((len(x), 3))
    kernels.contact_rows(x, y, np.ones(len(x)), deck, elems, vals, geo)  # speeds > 0: the +x rule at nodes
    dofs, values = bridge.deck_rows(x, y)
    h = 1e-4
    for i in range(len(x)):
        row = bridge.deck_point_row(x[i], y[i])
        np.testing.assert_allclose(vals[i], row.values, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(values[i], row.values, rtol=1e-12, atol=1e-14)
        # Only DECK_POINT_DOFS carry the row (the loop reads no other).
        others = np.setdiff1d(np.arange(14), DECK_POINT_DOFS)
        assert np.all(row.values[:, others] == 0.0)
        w = res.deck_displacement(x[i], y[i])
        assert w == pytest.approx(float(res.field("w_deck", [x[i]], y=y[i])[0]), rel=1e-12)
        slope = (res.deck_displacement(x[i] + h, y[i]) - res.deck_displacement(x[i] - h, y[i])) / (2 * h)
        assert row.values[1] @ res.d[row.dofs] == pytest.approx(slope, rel=1e-6, abs=1e-12)


def test_a_crawling_force_on_a_benscoter_deck_is_static():
    """The time integration with Benscoter torsion: a force crawling along an eccentric path reads the static
    (quasi-static, reciprocity §7.4) deflection at every step (DAF 1), so loop, sensors and statics agree."""
    from cosim.core.quasistatic import quasi_static
    from cosim.core.simulation import Sensor, SolverSettings, simulate
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
    from cosim.core.vehicles import MovingForce

    section = replace(doubly_symmetric(), y_s=0.05, I_ws=2.0e-5)
    bridge = build_bridge([10.0], 10, STEEL, section, ["rigid-end", "rigid-end"], theory=BENSCOTER)
    traffic = ScriptedTraffic((ScriptedVehicle("F", MovingForce(2000.0), 0.25, 0.05),), 10.0)
    sensors = [Sensor("edge", 5.0, 0.3), Sensor("axis", 5.0, 0.0)]
    duration, dt = 200.0, 0.02
    dynamic = simulate(bridge, traffic, duration, SolverSettings(dt=dt, gravity=9.81), sensors)
    static = quasi_static(bridge, traffic, duration, dt, sensors)
    for name in ("edge", "axis"):
        peak = np.max(np.abs(static.sensors[name]))
        # 0.05 m/s over a 10 m span: the free vibration left is 3e-4 of the peak (measured); 2e-3 allowed.
        assert np.max(np.abs(dynamic.sensors[name] - static.sensors[name])) < 2e-3 * peak
    assert np.min(dynamic.sensors["edge"]) < 2 * np.min(dynamic.sensors["axis"])  # the eccentric load twists
