"""One coupled vehicle-bridge time step: the heart of the co-simulation.

Unknown of the step: the bridge acceleration ``a = d''_{n+1}`` in the basis'
reduced coordinates. Every vehicle's own DOFs are eliminated inside the step
(they obey Newmark with the same beta, gamma), which leaves the deck force of
vehicle i linear in ``a``::

    Fz_i = f0_i - p_i . a          (N, positive up; the contact force is P_i = -Fz_i)

with ``p_i`` a combination of the contact rows ``n0 = N_bar``, ``n1 = N_bar_x``,
``n2 = N_bar_xx`` at the contact point. The wheel of the rigid-contact
quarter-car follows the deck, and its acceleration is differentiated honestly
for a vehicle with speed ``v`` and acceleration ``a_v`` (DESIGN.md section 4)::

    u_w'' = n0 d'' + 2 v n1 d' + (v^2 n2 + a_v n1) d

The bridge equation (HHT form; alpha = 0 is Newmark)::

    M a + (1+alpha)(C v_{n+1} + K d_{n+1}) - alpha (C v_n + K d_n) = (1+alpha) F_{n+1} - alpha F_n

becomes ``(A + U P^T) a = b`` with the constant, once-factorised
``A = M + (1+alpha)(gamma dt C + beta dt^2 K)``, ``U = (1+alpha)[n0_i]`` and
``P = [p_i]``: a rank-q update solved with the Woodbury identity (one solve
with q + 1 right-hand sides and a q x q dense solve per step).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .bridge import BridgeModel
from .errors import ModelError
from .integrator import DirectBasis, ModalBasis, Scheme, newmark_predict
from .roughness import RoadProfile, smooth_road
from .traffic import TrafficFrame
from .vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel

_MF, _QC, _TQC = 0, 1, 2


@dataclass
class StepReport:
    """What happened to the vehicles in the last step (arrays over the vehicles present)."""

    ids: tuple[str, ...]
    x: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    contact_force: npt.NDArray[np.float64]  # N, compression positive
    body_displacement: npt.NDArray[np.float64]  # m, from static equilibrium
    body_acceleration: npt.NDArray[np.float64]  # m/s^2
    lifted: npt.NDArray[np.bool_]  # contact force < 0 this step


class _Fleet:
    """Vehicle states as parallel arrays (structure of arrays), keyed by id."""

    def __init__(self) -> None:
        self.ids: tuple[str, ...] = ()
        self.models: tuple[VehicleModel, ...] = ()
        self.kind = np.zeros(0, dtype=np.int64)
        z = np.zeros(0)
        self.m_v = self.m_w = self.k_v = self.c_v = self.k_t = self.c_t = self.mass = z
        # Body (u_v) and wheel (u_w, tyre model only) states: displacement, velocity, acceleration.
        self.state = np.zeros((8, 0))
        self.lifted = np.zeros(0, dtype=bool)

    def sync(self, frame: TrafficFrame, init_state) -> list[str]:
        """Match the fleet to the frame's vehicles; returns the ids that newly appeared."""
        if frame.ids == self.ids:
            return []
        old = {vid: i for i, vid in enumerate(self.ids)}
        new_ids = [vid for vid in frame.ids if vid not in old]
        state = np.zeros((8, len(frame.ids)))
        lifted = np.zeros(len(frame.ids), dtype=bool)
        for j, vid in enumerate(frame.ids):
            if vid in old:
                state[:, j] = self.state[:, old[vid]]
                lifted[j] = self.lifted[old[vid]]
        self.ids, self.models, self.state, self.lifted = frame.ids, frame.models, state, lifted
        q = len(frame.ids)
        self.kind = np.empty(q, dtype=np.int64)
        params = np.zeros((7, q))
        for j, m in enumerate(frame.models):
            if isinstance(m, MovingForce):
                self.kind[j] = _MF
                params[6, j] = m.mass
            elif isinstance(m, QuarterCar):
                self.kind[j] = _QC
                params[:4, j] = m.m_v, m.m_w, m.k_v, m.c_v
                params[6, j] = m.total_mass
            elif isinstance(m, TyreQuarterCar):
                self.kind[j] = _TQC
                params[:6, j] = m.m_v, m.m_w, m.k_v, m.c_v, m.k_t, m.c_t
                params[6, j] = m.total_mass
            else:
                raise ModelError(f"vehicle {frame.ids[j]}: unknown vehicle model {type(m).__name__}")
        self.m_v, self.m_w, self.k_v, self.c_v, self.k_t, self.c_t, self.mass = params
        for vid in new_ids:
            init_state(frame.ids.index(vid))
        return new_ids


