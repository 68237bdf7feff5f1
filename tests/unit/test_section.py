"""Cross-section constants: FE section solver and thin-walled theory against closed forms.

Every reference value names its source. Tolerances are relative unless named
``*_ABS`` (then in metres).
"""
from __future__ import annotations

import math

import pytest

from cosim.core import section
from cosim.core.section import (
    Plate,
    SectionProperties,
    section_from_constants,
    section_from_plates,
)
from cosim.errors import ConfigError, ModelError
from cosim.validation.references import (
    channel_warping_shear_constant,
    i_section_warping_shear_constant,
    rectangle_torsion_constant,
)
from cosim.validation.thin_walled import thin_walled_properties

# Exact integrals of a polygon: only round-off and the FE quadrature remain.
EXACT_REL = 1e-6
# J of a solid rectangle: FE (quadratic triangles, default mesh) vs the series.
RECT_J_REL = 1e-2
# nu = 0: the flexure solution is the elementary parabolic shear stress, so
# k = 5/6 exactly up to discretisation.
RECT_K_NU0_REL = 1e-3
# nu = 0.2: sectionproperties defines k by the shear-strain energy of the
# Saint-Venant flexure solution (which depends on nu and on the aspect ratio);
# Cowper averages displacements and gets 10(1+nu)/(12+11nu) for any aspect
# ratio. For a deep rectangle loaded along its depth they differ by ~1.4 %.
RECT_K_COWPER_REL = 3e-2
# Thin plates (t/b = 1/20): the FE solver sees the real polygon (web and
# flanges overlap at the junctions, free ends and re-entrant corners of the
# thickness), which thin-walled theory neglects; that is worth O(t/b) = a few %.
THIN_REL = 4e-2
# Closed forms reproduced by thin_walled_properties: same formulas, round-off only.
THEORY_REL = 1e-9
# Shear centre by symmetry; the FE mesh is not exactly symmetric.
SYMMETRY_ABS = 1e-3
# Paper double-tee: FE area = thin-walled area minus the two web/deck
# overlaps (2 x 0.40 x 0.125 = 0.1 m^2 of 4.93 m^2, i.e. 2.0 %).
DOUBLE_TEE_AREA_REL = 3e-2


def double_tee(t_left: float = 0.40, t_right: float = 0.40) -> list[Plate]:
    """The paper's double-tee (docs/validation.md), midline dimensions."""
    return [
        Plate((-6.655, 0.0), (6.655, 0.0), 0.25),
        Plate((3.325, 0.0), (3.325, -2.0), t_left),
        Plate((-3.325, 0.0), (-3.325, -2.0), t_right),
    ]


def i_section(b: float, h: float, t_f: float, t_w: float) -> list[Plate]:
    """Doubly symmetric I: flanges b wide at z = +-h/2 (midlines), web of height h."""
    return [
        Plate((-b / 2, h / 2), (b / 2, h / 2), t_f),
        Plate((0.0, -h / 2), (0.0, h / 2), t_w),
        Plate((-b / 2, -h / 2), (b / 2, -h / 2), t_f),
    ]


def channel(b: float, h: float, t_f: float, t_w: float) -> list[Plate]:
    """Channel: web midline at y = 0, flanges reaching to y = +b at z = +-h/2."""
    return [
        Plate((0.0, h / 2), (b, h / 2), t_f),
        Plate((0.0, -h / 2), (0.0, h / 2), t_w),
        Plate((0.0, -h / 2), (b, -h / 2), t_f),
    ]


# --- solid rectangle --------------------------------------------------------

def test_solid_rectangle_matches_elasticity() -> None:
    depth, width = 1.0, 0.5  # one thick vertical plate: depth along z, width (thickness) along y
    sec = section_from_plates([Plate((0.0, -depth / 2), (0.0, depth / 2), width)], nu=0.2)
    # Exact integrals of a rectangle.
    assert sec.A == pytest.approx(width * depth, rel=EXACT_REL)
    assert sec.I_y == pytest.approx(width * depth**3 / 12, rel=EXACT_REL)
    assert sec.I_z == pytest.approx(depth * width**3 / 12, rel=EXACT_REL)
    assert sec.I_yz == pytest.approx(0.0, abs=EXACT_REL * sec.I_y)
    assert sec.deck_y == pytest.approx((-width / 2, width / 2))
    # Timoshenko & Goodier series (beta(2) = 0.229 in Roark's table); its other aspect ratios:
    # tests/verification/test_references.py.
    assert sec.J == pytest.approx(rectangle_torsion_constant(width, depth), rel=RECT_J_REL)
    # Cowper (1966), J. Appl. Mech. 33, rectangle: k = 10(1+nu)/(12+11nu).
    assert sec.k_z == pytest.approx(10 * 1.2 / (12 + 11 * 0.2), rel=RECT_K_COWPER_REL)


