"""Properties of the 7-DOF element that hold whatever the section (no closed form needed)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from cosim.core.element import (
    DOF_INDEX,
    FIELD_INDEX,
    BeamTheory,
    element_matrices,
    field_matrix,
    shear_parameters,
    torsion_parameter,
)
from cosim.core.section import Material, SectionProperties
from cosim.errors import ConfigError

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
# A deliberately general section: S off C in both directions and I_yz != 0.
GENERAL = SectionProperties(
    A=4.8, y_c=0.1, z_c=-0.4, I_y=2.1, I_z=40.0, I_yz=0.3, y_s=0.25, z_s=0.2,
    J=0.09, I_w=3.0, A_sy=2.5, A_sz=1.4, deck_y=(-6.6, 6.6),
)
L = 1.7


def _rigid_body_vectors():
    """Six rigid motions of a 2-node element of length L (u, v, w, rotations about x, y, z)."""
    vecs = []
    for name in ("u", "v", "w", "theta_x"):
        d = np.zeros(14)
        d[[DOF_INDEX[name], 7 + DOF_INDEX[name]]] = 1.0
        vecs.append(d)
    # Rotation about +y through node 1: theta_y = 1, w = -x.
    d = np.zeros(14)
    d[[DOF_INDEX["theta_y"], 7 + DOF_INDEX["theta_y"]]] = 1.0
    d[7 + DOF_INDEX["w"]] = -L
    vecs.append(d)
    # Rotation about +z: theta_z = 1, v = +x.
    d = np.zeros(14)
    d[[DOF_INDEX["theta_z"], 7 + DOF_INDEX["theta_z"]]] = 1.0
    d[7 + DOF_INDEX["v"]] = L
    vecs.append(d)
    return np.array(vecs).T


def test_element_matrices_are_symmetric_and_definite():
    k, m = element_matrices(L, MAT, GENERAL)
    np.testing.assert_array_equal(k, k.T)
    np.testing.assert_array_equal(m, m.T)
    ek = np.linalg.eigvalsh(k)
    assert ek[0] > -1e-9 * ek[-1], "K must be positive semi-definite"
    assert np.linalg.eigvalsh(m)[0] > 0, "consistent M must be positive definite"


def test_unsupported_element_has_exactly_six_rigid_body_modes():
    k, _ = element_matrices(L, MAT, GENERAL)
    r = _rigid_body_vectors()
    # Rigid motions produce no elastic forces (relative to the element's stiffness scale).
    assert np.max(np.abs(k @ r)) < 1e-9 * np.max(np.abs(k))
    ek = np.linalg.eigvalsh(k)
    assert np.sum(np.abs(ek) < 1e-9 * ek[-1]) == 6


def test_mass_matrix_carries_the_total_mass_and_the_shear_centre_offset():
    _, m = element_matrices(L, MAT, GENERAL)
    r = _rigid_body_vectors()
    # Rigid translation: kinetic energy 1/2 rho A L (exact, partition of unity).
    for j in range(3):
        assert r[:, j] @ m @ r[:, j] == pytest.approx(MAT.rho * GENERAL.A * L, rel=1e-12)
    # Coupling of a unit vertical translation with a unit twist: -rho A (y_s - y_c) L (from 2T').
    assert r[:, 2] @ m @ r[:, 3] == pytest.approx(-MAT.rho * GENERAL.A * (GENERAL.y_s - GENERAL.y_c) * L, rel=1e-12)
    assert r[:, 1] @ m @ r[:, 3] == pytest.approx(MAT.rho * GENERAL.A * (GENERAL.z_s - GENERAL.z_c) * L, rel=1e-12)


def test_shape_function_derivatives_match_finite_differences():
    phi_y, phi_z = shear_parameters(L, MAT, GENERAL)
    xi = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    for order in (1, 2):
        analytic = field_matrix(xi, L, phi_y, phi_z, order)
        lower = field_matrix(xi - h / L, L, phi_y, phi_z, order - 1)
        upper = field_matrix(xi + h / L, L, phi_y, phi_z, order - 1)
        fd = (upper - lower) / (2 * h)
        np.testing.assert_allclose(analytic, fd, atol=1e-5 * np.max(np.abs(analytic)))


def test_shape_functions_interpolate_the_nodal_values():
    phi_y, phi_z = shear_parameters(L, MAT, GENERAL)
    n = field_matrix([0.0, 1.0], L, phi_y, phi_z)
    for f, name in enumerate(("u", "v", "w", "theta_x", "theta_y", "theta_z")):
        for node in (0, 1):
            expected = np.zeros(14)
            expected[7 * node + DOF_INDEX[name]] = 1.0
            np.testing.assert_allclose(n[node, f], expected, atol=1e-12)
    # psi is the slope of theta_x at the nodes.
    n1 = field_matrix([0.0, 1.0], L, phi_y, phi_z, 1)
    assert n1[0, 3, DOF_INDEX["psi"]] == pytest.approx(1.0)
    assert n1[1, 3, 7 + DOF_INDEX["psi"]] == pytest.approx(1.0)


def test_shear_strain_is_constant_along_the_element():
    """Interdependent interpolation: gamma = w' + theta_y does not vary with x (no shear locking)."""
    phi_y, phi_z = shear_parameters(L, MAT, GENERAL)
    xi = np.linspace(0, 1, 5)
    n0 = field_matrix(xi, L, phi_y, phi_z, 0)
    n1 = field_matrix(xi, L, phi_y, phi_z, 1)
    gamma_xz = n1[:, 2] + n0[:, 4]
    gamma_xy = n1[:, 1] - n0[:, 5]
    np.testing.assert_allclose(gamma_xz, np.broadcast_to(gamma_xz[0], gamma_xz.shape), atol=1e-12)
    np.testing.assert_allclose(gamma_xy, np.broadcast_to(gamma_xy[0], gamma_xy.shape), atol=1e-12)


