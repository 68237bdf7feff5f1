"""The bridge: a continuous beam of 7-DOF elements with supports, damping, modes and statics (docs/theory.md §4).

Global DOF ``7 * node + k`` with ``k`` in :data:`cosim.core.element.DOF_NAMES` order;
nodes are numbered from the first abutment (x = 0) along +x.

Sign convention used everywhere (tested): the vertical displacement of a deck
point at lateral position ``y`` is ``w(x, y) = w_S(x) + (y - y_S) theta_x(x)``,
so a positive twist lifts the left side (y > y_S) and a downward load on the
left twists the deck negatively.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Union

import numpy as np
import numpy.typing as npt
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cosim.errors import ConfigError, ModelError

from .banded import upper_band
from .element import (
    DEFAULT_THEORY,
    DOF_INDEX,
    DOF_NAMES,
    ELEMENT_DOFS,
    FIELD_INDEX,
    NODE_DOFS,
    BeamTheory,
    DeckRow,
    deck_row_values,
    element_matrices,
    field_matrix,
    shape_coefficients,
    shear_parameters,
    torsion_parameter,
)
from .limits import MAX_DOFS
from .section import Material, SectionProperties

__all__ = [
    "BeamTheory",
    "DOF_NAMES",
    "SUPPORT_PRESETS",
    "MODE_KINDS",
    "RayleighDamping",
    "ExplicitDamping",
    "PointLoad",
    "BridgeModel",
    "ModalResult",
    "StaticResult",
    "build_bridge",
    "support_dofs",
]

SUPPORT_PRESETS: dict[str, tuple[str, ...]] = {
    "free": (),
    "fork": ("v", "w", "theta_x"),
    "warping-restrained": ("v", "w", "theta_x", "psi"),
    "pinned": ("u", "v", "w", "theta_x"),
    # The paper's rigid end section: the end face tied to a reference point whose
    # translations and twist are held. With theta_x = 0 the centroid and shear
    # centre translations coincide, and the rigid face also stops warping.
    "rigid-end": ("u", "v", "w", "theta_x", "psi"),
    "fixed": DOF_NAMES,
}

# Groups of DOFs whose strain energy names a mode's kind.
MODE_KINDS: dict[str, tuple[str, ...]] = {
    "axial": ("u",),
    "lateral": ("v", "theta_z"),
    "vertical": ("w", "theta_y"),
    "torsion": ("theta_x", "psi"),
}
_PURE_KIND_SHARE = 0.75
#: A Cholesky pivot of K below this share of its diagonal entry is a mechanism (round-off is ~1e-16).
MECHANISM_PIVOT = 1e-11

SupportSpec = Union[str, Sequence[str]]
#: Stress resultants :meth:`BridgeModel.field_row` gives (docs/theory.md §12.2).
RESULTANTS: tuple[str, ...] = ("axial_force", "bending_moment", "shear_force_y", "shear_force_z", "torque_sv",
                               "bimoment")


@dataclass(frozen=True)
class RayleighDamping:
    """Rayleigh damping ``C = alpha M + beta K`` from target ratios at two modes.

    Args:
        ratios: damping ratios (fraction of critical) at the two modes.
        modes: two mode references: a 1-based mode number, or ``"<kind>-<n>"``
            (the n-th mode of that kind, kind in vertical | lateral | torsion | axial).
    """

    ratios: tuple[float, float]
    modes: tuple[Union[int, str], Union[int, str]]


@dataclass(frozen=True)
class ExplicitDamping:
    """Rayleigh damping with explicit ``alpha`` (1/s) and ``beta`` (s)."""

    alpha: float
    beta: float


@dataclass(frozen=True)
class PointLoad:
    """A vertical point load on the deck at (x, y) m; ``Fz`` in N, positive up."""

    x: float
    y: float
    Fz: float


def support_dofs(spec: SupportSpec) -> tuple[str, ...]:
    """Resolve a support given as a preset name or a list of DOF names."""
    if isinstance(spec, str):
        if spec not in SUPPORT_PRESETS:
            raise ConfigError(
                f"unknown support preset {spec!r} (expected one of: {', '.join(SUPPORT_PRESETS)})"
            )
        return SUPPORT_PRESETS[spec]
    names = tuple(spec)
    for name in names:
        if name not in DOF_INDEX:
            raise ConfigError(f"unknown DOF {name!r} in a support (expected some of: {', '.join(DOF_NAMES)})")
    return names


@dataclass(frozen=True)
class ModalResult:
    """Natural frequencies and mode shapes (mass-normalised, full DOF vectors).

    Attributes:
        omega: circular frequencies, rad/s, ascending.
        shapes: array (ndof, n): column j is mode j, ``shapes.T M shapes = I``.
        energy_shares: dict kind -> array (n,) of strain-energy shares per DOF group.
        kinds: kind of each mode ("vertical", "lateral", "torsion", "axial" or
            "coupled <a>-<b>" when no group holds 75 % of the strain energy).
        dominant: the DOF group with the largest share, per mode.
        participation: dict direction -> effective modal mass fractions (n,)
            for rigid translations along z ("vertical"), y ("lateral"), x
            ("axial") and rotation about the shear-centre axis ("torsion").
    """

    omega: npt.NDArray[np.float64]
    shapes: npt.NDArray[np.float64]
    energy_shares: dict[str, npt.NDArray[np.float64]]
    kinds: list[str]
    dominant: list[str]
    participation: dict[str, npt.NDArray[np.float64]]
    bridge: BridgeModel = field(repr=False)

    @property
    def f_hz(self) -> npt.NDArray[np.float64]:
        """Natural frequencies, Hz."""
        return self.omega / (2.0 * np.pi)

    def index_of(self, ref: Union[int, str]) -> int:
        """0-based index of a mode reference (1-based number or ``"<kind>-<n>"``)."""
        if isinstance(ref, (int, np.integer)) and not isinstance(ref, bool):
            if not 1 <= ref <= len(self.omega):
                raise ConfigError(f"mode {ref} does not exist (computed {len(self.omega)} modes)")
            return int(ref) - 1
        kind, _, number = str(ref).rpartition("-")
        if kind not in MODE_KINDS or not number.isdigit() or int(number) < 1:
            raise ConfigError(
                f"mode reference {ref!r} must be a 1-based mode number or '<kind>-<n>' "
                f"with kind in {', '.join(MODE_KINDS)}"
            )
        hits = [i for i, d in enumerate(self.dominant) if d == kind]
        if len(hits) < int(number):
            raise ConfigError(
                f"mode reference {ref!r}: only {len(hits)} {kind} mode(s) among the first {len(self.omega)}"
            )
        return hits[int(number) - 1]

    def field(self, mode: int, name: str, x: npt.ArrayLike, y: float = 0.0) -> npt.NDArray[np.float64]:
        """Field ``name`` of mode ``mode`` (0-based) at positions x (see BridgeModel.field)."""
        return self.bridge.field(self.shapes[:, mode], name, x, y=y)


@dataclass(frozen=True)
class StaticResult:
    """Static displacements ``d`` (full DOF vector, m and rad) under given loads."""

    d: npt.NDArray[np.float64]
    bridge: BridgeModel = field(repr=False)

    def deck_displacement(self, x: float, y: float) -> float:
        """Vertical displacement of deck point (x, y), m, positive up."""
        row = self.bridge.deck_point_row(x, y)
        return float(row.values[0] @ self.d[row.dofs])

    def field(self, name: str, x: npt.ArrayLike, y: float = 0.0) -> npt.NDArray[np.float64]:
        """Field ``name`` at positions x (see :meth:`BridgeModel.field`)."""
        return self.bridge.field(self.d, name, x, y=y)


@dataclass(frozen=True, eq=False)
class BridgeModel:
    """An assembled bridge. Build it with :func:`build_bridge`; it never changes afterwards.

    Attributes:
        spans: span lengths, m.
        nodes_x: node positions along the axis, m.
        material, section: what every element is made of.
        restrained: sorted global DOF indices held by supports.
        K, M: full sparse stiffness (N/m, N, N m) and consistent mass (kg, kg m, kg m^2).
        alpha, beta: Rayleigh coefficients in use (1/s, s); zero when undamped.
        theory: the torsion and bending theories of the elements (docs/theory.md §10).
    """

    spans: tuple[float, ...]
    nodes_x: npt.NDArray[np.float64]
    material: Material
    section: SectionProperties
    supports: tuple[tuple[str, ...], ...]
    restrained: npt.NDArray[np.int64]
    K: sp.csr_matrix
    M: sp.csr_matrix
    alpha: float = 0.0
    beta: float = 0.0
    damping_note: str = "undamped"
    theory: BeamTheory = DEFAULT_THEORY

    # ----------------------------------------------------------------- sizes
    @property
    def length(self) -> float:
        """Total length, m."""
        return float(self.nodes_x[-1])

    @property
    def n_nodes(self) -> int:
        return len(self.nodes_x)

    @property
    def n_elements(self) -> int:
        return len(self.nodes_x) - 1

    @property
    def ndof(self) -> int:
        return NODE_DOFS * len(self.nodes_x)

    @cached_property
    def free(self) -> npt.NDArray[np.int64]:
        """Global indices of the unrestrained DOFs."""
        mask = np.ones(self.ndof, dtype=bool)
        mask[self.restrained] = False
        return np.flatnonzero(mask)

    @cached_property
    def support_x(self) -> npt.NDArray[np.float64]:
        """Positions of the support lines, m."""
        return np.concatenate([[0.0], np.cumsum(self.spans)])

    @cached_property
    def _element_data(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per element: length, phi_y, phi_z, phi_t."""
        lengths = np.diff(self.nodes_x)
        phis = np.array([shear_parameters(L, self.material, self.section, self.theory) for L in lengths])
        phi_t = np.array([torsion_parameter(L, self.material, self.section, self.theory) for L in lengths])
        return lengths, phis[:, 0], phis[:, 1], phi_t

    # ------------------------------------------------------- reduced matrices
    @cached_property
    def K_ff(self) -> sp.csc_matrix:
        return self.K[self.free][:, self.free].tocsc()

    @cached_property
    def M_ff(self) -> sp.csc_matrix:
        return self.M[self.free][:, self.free].tocsc()

    @property
    def C(self) -> sp.csr_matrix:
        """Rayleigh damping matrix, full size (N s/m-type units)."""
        return (self.alpha * self.M + self.beta * self.K).tocsr()

    @cached_property
    def _static_lu(self) -> spla.SuperLU:
        return spla.splu(self.K_ff)

    def expand(self, d_free: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Full DOF vector(s) from free-DOF vector(s) (restrained DOFs are zero)."""
        d_free = np.asarray(d_free)
        out = np.zeros((self.ndof,) + d_free.shape[1:])
        out[self.free] = d_free
        return out

    # -------------------------------------------------------------- location
    def locate(self, x: float) -> tuple[int, float]:
        """Element index and local coordinate xi in [0, 1] of axial position x (m)."""
        if not (-1e-9 <= x <= self.length + 1e-9):
            raise ModelError(f"x = {x} m is outside the bridge (0 to {self.length} m)")
        e = int(np.searchsorted(self.nodes_x, x, side="right")) - 1
        e = min(max(e, 0), self.n_elements - 1)
        lengths = self._element_data[0]
        xi = (x - self.nodes_x[e]) / lengths[e]
        return e, float(min(max(xi, 0.0), 1.0))

    def _element_dofs(self, e: int) -> npt.NDArray[np.int64]:
        return np.arange(NODE_DOFS * e, NODE_DOFS * e + ELEMENT_DOFS)

    def deck_point_row(self, x: float, y: float) -> DeckRow:
        """Row mapping all bridge DOFs to the vertical displacement of deck point (x, y).

        ``w(x, y) = w_S(x) + (y - y_S) theta_x(x)`` with bending and twist
        interpolated by the element's own shape functions; ``values[1]`` and
        ``values[2]`` are its first and second x-derivatives (1 and 1/m), as the
        moving-contact kinematics need.
        """
        e, xi = self.locate(x)
        lengths, phi_y, phi_z, phi_t = self._element_data
        values = deck_row_values(xi, lengths[e], phi_y[e], phi_z[e], y - self.section.y_s, phi_t[e])
        return DeckRow(dofs=self._element_dofs(e), values=values)

    @cached_property
    def deck_coefficients(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per element: the cubic polynomial coefficients in xi of the deck's w (at the shear centre) and of
        theta_x, per element DOF (n_el, 14, 4), and the element lengths, m (what the compiled step's contact
        rows evaluate: docs/theory.md §5.1)."""
        lengths, phi_y, phi_z, phi_t = self._element_data
        c_w = np.empty((self.n_elements, ELEMENT_DOFS, 4))
        c_t = np.empty_like(c_w)
        for e in range(self.n_elements):
            c = shape_coefficients(float(lengths[e]), float(phi_y[e]), float(phi_z[e]), float(phi_t[e]))
            c_w[e], c_t[e] = c[FIELD_INDEX["w"]], c[FIELD_INDEX["theta_x"]]
        return c_w, c_t, lengths

    def deck_rows(
        self, x: npt.ArrayLike, y: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]:
        """Vectorised :meth:`deck_point_row` for q points on the deck.

        Returns ``dofs`` (q, 14) and ``values`` (q, 3, 14): the rows of
        ``w(x, y)`` and of its first and second x-derivatives.
        """
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        c_w, c_t, lengths = self.deck_coefficients
        e = np.clip(np.searchsorted(self.nodes_x, x, side="right") - 1, 0, self.n_elements - 1)
        L = lengths[e]
        xi = np.clip((x - self.nodes_x[e]) / L, 0.0, 1.0)
        one, zero = np.ones_like(xi), np.zeros_like(xi)
        powers = np.stack(
            [
                np.stack([one, xi, xi * xi, xi**3], axis=-1),
                np.stack([zero, one, 2 * xi, 3 * xi * xi], axis=-1) / L[:, None],
                np.stack([zero, zero, 2 * one, 6 * xi], axis=-1) / (L * L)[:, None],
            ],
            axis=1,
        )  # (q, 3, 4)
        lever = (y - self.section.y_s)[:, None, None]
        values = np.einsum("qdp,qop->qod", c_w[e], powers) + lever * np.einsum("qdp,qop->qod", c_t[e], powers)
        dofs = NODE_DOFS * e[:, None] + np.arange(ELEMENT_DOFS)[None, :]
        return dofs, values

    def field_row(self, name: str, x: float, y: float = 0.0, order: int = 0, *, z: float = 0.0,
                  omega: float = 0.0) -> DeckRow:
        """Row mapping the element DOFs at ``x`` (m) to a field value.

        ``name`` is one of u, v, w, theta_x, theta_y, theta_z, psi (interpolated with
        the element's shape functions; psi = theta_x' for Vlasov torsion), ``w_deck`` (the
        vertical displacement of the deck point at lateral position ``y``, m),
        ``bending_moment`` (vertical bending moment about the centroidal y
        axis, N m, sagging positive: ``M = -E (I_y theta_y' - I_yz theta_z')``,
        which is ``E I_y w''`` for Euler-Bernoulli bending), or one of the
        stress resultants and the strain of docs/theory.md §12:

        - ``axial_force`` ``N = E A u'`` (N, tension positive);
        - ``shear_force_y`` ``V_y = -E (I_z theta_z'' - I_yz theta_y'')`` and
          ``shear_force_z`` ``V_z = E (I_y theta_y'' - I_yz theta_z'')`` (N, on the
          face whose outward normal is +x, along +y and +z; from equilibrium
          with the bending moments, so they hold for both bending theories);
        - ``torque_sv`` ``T_sv = G J theta_x'`` (N m, the St Venant part of the torque);
        - ``bimoment`` ``B = -E I_w psi'`` (N m^2; ``sigma = B omega / I_w``);
        - ``normal_strain`` ``eps_x = u' + (z - z_c) theta_y' - (y - y_c) theta_z' - omega psi'``
          at the section point ``(y, z)`` whose sectorial coordinate is ``omega`` (m^2).

        ``order`` adds x-derivatives. Only ``values[0]`` of the returned row is filled.
        """
        e, xi = self.locate(x)
        lengths, phi_y, phi_z, phi_t = self._element_data
        extra = {"bending_moment": 1, "axial_force": 1, "torque_sv": 1, "bimoment": 1, "normal_strain": 1,
                 "shear_force_y": 2, "shear_force_z": 2}.get(name, 0)
        n = field_matrix(xi, lengths[e], phi_y[e], phi_z[e], order + extra, phi_t[e])[0]
        sec, mat = self.section, self.material
        ty, tz = n[FIELD_INDEX["theta_y"]], n[FIELD_INDEX["theta_z"]]
        if name == "bending_moment":
            row = -mat.E * (sec.I_y * ty - sec.I_yz * tz)
        elif name == "shear_force_z":
            row = mat.E * (sec.I_y * ty - sec.I_yz * tz)
        elif name == "shear_force_y":
            row = -mat.E * (sec.I_z * tz - sec.I_yz * ty)
        elif name == "axial_force":
            row = mat.E * sec.A * n[FIELD_INDEX["u"]]
        elif name == "torque_sv":
            row = mat.G * sec.J * n[FIELD_INDEX["theta_x"]]
        elif name == "bimoment":
            row = -mat.E * sec.I_w * n[FIELD_INDEX["psi"]]
        elif name == "normal_strain":
            row = (n[FIELD_INDEX["u"]] + (z - sec.z_c) * ty - (y - sec.y_c) * tz - omega * n[FIELD_INDEX["psi"]])
        elif name == "w_deck":
            row = n[FIELD_INDEX["w"]] + (y - self.section.y_s) * n[FIELD_INDEX["theta_x"]]
        elif name in FIELD_INDEX:
            row = n[FIELD_INDEX[name]]
        else:
            raise ModelError(f"unknown field {name!r} (expected one of: {', '.join(FIELD_INDEX)}, w_deck, "
                             f"{', '.join(RESULTANTS)}, normal_strain)")
        return DeckRow(dofs=self._element_dofs(e), values=row[None, :])

    def field(
        self, d: npt.NDArray[np.float64], name: str, x: npt.ArrayLike, y: float = 0.0, order: int = 0
    ) -> npt.NDArray[np.float64]:
        """Evaluate field ``name`` (see :meth:`field_row`) of the full DOF vector ``d`` at positions ``x`` (m)."""
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        out = np.empty(len(xs))
        for i, xv in enumerate(xs):
            row = self.field_row(name, float(xv), y, order)
            out[i] = row.values[0] @ d[row.dofs]
        return out

    # ---------------------------------------------------------------- statics
    def load_vector(self, loads: Sequence[PointLoad]) -> npt.NDArray[np.float64]:
        """Consistent nodal force vector (full size, N and N m) of vertical point loads."""
        f = np.zeros(self.ndof)
        for load in loads:
            self._check_on_deck(load.x, load.y)
            row = self.deck_point_row(load.x, load.y)
            np.add.at(f, row.dofs, load.Fz * row.values[0])
        return f

    def _check_on_deck(self, x: float, y: float) -> None:
        y_min, y_max = self.section.deck_y
        if not (0.0 <= x <= self.length):
            raise ModelError(f"load at x = {x} m is off the bridge (0 to {self.length} m)")
        if not (y_min - 1e-9 <= y <= y_max + 1e-9):
            raise ModelError(f"load at y = {y} m is off the deck ({y_min} to {y_max} m)")

    def static(self, loads: Sequence[PointLoad] = (), f: npt.NDArray[np.float64] | None = None) -> StaticResult:
        """Static displacements under point loads (and/or a full force vector ``f``)."""
        total = self.load_vector(loads)
        if f is not None:
            total = total + f
        d_free = self._static_lu.solve(total[self.free])
        if not np.all(np.isfinite(d_free)):
            raise ModelError("static solve failed: the supports leave a mechanism (add restraints)")
        return StaticResult(d=self.expand(d_free), bridge=self)

    # ----------------------------------------------------------------- modes
    def modes(self, count: int = 10) -> ModalResult:
        """The ``count`` lowest natural modes (undamped), classified by strain energy."""
        n_free = len(self.free)
        if count < 1:
            raise ConfigError("`count` must be >= 1")
        count = min(count, n_free)
        if n_free <= 3000:
            w2, phi = scipy.linalg.eigh(
                self.K_ff.toarray(), self.M_ff.toarray(), subset_by_index=(0, count - 1), driver="gvx"
            )
        else:  # large meshes: shift-invert Lanczos around zero
            w2, phi = spla.eigsh(self.K_ff, k=count, M=self.M_ff, sigma=0.0, which="LM")
            order = np.argsort(w2)
            w2, phi = w2[order], phi[:, order]
        if len(w2) < count or not np.all(np.isfinite(w2)) or not np.all(np.isfinite(phi)):
            # The mass (or stiffness) is out of the range double precision can resolve, e.g. rho = 1e-300.
            raise ModelError(
                f"the modal analysis found {len(w2)} of {count} modes: the mass and stiffness matrices are "
                f"out of the range it can resolve (rho = {self.material.rho:g} kg/m^3, E = {self.material.E:g} Pa); "
                "check the material and section constants"
            )
        omega = np.sqrt(np.maximum(w2, 0.0))
        # Normalise each mode so its largest deflection is positive (repeatable signs).
        for j in range(phi.shape[1]):
            k = np.argmax(np.abs(phi[:, j]))
            if phi[k, j] < 0:
                phi[:, j] *= -1.0
        shapes = self.expand(phi)
        shares, kinds, dominant = self._classify(shapes)
        participation = self._participation(phi)
        return ModalResult(omega, shapes, shares, kinds, dominant, participation, bridge=self)

    @cached_property
    def _group_masks(self) -> dict[str, npt.NDArray[np.bool_]]:
        dof_kind = np.tile(np.arange(NODE_DOFS), self.n_nodes)
        return {
            kind: np.isin(dof_kind, [DOF_INDEX[n] for n in names]) for kind, names in MODE_KINDS.items()
        }

    def _classify(self, shapes: np.ndarray) -> tuple[dict[str, np.ndarray], list[str], list[str]]:
        k_phi = self.K @ shapes
        total = np.einsum("ij,ij->j", shapes, k_phi)
        shares = {
            kind: np.einsum("ij,ij->j", shapes[mask], k_phi[mask]) / total
            for kind, mask in self._group_masks.items()
        }
        kinds, dominant = [], []
        names = list(shares)
        table = np.array([shares[k] for k in names])
        for j in range(shapes.shape[1]):
            order = np.argsort(table[:, j])[::-1]
            top, second = names[order[0]], names[order[1]]
            dominant.append(top)
            if table[order[0], j] >= _PURE_KIND_SHARE:
                kinds.append(top)
            else:
                a, b = sorted([top, second], key=list(MODE_KINDS).index)
                kinds.append(f"coupled {a}-{b}")
        return shares, kinds, dominant

    def _participation(self, phi_free: np.ndarray) -> dict[str, np.ndarray]:
        """Effective modal mass fractions ``(phi^T M r)^2 / (r^T M r)`` per direction (docs/theory.md §4.6).

        ``r`` moves every node, the supports included, rigidly in the direction
        (base excitation): the free DOFs' mass coupling to the supports' DOFs
        (``M_fs r_s``) belongs in ``phi^T M r``; leaving it out overstates the
        first vertical mode of a simply supported beam (0.830 instead of 8/pi^2).
        """
        out = {}
        dof_kind = np.tile(np.arange(NODE_DOFS), self.n_nodes)
        phi = self.expand(phi_free)  # zero at restrained DOFs
        for direction, dof in (("vertical", "w"), ("lateral", "v"), ("axial", "u"), ("torsion", "theta_x")):
            r = (dof_kind == DOF_INDEX[dof]).astype(float)
            m_r = self.M @ r
            total = r @ m_r
            # Mass-normalised shapes: effective mass = (phi^T M r)^2.
            out[direction] = (phi.T @ m_r) ** 2 / total if total > 0 else np.zeros(phi.shape[1])
        return out

    def check_no_mechanism(self) -> None:
        """Raise ModelError when the supports leave the bridge free to move (a rigid-body mode).

        Cholesky factor of the free stiffness ``K_ff = U^T U``: a mechanism makes
        a pivot vanish. Each pivot is compared with its own diagonal entry
        (``U_jj^2 / K_jj``), so the test depends neither on the density nor on
        how fine the mesh is (a comparison of the lowest eigenvalue with the
        largest ``K_ii / M_ii`` did, and refused sound light or finely meshed decks).
        """
        band = upper_band(self.K_ff)
        diag = band[-1].copy()
        try:
            factor = scipy.linalg.cholesky_banded(band, lower=False, check_finite=False)
        except np.linalg.LinAlgError:
            ratio = 0.0
        else:
            ratio = float(np.min(factor[-1] ** 2 / diag))
        if not ratio > MECHANISM_PIVOT:
            raise ModelError(
                "the bridge has a rigid-body mode: its supports leave it free to move "
                "(for example no twist or no axial restraint anywhere); restrain more DOFs in `supports`"
            )


def _mesh(spans: Sequence[float], elements_per_span: Sequence[int]) -> np.ndarray:
    xs = [0.0]
    start = 0.0
    for span, n in zip(spans, elements_per_span):
        xs.extend(start + span * np.arange(1, n + 1) / n)
        start += span
    return np.array(xs)


def _rayleigh(w1: float, w2: float, z1: float, z2: float) -> tuple[float, float]:
    """alpha, beta with zeta(w) = alpha/(2w) + beta w/2 hitting (w1, z1) and (w2, z2)."""
    a = np.array([[1.0 / (2.0 * w1), w1 / 2.0], [1.0 / (2.0 * w2), w2 / 2.0]])
    alpha, beta = np.linalg.solve(a, [z1, z2])
    return float(alpha), float(beta)


def build_bridge(
    spans: Sequence[float],
    elements_per_span: Union[int, Sequence[int]],
    material: Material,
    section: SectionProperties,
    supports: Sequence[SupportSpec],
    damping: Union[RayleighDamping, ExplicitDamping, None] = None,
    theory: BeamTheory | None = None,
    stiffness_factors: Sequence[float] | npt.ArrayLike | None = None,
    support_springs: Sequence[tuple[int, str, float]] = (),
) -> BridgeModel:
    """Assemble a continuous beam bridge.

    Args:
        spans: span lengths, m (one per span, continuous over the inner supports).
        elements_per_span: elements in each span (one number for all, or one per span).
        material: the beam's material.
        section: the cross-section constants.
        supports: one entry per support line (``len(spans) + 1``): a preset
            name from :data:`SUPPORT_PRESETS` or a list of DOF names to restrain.
        damping: Rayleigh damping from two modes' ratios, explicit alpha/beta, or None.
        theory: torsion ("vlasov" | "benscoter") and bending ("timoshenko" |
            "euler-bernoulli") theories; default Vlasov and Timoshenko (the seed's element).
        stiffness_factors: one factor per element (from x = 0) on its stiffness matrix: damage such as
            cracking over a length of the deck (a factor 0.5 halves every stiffness of the element: E A,
            E I, G A_s, G J, E I_w); default 1 everywhere. The mass is not changed. Stress rows still use
            the material's E.
        support_springs: (support line index, DOF name, stiffness) for a degraded support: that DOF of the
            support line is no longer held but sits on a spring (N/m for translations, N m/rad for rotations).

    Returns:
        The assembled, immutable :class:`BridgeModel`.

    Raises:
        ConfigError: for inconsistent input.
    """
    spans = tuple(float(s) for s in spans)
    if not spans or any(not s > 0 for s in spans):
        raise ConfigError(f"`spans` must be one or more positive lengths (got {list(spans)})")
    if isinstance(elements_per_span, (int, np.integer)):
        n_per = [int(elements_per_span)] * len(spans)
    else:
        n_per = [int(n) for n in elements_per_span]
    if len(n_per) != len(spans) or any(n < 1 for n in n_per):
        raise ConfigError("`elements_per_span` must be >= 1, one number or one per span")
    if len(supports) != len(spans) + 1:
        raise ConfigError(f"`supports` needs {len(spans) + 1} entries, one per support line (got {len(supports)})")
    n_elements = sum(n_per)
    MAX_DOFS.check(NODE_DOFS * (n_elements + 1), "`elements_per_span`",
                   f"{n_elements:,} elements in {len(spans)} span(s), {NODE_DOFS} per node")
    support_sets = tuple(support_dofs(s) for s in supports)
    theory = DEFAULT_THEORY if theory is None else theory
    if not isinstance(theory, BeamTheory):
        raise ConfigError(f"`theory` must be a BeamTheory (got {theory!r})")
    if theory.torsion == "benscoter" and section.I_w > 0 and section.I_ws is None:
        raise ConfigError(
            'torsion = "benscoter" needs the warping shear constant `I_ws` of the section (m^4): give it with the '
            'section constants, or describe the section by plates (which compute it), or use torsion = "vlasov"'
        )

    nodes_x = _mesh(spans, n_per)
    n_nodes = len(nodes_x)
    ndof = NODE_DOFS * n_nodes
    lengths = np.diff(nodes_x)
    factors = np.ones(len(lengths)) if stiffness_factors is None else np.asarray(stiffness_factors, dtype=float)
    if factors.shape != lengths.shape or not np.all(np.isfinite(factors)) or np.any(factors <= 0):
        raise ConfigError(f"`stiffness_factors` must be {len(lengths)} numbers > 0, one per element "
                          f"(got {len(factors.ravel())})")

    # Element matrices depend only on the length: compute once per distinct length.
    cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    rows, cols, kv, mv = [], [], [], []
    local = np.arange(ELEMENT_DOFS)
    for e, L in enumerate(lengths):
        key = round(float(L), 12)
        if key not in cache:
            cache[key] = element_matrices(float(L), material, section, theory)
        k_e, m_e = cache[key]
        dofs = NODE_DOFS * e + local
        rows.append(np.repeat(dofs, ELEMENT_DOFS))
        cols.append(np.tile(dofs, ELEMENT_DOFS))
        kv.append(factors[e] * k_e.ravel())
        mv.append(m_e.ravel())
    rows_a, cols_a = np.concatenate(rows), np.concatenate(cols)
    K = sp.csr_matrix((np.concatenate(kv), (rows_a, cols_a)), shape=(ndof, ndof))
    M = sp.csr_matrix((np.concatenate(mv), (rows_a, cols_a)), shape=(ndof, ndof))

    support_nodes = np.concatenate([[0], np.cumsum(n_per)])
    restrained_set = {NODE_DOFS * int(node) + DOF_INDEX[name]
                      for node, names in zip(support_nodes, support_sets) for name in names}
    springs = np.zeros(ndof)
    for line, name, stiffness in support_springs:
        if not (isinstance(line, (int, np.integer)) and 0 <= line < len(support_nodes)):
            raise ConfigError(f"a support spring's support line must be 0 ... {len(support_nodes) - 1} (got {line!r})")
        if name not in DOF_INDEX:
            raise ConfigError(f"unknown DOF {name!r} of a support spring (expected one of: {', '.join(DOF_NAMES)})")
        if not (np.isfinite(stiffness) and stiffness > 0):
            raise ConfigError(f"a support spring's stiffness must be > 0 (got {stiffness!r})")
        dof = NODE_DOFS * int(support_nodes[line]) + DOF_INDEX[name]
        restrained_set.discard(dof)
        springs[dof] += float(stiffness)
    if np.any(springs):
        K = (K + sp.diags(springs)).tocsr()
    restrained = sorted(restrained_set)
    bridge = BridgeModel(
        spans=spans,
        nodes_x=nodes_x,
        material=material,
        section=section,
        supports=support_sets,
        restrained=np.array(restrained, dtype=np.int64),
        K=K,
        M=M,
        theory=theory,
    )
    bridge.check_no_mechanism()
    if damping is None:
        return bridge
    if isinstance(damping, ExplicitDamping):
        if damping.alpha < 0 or damping.beta < 0:
            raise ConfigError("Rayleigh `alpha` and `beta` must be >= 0")
        note = f"explicit alpha={damping.alpha:g}, beta={damping.beta:g}"
        return _with_damping(bridge, damping.alpha, damping.beta, note)
    z1, z2 = damping.ratios
    modal = bridge.modes(count=max(30, _max_mode_number(damping.modes)))
    i1, i2 = modal.index_of(damping.modes[0]), modal.index_of(damping.modes[1])
    if i1 == i2:
        raise ConfigError(f"damping `modes` {damping.modes} name the same mode twice")
    w1, w2 = modal.omega[i1], modal.omega[i2]
    alpha, beta = _rayleigh(w1, w2, z1, z2)
    note = (
        f"Rayleigh: {z1:.3g} at mode {i1 + 1} ({modal.f_hz[i1]:.4g} Hz, {damping.modes[0]}), "
        f"{z2:.3g} at mode {i2 + 1} ({modal.f_hz[i2]:.4g} Hz, {damping.modes[1]})"
    )
    return _with_damping(bridge, alpha, beta, note)


def _max_mode_number(refs: Sequence[Union[int, str]]) -> int:
    return max([int(r) for r in refs if isinstance(r, (int, np.integer))] + [1])


def _with_damping(bridge: BridgeModel, alpha: float, beta: float, note: str) -> BridgeModel:
    from dataclasses import replace

    return replace(bridge, alpha=alpha, beta=beta, damping_note=note)
