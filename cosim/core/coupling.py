"""The coupled vehicle-bridge time step: the heart of the co-simulation.

Unknown of the step: the bridge acceleration ``a = d''_{n+1}`` in the basis'
reduced coordinates. Every vehicle's own DOFs are eliminated inside the step
(they obey the same Newmark/HHT rule), which leaves the effective deck force
of vehicle i linear in ``a``::

    E_i = e0_i - p_i . a

with ``p_i = c0 n0 + c1 n1 + c2 n2`` a combination of the contact rows
``n0 = N_bar``, ``n1 = N_bar_x``, ``n2 = N_bar_xx`` at the contact point
(bending and twist: ``w = w_S + (y - y_S) theta_x``). The wheel of the
rigid-contact quarter-car follows the deck, and its acceleration is
differentiated honestly for a vehicle with speed ``v`` and acceleration
``a_v`` (DESIGN.md section 4)::

    u_w'' = n0 d'' + 2 v n1 d' + (v^2 n2 + a_v n1) d

The bridge equation (HHT form; alpha = 0 is Newmark's average acceleration)
weights every elastic and damping force, the suspension and tyre forces
included, while inertia (bridge and rigid-contact wheel) stays at t_{n+1}::

    M a + (1+alpha)(C v_{n+1} + K d_{n+1}) - alpha (C v_n + K d_n) = sum_i n0_i E_i - alpha F_n

It becomes ``(A + U P^T) a = b`` with the constant, once-factorised
``A = M + (1+alpha)(gamma dt C + beta dt^2 K)``, ``U = [n0_i]`` and
``P = [p_i]``: a rank-q update solved with the Woodbury identity. The loop
itself runs compiled (:mod:`cosim.core.kernels`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.errors import ModelError

from . import kernels
from .bridge import BridgeModel
from .integrator import DirectBasis, ModalBasis, Scheme
from .roughness import RoadProfile, smooth_road
from .traffic import TrafficBlock, TrafficFrame
from .vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel

SENSOR_KIND = {"displacement": 0, "velocity": 1, "acceleration": 2, "bending_moment": 0}


@dataclass
class BlockReport:
    """What the vehicles did over a block of K steps (arrays (K, q) over the block's vehicles).

    ``on_deck`` says where a vehicle was on the deck; contact forces (N,
    compression positive) are zero elsewhere; ``sensors`` is (K, s).
    """

    ids: tuple[str, ...]
    models: tuple[VehicleModel, ...]
    x: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    a: npt.NDArray[np.float64]
    on_deck: npt.NDArray[np.bool_]
    contact_force: npt.NDArray[np.float64]
    body_displacement: npt.NDArray[np.float64]
    body_acceleration: npt.NDArray[np.float64]
    sensors: npt.NDArray[np.float64]


def _model_parameters(models: tuple[VehicleModel, ...], ids: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    q = len(models)
    kind = np.empty(q, dtype=np.int64)
    params = np.zeros((7, q))  # m_v, m_w, k_v, c_v, k_t, c_t, total mass
    for j, m in enumerate(models):
        if isinstance(m, MovingForce):
            kind[j] = kernels.MOVING_FORCE
        elif isinstance(m, QuarterCar):
            kind[j] = kernels.QUARTER_CAR
            params[:4, j] = m.m_v, m.m_w, m.k_v, m.c_v
        elif isinstance(m, TyreQuarterCar):
            kind[j] = kernels.TYRE_QUARTER_CAR
            params[:6, j] = m.m_v, m.m_w, m.k_v, m.c_v, m.k_t, m.c_t
        else:
            raise ModelError(f"vehicle {ids[j]}: unknown vehicle model {type(m).__name__}")
        params[6, j] = m.total_mass
    return kind, params


class CoupledSystem:
    """Bridge plus vehicles, advanced by a constant step ``dt``.

    Args:
        bridge: the structural model.
        basis: :class:`DirectBasis` or :class:`ModalBasis`, built for ``dt`` and ``scheme``.
        scheme: the time-integration scheme.
        dt: time step, s.
        road: road profiles (default smooth).
        gravity: m/s^2.
        sensors: ``(x, y, quantity)`` triples sampled at every step.
    """

    def __init__(
        self,
        bridge: BridgeModel,
        basis: DirectBasis | ModalBasis,
        scheme: Scheme,
        dt: float,
        road: RoadProfile | None = None,
        gravity: float = 9.81,
        sensors: tuple[tuple[float, float, str], ...] = (),
    ) -> None:
        self.bridge, self.basis, self.scheme, self.dt = bridge, basis, scheme, float(dt)
        self.road = road if road is not None else smooth_road()
        self.gravity = float(gravity)
        n = basis.n
        self.t = 0.0
        self.d, self.v, self.a = np.zeros(n), np.zeros(n), np.zeros(n)
        self._force = np.zeros(n)  # F_n: non-inertial deck forces of the last step (HHT)
        self.n_steps = 0
        self._counters = np.zeros(4, dtype=np.int64)  # lift-off events, lift-off steps, solves, diverged
        c_w, c_t, _ = bridge._deck_coefficients
        self._geometry = (bridge.nodes_x, np.ascontiguousarray(c_w), np.ascontiguousarray(c_t),
                          float(bridge.section.y_s), float(bridge.length))
        # Fleet (structure of arrays).
        self.ids: tuple[str, ...] = ()
        self._kind = np.zeros(0, dtype=np.int64)
        self._params = np.zeros((7, 0))
        self._vstate = np.zeros((8, 0))
        self._lifted = np.zeros(0, dtype=bool)
        self._set_sensors(sensors)

    # ------------------------------------------------------------ bookkeeping
    @property
    def liftoff_events(self) -> int:
        return int(self._counters[0])

    @property
    def liftoff_steps(self) -> int:
        return int(self._counters[1])

    def _set_sensors(self, sensors: tuple[tuple[float, float, str], ...]) -> None:
        self._sens_kind = np.array([SENSOR_KIND[qty] for _, _, qty in sensors], dtype=np.int64)
        rows = [
            self.bridge.field_row("bending_moment" if qty == "bending_moment" else "w_deck", x, y)
            for x, y, qty in sensors
        ]
        if isinstance(self.basis, DirectBasis):
            idx = np.array([self.basis.reduced_index(r.dofs) for r in rows], dtype=np.int64).reshape(-1, 14)
            vals = np.array([r.values[0] for r in rows]).reshape(-1, 14)
            self._sens = (idx, vals)
        else:
            dense = np.array([self.basis.reduce_rows(r.dofs[None, :], r.values[:1])[0] for r in rows])
            self._sens = (dense.reshape(len(rows), self.basis.n),)

    def energy(self) -> float:
        """Bridge kinetic + strain energy, J."""
        return self.basis.energy(self.d, self.v)

    def set_state(self, d: np.ndarray, v: np.ndarray, a: np.ndarray | None = None) -> None:
        """Set the bridge state in reduced coordinates (``a`` defaults to zero)."""
        self.d, self.v = np.array(d, dtype=float), np.array(v, dtype=float)
        self.a = np.zeros_like(self.d) if a is None else np.array(a, dtype=float)

    def _deck_w(self, x: float, y: float) -> float:
        if not 0.0 <= x <= self.bridge.length:
            return 0.0
        row = self.bridge.deck_point_row(x, y)
        return float(self.basis.reduce_rows(row.dofs[None, :], row.values[:1])[0] @ self.d)

    def _sync(self, block: TrafficBlock) -> None:
        """Match the fleet to the block's vehicles; newcomers stand at static equilibrium."""
        if block.ids == self.ids:
            return
        old = {vid: i for i, vid in enumerate(self.ids)}
        q = len(block.ids)
        vstate = np.zeros((8, q))
        lifted = np.zeros(q, dtype=bool)
        kind, params = _model_parameters(block.models, block.ids)
        for j, vid in enumerate(block.ids):
            if vid in old:
                vstate[:, j] = self._vstate[:, old[vid]]
                lifted[j] = self._lifted[old[vid]]
            else:
                x0, y0 = float(block.x[0, j]), float(block.y[j])
                r0, _ = self.road.evaluate(np.array([y0]), np.array([x0]))
                level = float(r0[0]) + self._deck_w(x0, y0)
                vstate[0, j] = vstate[3, j] = level
        self.ids, self._kind, self._params, self._vstate, self._lifted = block.ids, kind, params, vstate, lifted

    # ------------------------------------------------------------------ steps
    def advance(self, block: TrafficBlock) -> BlockReport:
        """Advance ``K = len(block.x)`` steps; row k of the block is the traffic at ``t + (k+1) dt``."""
        self._sync(block)
        K, q = block.x.shape
        y = np.ascontiguousarray(block.y, dtype=float)
        r, r_x = self.road.evaluate(np.broadcast_to(y, (K, q)), block.x)
        out_sens = np.zeros((K, len(self._sens_kind)))
        out_contact = np.zeros((K, q))
        out_bu = np.zeros((K, q))
        out_ba = np.zeros((K, q))
        out_on = np.zeros((K, q), dtype=np.bool_)
        m_v, m_w, k_v, c_v, k_t, c_t, mass = self._params
        weight = mass * self.gravity
        sc = self.scheme
        common = (sc.beta, sc.gamma, sc.alpha)
        fleet = (self._kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, self._vstate, self._lifted,
                 np.ascontiguousarray(block.x, dtype=float), np.ascontiguousarray(block.v, dtype=float),
                 np.ascontiguousarray(block.a, dtype=float), y, np.ascontiguousarray(r), np.ascontiguousarray(r_x))
        outputs = (out_sens, out_contact, out_bu, out_ba, out_on, self._counters)
        self._counters[3] = 0
        if isinstance(self.basis, DirectBasis):
            b = self.basis
            kernels.direct_block(
                b.cholesky_rows, b.K.indptr, b.K.indices, b.K.data, b.M.indptr, b.M.indices, b.M.data,
                b.ray_alpha, b.ray_beta, b.inverse, b.reduced_map,
                *self._geometry, self.dt, *common, self.d, self.v, self.a, self._force,
                *fleet, *self._sens, self._sens_kind, *outputs)
        else:
            b = self.basis
            kernels.modal_block(
                b.phi_full, b.c_diag, b.k_diag, b.a_inv_diag,
                *self._geometry, self.dt, *common, self.d, self.v, self.a, self._force,
                *fleet, *self._sens, self._sens_kind, *outputs)
        self.basis.n_solves = int(self._counters[2])
        if self._counters[3]:
            k = int(self._counters[3])
            self.t += k * self.dt
            self.n_steps += k
            raise ModelError(f"the solution diverged at t = {self.t:.6g} s (non-finite bridge acceleration)")
        self.t += K * self.dt
        self.n_steps += K
        return BlockReport(block.ids, block.models, block.x, block.y, block.v, block.a, out_on, out_contact, out_bu,
                           out_ba, out_sens)

    def step(self, frame: TrafficFrame) -> BlockReport:
        """Advance one step; ``frame`` describes the vehicles at ``t + dt``."""
        return self.advance(TrafficBlock.from_frame(frame))
