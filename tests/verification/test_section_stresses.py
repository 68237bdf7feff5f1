"""Stress and strain sensors against hand calculations and against sectionproperties (docs/theory.md §12).

Static cases on cantilevers and on a beam with warping restrained: the
sensor's row applied to the static displacements must give the engineer's
formulas (N/A, M z/I, the bimoment B omega/I_w with Kollbrunner & Basler's
closed form, Jourawski's and Saint-Venant's shear stresses), and, for the same
section forces, the stresses sectionproperties computes on the same mesh.
"""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.bridge import build_bridge
from cosim.core.element import DOF_INDEX, NODE_DOFS
from cosim.core.section import Material, Plate, section_from_constants, section_from_plates
from cosim.core.sensors import Sensor, check_sensor_on, sensor_row
from cosim.errors import ConfigError

STEEL = Material(E=210e9, G=81e9, rho=7850.0)
# An I-section (flange midlines h apart, width b) and the paper's asymmetric double-tee.
H, B, TF, TW = 1.0, 0.5, 0.02, 0.015
I_PLATES = [Plate((-B / 2, H / 2), (B / 2, H / 2), TF), Plate((-B / 2, -H / 2), (B / 2, -H / 2), TF),
            Plate((0.0, -H / 2), (0.0, H / 2), TW)]
TEE_PLATES = [Plate((-3.0, 0.0), (5.0, 0.0), 0.25), Plate((-1.5, 0.0), (-1.5, -1.6), 0.35),
              Plate((2.5, 0.0), (2.5, -1.6), 0.45)]


@pytest.fixture(scope="module")
def i_section():
    return section_from_plates(I_PLATES, nu=STEEL.nu)


@pytest.fixture(scope="module")
def tee_section():
    return section_from_plates(TEE_PLATES, nu=STEEL.nu)


def _cantilever(section, length=10.0, elements=10):
    return build_bridge([length], elements, STEEL, section, ["fixed", "free"])


def _tip_loads(bridge, **forces):
    """Full force vector with nodal forces on the tip node's DOFs (u, v, w, theta_x, ...)."""
    f = np.zeros(bridge.ndof)
    tip = bridge.n_nodes - 1
    for name, value in forces.items():
        f[NODE_DOFS * tip + DOF_INDEX[name]] = value
    return f


def _read(bridge, d, sensor):
    row = sensor_row(bridge, sensor)
    return float(row.values[0] @ d[row.dofs])


def test_the_warping_function_is_the_principal_sectorial_coordinate(i_section):
    field = i_section.stress_field
    # Thin-walled I-section (Vlasov): omega = -h b / 4 at the tip (b/2, h/2) with the sign of (1.2); I_w = t b^3 h^2/24.
    assert field.omega_at(B / 2, H / 2) == pytest.approx(-H * B / 4, rel=1e-3)
    assert field.omega_at(-B / 2, H / 2) == pytest.approx(H * B / 4, rel=1e-3)
    assert field.omega_at(B / 2, -H / 2) == pytest.approx(H * B / 4, rel=1e-3)
    assert field.omega_at(0.0, 0.0) == pytest.approx(0.0, abs=1e-6)
    assert i_section.I_w == pytest.approx(TF * B**3 * H**2 / 24, rel=1e-3)
    assert not field.contains(0.2, 0.0)  # beside the web: no material


def test_axial_force_and_bending_give_n_over_a_and_m_z_over_i(i_section):
    bridge = _cantilever(i_section)
    N, P, Q, L, x = 2.0e5, -3.0e4, 1.0e4, 10.0, 4.0
    d = bridge.static(f=_tip_loads(bridge, u=N, w=P, v=Q)).d
    sec = i_section
    for y, z in [(B / 2, H / 2 + TF / 2), (-B / 4, -H / 2), (0.0, 0.1)]:
        sigma = _read(bridge, d, Sensor("s", x, y, "stress", z=z))
        # Hand calculation: sigma = N/A + M_sag (z_c - z)/I_y - M_z (y - y_c)/I_z with M_sag = P (L - x) for an
        # upward tip force P (Gere & Timoshenko, cantilever), and the lateral moment Q (L - x) likewise.
        expected = N / sec.A - P * (L - x) * (z - sec.z_c) / sec.I_y - Q * (L - x) * (y - sec.y_c) / sec.I_z
        assert sigma == pytest.approx(expected, rel=1e-9)
        strain = _read(bridge, d, Sensor("e", x, y, "strain", z=z))
        assert strain == pytest.approx(expected / STEEL.E, rel=1e-9)


def test_normal_stresses_match_sectionproperties_for_the_same_section_forces(tee_section):
    """Unsymmetric section (I_yz != 0): the stress row against sectionproperties' sigma_zz for N, M_y, M_z."""
    bridge = _cantilever(tee_section)
    d = bridge.static(f=_tip_loads(bridge, u=5.0e5, v=2.0e4, w=-8.0e4)).d
    x = 3.0
    sec, E = tee_section, STEEL.E
    dtheta_y = bridge.field(d, "theta_y", x, order=1)[0]
    dtheta_z = bridge.field(d, "theta_z", x, order=1)[0]
    n = bridge.field(d, "axial_force", x)[0]
    m_y = E * (sec.I_y * dtheta_y - sec.I_yz * dtheta_z)  # integral of sigma z dA: about +y
    m_z = E * (sec.I_z * dtheta_z - sec.I_yz * dtheta_y)  # -integral of sigma y dA: about +z
    # sectionproperties' (x, y, z) are our (y, z, x), so its mxx is our M_y and its myy our M_z.
    post = sec.stress_field.solved.calculate_stress(n=n, mxx=m_y, myy=m_z).get_stress()[0]
    sigma_sp = post["sig_zz_n"] + post["sig_zz_mxx"] + post["sig_zz_myy"]
    field = sec.stress_field
    for y, z in [(-3.0, 0.125), (5.0, -0.1), (-1.5, -1.6), (2.5, -0.8), (1.0, 0.0)]:
        ours = _read(bridge, d, Sensor("s", x, y, "stress", z=z))
        assert ours == pytest.approx(float(field.interpolate(sigma_sp, y, z)), rel=1e-6)


