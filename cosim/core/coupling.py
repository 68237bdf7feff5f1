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
``a_v`` (docs/theory.md §5.2)::

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

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError, ModelError

from . import kernels
from .bases import DeckModalBasis, DirectBasis, ModalBasis
from .bridge import BridgeModel
from .element import DECK_POINT_DOFS, NODE_DOFS
from .modal_bridge import ModalBridge
from .roughness import RoadProfile, smooth_road
from .schemes import Scheme
from .sensors import TIME_DERIVATIVE, Sensor, check_sensor_on, sensor_row
from .traffic import AXLE_SEPARATOR, LoadRecord, TrafficBlock, TrafficFrame, vehicle_of
from .vehicles import KERNEL_KINDS, LINEAR, MODELS, PARAM_ROWS, STATE_ROWS, VehicleModel

#: Lateral tolerance of "on the deck" for a wheel path, relative to the deck width.
_Y_TOL = 1e-9


@dataclass(frozen=True)
class BlockReport:
    """What the vehicles did over a block of K steps (arrays (K, q) over the block's vehicles).

    ``on_deck`` says where a vehicle was on the deck; contact forces (N,
    compression positive) are zero elsewhere; ``lifted`` marks the steps where
    a wheel on the deck pulled (negative contact force: lift-off, counted by the
    compiled loop); ``sensors`` is (K, s); ``off_surface`` marks the steps where a
    wheel was over the deck's length but beside its surface (its lateral ``y``
    beyond the deck's width): it loaded nothing then (rigid ground); ``loads``: the
    load records of the vehicles that came onto the deck in the block.
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
    lifted: npt.NDArray[np.bool_]
    off_surface: npt.NDArray[np.bool_] | None = None
    loads: tuple[LoadRecord, ...] = ()
    path_y: npt.NDArray[np.float64] | None = None

    @property
    def lateral(self) -> npt.NDArray[np.float64]:
        """Each wheel's lateral offset at every step, (K, q), m: its path's on a curved lane (a deck given by
        its modes follows it), else its ``y`` through the block."""
        if self.path_y is not None:
            return self.path_y
        return np.broadcast_to(self.y, self.x.shape)


def _fleet_parameters(models: tuple[VehicleModel, ...], columns: list[list[int]],
                      gravity: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compiled kind, parameters (PARAM_ROWS, q) and static load (N, q) of the contact columns (``columns``: each
    vehicle's, :func:`_vehicle_columns`). A linear vehicle's loads are set with its matrices (:meth:`_sync`)."""
    q = len(models)
    kind = np.empty(q, dtype=np.int64)
    params = np.zeros((PARAM_ROWS, q))
    weight = np.empty(q)
    for j, m in enumerate(models):
        kind[j] = m.kernel_kind
        packed = m.pack()
        params[: len(packed), j] = packed
        weight[j] = m.total_mass * gravity  # one contact carries the weight
    for cols in columns:
        model = models[cols[0]]
        if len(cols) > 1 and model.kernel_kind != LINEAR:
            weight[cols] = model.static_axle_loads(gravity)
    return kind, params, weight


def _check_models(models: tuple[VehicleModel, ...], ids: tuple[str, ...]) -> None:
    """Raise ConfigError for a column whose model is not a vehicle model the compiled loop can run."""
    for j, m in enumerate(models):
        if not isinstance(m, VehicleModel):
            raise ConfigError(f"vehicle {ids[j]}: unknown vehicle model {type(m).__name__} "
                              f"(expected one of: {', '.join(MODELS)})")
        if m.kernel_kind not in KERNEL_KINDS:
            raise ConfigError(f"vehicle {ids[j]}: model {m.kind} has kernel kind {m.kernel_kind}, which the "
                              f"compiled loop does not know ({', '.join(map(str, KERNEL_KINDS))})")


@dataclass
class _LinearVehicle:
    """A linear vehicle's matrices (for this run's gravity) and its state between blocks."""

    system: dict[str, np.ndarray]
    state: np.ndarray  # z, z', z'', previous elastic forces (4 nz)
    flying: np.ndarray  # per contact