def test_rectangle_shear_coefficient_is_five_sixths_without_poisson() -> None:
    sec = section_from_plates([Plate((0.0, -0.5), (0.0, 0.5), 0.5)], nu=0.0)
    # Elementary beam theory (parabolic shear stress, exact for nu = 0): k = 5/6.
    assert sec.k_z == pytest.approx(5 / 6, rel=RECT_K_NU0_REL)
    assert sec.k_y == pytest.approx(5 / 6, rel=RECT_K_NU0_REL)


# --- thin-walled I and channel ---------------------------------------------

def test_doubly_symmetric_i_section() -> None:
    b, h, t = 1.0, 1.0, 0.05  # t/b = 1/20
    plates = i_section(b, h, t, t)
    fe = section_from_plates(plates)
    tw = thin_walled_properties(plates)
    # Thin-walled formulas (any steel-design text, e.g. Trahair & Bradford):
    i_y = t * h**3 / 12 + 2 * b * t * (h / 2) ** 2 + 2 * b * t**3 / 12
    i_z = 2 * t * b**3 / 12 + h * t**3 / 12
    j = (2 * b + h) * t**3 / 3
    i_w = t * b**3 * h**2 / 24  # I_f h^2 / 2 with I_f = t b^3 / 12
    for value, ref in ((tw.I_y, i_y), (tw.I_z, i_z), (tw.J, j), (tw.I_w, i_w)):
        assert value == pytest.approx(ref, rel=THEORY_REL)
    for value, ref in ((fe.I_y, i_y), (fe.I_z, i_z), (fe.J, j), (fe.I_w, i_w)):
        assert value == pytest.approx(ref, rel=THIN_REL)
    # Double symmetry: shear centre at the centroid.
    assert (fe.y_s, fe.z_s) == pytest.approx((fe.y_c, fe.z_c), abs=SYMMETRY_ABS)
    assert (tw.y_s, tw.z_s) == pytest.approx((0.0, 0.0), abs=SYMMETRY_ABS)
    # Shear areas from the Jourawski shear flow, 1/A_s = integral of q^2/t ds
    # for V = 1 (midline I): lateral shear is carried by the two flanges as
    # parabolic flows (5/6 of their area); vertical shear mostly by the web.
    # Different values in the two directions pin the mapping of
    # sectionproperties' (x, y) shear areas to our (y, z).
    i_mid = t * h**3 / 12 + b * t * h**2 / 2
    q0 = b * t * h / 2  # web shear flow at the flange junction, times I
    flanges = t * h**2 * b**3 / (24 * i_mid**2)
    web = (q0**2 * h + q0 * t * h**3 / 6 + t**2 * h**5 / 120) / (t * i_mid**2)
    a_sz = 1 / (flanges + web)
    a_sy = 5 / 6 * 2 * b * t
    assert tw.A_sz == pytest.approx(a_sz, rel=THEORY_REL)
    assert tw.A_sy == pytest.approx(a_sy, rel=THEORY_REL)
    assert fe.A_sz == pytest.approx(a_sz, rel=THIN_REL)
    assert fe.A_sy == pytest.approx(a_sy, rel=THIN_REL)
    # Warping shear constant (docs/theory.md §10.2): the flanges carry the secondary torque as lateral shear
    # T_w / h with the parabolic flow of a b t rectangle, so I_ws = 5/12 b t h^2 (the web carries none). The FE
    # value solves laplacian F = omega on the real polygon: an independent computation.
    i_ws = i_section_warping_shear_constant(b, h, t)
    assert tw.I_ws == pytest.approx(i_ws, rel=THEORY_REL)
    assert fe.I_ws == pytest.approx(i_ws, rel=THIN_REL)


