"""The 7-DOF beam against closed-form solutions the validation cases do not cover (docs/theory.md §8).

Static deflections, Timoshenko, torsional and lateral-torsional frequencies and
non-uniform torsion are validation cases (``cosim validate``), judged in
``test_cases.py``. Each test here names the source of its reference value and
states its tolerance.
"""
from __future__ import annotations

import numpy as np
import pytest
from _beams import STEEL, monosymmetric, rectangle

from cosim.core.bridge import PointLoad, build_bridge
from cosim.core.element import DOF_INDEX
from cosim.validation.references import euler_bernoulli_ss_frequency_hz, timoshenko_ss_frequency_hz

# Tolerances (relative unless stated).
NODAL_EXACT = 1e-9  # locking-free Timoshenko element: exact at the nodes for point loads
TWO_SPAN = 1e-6  # Euler-Bernoulli limit with a finite (1e6 x) shear area
RAYLEIGH_BEAM = 5e-4  # rotary inertia lowers the Euler-Bernoulli frequencies by < 4e-4 here
RATE_EULER_BERNOULLI = 3.7  # observed order of the eigenvalue error, expected 4
RATE_TIMOSHENKO = (1.9, 2.3)  # expected 2 (constant shear strain per element)
E, RHO = STEEL.E, STEEL.rho


def _vertical_modes(bridge, count=30):
    modal = bridge.modes(count)
    return np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == "vertical"])


# ----------------------------------------------------------------- statics
def test_cantilever_timoshenko_tip_rotation_is_exact():
    """The deflections are the validation cases "Timoshenko static deflection" (test_cases.py); this is the slope."""
    sec = rectangle(0.3, 1.2)
    L, P = 4.0, -1.0e5
    bridge = build_bridge([L], 8, STEEL, sec, ["fixed", "free"])
    # Rotation at the tip: P L^2 / (2 E I), shear adds none (Timoshenko & Gere); theta_y = -w'; tolerance 1e-9.
    theta_y = bridge.static([PointLoad(L, 0.0, P)]).field("theta_y", [L])[0]
    assert -theta_y == pytest.approx(P * L**2 / (2 * E * sec.I_y), rel=NODAL_EXACT)


def test_two_span_continuous_beam_midspan_deflection():
    """Continuity over the inner support, Euler-Bernoulli limit (huge shear area)."""
    sec = rectangle(0.3, 0.6, shear_factor=1e6)
    L, P = 10.0, -1.0e5
    bridge = build_bridge([L, L], 10, STEEL, sec, ["pinned", "fork", "fork"])
    d = bridge.static([PointLoad(L / 2, 0.0, P)]).deck_displacement(L / 2, 0.0)
    # Two equal spans, load at mid-span of one: 23 P L^3 / (1536 E I) (Roark, Table 8.2); tolerance 1e-6.
    assert d == pytest.approx(23 * P * L**3 / (1536 * E * sec.I_y), rel=TWO_SPAN)


# ----------------------------------------------------------- bending modes
def _timoshenko_ss_frequency(n, L, sec):
    """Smaller root of the simply supported Timoshenko frequency equation (Han, Benaroya & Wei, JSV 1999)."""
    return timoshenko_ss_frequency_hz(n, L, STEEL, sec)


def test_slender_beam_reaches_the_euler_bernoulli_limit():
    sec = rectangle(0.05, 0.1, shear_factor=1e6)  # no shear flexibility; rotary inertia stays
    L = 10.0  # L/h = 100
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    fe = _vertical_modes(bridge)[:3]
    # Euler-Bernoulli: f_n = (n pi / L)^2 sqrt(EI / (rho A)) / (2 pi); rotary inertia lowers it by
    # about (n pi r / L)^2 / 2 < 4e-4 for n <= 3 here (Rayleigh beam); tolerance 5e-4.
    euler = euler_bernoulli_ss_frequency_hz(np.arange(1, 4), L, E * sec.I_y, RHO * sec.A)
    np.testing.assert_allclose(fe, euler, rtol=RAYLEIGH_BEAM)
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
    strain is constant per element. Mode 3 on 4, 8, 16 elements (the validation case "Mesh convergence"
    checks mode 1)."""
    slender_rates = _mode3_error_rates(rectangle(0.3, 0.8, shear_factor=1e6), 6.0)
    deep_rates = _mode3_error_rates(rectangle(0.3, 0.8), 6.0)
    # Strang & Fix rates; tolerance: > 3.7 for 4, within 1.9-2.3 for 2.
    assert np.all(slender_rates > RATE_EULER_BERNOULLI), slender_rates
    lo, hi = RATE_TIMOSHENKO
    assert np.all((deep_rates > lo) & (deep_rates < hi)), deep_rates


# ------------------------------------------------------------ twist sign
def test_eccentric_load_twists_with_the_documented_sign():
    """A downward load on the left (y > y_S) twists negatively; over S it does not twist."""
    # Sign convention of docs/theory.md §1.4 (y > y_S is the left side, z up); a load over S: no twist to 1e-14 rad.
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
    # Definition of the shear centre (Timoshenko & Gere): a load through S bends without twist; 1e-15 rad.
    sec = monosymmetric(e_z=0.0)
    from dataclasses import replace

    # Shear centre 0.05 m to the left of the centroid (an unsymmetric deck).
    sec = replace(sec, y_s=0.05, y_c=0.0)
    bridge = build_bridge([8.0], 8, STEEL, sec, ["rigid-end", "rigid-end"])
    over_s = bridge.static([PointLoad(4.0, 0.05, -1e4)])
    over_c = bridge.static([PointLoad(4.0, 0.0, -1e4)])
    assert abs(over_s.field("theta_x", [4.0])[0]) < 1e-15
    assert over_c.field("theta_x", [4.0])[0] > 0  # load right of S lifts the left side
