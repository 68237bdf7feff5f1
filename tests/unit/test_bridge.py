"""Bridge assembly, supports, deck rows, modal bookkeeping and damping."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.bridge import ExplicitDamping, PointLoad, RayleighDamping, build_bridge, support_dofs
from cosim.core.section import Material, SectionProperties
from cosim.errors import ConfigError, ModelError

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(
    A=4.8, y_c=0.0, z_c=-0.4, I_y=2.1, I_z=40.0, I_yz=0.0, y_s=0.0, z_s=0.3,
    J=0.09, I_w=3.0, A_sy=2.5, A_sz=1.4, deck_y=(-6.6, 6.6),
)


def test_support_presets():
    assert support_dofs("fork") == ("v", "w", "theta_x")
    assert set(support_dofs("warping-restrained")) == {"v", "w", "theta_x", "psi"}
    assert set(support_dofs("rigid-end")) == {"u", "v", "w", "theta_x", "psi"}
    assert support_dofs(["w", "theta_x"]) == ("w", "theta_x")
    with pytest.raises(ConfigError, match="unknown support preset 'forks'"):
        support_dofs("forks")
    with pytest.raises(ConfigError, match="unknown DOF 'phi'"):
        support_dofs(["w", "phi"])


def test_deck_point_row_derivatives_match_finite_differences_of_the_deflected_shape():
    bridge = build_bridge([20.0, 30.0], [8, 12], MAT, SEC, ["pinned", "fork", "fork"])
    res = bridge.static([PointLoad(13.0, 4.0, -1e5), PointLoad(33.0, -2.0, -2e5)])
    y, h = 3.0, 1e-4
    for x in (1.3, 12.1, 27.7, 44.4):
        row = bridge.deck_point_row(x, y)
        w = lambda xv: res.deck_displacement(xv, y)  # noqa: E731
        assert row.values[0] @ res.d[row.dofs] == pytest.approx(w(x), rel=1e-12)
        assert row.values[1] @ res.d[row.dofs] == pytest.approx((w(x + h) - w(x - h)) / (2 * h), rel=1e-6)
        row_p, row_m = bridge.deck_point_row(x + h, y), bridge.deck_point_row(x - h, y)
        w_x = lambda r: r.values[1] @ res.d[r.dofs]  # noqa: E731
        assert row.values[2] @ res.d[row.dofs] == pytest.approx((w_x(row_p) - w_x(row_m)) / (2 * h), rel=1e-5)
        np.testing.assert_allclose(row.dense(bridge.ndof) @ res.d, w(x), rtol=1e-12)


def test_deflection_is_continuous_across_element_boundaries():
    bridge = build_bridge([20.0], 5, MAT, SEC, ["rigid-end", "rigid-end"])
    res = bridge.static([PointLoad(7.0, 5.0, -1e5)])
    for node_x in bridge.nodes_x[1:-1]:
        left = res.deck_displacement(node_x - 1e-12, 5.0)
        right = res.deck_displacement(node_x + 1e-12, 5.0)
        assert left == pytest.approx(right, rel=1e-9)


def test_effective_modal_masses_of_all_modes_plus_the_supports_mass_make_the_whole():
    """Completeness of the modes: sum over modes of (phi^T M r)^2 = (M r)_f^T M_ff^-1 (M r)_f, and what is
    missing from 1 is the mass that moves with the supports (exact identity, round-off tolerance)."""
    import scipy.sparse.linalg as spla

    bridge = build_bridge([20.0], 4, MAT, SEC, ["pinned", "fork"])
    modal = bridge.modes(len(bridge.free))
    kinds = np.tile(np.arange(7), bridge.n_nodes)
    for direction, dof in (("vertical", 2), ("lateral", 1), ("torsion", 3), ("axial", 0)):
        r = (kinds == dof).astype(float)
        m_r = bridge.M @ r
        moving_with_modes = m_r[bridge.free] @ spla.spsolve(bridge.M_ff, m_r[bridge.free])
        expected = moving_with_modes / (r @ m_r)
        assert modal.participation[direction].sum() == pytest.approx(expected, rel=1e-8)
        assert expected < 1.0


def test_modes_are_mass_normalised_and_classified():
    bridge = build_bridge([40.0], 20, MAT, SEC, ["rigid-end", "rigid-end"])
    modal = bridge.modes(8)
    phi = modal.shapes[bridge.free]
    np.testing.assert_allclose(phi.T @ (bridge.M_ff @ phi), np.eye(8), atol=1e-9)
    for j in range(8):
        shares = [modal.energy_shares[k][j] for k in ("axial", "lateral", "vertical", "torsion")]
        assert sum(shares) == pytest.approx(1.0, rel=1e-9)
    assert modal.kinds[0] == "vertical"
    assert modal.index_of("vertical-1") == 0
    assert modal.index_of(1) == 0


def test_rayleigh_damping_hits_both_target_ratios():
    damping = RayleighDamping(ratios=(0.02, 0.03), modes=("vertical-1", "torsion-1"))
    bridge = build_bridge([40.0], 20, MAT, SEC, ["rigid-end", "rigid-end"], damping)
    modal = bridge.modes(20)
    for ref, target in (("vertical-1", 0.02), ("torsion-1", 0.03)):
        w = modal.omega[modal.index_of(ref)]
        # zeta = alpha / (2 w) + beta w / 2 (Chopra, Dynamics of Structures, eq. 11.4.3)
        assert bridge.alpha / (2 * w) + bridge.beta * w / 2 == pytest.approx(target, rel=1e-10)
    explicit = build_bridge([40.0], 20, MAT, SEC, ["rigid-end", "rigid-end"], ExplicitDamping(0.1, 1e-4))
    assert (explicit.alpha, explicit.beta) == (0.1, 1e-4)


def test_mechanism_and_bad_input_are_reported():
    with pytest.raises(ModelError, match="rigid-body mode"):
        build_bridge([10.0], 4, MAT, SEC, ["fork", "fork"]).modes(3)  # nothing holds u
    with pytest.raises(ConfigError, match="`supports` needs 3 entries"):
        build_bridge([10.0, 10.0], 4, MAT, SEC, ["fork", "fork"])
    with pytest.raises(ConfigError, match="`spans`"):
        build_bridge([0.0], 4, MAT, SEC, ["pinned", "fork"])
    with pytest.raises(ConfigError, match="same mode twice"):
        build_bridge([10.0], 4, MAT, SEC, ["pinned", "fork"], RayleighDamping((0.02, 0.02), ("torsion-1", "torsion-1")))
    bridge = build_bridge([10.0], 4, MAT, SEC, ["pinned", "fork"])
    with pytest.raises(ModelError, match="off the deck"):
        bridge.static([PointLoad(5.0, 7.0, -1.0)])


def test_model_is_immutable():
    bridge = build_bridge([10.0], 4, MAT, SEC, ["pinned", "fork"])
    with pytest.raises(AttributeError):
        bridge.alpha = 1.0  # type: ignore[misc]


def test_stiffness_factors_and_support_springs_change_the_frequencies_as_closed_forms_say():
    build = build_bridge
    healthy = build([20.0], 20, MAT, SEC, ["pinned", "fork"])
    uniform = build([20.0], 20, MAT, SEC, ["pinned", "fork"], stiffness_factors=[0.64] * 20)
    # K scaled by 0.64 everywhere with M unchanged: every frequency scales by sqrt(0.64) = 0.8 exactly.
    f0, f1 = healthy.modes(6).f_hz, uniform.modes(6).f_hz
    np.testing.assert_allclose(f1, 0.8 * f0, rtol=1e-9)
    local = build([20.0], 20, MAT, SEC, ["pinned", "fork"], stiffness_factors=[1.0] * 9 + [0.5] * 2 + [1.0] * 9)
    assert local.modes(1).f_hz[0] < f0[0]  # less stiffness at mid-span: a lower first frequency
    # A very stiff spring replacing a held DOF changes nothing; a soft one lowers the frequency.
    stiff = build([20.0], 20, MAT, SEC, ["pinned", "fork"], support_springs=[(1, "w", 1e16)])
    soft = build([20.0], 20, MAT, SEC, ["pinned", "fork"], support_springs=[(1, "w", 1e6)])
    assert stiff.modes(1).f_hz[0] == pytest.approx(f0[0], rel=1e-6)
    assert soft.modes(1).f_hz[0] < 0.99 * f0[0]
