"""The two bases the coupled step runs on (docs/theory.md §6.6-6.8).

:class:`DirectBasis` keeps every free DOF of the FE model (the reference);
:class:`ModalBasis` keeps a truncated set of mass-normalised modes (fast).
Both factorise the effective matrix ``A = M + (1 + alpha)(gamma dt C + beta
dt^2 K)`` exactly once (``n_factorizations`` counts the factorisations
actually done, ``n_solves`` the solves of the compiled step); vehicles enter
the step as low-rank updates (:mod:`cosim.core.coupling`). Each basis hands
the compiled block loop its arrays as one :class:`cosim.core.kernels.BasisArrays`.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from cosim.errors import ConfigError

from .banded import upper_band
from .bridge import BridgeModel
from .element import DeckRow
from .kernels import DIRECT, MODAL, BasisArrays
from .modal_bridge import ModalBridge
from .schemes import Scheme

_EMPTY_1 = np.zeros(0)
_EMPTY_2 = np.zeros((0, 0))
_EMPTY_I = np.zeros(0, dtype=np.int64)


class _Counts:
    """What both bases count: factorisations of their effective matrix and solves with it."""

    n_factorizations: int
    n_solves: int

    def count_solves(self, total: int) -> None:
        """The solves a coupled system's compiled step has done with this basis so far (counted there: the
        compiled code cannot update this object)."""
        self.n_solves = int(total)


class DirectBasis(_Counts):
    """All free DOFs of the FE model: the full finite-element solution.

    Two exact engines solve it (docs/theory.md §6.7-6.8, §12):

    - *banded*: the banded Cholesky factor of the effective matrix, K and M
      in CSR form, and the dense inverse of the effective matrix, whose
      entries give the Woodbury capacitance matrix without one solve per
      vehicle (n^2 doubles: the basis refuses models above
      ``MAX_DIRECT_DOFS`` and points to the modal basis);
    - *complete modal*: with Rayleigh damping every mode of the model
      diagonalises the Newmark/HHT operator, so the same solution costs O(n)
      per step plus the vehicles' rows projected on the n modes. Far cheaper
      with few vehicles on the deck (free vibration above all); the block loop
      uses it for blocks with at most ``COMPLETE_MODAL_MAX_VEHICLES`` contact
      points and the banded engine for busier ones. Both agree to round-off
      (1e-10 of the peak, tests/unit/test_direct_engines.py). Built for models
      up to ``COMPLETE_MODAL_MAX_DOFS`` free DOFs (a dense eigen-solution).

    Args:
        complete_modal: allow the complete modal engine (False: banded only).
    """

    name = "direct"
    MAX_DIRECT_DOFS = 6000
    COMPLETE_MODAL_MAX_DOFS = 2000
    COMPLETE_MODAL_MAX_VEHICLES = 8

    def __init__(self, bridge: BridgeModel, dt: float, scheme: Scheme, complete_modal: bool = True) -> None:
        self.bridge, self.dt, self.scheme = bridge, float(dt), scheme
        self.n = len(bridge.free)
        if self.n > self.MAX_DIRECT_DOFS:
            raise ConfigError(
                f"the direct basis keeps a dense {self.n} x {self.n} inverse; above {self.MAX_DIRECT_DOFS} "
                "free DOFs use `basis = \"modal\"` (or fewer elements)"
            )
        self.K = bridge.K_ff.tocsr()
        self.M = bridge.M_ff.tocsr()
        for mat in (self.K, self.M):  # drop explicit zeros the assembly left (CSR work is per entry)
            mat.eliminate_zeros()
        self.ray_alpha, self.ray_beta = float(bridge.alpha), float(bridge.beta)
        self.C = (self.ray_alpha * self.M + self.ray_beta * self.K).tocsr()
        c = 1.0 + scheme.alpha
        a_eff = (self.M + c * (scheme.gamma * dt * self.C + scheme.beta * dt * dt * self.K)).tocoo()
        self.bandwidth = int(np.max(np.abs(a_eff.col - a_eff.row)))
        self.n_factorizations = 0
        self.n_solves = 0
        self.cholesky_band = self._factorize(upper_band(a_eff))
        bw = self.bandwidth
        # The same factor stored by rows (row j holds U[j, j:j+bw+1]) for the compiled solve.
        self.cholesky_rows = np.zeros((self.n, bw + 1))
        for k in range(bw + 1):
            self.cholesky_rows[: self.n - k, k] = self.cholesky_band[bw - k, k:]
        # C order and int64 CSR indices (kernel_arrays) for every engine and basis of a beam deck: numba compiles
        # the block loop once per argument layout (about a minute each on a first run), and LAPACK's answer is F.
        self.inverse = np.ascontiguousarray(
            scipy.linalg.cho_solve_banded((self.cholesky_band, False), np.eye(self.n), check_finite=False))
        # Full DOF -> reduced index, -1 for restrained DOFs.
        self.reduced_map = np.full(bridge.ndof, -1, dtype=np.int64)
        self.reduced_map[bridge.free] = np.arange(self.n)
        self.complete: _CompleteModes | None = None
        if complete_modal and self.n <= self.COMPLETE_MODAL_MAX_DOFS:
            self.complete = _CompleteModes(self, scheme, dt)

    def _factorize(self, band: np.ndarray) -> np.ndarray:
        """The banded Cholesky factor of the effective matrix: the only factorisation a run does (counted)."""
        # Hand-off to LAPACK's banded Cholesky (pbtrf): the bridge is a beam, so its
        # matrices are banded, and a banded factor is the cheapest exact solve.
        self.n_factorizations += 1
        return scipy.linalg.cholesky_banded(band, lower=False)

    def kernel_arrays(self) -> BasisArrays:
        """What the compiled block loop needs of this basis."""
        index = [np.asarray(a, dtype=np.int64) for a in (self.K.indptr, self.K.indices, self.M.indptr, self.M.indices)]
        return BasisArrays(
            DIRECT, self.n, self.cholesky_rows, index[0], index[1], self.K.data,
            index[2], index[3], self.M.data, self.ray_alpha, self.ray_beta, self.inverse,
            self.reduced_map, _EMPTY_2, _EMPTY_1, _EMPTY_1, _EMPTY_1,
        )

    def complete_kernel_arrays(self) -> BasisArrays:
        """The complete modal engine's arrays (the physical inverse serves the capacitance matrix)."""
        c = self.complete
        if c is None:
            raise ConfigError("this direct basis was built without its complete modal engine")
        return BasisArrays(
            MODAL, self.n, _EMPTY_2, _EMPTY_I, _EMPTY_I, _EMPTY_1, _EMPTY_I, _EMPTY_I, _EMPTY_1, 0.0, 0.0,
            self.inverse, self.reduced_map, c.phi_full, c.c_diag, c.k_diag, c.a_inv,
        )

    def sparse_rows(self, rows: list[DeckRow]) -> tuple[np.ndarray, np.ndarray]:
        """Rows of element DOFs (``values[0]``) as (unknown index, value) pairs; -1 marks restrained DOFs."""
        if not rows:
            return np.zeros((0, 0), dtype=np.int64), np.zeros((0, 0))
        idx = np.array([self.reduced_index(r.dofs) for r in rows], dtype=np.int64)
        vals = np.array([r.values[0] for r in rows], dtype=float)
        return idx, vals

    def reduced_index(self, dofs: np.ndarray) -> np.ndarray:
        """Reduced indices of full DOFs (-1 where restrained)."""
        return self.reduced_map[dofs]

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A^{-1} b for a vector or a matrix of right-hand sides."""
        self.n_solves += 1
        return scipy.linalg.cho_solve_banded((self.cholesky_band, False), b, check_finite=False)

    def internal_force(self, d: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C v + K d."""
        return self.C @ v + self.K @ d

    def reduce_rows(self, dofs: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Dense reduced rows (q, n) from element rows (dofs (q, 14), values (q, 14))."""
        q = dofs.shape[0]
        out = np.zeros((q, self.n + 1))
        idx = np.where(self.reduced_map[dofs] >= 0, self.reduced_map[dofs], self.n)
        np.add.at(out, (np.repeat(np.arange(q), dofs.shape[1]), idx.ravel()), values.ravel())
        return out[:, : self.n]

    def full(self, x: np.ndarray) -> np.ndarray:
        """Full DOF vector from reduced coordinates."""
        return self.bridge.expand(x)

    def energy(self, d: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus strain energy, J."""
        return float(0.5 * v @ (self.M @ v) + 0.5 * d @ (self.K @ d))


class _CompleteModes:
    """Every mode of a direct basis' model, for its complete modal engine (see :class:`DirectBasis`)."""

    def __init__(self, basis: DirectBasis, scheme: Scheme, dt: float) -> None:
        bridge = basis.bridge
        # The dense generalized eigen-solution (LAPACK sygvd): mass-normalised modes, Phi^T M Phi = I.
        w2, phi = scipy.linalg.eigh(bridge.K_ff.toarray(), bridge.M_ff.toarray(), driver="gvd")
        self.phi = np.ascontiguousarray(phi)  # (n, n), reduced coordinates
        self.phi_full = np.ascontiguousarray(bridge.expand(phi))  # (ndof, n)
        self.k_diag = w2
        self.c_diag = basis.ray_alpha + basis.ray_beta * w2  # Rayleigh: C is diagonal in the modes
        c = 1.0 + scheme.alpha
        self.a_inv = 1.0 / (1.0 + c * (scheme.gamma * dt * self.c_diag + scheme.beta * dt * dt * self.k_diag))
        self._m_phi = basis.M @ self.phi  # M Phi: the modal coordinates of a state are Phi^T M x

    def to_modal(self, x: np.ndarray) -> np.ndarray:
        """Modal coordinates of a displacement-like reduced vector: eta = Phi^T M x."""
        return self._m_phi.T @ x

    def from_modal(self, eta: np.ndarray) -> np.ndarray:
        """The reduced vector of modal coordinates: x = Phi eta."""
        return self.phi @ eta

    def force_to_modal(self, f: np.ndarray) -> np.ndarray:
        """Modal components of a force vector: Phi^T f."""
        return self.phi.T @ f

    def force_from_modal(self, f_modal: np.ndarray) -> np.ndarray:
        """The force vector of modal components: M Phi f_modal (since Phi^T M Phi = I)."""
        return self._m_phi @ f_modal


class ModalBasis(_Counts):
    """A truncated set of mass-normalised modes; the effective matrix is diagonal.

    Damping: the bridge's Rayleigh coefficients give each mode
    ``2 zeta_j omega_j = alpha + beta omega_j^2`` (exact, the modes are M- and
    K-orthogonal), or ``modal_damping`` sets one ratio for every mode.
    """

    name = "modal"

    def __init__(
        self,
        bridge: BridgeModel,
        dt: float,
        scheme: Scheme,
        n_modes: int | None = None,
        cutoff_hz: float | None = None,
        modal_damping: float | None = None,
    ) -> None:
        if n_modes is None and cutoff_hz is None:
            raise ConfigError("the modal basis needs `modes` (a count) or `cutoff_hz`")
        count = n_modes if n_modes is not None else min(len(bridge.free), 400)
        modal = bridge.modes(count)
        keep = np.ones(len(modal.omega), dtype=bool)
        if cutoff_hz is not None:
            keep &= modal.f_hz <= cutoff_hz
            if cutoff_hz > modal.f_hz[-1] and n_modes is None and count < len(bridge.free):
                raise ConfigError(f"`cutoff_hz` = {cutoff_hz} Hz needs more than {count} modes; give `modes`")
        if not keep.any():
            raise ConfigError(f"no mode below `cutoff_hz` = {cutoff_hz} Hz (first is {modal.f_hz[0]:.3g} Hz)")
        self.modal = modal
        self.dt, self.scheme = float(dt), scheme
        self.omega = modal.omega[keep]
        self.n = int(keep.sum())
        self.bridge = bridge
        self.phi_full = np.ascontiguousarray(modal.shapes[:, keep])  # (ndof, n)
        if modal_damping is not None:
            self.c_diag = 2.0 * modal_damping * self.omega
        else:
            self.c_diag = bridge.alpha + bridge.beta * self.omega**2
        self.k_diag = self.omega**2
        self.n_factorizations = 0
        self.n_solves = 0
        self.a_inv_diag = self._factorize(scheme, dt)

    def _factorize(self, scheme: Scheme, dt: float) -> np.ndarray:
        """The inverse of the (diagonal) effective matrix: the modal basis' one factorisation (counted)."""
        self.n_factorizations += 1
        c = 1.0 + scheme.alpha
        return 1.0 / (1.0 + c * (scheme.gamma * dt * self.c_diag + scheme.beta * dt * dt * self.k_diag))

    def kernel_arrays(self) -> BasisArrays:
        """What the compiled block loop needs of this basis."""
        return BasisArrays(
            MODAL, self.n, _EMPTY_2, _EMPTY_I, _EMPTY_I, _EMPTY_1, _EMPTY_I, _EMPTY_I, _EMPTY_1, 0.0, 0.0, _EMPTY_2,
            _EMPTY_I, self.phi_full, self.c_diag, self.k_diag, self.a_inv_diag,
        )

    def sparse_rows(self, rows: list[DeckRow]) -> tuple[np.ndarray, np.ndarray]:
        """Rows of element DOFs (``values[0]``) projected on the modes, as (mode index, value) pairs."""
        vals = np.array([self.reduce_rows(r.dofs[None, :], r.values[:1])[0] for r in rows],
                        dtype=float).reshape(len(rows), self.n)
        idx = np.tile(np.arange(self.n, dtype=np.int64), (len(rows), 1))
        return idx, vals

    def solve(self, b: np.ndarray) -> np.ndarray:
        self.n_solves += 1
        return b * (self.a_inv_diag if b.ndim == 1 else self.a_inv_diag[:, None])

    def internal_force(self, d: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.c_diag * v + self.k_diag * d

    def reduce_rows(self, dofs: np.ndarray, values: np.ndarray) -> np.ndarray:
        return np.einsum("qk,qkm->qm", values, self.phi_full[dofs])

    def full(self, x: np.ndarray) -> np.ndarray:
        return self.phi_full @ x

    def energy(self, d: np.ndarray, v: np.ndarray) -> float:
        return float(0.5 * v @ v + 0.5 * d @ (self.k_diag * d))


class DeckModalBasis(_Counts):
    """The modes of a deck given by its modes (:class:`cosim.core.modal_bridge.ModalBridge`): the same diagonal
    Newmark/HHT operator as :class:`ModalBasis`, each mode damped by its own ratio (``c = 2 zeta omega``).
    Contact and sensor rows come from the deck's surface in modal coordinates, so there is no DOF vector to
    project from (``phi`` is empty in the kernel's arrays)."""

    name = "modal"

    def __init__(self, bridge: ModalBridge, dt: float, scheme: Scheme) -> None:
        self.bridge, self.dt, self.scheme = bridge, float(dt), scheme
        self.omega = np.array(bridge.omega, dtype=float)
        self.n = int(bridge.n_modes)
        self.c_diag = 2.0 * bridge.zeta * self.omega
        self.k_diag = self.omega**2
        self.n_factorizations = 0
        self.n_solves = 0
        self.n_factorizations += 1
        c = 1.0 + scheme.alpha
        self.a_inv_diag = 1.0 / (1.0 + c * (scheme.gamma * dt * self.c_diag + scheme.beta * dt * dt * self.k_diag))

    def kernel_arrays(self) -> BasisArrays:
        """What the compiled block loop needs of this basis."""
        return BasisArrays(
            MODAL, self.n, _EMPTY_2, _EMPTY_I, _EMPTY_I, _EMPTY_1, _EMPTY_I, _EMPTY_I, _EMPTY_1, 0.0, 0.0, _EMPTY_2,
            _EMPTY_I, np.zeros((0, self.n)), self.c_diag, self.k_diag, self.a_inv_diag,
        )

    def sparse_rows(self, rows: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Modal rows (m,) as (mode index, value) pairs."""
        vals = np.array(rows, dtype=float).reshape(len(rows), self.n)
        idx = np.tile(np.arange(self.n, dtype=np.int64), (len(rows), 1))
        return idx, vals

    def energy(self, d: np.ndarray, v: np.ndarray) -> float:
        return float(0.5 * v @ v + 0.5 * d @ (self.k_diag * d))


def make_basis(
    bridge: BridgeModel | ModalBridge,
    dt: float,
    scheme: Scheme,
    basis: str = "direct",
    n_modes: int | None = None,
    cutoff_hz: float | None = None,
    modal_damping: float | None = None,
) -> DirectBasis | ModalBasis | DeckModalBasis:
    """The basis named ``basis`` ("direct" or "modal"). A deck given by its modes is solved on them
    (:class:`DeckModalBasis`): ``n_modes``/``cutoff_hz``, when given, must describe the modes it keeps (select
    them on the deck: :meth:`cosim.core.modal_deck.ModalDeck.select`)."""
    if not dt > 0:
        raise ConfigError(f"`dt` must be > 0 s (got {dt})")
    if isinstance(bridge, ModalBridge):
        if basis != "modal":
            raise ConfigError(f"a deck given by its modes is solved on its modes: `basis` must be 'modal' "
                              f"(got {basis!r})")
        if n_modes is not None and n_modes != bridge.n_modes:
            raise ConfigError(f"`modes` = {n_modes}, but the deck keeps {bridge.n_modes}: select the modes on the "
                              "deck (ModalDeck.select) before building its ModalBridge")
        if cutoff_hz is not None and bridge.n_modes and float(bridge.f_hz[-1]) > cutoff_hz * (1 + 1e-12):
            raise ConfigError(f"`cutoff_hz` = {cutoff_hz} Hz, but the deck keeps a mode at "
                              f"{float(bridge.f_hz[-1]):.6g} Hz: select the modes on the deck first")
        if modal_damping is not None:
            raise ConfigError("a deck given by its modes takes its damping from its ModalBridge (ModalRatios)")
        return DeckModalBasis(bridge, dt, scheme)
    if basis == "direct":
        return DirectBasis(bridge, dt, scheme)
    if basis == "modal":
        return ModalBasis(bridge, dt, scheme, n_modes, cutoff_hz, modal_damping)
    raise ConfigError(f"`basis` must be 'direct' or 'modal' (got {basis!r})")