# ----------------------------------------------------------------- the theories of docs/theory.md §10
BENSCOTER = BeamTheory(torsion="benscoter")
EULER_BERNOULLI = BeamTheory(bending="euler-bernoulli")
WITH_IWS = replace(GENERAL, I_ws=0.8)  # m^4: phi_t = 12 E I_w / (G I_ws L^2) = 5.5 on this short element


def test_the_theories_are_checked():
    with pytest.raises(ConfigError, match="`torsion` must be one of vlasov, benscoter"):
        BeamTheory(torsion="timoshenko")
    with pytest.raises(ConfigError, match="`bending` must be one of"):
        BeamTheory(bending="rayleigh")
    assert BeamTheory().is_default and not BENSCOTER.is_default


@pytest.mark.parametrize("theory", [BENSCOTER, EULER_BERNOULLI, BeamTheory("benscoter", "euler-bernoulli")])
def test_every_theory_keeps_symmetry_definiteness_and_the_six_rigid_body_modes(theory):
    k, m = element_matrices(L, MAT, WITH_IWS, theory)
    np.testing.assert_array_equal(k, k.T)
    np.testing.assert_array_equal(m, m.T)
    assert np.linalg.eigvalsh(m)[0] > 0
    assert np.max(np.abs(k @ _rigid_body_vectors())) < 1e-9 * np.max(np.abs(k))
    ek = np.linalg.eigvalsh(k)
    assert ek[0] > -1e-9 * ek[-1]
    assert np.sum(np.abs(ek) < 1e-9 * ek[-1]) == 6


def test_benscoter_tends_to_vlasov_as_the_warping_shear_stiffens():
    """G I_ws -> inf forces psi = theta_x' (docs/theory.md §10.3): the matrices tend to Vlasov's, O(1/I_ws)."""
    k_v, m_v = element_matrices(L, MAT, GENERAL)
    errors = []
    for i_ws in (1e4, 1e6):
        k_b, m_b = element_matrices(L, MAT, replace(GENERAL, I_ws=i_ws), BENSCOTER)
        errors.append(max(np.max(np.abs(k_b - k_v)) / np.max(np.abs(k_v)), np.max(np.abs(m_b - m_v)) / np.max(m_v)))
    assert errors[1] < 2e-5 and errors[1] < 0.02 * errors[0]  # phi_t = 3e-5 at 1e6: O(phi_t)
    # Without warping, or with an infinite I_ws, Benscoter is the Vlasov element exactly.
    for section in (replace(GENERAL, I_ws=math.inf), replace(GENERAL, I_w=0.0, I_ws=0.8)):
        vlasov = element_matrices(L, MAT, section)
        for a, b in zip(element_matrices(L, MAT, section, BENSCOTER), vlasov):
            np.testing.assert_array_equal(a, b)