def _vehicle_columns(ids: tuple[str, ...], models: tuple[VehicleModel, ...]) -> list[list[int]]:
    """Each vehicle's contact columns: one for a one-contact model, else consecutive columns "v#0", "v#1", ...
    sharing a model (its contact points, in order)."""
    groups: list[list[int]] = []
    j = 0
    while j < len(ids):
        model = models[j]
        count = model.contacts
        cols = list(range(j, j + count))
        if count > 1:
            owner = vehicle_of(ids[j])
            expected = [f"{owner}{AXLE_SEPARATOR}{k}" for k in range(count)]
            if len(ids) < j + count or [ids[c] for c in cols] != expected or \
                    any(models[c] != model for c in cols):
                raise ConfigError(f"vehicle {owner}: its {count} axles must come together as {', '.join(expected)} "
                                  "(one contact column per axle, in order, with the same model)")
        groups.append(cols)
        j += count
    return groups


def _no_groups(q: int) -> kernels.GroupArrays:
    """No linear vehicles among q contact columns."""
    empty_i = np.zeros(0, dtype=np.int64)
    return kernels.GroupArrays(empty_i, empty_i, empty_i, empty_i, np.zeros(0), empty_i, np.zeros(0), empty_i,
                               np.zeros(0), np.full(q, -1, dtype=np.int64), np.zeros(q, dtype=np.bool_), False)