class CoupledSystem:
    """Bridge plus vehicles, advanced one constant step ``dt`` at a time.

    Args:
        bridge: the structural model (only used to locate contact points).
        basis: :class:`DirectBasis` or :class:`ModalBasis`, built for ``dt`` and ``scheme``.
        scheme: the time-integration scheme.
        dt: time step, s.
        road: road profiles (default smooth).
        gravity: m/s^2.
    """

    def __init__(
        self,
        bridge: BridgeModel,
        basis: DirectBasis | ModalBasis,
        scheme: Scheme,
        dt: float,
        road: RoadProfile | None = None,
        gravity: float = 9.81,
    ) -> None:
        self.bridge, self.basis, self.scheme, self.dt = bridge, basis, scheme, float(dt)
        self.road = road if road is not None else smooth_road()
        self.gravity = float(gravity)
        n = basis.n
        self.t = 0.0
        self.d, self.v, self.a = np.zeros(n), np.zeros(n), np.zeros(n)
        self._force = np.zeros(n)  # F_n, reduced deck forces of the last step (for HHT)
        self.fleet = _Fleet()
        self.n_steps = 0
        self.liftoff_events = 0
        self.liftoff_steps = 0

    # ------------------------------------------------------------------ state
    def energy(self) -> float:
        """Bridge kinetic + strain energy, J."""
        return self.basis.energy(self.d, self.v)

    def set_state(self, d: np.ndarray, v: np.ndarray, a: np.ndarray | None = None) -> None:
        """Set the bridge state in reduced coordinates (``a`` defaults to zero)."""
        self.d, self.v = np.array(d, dtype=float), np.array(v, dtype=float)
        self.a = np.zeros_like(self.d) if a is None else np.array(a, dtype=float)

    def _init_vehicle(self, j: int, frame: TrafficFrame) -> None:
        """A vehicle that appears stands at static equilibrium on the deck and road under it."""
        x, y = frame.x[j : j + 1], frame.y[j : j + 1]
        r, _ = self.road.evaluate(y, x)
        dofs, values = self.bridge.deck_rows(np.clip(x, 0.0, self.bridge.length), y)
        w = self.basis.reduce_rows(dofs, values[:, 0]) @ self.d if self._on_deck(x)[0] else np.zeros(1)
        level = float(r[0] + w[0])
        self.fleet.state[:, j] = (level, 0.0, 0.0, level, 0.0, 0.0, 0.0, 0.0)

    def _on_deck(self, x: np.ndarray) -> np.ndarray:
        return (x >= 0.0) & (x <= self.bridge.length)

    # ------------------------------------------------------------------- step
    def step(self, frame: TrafficFrame) -> StepReport:
        """Advance from ``t`` to ``t + dt``; ``frame`` describes the vehicles at ``t + dt``.

        HHT weighting applies to every elastic and damping force, the
        vehicles' suspension and tyre forces included (``(1+alpha) F_{n+1} -
        alpha F_n``), while inertia (the bridge's and the rigid-contact wheel's)
        stays at ``t_{n+1}``; with alpha = 0 this is Newmark's average acceleration.
        """
        sc, dt, fl = self.scheme, self.dt, self.fleet
        beta, gamma, alpha = sc.beta, sc.gamma, sc.alpha
        ca = 1.0 + alpha
        b2, g1 = beta * dt * dt, gamma * dt
        fl.sync(frame, lambda j: self._init_vehicle(j, frame))
        q = len(frame.ids)
        x, y, speed, acc = frame.x, frame.y, frame.v, frame.a

        d_star, v_star = newmark_predict(self.d, self.v, self.a, dt, sc)
        rhs = -ca * self.basis.internal_force(d_star, v_star) - alpha * self._force
        if alpha:
            rhs += alpha * self.basis.internal_force(self.d, self.v)
        if not q:
            a_new = self.basis.solve(rhs)
            self._advance(d_star, v_star, a_new)
            self._force = np.zeros(self.basis.n)
            return StepReport((), *(np.zeros(0),) * 7)  # type: ignore[arg-type]

        on = self._on_deck(x)
        dofs, vals = self.bridge.deck_rows(np.clip(x, 0.0, self.bridge.length), y)
        vals = vals * on[:, None, None]  # off the deck: rigid ground, no rows
        r, r_x = self.road.evaluate(y, x)
        n0 = self.basis.reduce_rows(dofs, vals[:, 0])
        n1 = self.basis.reduce_rows(dofs, vals[:, 1])
        n2 = self.basis.reduce_rows(dofs, vals[:, 2])
        # Deck motion at the contact points from the predictors.
        w0, w1d, w1v, w2d, w1v1 = n0 @ d_star, n1 @ d_star, n0 @ v_star, n2 @ d_star, n1 @ v_star
        # Vehicle predictors: rows 0-2 body (u, u', u''), rows 3-5 wheel, 6 suspension force, 7 tyre force.
        st = fl.state
        ub_s = st[0] + dt * st[1] + (0.5 - beta) * dt * dt * st[2]
        vb_s = st[1] + (1 - gamma) * dt * st[2]
        uw_s = st[3] + dt * st[4] + (0.5 - beta) * dt * dt * st[5]
        vw_s = st[4] + (1 - gamma) * dt * st[5]
        weight = fl.mass * self.gravity
        # Effective deck force E = e0 - p . a with p = c0 n0 + c1 n1 + c2 n2.
        e0 = -ca * weight
        c0, c1, c2 = np.zeros(q), np.zeros(q), np.zeros(q)
        qc, tq = fl.kind == _QC, fl.kind == _TQC
        if qc.any():
            m_v, m_w, k, c = fl.m_v[qc], fl.m_w[qc], fl.k_v[qc], fl.c_v[qc]
            vq, aq = speed[qc], acc[qc]
            m_hat = k * b2 + c * g1
            den = m_v + ca * m_hat
            h = 2 * vq * w1v1[qc] + vq * vq * w2d[qc] + aq * w1d[qc]
            F0 = k * (ub_s[qc] - w0[qc] - r[qc]) + c * (vb_s[qc] - w1v[qc] - vq * w1d[qc] - vq * r_x[qc])
            qc_F0, qc_h, qc_den, qc_mhat = F0, h, den, m_hat
            e0[qc] += ca * (m_v * F0 + alpha * m_hat * st[6, qc]) / den - m_w * h
            c0[qc] = m_w + ca * m_v / den * m_hat
            c1[qc] = m_w * (2 * vq * g1 + b2 * aq) + ca * m_v / den * c * vq * b2
            c2[qc] = m_w * b2 * vq * vq
        if tq.any():
            m_v, m_w, kv, cv, kt, ct = (fl.m_v[tq], fl.m_w[tq], fl.k_v[tq], fl.c_v[tq], fl.k_t[tq], fl.c_t[tq])
            vq = speed[tq]
            mv, mt = kv * b2 + cv * g1, kt * b2 + ct * g1
            S0 = kv * (ub_s[tq] - uw_s[tq]) + cv * (vb_s[tq] - vw_s[tq])
            T0 = kt * (uw_s[tq] - w0[tq] - r[tq]) + ct * (vw_s[tq] - w1v[tq] - vq * w1d[tq] - vq * r_x[tq])
            R1 = -ca * S0 + alpha * st[6, tq]
            R2 = ca * (S0 - T0) - alpha * (st[6, tq] - st[7, tq])
            den = (m_v + ca * mv) * (m_w + ca * mv + ca * mt) - (ca * mv) ** 2
            tq_terms = (S0, T0, R1, R2, den, mv, mt)
            e0[tq] += ca * (T0 + mt * ((m_v + ca * mv) * R2 + ca * mv * R1) / den)
            kappa = ca * (1.0 - ca * mt * (m_v + ca * mv) / den)
            c0[tq] = kappa * (kt * b2 + ct * g1)
            c1[tq] = kappa * ct * vq * b2
        p = c0[:, None] * n0 + c1[:, None] * n1 + c2[:, None] * n2

        # (A + U P^T) a = rhs with U = [n0_i]: Woodbury, one solve with q + 1 right-hand sides.
        rhs += n0.T @ e0
        z = self.basis.solve(np.column_stack([rhs, n0.T]))
        z_b, z_u = z[:, 0], z[:, 1:]
        a_new = z_b - z_u @ np.linalg.solve(np.eye(q) + p @ z_u, p @ z_b)
        self._advance(d_star, v_star, a_new)

        # Vehicles, now that the deck is known.
        n0a, n1a = n0 @ a_new, n1 @ a_new
        w_new = n0 @ self.d
        w_dot = n0 @ self.v + speed * (n1 @ self.d)
        acc_b, acc_w = np.zeros(q), np.zeros(q)
        deck_force = -weight.copy()  # physical force on the deck at t_{n+1}, up positive
        susp, tyre = np.zeros(q), np.zeros(q)
        if qc.any():
            k, c, m_w, vq, aq = fl.k_v[qc], fl.c_v[qc], fl.m_w[qc], speed[qc], acc[qc]
            qa = qc_mhat * n0a[qc] + c * vq * b2 * n1a[qc]
            acc_b[qc] = -(ca * (qc_F0 - qa) - alpha * st[6, qc]) / qc_den
            susp[qc] = qc_F0 - qa + qc_mhat * acc_b[qc]
            acc_w[qc] = n0a[qc] + (2 * vq * g1 + b2 * aq) * n1a[qc] + b2 * vq * vq * (n2[qc] @ a_new) + qc_h
            deck_force[qc] += susp[qc] - m_w * acc_w[qc]
        if tq.any():
            S0, T0, R1, R2, den, mv, mt = tq_terms
            m_v, m_w, kt, ct, vq = fl.m_v[tq], fl.m_w[tq], fl.k_t[tq], fl.c_t[tq], speed[tq]
            ta = (kt * b2 + ct * g1) * n0a[tq] + ct * vq * b2 * n1a[tq]
            acc_w[tq] = ((m_v + ca * mv) * (R2 + ca * ta) + ca * mv * R1) / den
            acc_b[tq] = ((m_w + ca * mv + ca * mt) * R1 + ca * mv * (R2 + ca * ta)) / den
            susp[tq] = S0 + mv * (acc_b[tq] - acc_w[tq])
            tyre[tq] = T0 + mt * acc_w[tq] - ta
            deck_force[tq] += tyre[tq]
        # F_{n+1} of the HHT weighting: the elastic/damping (non-inertial) part of the deck forces.
        weighted = -weight + np.where(qc, susp, 0.0) + np.where(tq, tyre, 0.0)
        self._force = n0.T @ weighted

        rigid = fl.kind != _TQC
        st[0], st[1], st[2] = ub_s + b2 * acc_b, vb_s + g1 * acc_b, acc_b
        st[3] = np.where(rigid, w_new, uw_s + b2 * acc_w)
        st[4] = np.where(rigid, w_dot, vw_s + g1 * acc_w)
        st[5] = acc_w
        st[6], st[7] = susp, tyre

        contact = -deck_force
        lifted = contact < 0.0
        self.liftoff_events += int(np.count_nonzero(lifted & ~fl.lifted))
        self.liftoff_steps += int(np.count_nonzero(lifted))
        fl.lifted = lifted
        return StepReport(
            ids=frame.ids, x=x, y=y, v=speed, contact_force=contact,
            body_displacement=st[0].copy(), body_acceleration=acc_b, lifted=lifted,
        )

    def _advance(self, d_star: np.ndarray, v_star: np.ndarray, a_new: np.ndarray) -> None:
        if not np.all(np.isfinite(a_new)):
            raise ModelError(f"the solution diverged at t = {self.t + self.dt:.6g} s (non-finite bridge acceleration)")
        dt = self.dt
        self.d = d_star + self.scheme.beta * dt * dt * a_new
        self.v = v_star + self.scheme.gamma * dt * a_new
        self.a = a_new
        self.t += dt
        self.n_steps += 1