def test_benscoter_secondary_torsion_strain_is_constant_along_the_element():
    """theta_x' - psi is constant (interdependent interpolation with phi_t), like the bending shear strain."""
    phi_t = torsion_parameter(L, MAT, WITH_IWS, BENSCOTER)
    assert phi_t == pytest.approx(12 * MAT.E * GENERAL.I_w / (MAT.G * 0.8 * L**2))
    xi = np.linspace(0, 1, 5)
    n0 = field_matrix(xi, L, 0.0, 0.0, 0, phi_t)
    n1 = field_matrix(xi, L, 0.0, 0.0, 1, phi_t)
    gamma = n1[:, FIELD_INDEX["theta_x"]] - n0[:, FIELD_INDEX["psi"]]
    np.testing.assert_allclose(gamma, np.broadcast_to(gamma[0], gamma.shape), atol=1e-12)
    assert np.max(np.abs(gamma[0])) > 0.1  # psi is independent: the strain is not zero
    # psi interpolates its nodal values.
    n_nodes = field_matrix([0.0, 1.0], L, 0.0, 0.0, 0, phi_t)
    assert n_nodes[0, FIELD_INDEX["psi"], DOF_INDEX["psi"]] == pytest.approx(1.0)
    assert n_nodes[1, FIELD_INDEX["psi"], 7 + DOF_INDEX["psi"]] == pytest.approx(1.0)


def test_benscoter_torsion_block_is_the_timoshenko_analogue_when_gj_vanishes():
    """With J = 0 the (theta_x, psi) block is Przemieniecki's Timoshenko matrix (3.9) with E I_w and phi_t (§10.3)."""
    section = replace(GENERAL, J=1e-30, I_ws=0.8)
    k, _ = element_matrices(L, MAT, section, BENSCOTER)
    idx = [DOF_INDEX["theta_x"], DOF_INDEX["psi"], 7 + DOF_INDEX["theta_x"], 7 + DOF_INDEX["psi"]]
    phi = torsion_parameter(L, MAT, section, BENSCOTER)
    ref = MAT.E * section.I_w / ((1 + phi) * L**3) * np.array([
        [12, 6 * L, -12, 6 * L], [6 * L, (4 + phi) * L**2, -6 * L, (2 - phi) * L**2],
        [-12, -6 * L, 12, -6 * L], [6 * L, (2 - phi) * L**2, -6 * L, (4 + phi) * L**2]])
    np.testing.assert_allclose(k[np.ix_(idx, idx)], ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(ref)))


def test_euler_bernoulli_bending_is_the_hermite_beam():
    """phi = 0 exactly and no shear energy: the lateral block is (3.9) at phi = 0, the classical 12/6/4/2 matrix."""
    assert shear_parameters(L, MAT, GENERAL, EULER_BERNOULLI) == (0.0, 0.0)
    k, _ = element_matrices(L, MAT, GENERAL, EULER_BERNOULLI)
    idx = [DOF_INDEX["v"], DOF_INDEX["theta_z"], 7 + DOF_INDEX["v"], 7 + DOF_INDEX["theta_z"]]
    ref = MAT.E * GENERAL.I_z / L**3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                                 [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    np.testing.assert_allclose(k[np.ix_(idx, idx)], ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(ref)))


def test_mass_per_length_and_rotary_inertia():
    """The translational mass is the given m L; its coupling with the twist m e L; no rotary inertia when off."""
    mbar = 1.234e4
    section = replace(GENERAL, mass_per_length=mbar, rotary_inertia=False)
    _, m = element_matrices(L, MAT, section)
    r = _rigid_body_vectors()
    for j in range(3):
        assert r[:, j] @ m @ r[:, j] == pytest.approx(mbar * L, rel=1e-12)
    e_y, e_z = GENERAL.y_s - GENERAL.y_c, GENERAL.z_s - GENERAL.z_c
    assert r[:, 2] @ m @ r[:, 3] == pytest.approx(-mbar * e_y * L, rel=1e-12)
    assert r[:, 1] @ m @ r[:, 3] == pytest.approx(mbar * e_z * L, rel=1e-12)
    # Rigid twist: rho (I_y + I_z) + m e^2 per length (the mass lumped at C).
    polar = MAT.rho * (GENERAL.I_y + GENERAL.I_z) + mbar * (e_y**2 + e_z**2)
    assert r[:, 3] @ m @ r[:, 3] == pytest.approx(polar * L, rel=1e-12)
    # Rigid rotations about y and z: rotary inertia adds exactly rho I L, and nothing without it.
    _, m_with = element_matrices(L, MAT, GENERAL)
    _, m_without = element_matrices(L, MAT, replace(GENERAL, rotary_inertia=False))
    for j, inertia in ((4, GENERAL.I_y), (5, GENERAL.I_z)):
        added = r[:, j] @ (m_with - m_without) @ r[:, j]
        assert added == pytest.approx(MAT.rho * inertia * L, rel=1e-9)