class CoupledSystem:
    """Bridge plus vehicles, advanced by a constant step ``dt``.

    Args:
        bridge: the structural model.
        basis: :class:`DirectBasis` or :class:`ModalBasis`, built for ``dt`` and ``scheme``.
        scheme: the time-integration scheme.
        dt: time step, s.
        road: road profiles (default smooth).
        gravity: m/s^2.
        sensors: the sensors sampled at every step (on the deck).

    Raises:
        ConfigError: a basis built for another bridge, time step or scheme; a
            sensor off the deck; later, in :meth:`advance`, a vehicle whose wheel
            path lies off the deck.
    """

    def __init__(
        self,
        bridge: BridgeModel | ModalBridge,
        basis: DirectBasis | ModalBasis | DeckModalBasis,
        scheme: Scheme,
        dt: float,
        road: RoadProfile | None = None,
        gravity: float = 9.81,
        sensors: tuple[Sensor, ...] = (),
    ) -> None:
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ConfigError(f"`dt` must be a finite number > 0 s (got {dt!r})")
        if not (isinstance(gravity, (int, float)) and math.isfinite(gravity) and gravity >= 0):
            raise ConfigError(f"`gravity` must be a finite number >= 0 m/s^2 (got {gravity!r})")
        if basis.bridge is not bridge:
            raise ConfigError("the basis was built for another bridge model: build it with this bridge (make_basis)")
        if (basis.dt, basis.scheme) != (float(dt), scheme):
            raise ConfigError(f"the basis was built for dt = {basis.dt} s and scheme {basis.scheme.name}; "
                              f"build it for dt = {dt} s and scheme {scheme.name} (make_basis)")
        for sensor in sensors:
            if isinstance(bridge, ModalBridge):
                bridge.sensor_row(sensor)  # raises, naming the sensor, when the modes cannot give it
            else:
                check_sensor_on(bridge, sensor)
        self.bridge, self.basis, self.scheme, self.dt = bridge, basis, scheme, float(dt)
        self.road = road if road is not None else smooth_road()
        self.gravity = float(gravity)
        n = basis.n
        self.t = 0.0
        self._state = kernels.BridgeState(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n))
        self.n_steps = 0
        self._counters = np.zeros(4, dtype=np.int64)  # lift-off events, lift-off steps, solves, diverged
        if isinstance(bridge, ModalBridge):  # the deck seam: the mode surface says where it is
            self._y_range = (-math.inf, math.inf)
            self._deck = bridge.kernel_deck()
        else:
            c_w, c_t, _ = bridge.deck_coefficients
            y_min, y_max = bridge.section.deck_y
            tol = _Y_TOL * max(y_max - y_min, 1.0)
            self._y_range = (float(y_min - tol), float(y_max + tol))  # the surface, round-off of lanes allowed
            self._deck = kernels.DeckArrays(bridge.nodes_x, np.ascontiguousarray(c_w), np.ascontiguousarray(c_t),
                                            float(bridge.section.y_s), float(bridge.length),
                                            np.array(DECK_POINT_DOFS, dtype=np.int64), NODE_DOFS, *self._y_range)
        self._scheme = kernels.StepScheme(self.dt, scheme.beta, scheme.gamma, scheme.alpha)
        self._off: dict[str, bool] = {}  # contact points beside the surface at the end of the last block
        self.offdeck_events = 0  # times a wheel over the deck's length went beside its surface
        self.offdeck_steps = 0  # wheel-steps beside the surface over the deck's length
        # Fleet (structure of arrays).
        self.ids: tuple[str, ...] = ()
        self._kind = np.zeros(0, dtype=np.int64)
        self._params = np.zeros((PARAM_ROWS, 0))
        self._weight = np.zeros(0)
        self._linear: dict[str, _LinearVehicle] = {}  # by vehicle id
        self._group_cols: list[list[int]] = []
        self._groups = _no_groups(0)
        self._vstate = np.zeros((STATE_ROWS, 0))
        self._lifted = np.zeros(0, dtype=bool)
        self.sensors = tuple(sensors)
        rows = []
        if isinstance(bridge, ModalBridge) and isinstance(basis, DeckModalBasis):
            idx, vals = basis.sparse_rows([bridge.sensor_row(s) for s in self.sensors])
        elif isinstance(bridge, BridgeModel) and not isinstance(basis, DeckModalBasis):
            rows = [sensor_row(bridge, s) for s in self.sensors]
            idx, vals = basis.sparse_rows(rows)
        else:
            raise ConfigError("a deck given by its modes runs on its own modes and a beam on its basis (make_basis)")
        order = np.array([TIME_DERIVATIVE[s.quantity] for s in self.sensors], dtype=np.int64)
        every = np.array([s.every for s in self.sensors], dtype=np.int64)
        self._step0 = np.zeros(1, dtype=np.int64)  # shared by both engines' rows, set before each block
        # The engines that solve this basis: name -> (arrays, sensor rows in its coordinates).
        self._engines = {"basis": (kernels.with_modal_polynomials(basis.kernel_arrays(), self._deck),
                                   kernels.SensorRows(idx, vals, order, every, self._step0))}
        self._complete = basis.complete if isinstance(basis, DirectBasis) else None
        if self._complete is not None and isinstance(basis, DirectBasis):
            dense = np.array([basis.reduce_rows(r.dofs[None, :], r.values[:1])[0] for r in rows],
                             dtype=float).reshape(len(rows), basis.n)
            modal_rows = dense @ self._complete.phi
            modal_idx = np.tile(np.arange(basis.n, dtype=np.int64), (len(rows), 1))
            complete = kernels.with_modal_polynomials(basis.complete_kernel_arrays(), self._deck)
            self._engines["complete-modal"] = (complete,
                                               kernels.SensorRows(modal_idx, modal_rows, order, every,
                                                                                  self._step0))
        self._engine = "basis"

    # ------------------------------------------------------------ bookkeeping
    @property
    def d(self) -> npt.NDArray[np.float64]:
        """Bridge displacements in the basis' coordinates (m, rad)."""
        return self._in_basis(self._state.d)

    @property
    def v(self) -> npt.NDArray[np.float64]:
        """Bridge velocities in the basis' coordinates."""
        return self._in_basis(self._state.v)

    @property
    def a(self) -> npt.NDArray[np.float64]:
        """Bridge accelerations in the basis' coordinates."""
        return self._in_basis(self._state.a)

    @property
    def engine(self) -> str:
        """The engine of the last block: "basis" (the basis' own), or "complete-modal" (a direct basis solved
        on all its modes, for blocks with few vehicles)."""
        return self._engine

    def _in_basis(self, x: np.ndarray) -> np.ndarray:
        if self._engine == "complete-modal":
            assert self._complete is not None
            return self._complete.from_modal(x)
        return x

    def _switch_engine(self, name: str) -> None:
        """Carry the bridge's state over to another engine's coordinates (exact up to round-off)."""
        if name == self._engine:
            return
        c = self._complete
        assert c is not None
        st = self._state
        if name == "complete-modal":
            self._state = kernels.BridgeState(c.to_modal(st.d), c.to_modal(st.v), c.to_modal(st.a),
                                              c.force_to_modal(st.force))
        else:
            self._state = kernels.BridgeState(c.from_modal(st.d), c.from_modal(st.v), c.from_modal(st.a),
                                              c.force_from_modal(st.force))
        self._engine = name

    @property
    def factorizations(self) -> int:
        """Effective-matrix factorisations done (by the basis)."""
        return self.basis.n_factorizations

    @property
    def liftoff_events(self) -> int:
        """How many times a wheel on the deck started to pull (contact force < 0)."""
        return int(self._counters[0])

    @property
    def liftoff_steps(self) -> int:
        """Vehicle-steps with a negative contact force on the deck."""
        return int(self._counters[1])

    def energy(self) -> float:
        """Bridge kinetic + strain energy, J."""
        return self.basis.energy(self.d, self.v)

    def set_state(self, d: np.ndarray, v: np.ndarray, a: np.ndarray | None = None) -> None:
        """Set the bridge state in reduced coordinates (``a`` defaults to zero)."""
        n = self.basis.n
        values = [np.array(d, dtype=float), np.array(v, dtype=float),
                  np.zeros(n) if a is None else np.array(a, dtype=float)]
        for name, value in zip(("d", "v", "a"), values):
            if value.shape != (n,) or not np.all(np.isfinite(value)):
                raise ConfigError(f"`{name}` must be {n} finite numbers (the basis' unknowns)")
        self._switch_engine("basis")
        self._state = kernels.BridgeState(values[0], values[1], values[2], self._state.force)

    def on_surface(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.bool_]:
        """Which wheel paths ``y`` (m) lie on the deck's surface (its width, round-off allowed)."""
        return (y >= self._y_range[0]) & (y <= self._y_range[1])

    def _deck_w(self, x: float, y: float) -> float:
        if isinstance(self.bridge, ModalBridge):
            return float(self.bridge.deck_w_row(x, y) @ self.d)
        if not kernels.on_deck(x, self.bridge.length) or not bool(self.on_surface(np.array([y]))[0]):
            return 0.0
        row = self.bridge.deck_point_row(x, y)
        assert not isinstance(self.basis, DeckModalBasis)
        return float(self.basis.reduce_rows(row.dofs[None, :], row.values[:1])[0] @ self.d)

    def _sync(self, block: TrafficBlock) -> None:
        """Match the fleet to the block's vehicles; newcomers stand at static equilibrium."""
        if block.ids == self.ids:
            return
        self._store_linear_states()
        old = {vid: i for i, vid in enumerate(self.ids)}
        q = len(block.ids)
        vstate = np.zeros((STATE_ROWS, q))
        lifted = np.zeros(q, dtype=bool)
        _check_models(block.models, block.ids)
        columns = _vehicle_columns(block.ids, block.models)
        kind, params, weight = _fleet_parameters(block.models, columns, self.gravity)
        for j, vid in enumerate(block.ids):
            if vid in old:
                vstate[:, j] = self._vstate[:, old[vid]]
                lifted[j] = self._lifted[old[vid]]
            else:
                level = self._level(float(block.x[0, j]), float(block.y[j]))
                vstate[0, j] = vstate[3, j] = level
        group_cols = [cols for cols in columns if kind[cols[0]] == LINEAR]
        present = set()
        for cols in group_cols:
            owner = vehicle_of(block.ids[cols[0]]) if len(cols) > 1 else block.ids[cols[0]]
            present.add(owner)
            model = block.models[cols[0]]
            if owner not in self._linear:
                self._linear[owner] = self._new_linear(model, block, cols)
            system = self._linear[owner].system
            for k, c in enumerate(cols):
                params[:3, c] = system["k_t"][k], system["c_t"][k], 1.0 if model.unilateral else 0.0
                weight[c] = system["loads"][k]
        self._linear = {k: v for k, v in self._linear.items() if k in present}
        self.ids, self._kind, self._params, self._weight = block.ids, kind, params, weight
        self._vstate, self._lifted = vstate, lifted
        self._group_cols = group_cols
        self._groups = self._pack_groups(block, group_cols)

    def _level(self, x: float, y: float) -> float:
        """Road plus deck at (x, y): where a newcomer's wheel stands (static equilibrium), m."""
        r0, _ = self.road.evaluate(np.array([y]), np.array([x]))
        return float(r0[0]) + self._deck_w(x, y)

    def _new_linear(self, model: VehicleModel, block: TrafficBlock, cols: list[int]) -> _LinearVehicle:
        """A linear vehicle arriving: its matrices and its static equilibrium on the road under its wheels."""
        system = model.linear_system(self.gravity)
        if system is None:
            raise ConfigError(f"vehicle {vehicle_of(block.ids[cols[0]])}: model {model.kind} has the LINEAR kernel "
                              "kind but no linear system")
        levels = np.array([self._level(float(block.x[0, c]), float(block.y[c])) for c in cols])
        b, k_t = system["b"], system["k_t"]
        k_total = system["kv"] + (b.T * k_t) @ b
        z0 = np.linalg.solve(k_total, b.T @ (k_t * levels))
        nz = len(z0)
        state = np.zeros(4 * nz)
        state[:nz] = z0
        state[3 * nz:] = system["kv"] @ z0 + b.T @ (k_t * (b @ z0 - levels))  # elastic forces at rest: zero sum
        return _LinearVehicle(system, state, np.zeros(len(cols), dtype=bool))

    def _pack_groups(self, block: TrafficBlock, group_cols: list[list[int]]) -> kernels.GroupArrays:
        """The linear vehicles of this fleet as the flat arrays the compiled loop reads."""
        if not group_cols:
            return _no_groups(len(block.ids))
        first, ncont, nzs, moff, soff, aoff = [], [], [], [], [], []
        mats, state = [], []
        col = np.full(len(block.ids), -1, dtype=np.int64)
        flying = np.zeros(len(block.ids), dtype=np.bool_)
        m_at = s_at = a_at = 0
        unilateral = False
        for g, cols in enumerate(group_cols):
            owner = vehicle_of(block.ids[cols[0]]) if len(cols) > 1 else block.ids[cols[0]]
            vehicle = self._linear[owner]
            sys_ = vehicle.system
            nz, nc = sys_["mv"].shape[0], len(cols)
            first.append(cols[0])
            ncont.append(nc)
            nzs.append(nz)
            moff.append(m_at)
            soff.append(s_at)
            aoff.append(a_at)
            part = np.concatenate([sys_["mv"].ravel(), sys_["cv"].ravel(), sys_["kv"].ravel(),
                                   sys_["b"].ravel(), sys_["obs"].ravel()])
            mats.append(part)
            state.append(vehicle.state)
            m_at += len(part)
            s_at += len(vehicle.state)
            a_at += nz + nz * nc + nc + nc * nc
            col[cols] = g
            flying[cols] = vehicle.flying
            unilateral = unilateral or block.models[cols[0]].unilateral
        return kernels.GroupArrays(
            np.array(first, dtype=np.int64), np.array(ncont, dtype=np.int64), np.array(nzs, dtype=np.int64),
            np.array(moff, dtype=np.int64), np.concatenate(mats), np.array(soff, dtype=np.int64),
            np.concatenate(state), np.array(aoff, dtype=np.int64), np.zeros(a_at), col, flying, unilateral)

    def _store_linear_states(self) -> None:
        """Copy the linear vehicles' states out of the flat arrays before the fleet changes."""
        groups = self._groups
        for g, cols in enumerate(self._group_cols):
            owner = vehicle_of(self.ids[cols[0]]) if len(cols) > 1 else self.ids[cols[0]]
            vehicle = self._linear.get(owner)
            if vehicle is None:
                continue
            s0 = int(groups.soff[g])
            vehicle.state[:] = groups.state[s0:s0 + len(vehicle.state)]
            vehicle.flying[:] = groups.flying[cols]

    # ------------------------------------------------------------------ steps
    def advance(self, block: TrafficBlock) -> BlockReport:
        """Advance ``K = len(block.x)`` steps; row k of the block is the traffic at ``t + (k+1) dt``.

        A wheel over the deck's length but beside its surface loads nothing (rigid ground) and is reported in
        :attr:`BlockReport.off_surface` and counted (:attr:`offdeck_events`, :attr:`offdeck_steps`).

        Raises:
            ConfigError: an unknown model.
            ModelError: the solution diverged (non-finite bridge acceleration).
        """
        self._sync(block)
        K, q = block.x.shape
        y = np.ascontiguousarray(block.y, dtype=float)
        r, r_x = self.road.evaluate(y, block.x)  # a path per vehicle (q,), broadcast over the steps (K, q)
        out = kernels.BlockOutputs(
            np.zeros((K, len(self.sensors))), np.zeros((K, q)), np.zeros((K, q)), np.zeros((K, q)),
            np.zeros((K, q), dtype=np.bool_), np.zeros((K, q), dtype=np.bool_), self._counters)
        fleet = kernels.Fleet(self._kind, self._params, self._weight, self._vstate, self._lifted)
        kin = kernels.Kinematics(
            np.ascontiguousarray(block.x, dtype=float), np.ascontiguousarray(block.v, dtype=float),
            np.ascontiguousarray(block.a, dtype=float), y, np.ascontiguousarray(r), np.ascontiguousarray(r_x),
            *self._path(block))
        self._counters[3] = 0
        few = self._complete is not None and q <= DirectBasis.COMPLETE_MODAL_MAX_VEHICLES
        self._switch_engine("complete-modal" if few else "basis")
        arrays, sensor_rows = self._engines[self._engine]
        self._step0[0] = self.n_steps + 1  # row k of the block is step n_steps + 1 + k
        kernels.advance_block(arrays, self._deck, self._scheme, self._state, fleet, kin, sensor_rows, out,
                              self._groups)
        self.basis.count_solves(int(self._counters[2]))
        if self._counters[3]:
            k = int(self._counters[3])
            self.t += k * self.dt
            self.n_steps += k
            raise ModelError(f"the solution diverged at t = {self.t:.6g} s (non-finite bridge acceleration)")
        self.t += K * self.dt
        self.n_steps += K
        return BlockReport(block.ids, block.models, block.x, block.y, block.v, block.a, out.on, out.contact,
                           out.body_u, out.body_a, out.sensors, out.lifted, self._beside_surface(block, out.on),
                           block.loads, kin.path[:, :, 0] if len(kin.path) else None)

    def _path(self, block: TrafficBlock) -> tuple[np.ndarray, ...]:
        """The block's per-step paths for a deck given by its modes (a beam reads each wheel's ``y``)."""
        if block.path is None or self._deck.kind == kernels.BEAM_DECK:
            return ()
        return (np.ascontiguousarray(block.path, dtype=float),)

    def _beside_surface(self, block: TrafficBlock, on: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """The block's steps at which a wheel was over the deck's length but beside its surface (it loaded
        nothing then), counted: an event each time a wheel goes there, and every such wheel-step. Where the
        surface is was decided once, by the compiled step (``on``: on the length and the surface), for a beam's
        width and a mode surface alike."""
        off = kernels.on_deck(block.x, self.bridge.length) & ~on
        beside = off.any(axis=0)
        if beside.any():
            cols = np.flatnonzero(beside)
            self.offdeck_steps += int(off.sum())
            before = np.array([self._off.get(block.ids[j], False) for j in cols])
            went = np.diff(np.vstack([before[None, :], off[:, cols]]).astype(np.int8), axis=0) > 0
            self.offdeck_events += int(went.sum())
        if len(off):
            self._off = {block.ids[j]: True for j in np.flatnonzero(off[-1])}
        return off

    def step(self, frame: TrafficFrame) -> BlockReport:
        """Advance one step; ``frame`` describes the vehicles at ``t + dt``."""
        return self.advance(TrafficBlock.from_frame(frame))
