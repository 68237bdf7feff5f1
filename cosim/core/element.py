"""The 7-DOF shear-deformable, warping beam element (one copy of its shape functions).

Degrees of freedom per node, in this order (``DOF_NAMES``)::

    0 u        axial displacement of the centroid C, m
    1 v        lateral displacement of the shear centre S (along +y), m
    2 w        vertical displacement of S (along +z), m
    3 theta_x  twist about the shear-centre axis, rad (right-handed about +x)
    4 theta_y  bending rotation about +y (vertical bending), rad
    5 theta_z  bending rotation about +z (lateral bending), rad
    6 psi      warping parameter, rad/m: psi = theta_x' (Vlasov, the default) or an
               independent field (Benscoter, shear-deformable warping)

Kinematics (reference: translations and twist at S, axial at C, principal
sectorial coordinate ``omega`` normalised at S). A point (y, z) of the section
moves by::

    u_x = u + (z - z_c) theta_y - (y - y_c) theta_z - omega psi
    u_y = v - (z - z_s) theta_x
    u_z = w + (y - y_s) theta_x          <- deck points: w(y) = w_S + (y - y_S) theta_x

Strain energy per unit length (S-reference makes it block diagonal apart from
``I_yz``)::

    2U' = EA u'^2 + EI_y theta_y'^2 + EI_z theta_z'^2 - 2 E I_yz theta_y' theta_z'
        + G A_sz (w' + theta_y)^2 + G A_sy (v' - theta_z)^2 + GJ theta_x'^2 + E I_w theta_x''^2

Kinetic energy per unit length (the S-C offset couples translations and twist)::

    2T'/rho = A (u.^2 + v.^2 + w.^2) + 2 A (e_z v. - e_y w.) theta_x. + I_ps theta_x.^2
            + I_y theta_y.^2 + I_z theta_z.^2 - 2 I_yz theta_y. theta_z. + I_w theta_x'.^2

with ``e_y = y_s - y_c``, ``e_z = z_s - z_c``. These are derived from the
displacement field above, not transcribed from the paper (whose eqs. 7-10 have
typos, see docs/theory.md §3.7).

Two switches (:class:`BeamTheory`, docs/theory.md §10): ``torsion="benscoter"``
frees psi from theta_x' and adds the secondary-torsion (warping shear) energy
``G I_ws (theta_x' - psi)^2`` (``EI_w psi'^2`` replaces ``EI_w theta_x''^2``,
``rho I_w psi.^2`` the warping inertia); ``bending="euler-bernoulli"`` drops the
bending shear strains (phi = 0 exactly, no ``G A_s`` energy). The section may
replace ``rho A`` by a mass per length and switch the rotary inertia off.

Interpolation: linear ``u``; bending in each plane with the interdependent
(Friedman-Kosmatka) Timoshenko shape functions, which are free of shear locking
and exact at the nodes for end-loaded prismatic beams; Hermite cubic
``theta_x`` with ``psi`` as its slope (Vlasov), or the same interdependent
functions with ``phi_t = 12 E I_w / (G I_ws L^2)`` for ``(theta_x, psi)``
(Benscoter: the warping analogue of Timoshenko bending). Every shape function is a cubic in
``xi = x/L``, so they are stored as polynomial coefficients and differentiated
exactly. Element matrices are integrated from the energies with 4-point Gauss
quadrature, which is exact for these cubic fields.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import numpy.typing as npt

from .checks import one_of
from .section import Material, SectionProperties

DOF_NAMES: tuple[str, ...] = ("u", "v", "w", "theta_x", "theta_y", "theta_z", "psi")
DOF_INDEX: dict[str, int] = {name: i for i, name in enumerate(DOF_NAMES)}
NODE_DOFS = 7
ELEMENT_DOFS = 14
#: Per node, the DOFs a deck point's vertical displacement w_S + (y - y_S) theta_x depends on: w and, through
#: the interdependent Timoshenko interpolation, theta_y; theta_x and, through its Hermite interpolation, psi.
DECK_POINT_NODE_DOFS: tuple[str, ...] = ("w", "theta_x", "theta_y", "psi")
#: The same as element DOF indices (both nodes), ascending.
DECK_POINT_DOFS: tuple[int, ...] = tuple(sorted(
    node * NODE_DOFS + DOF_INDEX[name] for node in (0, 1) for name in DECK_POINT_NODE_DOFS))

# Field rows of the interpolation matrix (all fields are cubic polynomials in xi). ``psi`` is the warping
# parameter's field: theta_x' (Vlasov) or its own interpolation (Benscoter).
FIELD_NAMES: tuple[str, ...] = ("u", "v", "w", "theta_x", "theta_y", "theta_z", "psi")
FIELD_INDEX: dict[str, int] = {name: i for i, name in enumerate(FIELD_NAMES)}

_U, _V, _W, _TX, _TY, _TZ, _PSI = range(7)

_GAUSS_XI, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_GAUSS_XI = 0.5 * (_GAUSS_XI + 1.0)
_GAUSS_W = 0.5 * _GAUSS_W

#: Torsion theories: Vlasov (psi = theta_x', the seed's element) and Benscoter (shear-deformable warping).
TORSION_THEORIES: tuple[str, ...] = ("vlasov", "benscoter")
#: Bending theories: Timoshenko (shear deformation) and Euler-Bernoulli (phi = 0, no shear energy).
BENDING_THEORIES: tuple[str, ...] = ("timoshenko", "euler-bernoulli")


@dataclass(frozen=True)
class BeamTheory:
    """Which kinematics the element uses (docs/theory.md §10).

    Args:
        torsion: ``"vlasov"`` (default: psi = theta_x', no shear strain in warping)
            or ``"benscoter"`` (psi independent, secondary torsion ``G I_ws``).
        bending: ``"timoshenko"`` (default: shear deformation through ``A_sy``,
            ``A_sz``) or ``"euler-bernoulli"`` (sections stay normal: phi = 0).

    Raises:
        ConfigError: an unknown theory.
    """

    torsion: str = "vlasov"
    bending: str = "timoshenko"

    def __post_init__(self) -> None:
        one_of(self.torsion, TORSION_THEORIES, "torsion")
        one_of(self.bending, BENDING_THEORIES, "bending")

    @property
    def is_default(self) -> bool:
        """The seed's element: Vlasov torsion and Timoshenko bending."""
        return self == BeamTheory()


DEFAULT_THEORY = BeamTheory()


def _timoshenko_coefficients(length: float, phi: float) -> tuple[np.ndarray, np.ndarray]:
    """Interdependent Timoshenko shape functions for DOFs (w1, beta1, w2, beta2).

    ``beta`` is the cross-section rotation that equals ``w'`` in the
    Euler-Bernoulli limit; ``phi = 12 EI / (G A_s L^2)``. Returns the
    coefficient arrays (4 DOFs x 4 powers of xi) of the displacement and of the
    rotation. Reference: Friedman & Kosmatka, Computers & Structures 47 (1993).
    """
    f = 1.0 / (1.0 + phi)
    L = length
    n_w = f * np.array(
        [
            [1.0 + phi, -phi, -3.0, 2.0],
            [0.0, L * (1.0 + phi / 2.0), -L * (2.0 + phi / 2.0), L],
            [0.0, phi, 3.0, -2.0],
            [0.0, -L * phi / 2.0, L * (-1.0 + phi / 2.0), L],
        ]
    )
    n_beta = f * np.array(
        [
            [0.0, -6.0 / L, 6.0 / L, 0.0],
            [1.0 + phi, -4.0 - phi, 3.0, 0.0],
            [0.0, 6.0 / L, -6.0 / L, 0.0],
            [0.0, -2.0 + phi, 3.0, 0.0],
        ]
    )
    return n_w, n_beta


def shear_parameters(
    length: float, material: Material, section: SectionProperties, theory: BeamTheory = DEFAULT_THEORY
) -> tuple[float, float]:
    """Shear-flexibility parameters ``(phi_y, phi_z)`` of an element of ``length`` m.

    ``phi_y = 12 E I_z / (G A_sy L^2)`` (lateral plane v-theta_z),
    ``phi_z = 12 E I_y / (G A_sz L^2)`` (vertical plane w-theta_y); both exactly
    0 for Euler-Bernoulli bending.
    """
    if theory.bending == "euler-bernoulli":
        return 0.0, 0.0
    phi_y = 12.0 * material.E * section.I_z / (material.G * section.A_sy * length**2)
    phi_z = 12.0 * material.E * section.I_y / (material.G * section.A_sz * length**2)
    return phi_y, phi_z


def _benscoter(material: Material, section: SectionProperties, theory: BeamTheory) -> bool:
    """Whether the element carries secondary torsion: Benscoter with warping and a finite ``I_ws``.

    Without warping (``I_w = 0``) or with rigid warping shear (``I_ws`` infinite) the
    Benscoter element is the Vlasov one (phi_t = 0 makes theta_x' - psi vanish).
    """
    return (theory.torsion == "benscoter" and section.I_w > 0 and section.I_ws is not None
            and math.isfinite(section.I_ws))


def torsion_parameter(
    length: float, material: Material, section: SectionProperties, theory: BeamTheory = DEFAULT_THEORY
) -> float:
    """Warping-shear parameter ``phi_t = 12 E I_w / (G I_ws L^2)`` of an element (0 for Vlasov torsion)."""
    if not _benscoter(material, section, theory):
        return 0.0
    assert section.I_ws is not None
    return 12.0 * material.E * section.I_w / (material.G * section.I_ws * length**2)


@lru_cache(maxsize=256)
def shape_coefficients(length: float, phi_y: float, phi_z: float, phi_t: float = 0.0) -> npt.NDArray[np.float64]:
    """Polynomial coefficients of all fields: array (7 fields, 14 DOFs, 4 powers of xi).

    ``field(xi) = C[f] @ d_e`` with ``C[f, :, p]`` the coefficient of ``xi**p``.
    Fields in ``FIELD_NAMES`` order; element DOFs are node 1's seven then
    node 2's seven, each in ``DOF_NAMES`` order. ``phi_t`` is the torsion
    parameter (:func:`torsion_parameter`): 0 gives the Hermite twist with
    ``psi = theta_x'``.
    """
    c = np.zeros((len(FIELD_NAMES), ELEMENT_DOFS, 4))
    n1, n2 = 0, NODE_DOFS
    # Axial: linear.
    c[_U, n1 + _U] = [1.0, -1.0, 0.0, 0.0]
    c[_U, n2 + _U] = [0.0, 1.0, 0.0, 0.0]
    # Lateral plane: beta = theta_z (Euler-Bernoulli: theta_z = v').
    n_w, n_beta = _timoshenko_coefficients(length, phi_y)
    lat = [n1 + _V, n1 + _TZ, n2 + _V, n2 + _TZ]
    c[_V, lat] = n_w
    c[_TZ, lat] = n_beta
    # Vertical plane: beta = -theta_y (Euler-Bernoulli: theta_y = -w').
    n_w, n_beta = _timoshenko_coefficients(length, phi_z)
    sign = np.array([1.0, -1.0, 1.0, -1.0])[:, None]
    ver = [n1 + _W, n1 + _TY, n2 + _W, n2 + _TY]
    c[_W, ver] = sign * n_w
    c[_TY, ver] = -sign * n_beta
    # Torsion: (theta_x, psi) as (w, beta) of bending with phi_t; at phi_t = 0 the Hermite cubic with psi its slope.
    n_h, n_psi = _timoshenko_coefficients(length, phi_t)
    tor = [n1 + _TX, n1 + _PSI, n2 + _TX, n2 + _PSI]
    c[_TX, tor] = n_h
    c[_PSI, tor] = n_psi
    c.setflags(write=False)
    return c


def _powers(xi: npt.ArrayLike, length: float, order: int) -> np.ndarray:
    """Rows of d^order/dx^order [1, xi, xi^2, xi^3] at the given xi, shape (n, 4)."""
    xi = np.atleast_1d(np.asarray(xi, dtype=float))
    one, zero = np.ones_like(xi), np.zeros_like(xi)
    if order == 0:
        p = [one, xi, xi**2, xi**3]
    elif order == 1:
        p = [zero, one, 2.0 * xi, 3.0 * xi**2]
    elif order == 2:
        p = [zero, zero, 2.0 * one, 6.0 * xi]
    elif order == 3:
        p = [zero, zero, zero, 6.0 * one]
    else:
        raise ValueError("`order` must be 0, 1, 2 or 3")
    return np.stack(p, axis=-1) / length**order


def field_matrix(
    xi: npt.ArrayLike, length: float, phi_y: float, phi_z: float, order: int = 0, phi_t: float = 0.0
) -> npt.NDArray[np.float64]:
    """Interpolation matrices of all fields, or their ``order``-th x-derivative.

    Args:
        xi: local coordinates x/L in [0, 1], scalar or array of n points.
        length: element length, m.
        phi_y, phi_z: shear parameters from :func:`shear_parameters`.
        order: derivative order with respect to x (0, 1, 2 or 3), 1/m^order.
        phi_t: torsion parameter from :func:`torsion_parameter` (0: Vlasov).

    Returns:
        Array (n, 7, 14): ``fields[k] = N[k] @ d_e`` in ``FIELD_NAMES`` order.
    """
    c = shape_coefficients(float(length), float(phi_y), float(phi_z), float(phi_t))
    return np.einsum("fdp,np->nfd", c, _powers(xi, length, order))


def element_matrices(
    length: float, material: Material, section: SectionProperties, theory: BeamTheory = DEFAULT_THEORY
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Stiffness and consistent mass of one element, both 14 x 14 (N/m-type units, kg-type units).

    Integrated from the strain and kinetic energies in the module docstring
    (docs/theory.md §3.5; the theories of ``theory``: §10).
    """
    E, G, rho = material.E, material.G, material.rho
    s = section
    phi_y, phi_z = shear_parameters(length, material, s, theory)
    phi_t = torsion_parameter(length, material, s, theory)
    n0 = field_matrix(_GAUSS_XI, length, phi_y, phi_z, 0, phi_t)
    n1 = field_matrix(_GAUSS_XI, length, phi_y, phi_z, 1, phi_t)
    n2 = field_matrix(_GAUSS_XI, length, phi_y, phi_z, 2, phi_t)
    benscoter = _benscoter(material, s, theory)

    # Generalised strains: u', theta_y', theta_z', gamma_xz, gamma_xy, theta_x', then theta_x'' (Vlasov) or
    # psi' and the secondary-torsion shear theta_x' - psi (Benscoter).
    rows = [n1[:, _U], n1[:, _TY], n1[:, _TZ], n1[:, _W] + n0[:, _TY], n1[:, _V] - n0[:, _TZ], n1[:, _TX]]
    if benscoter:
        rows += [n1[:, _PSI], n1[:, _TX] - n0[:, _PSI]]
    else:
        rows += [n2[:, _TX]]
    strains = np.stack(rows, axis=1)
    d = np.zeros((len(rows), len(rows)))
    d[0, 0] = E * s.A
    d[1, 1] = E * s.I_y
    d[2, 2] = E * s.I_z
    d[1, 2] = d[2, 1] = -E * s.I_yz
    if theory.bending == "timoshenko":  # Euler-Bernoulli: no shear strain, hence no shear energy
        d[3, 3] = G * s.A_sz
        d[4, 4] = G * s.A_sy
    d[5, 5] = G * s.J
    d[6, 6] = E * s.I_w
    if benscoter:
        assert s.I_ws is not None
        d[7, 7] = G * s.I_ws

    # Inertia fields: u, v, w, theta_x, theta_y, theta_z and the warping psi (theta_x' for Vlasov).
    warping = n0[:, _PSI : _PSI + 1] if benscoter else n1[:, _TX : _TX + 1]
    fields = np.concatenate([n0[:, :_PSI], warping], axis=1)
    e_y, e_z = s.y_s - s.y_c, s.z_s - s.z_c
    m = np.zeros((7, 7))
    m[_U, _U] = m[_V, _V] = m[_W, _W] = s.A
    m[_V, _TX] = m[_TX, _V] = s.A * e_z
    m[_W, _TX] = m[_TX, _W] = -s.A * e_y
    m[_TX, _TX] = s.I_ps
    if s.rotary_inertia:
        m[_TY, _TY] = s.I_y
        m[_TZ, _TZ] = s.I_z
        m[_TY, _TZ] = m[_TZ, _TY] = -s.I_yz
    m[6, 6] = s.I_w
    m *= rho
    if s.mass_per_length is not None:
        # The given mass per length replaces rho A, lumped at C (which is what rho A is): the translations, their
        # coupling with the twist about S, and its share m e^2 of the polar inertia; rho (I_y + I_z) stays.
        mbar = s.mass_per_length
        m[_U, _U] = m[_V, _V] = m[_W, _W] = mbar
        m[_V, _TX] = m[_TX, _V] = mbar * e_z
        m[_W, _TX] = m[_TX, _W] = -mbar * e_y
        m[_TX, _TX] = rho * (s.I_y + s.I_z) + mbar * (e_y**2 + e_z**2)

    w = _GAUSS_W * length
    k_e = np.einsum("g,gad,ab,gbe->de", w, strains, d, strains)
    m_e = np.einsum("g,gad,ab,gbe->de", w, fields, m, fields)
    # Symmetrise away round-off so eigen-solvers see exactly symmetric matrices.
    return 0.5 * (k_e + k_e.T), 0.5 * (m_e + m_e.T)


@dataclass(frozen=True)
class DeckRow:
    """Map from element DOFs to a deck point's vertical displacement and its x-derivatives.

    ``w(x, y) = values[0] @ d[dofs]`` (m), ``w_x = values[1] @ d[dofs]`` (1),
    ``w_xx = values[2] @ d[dofs]`` (1/m), with ``d`` the full bridge DOF vector.
    """

    dofs: npt.NDArray[np.int64]
    values: npt.NDArray[np.float64]

    def dense(self, ndof: int, order: int = 0) -> npt.NDArray[np.float64]:
        """The row as a dense vector of length ``ndof`` (derivative ``order`` 0, 1 or 2)."""
        row = np.zeros(ndof)
        np.add.at(row, self.dofs, self.values[order])
        return row


def deck_row_values(
    xi: float, length: float, phi_y: float, phi_z: float, lever: float, phi_t: float = 0.0
) -> npt.NDArray[np.float64]:
    """(3, 14) rows giving w + lever * theta_x and its first two x-derivatives.

    ``lever = y - y_s`` is the lateral distance of the deck point from the
    shear centre, m: the twist contribution that makes eccentric loads twist
    the deck. ``phi_t``: the torsion parameter (the twist's interpolation).
    """
    rows = np.empty((3, ELEMENT_DOFS))
    for order in range(3):
        n = field_matrix(xi, length, phi_y, phi_z, order, phi_t)[0]
        rows[order] = n[_W] + lever * n[_TX]
    return rows
