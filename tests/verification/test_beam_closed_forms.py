"""The 7-DOF beam against closed-form solutions (DESIGN.md section 8).

Each test names the source of its reference value and states its tolerance.
"""
from __future__ import annotations

import numpy as np
import pytest
from _beams import STEEL, doubly_symmetric, monosymmetric, rectangle

from cosim.core.bridge import PointLoad, build_bridge
from cosim.core.element import DOF_INDEX
from cosim.validation.references import (
    cantilever_tip_load_deflection,
    euler_bernoulli_ss_frequency_hz,
    lateral_torsional_frequencies_hz,
    midspan_torque_twist,
    ss_point_load_deflection,
    timoshenko_ss_frequency_hz,
    torsional_frequencies_hz,
)

# Tolerances (relative unless stated).
NODAL_EXACT = 1e-9  # locking-free Timoshenko element: exact at the nodes for point loads
FREQ_FE_40 = 2e-4  # 40 elements, first modes, bending without shear / torsion
# Deep Timoshenko beam, 40 elements, first 4 modes: the interdependent element has a
# constant shear strain per element, so with real shear flexibility its
# eigenvalues converge at O(h^2) (measured rate 2.0), not O(h^4).
FREQ_TIMOSHENKO_40 = 2e-3
TORSION_STATIC = 2e-4  # Hermite torsion vs hyperbolic closed form, 40 elements
E, G, RHO = STEEL.E, STEEL.G, STEEL.rho


def _vertical_modes(bridge, count=30):
    modal = bridge.modes(count)
    return np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == "vertical"])


# ----------------------------------------------------------------- statics
@pytest.mark.parametrize("a_over_l", [0.5, 0.3])
def test_simply_supported_timoshenko_deflection_is_exact_at_the_load(a_over_l):
    """Deep beam (L/h = 5): bending + shear deflection under a point load."""
    sec = rectangle(0.3, 1.2)
    L, P = 6.0, -2.0e5
    bridge = build_bridge([L], 20, STEEL, sec, ["pinned", "fork"])
    a = a_over_l * L
    b = L - a
    d = bridge.static([PointLoad(a, 0.0, P)]).deck_displacement(a, 0.0)
    # Timoshenko (e.g. Gere & Timoshenko, Mechanics of Materials): P a^2 b^2/(3 E I L) + P a b/(k G A L).
    ref = float(ss_point_load_deflection(a, a, L, P, E * sec.I_y, G * sec.A_sz))
    shear_part = P * a * b / (G * sec.A_sz * L) / ref
    assert shear_part > 0.1, "the case must exercise shear deformation"
    assert d == pytest.approx(ref, rel=NODAL_EXACT)


def test_cantilever_timoshenko_tip_deflection_is_exact():
    sec = rectangle(0.3, 1.2)
    L, P = 4.0, -1.0e5
    bridge = build_bridge([L], 8, STEEL, sec, ["fixed", "free"])
    d = bridge.static([PointLoad(L, 0.0, P)]).deck_displacement(L, 0.0)
    # Cantilever with shear: P L^3 / (3 E I) + P L / (k G A)  (Timoshenko & Gere).
    ref = float(cantilever_tip_load_deflection(L, L, P, E * sec.I_y, G * sec.A_sz))
    assert d == pytest.approx(ref, rel=NODAL_EXACT)
    # Rotation at the tip: P L^2 / (2 E I) (shear adds none); theta_y = -w' for bending.
    theta_y = bridge.static([PointLoad(L, 0.0, P)]).field("theta_y", [L])[0]
    assert -theta_y == pytest.approx(P * L**2 / (2 * E * sec.I_y), rel=NODAL_EXACT)


def test_two_span_continuous_beam_midspan_deflection():
    """Continuity over the inner support, Euler-Bernoulli limit (huge shear area)."""
    sec = rectangle(0.3, 0.6, shear_factor=1e6)
    L, P = 10.0, -1.0e5
    bridge = build_bridge([L, L], 10, STEEL, sec, ["pinned", "fork", "fork"])
    d = bridge.static([PointLoad(L / 2, 0.0, P)]).deck_displacement(L / 2, 0.0)
    # Two equal spans, point load at mid-span of one: 23 P L^3 / (1536 E I)  (Roark, Table 8.2 / moment distribution).
    assert d == pytest.approx(23 * P * L**3 / (1536 * E * sec.I_y), rel=1e-6)