def test_channel_shear_centre_and_warping_constant() -> None:
    b, h, t_f, t_w = 1.0, 2.0, 0.05, 0.05
    plates = channel(b, h, t_f, t_w)
    fe = section_from_plates(plates)
    tw = thin_walled_properties(plates)
    # Closed forms for a channel (Timoshenko & Gere, Theory of Elastic
    # Stability, sec. 5.10; Trahair & Bradford): distance of S from the web
    # midline, away from the flanges, and the warping constant about S.
    e = 3 * b**2 * t_f / (6 * b * t_f + h * t_w)
    i_w = t_f * b**3 * h**2 * (3 * b * t_f + 2 * h * t_w) / (12 * (6 * b * t_f + h * t_w))
    assert tw.y_s == pytest.approx(-e, rel=THEORY_REL)
    assert tw.I_w == pytest.approx(i_w, rel=THEORY_REL)
    assert fe.y_s == pytest.approx(-e, rel=THIN_REL)
    assert fe.I_w == pytest.approx(i_w, rel=THIN_REL)
    # Symmetric about z = 0.
    assert fe.z_s == pytest.approx(0.0, abs=SYMMETRY_ABS)
    assert fe.I_yz == pytest.approx(0.0, abs=EXACT_REL * fe.I_y)
    # Warping shear constant: I_w^2 / integral(S_w^2 / t ds), integrated by hand over the flanges and the web
    # (docs/theory.md §10.2), against the tree integration of thin-walled theory and the FE Neumann problem.
    i_ws = channel_warping_shear_constant(b, h, t_f, t_w)
    assert tw.I_ws == pytest.approx(i_ws, rel=THEORY_REL)
    assert fe.I_ws == pytest.approx(i_ws, rel=THIN_REL)


def test_a_section_without_warping_has_no_secondary_torsion() -> None:
    """A tee's midlines meet at one point: omega = 0, I_w = 0 (round-off) and I_ws infinite (Benscoter = Vlasov)."""
    tee = [Plate((-0.5, 0.0), (0.5, 0.0), 0.02), Plate((0.0, 0.0), (0.0, -0.6), 0.02)]
    tw = thin_walled_properties(tee)
    assert tw.I_w < 1e-30 and tw.I_ws == math.inf


# --- the paper's double-tee ------------------------------------------------

def test_paper_double_tee_symmetric() -> None:
    fe = section_from_plates(double_tee())
    tw = thin_walled_properties(double_tee())
    assert fe.y_c == pytest.approx(0.0, abs=SYMMETRY_ABS)
    assert fe.y_s == pytest.approx(0.0, abs=SYMMETRY_ABS)
    assert fe.I_yz == pytest.approx(0.0, abs=EXACT_REL * fe.I_y)
    # Deck on top of an open section: S lies above C (closer to the deck).
    assert fe.z_s > fe.z_c
    assert tw.z_s > tw.z_c
    assert fe.deck_y == pytest.approx((-6.655, 6.655))
    assert fe.A == pytest.approx(tw.A, rel=DOUBLE_TEE_AREA_REL)
    # Measured (see docs/sections.md): FE J is 3.4 % below sum(b t^3/3) and
    # FE I_w is 1.4 % above thin-walled I_w; t/b reaches 0.2 for the webs, so
    # the thickness effects thin-walled theory neglects are not small. The
    # model uses the FE values.
    assert fe.J == pytest.approx(tw.J, rel=0.05)
    assert fe.I_w == pytest.approx(tw.I_w, rel=0.05)


def test_paper_double_tee_asymmetric() -> None:
    fe = section_from_plates(double_tee(t_left=0.40, t_right=0.25))
    tw = thin_walled_properties(double_tee(t_left=0.40, t_right=0.25))
    # Heavier left web (y = +3.325) pulls C and S to the left.
    assert fe.y_c > 0.0
    assert fe.y_s > fe.y_c
    assert tw.y_s > tw.y_c > 0.0
    assert fe.z_s > fe.z_c
    assert fe.I_yz != pytest.approx(0.0, abs=1e-3)
    assert fe.A == pytest.approx(tw.A, rel=DOUBLE_TEE_AREA_REL)


# --- caching ----------------------------------------------------------------

def test_second_call_does_not_solve_again() -> None:
    plates = i_section(0.8, 0.6, 0.04, 0.03)  # used by no other test
    solves = section.FE_SOLVES
    first = section_from_plates(plates)
    assert section.FE_SOLVES == solves + 1
    again = section_from_plates(plates)
    # Same plates in another order and direction: the same geometry.
    shuffled = [Plate(p.end, p.start, p.thickness) for p in reversed(plates)]
    assert section_from_plates(shuffled) is first
    assert again is first
    assert section.FE_SOLVES == solves + 1
    # A different geometry, or another nu, solves.
    section_from_plates(i_section(0.8, 0.6, 0.04, 0.035))
    assert section.FE_SOLVES == solves + 2
    section_from_plates(plates, nu=0.3)
    assert section.FE_SOLVES == solves + 3
    assert section_from_plates.cache_info().hits >= 2


