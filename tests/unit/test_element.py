"""Properties of the 7-DOF element that hold whatever the section (no closed form needed)."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.element import DOF_INDEX, element_matrices, field_matrix, shear_parameters
from cosim.core.section import Material, SectionProperties

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