def test_the_bimoment_stress_of_a_torque_with_warping_restrained_matches_the_closed_form(i_section):
    L, T, n_el = 12.0, 5.0e4, 48
    bridge = build_bridge([L], n_el, STEEL, i_section, ["rigid-end", "warping-restrained"])
    f = np.zeros(bridge.ndof)
    f[NODE_DOFS * (n_el // 2) + DOF_INDEX["theta_x"]] = T
    d = bridge.static(f=f).d
    GJ, EIw = STEEL.G * i_section.J, STEEL.E * i_section.I_w
    lam = np.sqrt(GJ / EIw)

    def theta_xx(s):
        # Kollbrunner & Basler (Torsion in Structures, ch. 4), mid-span torque, theta = theta' = 0 at the ends:
        # theta = T/(2GJ) (s + tanh(lam L/4) (cosh(lam s) - 1)/lam - sinh(lam s)/lam), differentiated twice.
        return T / (2 * GJ) * lam * (np.tanh(lam * L / 4) * np.cosh(lam * s) - np.sinh(lam * s))

    for x in (0.0, 1.5, 6.0):
        tip = _read(bridge, d, Sensor("s", x, B / 2, "stress", z=H / 2))
        # sigma = B omega / I_w = -E omega theta'' with omega = -h b/4 at the flange tip (thin-walled theory).
        expected = -STEEL.E * (-H * B / 4) * theta_xx(x)
        assert tip == pytest.approx(expected, rel=5e-3)  # FE omega (1e-3) and 48 cubic elements
        bimoment = bridge.field(d, "bimoment", x)[0]
        assert bimoment == pytest.approx(-EIw * theta_xx(x), rel=5e-3)


def test_shear_stresses_match_jourawski_saint_venant_and_sectionproperties():
    # A narrow rectangle 0.25 m x 1.0 m (one plate): tau_xz at the centroid is 1.5 V/A within the elasticity
    # correction of a b/h = 1/4 rectangle (Timoshenko & Goodier, art. 124: < 1 %).
    section = section_from_plates([Plate((0.0, -0.5), (0.0, 0.5), 0.25)], nu=STEEL.nu)
    bridge = _cantilever(section, length=8.0, elements=8)
    P, T, x = -4.0e4, 3.0e3, 5.0
    d = bridge.static(f=_tip_loads(bridge, w=P, theta_x=T)).d
    v_z = bridge.field(d, "shear_force_z", x)[0]
    # Statics of the part beyond the cut: its face (outward normal -x) carries -V_z, so -V_z + P = 0.
    assert v_z == pytest.approx(P, rel=1e-9)
    tau_c = _read(bridge, d, Sensor("t", x, 0.0, "shear_stress_xz", z=0.0))
    assert tau_c == pytest.approx(1.5 * v_z / section.A, rel=1e-2)
    # Saint-Venant: on the long face of the rectangle tau = T / (k2 b t^2) with k2 = 0.282 for h/t = 4
    # (Roark, table 10.1), and the torque is uniform (no warping worth speaking of).
    t_sv = bridge.field(d, "torque_sv", x)[0]
    assert t_sv == pytest.approx(T, rel=1e-3)
    tau_face = _read(bridge, d, Sensor("t", x, 0.125, "shear_stress_xz", z=0.0))
    tau_torsion = tau_face - tau_c  # the flexure part is even in y, the torsion part odd: take it at y = 0.125
    assert abs(tau_torsion) == pytest.approx(T / (0.282 * 1.0 * 0.25**2), rel=2e-2)
    # The same section forces into sectionproperties give the same shear stresses at any point.
    v_y = bridge.field(d, "shear_force_y", x)[0]
    post = section.stress_field.solved.calculate_stress(vx=v_y, vy=v_z, mzz=t_sv).get_stress()[0]
    for y, z in [(0.05, 0.3), (-0.1, -0.45), (0.125, 0.0)]:
        for quantity, key in (("shear_stress_xy", "sig_zx"), ("shear_stress_xz", "sig_zy")):
            ours = _read(bridge, d, Sensor("t", x, y, quantity, z=z))
            theirs = float(section.stress_field.interpolate(post[key], y, z))
            assert ours == pytest.approx(theirs, rel=1e-6, abs=1e-6 * abs(tau_c))


def test_constant_sections_need_omega_when_they_warp_and_refuse_shear_stresses():
    warping = section_from_constants(A=0.5, I_y=0.2, I_z=0.3, J=0.01, I_w=0.05, deck_y=(-3.0, 3.0))
    bridge = build_bridge([20.0], 4, STEEL, warping, ["pinned", "fork"])
    with pytest.raises(ConfigError, match="give `omega`"):
        check_sensor_on(bridge, Sensor("s", 10.0, 1.0, "stress", z=0.5))
    check_sensor_on(bridge, Sensor("s", 10.0, 1.0, "stress", z=0.5, omega=0.3))
    with pytest.raises(ConfigError, match="only a section of plates"):
        check_sensor_on(bridge, Sensor("t", 10.0, 1.0, "shear_stress_xz", z=0.5))
    with pytest.raises(ConfigError, match="give `z`"):
        Sensor("s", 10.0, 1.0, "stress")
    with pytest.raises(ConfigError, match="only used by"):
        Sensor("d", 10.0, 1.0, "displacement", z=0.2)