# --- errors -----------------------------------------------------------------

def test_negative_thickness_names_the_plate() -> None:
    plates = double_tee()
    plates[2] = Plate((-3.325, 0.0), (-3.325, -2.0), -0.25)
    with pytest.raises(ConfigError, match=r"plate 2: `thickness` must be > 0 \(got -0.25\)"):
        section_from_plates(plates)
    with pytest.raises(ConfigError, match="plate 2"):
        thin_walled_properties(plates)


def test_zero_length_plate_names_the_plate() -> None:
    plates = double_tee()
    plates[1] = Plate((3.325, 0.0), (3.325, 0.0), 0.4)
    with pytest.raises(ConfigError, match="plate 1: .*non-zero length"):
        section_from_plates(plates)


def test_non_finite_coordinate_names_the_plate() -> None:
    plates = double_tee()
    plates[0] = Plate((-6.655, float("nan")), (6.655, 0.0), 0.25)
    with pytest.raises(ConfigError, match=r"plate 0: `start\[1\]` must be a finite number \(got nan\)"):
        section_from_plates(plates)


def test_disconnected_plates_are_rejected() -> None:
    plates = double_tee()
    plates[1] = Plate((3.325, -0.5), (3.325, -2.0), 0.4)  # web hangs below the deck
    with pytest.raises(ConfigError, match="plates do not form one connected section: plate 1 "):
        section_from_plates(plates)
    with pytest.raises(ModelError, match="midlines do not meet"):
        thin_walled_properties(plates)


def test_plates_touching_at_a_corner_are_not_connected() -> None:
    plates = [Plate((0.0, 0.0), (1.0, 0.0), 0.1), Plate((1.05, 0.05), (1.05, 1.0), 0.1)]
    with pytest.raises(ConfigError, match="plate 1"):
        section_from_plates(plates)


def test_closed_cell_is_fe_only() -> None:
    box = [
        Plate((-1.0, 0.0), (1.0, 0.0), 0.1),
        Plate((1.0, 0.0), (1.0, -1.0), 0.1),
        Plate((1.0, -1.0), (-1.0, -1.0), 0.1),
        Plate((-1.0, -1.0), (-1.0, 0.0), 0.1),
    ]
    with pytest.raises(ModelError, match="closed cells not supported"):
        thin_walled_properties(box)
    fe = section_from_plates(box, mesh_size=0.005)
    # Bredt: J = 4 A_m^2 / (sum b/t) = 4 * 2^2 / (6 / 0.1) for the midline cell.
    assert fe.J == pytest.approx(4 * 2.0**2 / (6 / 0.1), rel=THIN_REL)


# --- explicit constants -----------------------------------------------------

def test_constants_defaults_and_validation() -> None:
    sec = section_from_constants(4.8, 1.6, 65.0, 0.15, I_w=19.0, z_c=-0.33, z_s=0.26, deck_y=(-6.655, 6.655))
    assert isinstance(sec, SectionProperties)
    assert (sec.y_s, sec.k_y, sec.k_z) == pytest.approx((0.0, 5 / 6, 5 / 6))
    assert sec.source == "constants"
    assert (sec.I_ws, sec.mass_per_length, sec.rotary_inertia) == (None, None, True)
    bad = [
        (dict(A=0.0), "`A` must be > 0"),
        (dict(J=-1.0), "`J` must be > 0"),
        (dict(I_w=-1.0), "`I_w` must be >= 0"),
        (dict(I_yz=11.0), "`I_yz`"),
        (dict(A_sz=0.0), "`A_sz` must be > 0"),
        (dict(deck_y=(6.0, -6.0)), "`deck_y` must be ordered"),
        (dict(deck_y=None), "`deck_y` is required"),
        (dict(I_y=float("inf")), "`I_y` must be a finite number \\(got inf\\)"),
        (dict(I_ws=0.0), "`I_ws` must be > 0 m\\^4"),
        (dict(mass_per_length=-1.0), "`mass_per_length` must be > 0 kg/m"),
        (dict(rotary_inertia=0), "`rotary_inertia` must be true or false"),
    ]
    for change, message in bad:
        kwargs = dict(A=4.8, I_y=1.6, I_z=65.0, J=0.15, deck_y=(-6.655, 6.655)) | change
        with pytest.raises(ConfigError, match=message):
            section_from_constants(**kwargs)