# ----------------------------------------------------------- bending modes
def _timoshenko_ss_frequency(n, L, sec):
    """Smaller root of the simply supported Timoshenko frequency equation (Han, Benaroya & Wei, JSV 1999)."""
    return timoshenko_ss_frequency_hz(n, L, STEEL, sec)


def test_simply_supported_timoshenko_frequencies():
    sec = rectangle(0.3, 0.8)
    L = 6.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    fe = _vertical_modes(bridge)[:4]
    ref = np.array([_timoshenko_ss_frequency(n, L, sec) for n in range(1, 5)])
    euler = euler_bernoulli_ss_frequency_hz(np.arange(1, 5), L, E * sec.I_y, RHO * sec.A)
    assert euler[0] / ref[0] > 1.02 and euler[3] / ref[3] > 1.3, "deep beam: shear and rotary inertia must matter"
    np.testing.assert_allclose(fe, ref, rtol=FREQ_TIMOSHENKO_40)


def test_slender_beam_reaches_the_euler_bernoulli_limit():
    sec = rectangle(0.05, 0.1, shear_factor=1e6)  # no shear flexibility; rotary inertia stays
    L = 10.0  # L/h = 100
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    fe = _vertical_modes(bridge)[:3]
    # Euler-Bernoulli: f_n = (n pi / L)^2 sqrt(EI / (rho A)) / (2 pi); rotary inertia lowers it by
    # about (n pi r / L)^2 / 2 < 4e-4 for n <= 3 here (Rayleigh beam).
    euler = euler_bernoulli_ss_frequency_hz(np.arange(1, 4), L, E * sec.I_y, RHO * sec.A)
    np.testing.assert_allclose(fe, euler, rtol=5e-4)
    assert np.all(fe < euler)


def _mode3_error_rates(sec, L):
    ref = _timoshenko_ss_frequency(3, L, sec)
    errors = np.array(
        [_vertical_modes(build_bridge([L], n_el, STEEL, sec, ["pinned", "fork"]))[2] - ref for n_el in (4, 8, 16)]
    )
    assert np.all(errors > 0), "consistent mass converges from above"
    return np.log2(errors[:-1] / errors[1:])


def test_frequency_convergence_rates():
    """Eigenvalue error ~ h^(2(p+1-m)) (Strang & Fix): O(h^4) for the cubic bending field in the
    Euler-Bernoulli limit; O(h^2) with shear flexibility, where the interdependent element's shear
    strain is constant per element."""
    slender_rates = _mode3_error_rates(rectangle(0.3, 0.8, shear_factor=1e6), 6.0)
    deep_rates = _mode3_error_rates(rectangle(0.3, 0.8), 6.0)
    assert np.all(slender_rates > 3.7), slender_rates
    assert np.all((deep_rates > 1.9) & (deep_rates < 2.3)), deep_rates


# ------------------------------------------------------- non-uniform torsion
def _midspan_torque_twist(L, n_el, supports, T=1.0e4):
    sec = doubly_symmetric()
    bridge = build_bridge([L], n_el, STEEL, sec, supports)
    f = np.zeros(bridge.ndof)
    mid_node = n_el // 2
    f[7 * mid_node + DOF_INDEX["theta_x"]] = T
    res = bridge.static(f=f)
    return res.field("theta_x", [L / 2])[0], sec, T


def test_non_uniform_torsion_warping_free_ends():
    L = 10.0
    theta, sec, T = _midspan_torque_twist(L, 40, ["pinned", "fork"])
    lam = np.sqrt(G * sec.J / (E * sec.I_w))
    # GJ theta' - E I_w theta''' = T/2, theta = theta'' = 0 at the ends (Vlasov; Kollbrunner & Basler, Torsion, ch. 4):
    ref = float(midspan_torque_twist(L / 2, L, T, G * sec.J, E * sec.I_w, "free"))  # T/(2GJ) (L/2 - tanh(lam L/2)/lam)
    assert 1 < lam * L < 10, "mixed torsion regime"
    assert theta == pytest.approx(ref, rel=TORSION_STATIC)


