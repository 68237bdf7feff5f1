"""Effective modal masses against closed forms, and the mechanism check."""
from __future__ import annotations

import math

import pytest

from cosim.core.bridge import build_bridge
from cosim.core.section import Material, SectionProperties
from cosim.errors import ModelError

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))
TOL_MASS_FRACTION = 0.005  # relative; 80 elements, consistent mass


def test_first_vertical_mode_of_a_simply_supported_beam_carries_8_over_pi_squared_of_the_mass():
    # Reference: simply supported uniform beam, mode sin(pi x / L): (int m phi)^2 / (m L int phi^2) = 8 / pi^2
    # (Chopra, Dynamics of Structures, effective modal mass of a uniform beam).
    bridge = build_bridge([40.0], 80, MAT, SEC, ["pinned", "fork"])
    modal = bridge.modes(4)
    first = modal.index_of("vertical-1")
    assert modal.participation["vertical"][first] == pytest.approx(8.0 / math.pi**2, rel=TOL_MASS_FRACTION)


def test_a_shallow_finely_meshed_deck_is_not_taken_for_a_mechanism():
    # A 40 m slab in 1000 elements: its first eigenvalue is 2e-11 of the largest K_ii / M_ii (the 4 cm
    # elements' axial terms), which the former check (1e-10 of that) took for a rigid-body mode.
    slab = SectionProperties(A=10.0, y_c=0.0, z_c=0.0, I_y=0.05, I_z=100.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                             J=0.2, I_w=0.01, A_sy=8.0, A_sz=8.0, deck_y=(-6.6, 6.6))
    bridge = build_bridge([40.0], 1000, MAT, slab, ["pinned", "fork"])
    # Euler-Bernoulli reference f1 = (pi / 2 L^2) sqrt(EI / m): within 1 % (shear and rotary inertia are tiny).
    f_eb = math.pi / (2 * 40.0**2) * math.sqrt(MAT.E * 0.05 / (MAT.rho * 10.0))
    assert bridge.modes(1).f_hz[0] == pytest.approx(f_eb, rel=0.01)


def test_a_mechanism_is_refused_when_the_bridge_is_built():
    with pytest.raises(ModelError, match="rigid-body mode: .* restrain more DOFs"):
        build_bridge([40.0], 10, MAT, SEC, [["w"], ["w"]])  # nothing holds the twist or the axial motion