def test_non_uniform_torsion_warping_restrained_ends():
    L = 10.0
    theta, sec, T = _midspan_torque_twist(L, 40, ["rigid-end", "rigid-end"])
    # Same equation with theta = theta' = 0 at the ends (Kollbrunner & Basler):
    ref = float(midspan_torque_twist(L / 2, L, T, G * sec.J, E * sec.I_w, "restrained"))  # T/(2GJ) (L/2 - 2 tanh(lam L/4)/lam)
    free, _, _ = _midspan_torque_twist(L, 40, ["pinned", "fork"])
    assert theta < 0.9 * free, "restraining warping must stiffen the section noticeably"
    assert theta == pytest.approx(ref, rel=TORSION_STATIC)


def test_torsional_frequencies_with_warping():
    sec = doubly_symmetric()
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    modal = bridge.modes(40)
    fe = np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == "torsion"])[:3]
    # omega^2 = (GJ k^2 + E I_w k^4) / (rho I_p + rho I_w k^2), k = n pi / L, fork supports (DESIGN.md section 8).
    ref = torsional_frequencies_hz(np.arange(1, 4), L, STEEL, sec)
    np.testing.assert_allclose(fe, ref, rtol=FREQ_FE_40)


def test_coupled_lateral_torsional_frequencies_of_a_monosymmetric_section():
    sec = monosymmetric(e_z=0.12)
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    modal = bridge.modes(6)
    # Fork supports, sine modes in v and theta_x, n = 1..8 (Timoshenko & Gere, Theory of Elastic Stability;
    # Rayleigh beam: rotary inertia rho I_z k^2 and warping inertia rho I_w k^2 kept):
    # det([[EI_z k^4 - w^2 rho(A + I_z k^2), -w^2 rho A e_z], [-w^2 rho A e_z, GJ k^2 + E I_w k^4 - w^2 rho (I_ps + I_w k^2)]]) = 0
    ref = lateral_torsional_frequencies_hz(8, L, STEEL, sec)[:6]
    assert all(kind.startswith("coupled") or kind in ("lateral", "torsion") for kind in modal.kinds)
    np.testing.assert_allclose(modal.f_hz[:6], ref, rtol=FREQ_FE_40)
    # Without the offset the pair would be uncoupled: coupling must move the first frequency by > 1 %.
    uncoupled = build_bridge([L], 40, STEEL, monosymmetric(e_z=0.0), ["pinned", "fork"]).modes(1).f_hz[0]
    assert abs(modal.f_hz[0] / uncoupled - 1) > 0.01


# ------------------------------------------------------------ twist sign
def test_eccentric_load_twists_with_the_documented_sign():
    """A downward load on the left (y > y_S) twists negatively; over S it does not twist."""
    sec = rectangle(2.0, 1.0)
    L = 10.0
    bridge = build_bridge([L], 10, STEEL, sec, ["rigid-end", "rigid-end"])
    left = bridge.static([PointLoad(L / 2, 0.8, -1e5)])
    centre = bridge.static([PointLoad(L / 2, 0.0, -1e5)])
    assert left.field("theta_x", [L / 2])[0] < 0
    # The left edge goes down more than the axis, the right edge less.
    assert left.deck_displacement(L / 2, 1.0) < left.deck_displacement(L / 2, 0.0) < left.deck_displacement(L / 2, -1.0)
    assert abs(centre.field("theta_x", [L / 2])[0]) < 1e-14
    # w(y) = w_S + (y - y_S) theta_x, evaluated directly from the nodal DOFs at mid-span.
    node = 5
    w_s, theta = left.d[7 * node + DOF_INDEX["w"]], left.d[7 * node + DOF_INDEX["theta_x"]]
    assert left.deck_displacement(L / 2, 1.0) == pytest.approx(w_s + 1.0 * theta, rel=1e-12)


def test_load_over_the_shear_centre_does_not_twist_an_eccentric_section():
    sec = monosymmetric(e_z=0.0)
    from dataclasses import replace

    # Shear centre 0.05 m to the left of the centroid (an unsymmetric deck).
    sec = replace(sec, y_s=0.05, y_c=0.0)
    bridge = build_bridge([8.0], 8, STEEL, sec, ["rigid-end", "rigid-end"])
    over_s = bridge.static([PointLoad(4.0, 0.05, -1e4)])
    over_c = bridge.static([PointLoad(4.0, 0.0, -1e4)])
    assert abs(over_s.field("theta_x", [4.0])[0]) < 1e-15
    assert over_c.field("theta_x", [4.0])[0] > 0  # load right of S lifts the left side
