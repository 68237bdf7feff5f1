"""Run a vehicle-bridge simulation and collect named results.

:func:`simulate` drives a :class:`~cosim.core.coupling.CoupledSystem` with any
traffic source and samples the sensors (deck displacement, velocity,
acceleration including the twist contribution, bending moment) and every
vehicle (the fields of :data:`cosim.core.fields.VEHICLE_FIELDS`). It checks
its inputs as a scenario file is checked: a traffic source made for a bridge
of another length, a road that does not cover the deck, a sensor or a wheel
path off the deck, or a non-finite setting are errors that name the culprit.
"""
from __future__ import annotations

import collections
import csv
import math
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Protocol

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .bases import make_basis
from .bridge import BridgeModel
from .checks import finite, one_of
from .coupling import BlockReport, CoupledSystem
from .fields import VEHICLE_NUMBERS
from .jit import compiled
from .modal_bridge import ModalBridge
from .quasistatic import QuasiStaticSystem
from .roughness import RoadProfile
from .schemes import Scheme
from .sensors import Sensor
from .traffic import TrafficBlock, TrafficSource, vehicle_of

SCHEMES: tuple[str, ...] = ("newmark", "hht")
BASES: tuple[str, ...] = ("direct", "modal")
#: How the deck answers its loads: in time, with inertia and the vehicles' dynamics (the coupled step), or the
#: static response at every step (no inertia, no vehicle dynamics, no roughness: docs/theory.md §7.4).
METHODS: tuple[str, ...] = ("dynamic", "quasi-static")
#: The interpreter's thread switch interval while a run overlaps traffic and solver, s. At Python's default
#: (5 ms) the solver thread waited that long for the GIL to leave its compiled loop while the traffic thread
#: (SUMO, the adapter) ran Python: the two threads took turns instead of overlapping (benchmarks/results/).
SWITCH_INTERVAL = 1e-4
#: Steps advanced in one call at most when consecutive blocks of one fleet are joined (``join_blocks``).
JOINED_STEPS = 2000
#: Columns of :attr:`SimulationResult.vehicle_table`: the sample time, the vehicle's index, its fields.
VEHICLE_COLUMNS: tuple[str, ...] = ("t", "vehicle", *VEHICLE_NUMBERS)


@dataclass(frozen=True)
class SolverSettings:
    """Time step (s), scheme (newmark | hht), basis (direct | modal) and modal truncation; gravity, m/s^2;
    ``method``: dynamic or quasi-static (:data:`METHODS`).

    Raises:
        ConfigError: a non-finite or non-physical value, or an unknown scheme or basis.
    """

    dt: float = 0.005
    scheme: str = "newmark"
    hht_alpha: float = -0.05
    basis: str = "direct"
    modes: int | None = None
    cutoff_hz: float | None = None
    gravity: float = 9.81
    method: str = "dynamic"

    def __post_init__(self) -> None:
        finite(self.dt, "dt", above=0.0)
        finite(self.gravity, "gravity", at_least=0.0)
        one_of(self.method, METHODS, "method")
        one_of(self.scheme, SCHEMES, "scheme")
        one_of(self.basis, BASES, "basis")
        if self.modes is not None and (isinstance(self.modes, bool) or not isinstance(self.modes, int)
                                       or self.modes < 1):
            raise ConfigError(f"`modes` must be an integer >= 1 (got {self.modes!r})")
        if self.cutoff_hz is not None:
            finite(self.cutoff_hz, "cutoff_hz", above=0.0)

    def make_scheme(self) -> Scheme:
        """The :class:`~cosim.core.schemes.Scheme` named by ``scheme``."""
        return Scheme.hht(self.hht_alpha) if self.scheme == "hht" else Scheme.newmark()


@dataclass(frozen=True)
class WeightStats:
    """Gross weights of one class of vehicles that came onto the deck (N).

    Attributes:
        count: vehicles; mean, sd: of their gross weights; low, high: the lightest and the heaviest.
    """

    count: int
    mean: float
    sd: float
    low: float
    high: float


class _Weights:
    """Gross-weight statistics per vehicle class from the blocks' load records (constant memory, Welford)."""

    def __init__(self) -> None:
        self.acc: dict[str, list[float]] = {}  # class -> [count, mean, M2, min, max]

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001 - the observer protocol
        for record in getattr(report, "loads", ()):
            a = self.acc.setdefault(record.vehicle_class, [0, 0.0, 0.0, math.inf, -math.inf])
            a[0] += 1
            delta = record.gvw - a[1]
            a[1] += delta / a[0]
            a[2] += delta * (record.gvw - a[1])
            a[3], a[4] = min(a[3], record.gvw), max(a[4], record.gvw)

    def stats(self) -> dict[str, WeightStats]:
        return {k: WeightStats(int(a[0]), a[1], math.sqrt(a[2] / (a[0] - 1)) if a[0] > 1 else 0.0, a[3], a[4])
                for k, a in sorted(self.acc.items())}


@dataclass(frozen=True)
class SimulationResult:
    """Time histories of a run, as numpy arrays with names.

    Attributes:
        t: sample times, s.
        sensors: sensor name -> samples (unit of its quantity).
        vehicle_ids: every vehicle (contact point) that was on the deck.
        vehicle_table: long-format vehicle samples, column name -> array
            (:data:`VEHICLE_COLUMNS`); one row per vehicle on the deck per
            sample: ``t``, ``vehicle`` (index into ``vehicle_ids``) and the
            fields of :data:`cosim.core.fields.VEHICLE_FIELDS` (``x``, ``y``,
            ``speed``, ``acceleration``, ``body_displacement``,
            ``body_acceleration``, ``contact_force``; SI units).
        liftoff_events: how many times a wheel's contact force turned negative.
        liftoff_steps: vehicle-steps with a negative contact force.
        offdeck_events: times a wheel over the deck's length went beside its surface (it loads nothing there).
        offdeck_steps: wheel-steps beside the surface over the deck's length.
        factorizations: effective-matrix factorisations done (counted by the basis; 1 per run).
        steps: time steps taken; wall_time: s.
        sensor_min, sensor_max: extremes per sensor over every step (not only the samples).
        contact_force_range: (min, max) contact force per vehicle while on the deck, N (a run of more than
            :data:`MAX_FORCE_RANGES` contact points keeps those with the largest forces and those that pulled:
            constant memory over a year of records).
        max_on_deck: most vehicles on the deck at once (a vehicle's axles count once).
        weights: gross-weight statistics per vehicle class of the vehicles that came onto the deck (from their
            load records: ``/cosim/vehicle_loads``).
    """

    t: npt.NDArray[np.float64]
    sensors: dict[str, npt.NDArray[np.float64]]
    vehicle_ids: list[str]
    vehicle_table: dict[str, npt.NDArray[np.float64]]
    liftoff_events: int = 0
    liftoff_steps: int = 0
    offdeck_events: int = 0
    offdeck_steps: int = 0
    factorizations: int = 0
    steps: int = 0
    wall_time: float = 0.0
    info: dict = field(default_factory=dict)
    sensor_min: dict[str, float] = field(default_factory=dict)
    sensor_max: dict[str, float] = field(default_factory=dict)
    contact_force_range: dict[str, tuple[float, float]] = field(default_factory=dict)
    max_on_deck: int = 0
    weights: dict[str, WeightStats] = field(default_factory=dict)

    def vehicle(self, vehicle_id: str) -> dict[str, npt.NDArray[np.float64]]:
        """The samples of one vehicle, column name -> array."""
        if vehicle_id not in self.vehicle_ids:
            raise KeyError(f"no vehicle {vehicle_id!r} (have: {', '.join(self.vehicle_ids)})")
        sel = self.vehicle_table["vehicle"] == self.vehicle_ids.index(vehicle_id)
        return {k: v[sel] for k, v in self.vehicle_table.items() if k != "vehicle"}

    def peaks(self) -> dict[str, float]:
        """Largest absolute value per sensor."""
        return {name: float(np.max(np.abs(v))) if len(v) else 0.0 for name, v in self.sensors.items()}

    def write_csv(self, path: str | Path) -> None:
        """Sensor channels as columns ``t,<sensor names>`` (SI units)."""
        with open(path, "w", newline="") as fh:
            writer = csv.writer(fh)
            names = list(self.sensors)
            writer.writerow(["t"] + names)
            columns = np.column_stack([self.t] + [self.sensors[n] for n in names])
            for row in columns:
                writer.writerow([repr(float(v)) for v in row])


class BlockObserver(Protocol):
    """Anything that wants to see every block of steps as it is computed (a log writer, a collector)."""

    def on_block(self, times: npt.NDArray[np.float64], keep: npt.NDArray[np.bool_], report: BlockReport) -> None: ...


class _Collector:
    """Accumulates the sampled histories into a :class:`SimulationResult` (memory grows with the run)."""

    COLUMNS = VEHICLE_COLUMNS

    def __init__(self, n_sensors: int) -> None:
        self.t_parts = [np.zeros(1)]  # sample 0: at rest
        self.s_parts = [np.zeros((1, n_sensors))]
        self.vehicle_ids: list[str] = []
        self.index_of: dict[str, int] = {}
        self.table: dict[str, list[np.ndarray]] = {k: [] for k in self.COLUMNS}

    def on_block(self, times, keep, report) -> None:
        self.t_parts.append(times[keep])
        self.s_parts.append(report.sensors[keep])
        if not report.ids:
            return
        for vid in report.ids:
            if vid not in self.index_of:
                self.index_of[vid] = len(self.vehicle_ids)
                self.vehicle_ids.append(vid)
        rows, cols = np.nonzero(report.on_deck & keep[:, None])
        vidx = np.array([self.index_of[v] for v in report.ids], dtype=np.int64)
        values = {
            "t": times[rows], "vehicle": vidx[cols].astype(float), "x": report.x[rows, cols],
            "y": report.lateral[rows, cols],
            "speed": report.v[rows, cols], "acceleration": report.a[rows, cols],
            "body_displacement": report.body_displacement[rows, cols],
            "body_acceleration": report.body_acceleration[rows, cols],
            "contact_force": report.contact_force[rows, cols],
        }
        for name in self.COLUMNS:
            self.table[name].append(values[name])


#: A run keeps the contact-force ranges of at most about this many contact points (twice it between prunes):
#: those with the largest forces, those that pulled, those on the deck (:attr:`SimulationResult.contact_force_range`).
MAX_FORCE_RANGES = 20_000


class _Extremes:
    """Running extremes for summaries, in constant memory whatever the run's length."""

    def __init__(self, names: Sequence[str]) -> None:
        self.names = list(names)
        self.s_min = np.zeros(len(names))
        self.s_max = np.zeros(len(names))
        self.force: dict[str, list[float]] = {}
        self.max_on_deck = 0
        self._owners: tuple[tuple[str, ...], np.ndarray] = ((), np.zeros(0, dtype=np.int64))

    def on_block(self, times, keep, report) -> None:
        # One compiled pass: with numpy the masked and NaN-skipping reductions took a third of a second of the
        # run's thread in 10 min of the default run.
        col_owner = self._owners[1]
        if report.ids and self._owners[0] != report.ids:  # the same vehicles block after block: worked out once
            # Vehicles, not contact points: the axles of one vehicle ("id#k") count once. (A dict, not np.unique:
            # the fleet changes with every vehicle of a long run of records, and sorting strings cost more.)
            number: dict[str, int] = {}
            col_owner = np.array([number.setdefault(vehicle_of(v), len(number)) for v in report.ids], dtype=np.int64)
            self._owners = (report.ids, col_owner)
        q = len(report.ids)
        f_min, f_max = np.full(q, np.inf), np.full(q, -np.inf)
        on_deck = block_extremes(report.sensors, self.s_min, self.s_max, report.on_deck, report.contact_force,
                                 col_owner if q else np.zeros(0, dtype=np.int64), f_min, f_max)
        self.max_on_deck = max(self.max_on_deck, on_deck)
        for j in np.flatnonzero(f_min <= f_max).tolist():
            lo_hi = self.force.setdefault(report.ids[j], [np.inf, -np.inf])
            lo_hi[0] = min(lo_hi[0], float(f_min[j]))
            lo_hi[1] = max(lo_hi[1], float(f_max[j]))
        if len(self.force) > 2 * MAX_FORCE_RANGES:
            self._prune(set(report.ids))

    def _prune(self, current: set[str]) -> None:
        """Keep the force ranges a summary shows: the contact points still in the fleet, those that pulled
        (min < 0) and the :data:`MAX_FORCE_RANGES` with the largest force; a year of records has millions of
        axles, and their ranges (about 200 bytes each) were the run's only memory that grew with its length."""
        ranked = sorted(self.force.items(), key=lambda item: item[1][1], reverse=True)
        self.force = {k: v for i, (k, v) in enumerate(ranked) if i < MAX_FORCE_RANGES or v[0] < 0 or k in current}


@compiled(nogil=True)
def block_extremes(sensors: np.ndarray, s_min: np.ndarray, s_max: np.ndarray, on_deck: np.ndarray,
                   force: np.ndarray, col_owner: np.ndarray, f_min: np.ndarray, f_max: np.ndarray) -> int:
    """A block's extremes, in place: each sensor's (a NaN, a step it was not read at, does not count), each
    contact column's force over the steps it was on the deck (``f_min``, ``f_max`` start at +inf, -inf; a
    column never on the deck keeps them); returns the most vehicles (``col_owner``: each column's vehicle) on
    the deck at one step."""
    steps, n_sensors = sensors.shape
    for k in range(steps):
        for i in range(n_sensors):
            value = sensors[k, i]
            if value < s_min[i]:  # False for NaN
                s_min[i] = value
            if value > s_max[i]:
                s_max[i] = value
    q = on_deck.shape[1]
    most = 0
    if q == 0:
        return most
    seen_at = np.full(col_owner.max() + 1, -1)
    for k in range(on_deck.shape[0]):
        count = 0
        for j in range(q):
            if on_deck[k, j]:
                f = force[k, j]
                if f < f_min[j]:
                    f_min[j] = f
                if f > f_max[j]:
                    f_max[j] = f
                owner = col_owner[j]
                if seen_at[owner] != k:
                    seen_at[owner] = k
                    count += 1
        most = max(most, count)
    return most


class _EmptyBlocks:
    """Blocks of k steps without vehicles, one per k (a stretch of traffic skipped by its ``quiet_until``)."""

    def __init__(self) -> None:
        self._made: dict[int, TrafficBlock] = {}
        self._y = np.zeros(0)

    def __call__(self, k: int) -> TrafficBlock:
        block = self._made.get(k)
        if block is None:
            none = np.zeros((k, 0))
            block = self._made[k] = TrafficBlock((), (), none, none, none, self._y)
        return block


def _quiet_steps(quiet: Callable[[float], float], done: int, n_steps: int, dt: float) -> int:
    """How many steps after step ``done`` (up to ``n_steps``) the traffic says are empty: steps s with
    ``done < s`` and ``s dt < quiet_until(done dt)``."""
    until = quiet(done * dt)
    if not until > (done + 1) * dt:
        return 0
    if math.isinf(until):
        return n_steps - done
    last = min(int(math.ceil(until / dt)) - 1, n_steps)
    while last > done and last * dt >= until:
        last -= 1
    while last + 1 <= n_steps and (last + 1) * dt < until:
        last += 1
    return max(last - done, 0)


def check_traffic_fits(bridge: BridgeModel | ModalBridge, traffic: TrafficSource) -> None:
    """Raise :class:`ConfigError` when a traffic source was made for a bridge of another length.

    Scripted vehicles and replayed frames know the deck length they move on
    (``traffic.length``): on another bridge their entry and exit times, and so
    the loading, would silently be wrong.
    """
    length = getattr(traffic, "length", None)
    if length is None:
        return
    if not abs(float(length) - bridge.length) <= 1e-9 * max(bridge.length, 1.0):
        raise ConfigError(f"the traffic was made for a bridge {float(length):g} m long, this one is "
                          f"{bridge.length:g} m: build the traffic with length = {bridge.length:g}")


def check_paths_on_deck(bridge: BridgeModel | ModalBridge, traffic: TrafficSource) -> None:
    """Raise :class:`ConfigError` for a scripted vehicle whose wheel path lies beside the deck's surface.

    A scripted vehicle keeps its lateral offset for the whole run: off the deck it would never load it, which
    is a mistake in the script, not traffic. (A traffic simulation's wheel that leaves the surface is an event
    of the run instead: :attr:`cosim.core.coupling.BlockReport.off_surface`.)
    """
    if isinstance(bridge, ModalBridge):
        for vehicle in getattr(traffic, "vehicles", ()):
            y = getattr(vehicle, "y", None)
            if isinstance(y, (int, float)) and not bridge.path_on_deck(y):
                lo, hi = bridge.deck_y
                raise ConfigError(f"vehicle {vehicle.id}: its wheel path y = {y:g} m never crosses the deck's "
                                  f"surface ({bridge.source or 'its modes'}: {lo:g} <= y <= {hi:g} m at its widest); "
                                  "put it on a lane of this bridge")
        return
    y_min, y_max = bridge.section.deck_y
    tol = 1e-9 * max(y_max - y_min, 1.0)
    for vehicle in getattr(traffic, "vehicles", ()):
        y = getattr(vehicle, "y", None)
        if isinstance(y, (int, float)) and not y_min - tol <= y <= y_max + tol:
            raise ConfigError(f"vehicle {vehicle.id}: its wheel path y = {y:g} m lies off the deck "
                              f"({y_min:g} <= y <= {y_max:g} m); put it on a lane of this bridge")


def check_road_covers(bridge: BridgeModel | ModalBridge, road: RoadProfile) -> None:
    """Raise :class:`ConfigError` unless the road profile covers the deck, 0 <= x <= L."""
    x_end = road.x0 + road.dx * (road.r.shape[1] - 1)
    tol = 1e-6 * max(bridge.length, 1.0)
    if road.x0 > tol or x_end < bridge.length - tol:
        raise ConfigError(f"the road profile ({road.description}) covers {road.x0:g} <= x <= {x_end:g} m; "
                          f"it must cover the deck, 0 <= x <= {bridge.length:g} m")


def simulate(
    bridge: BridgeModel | ModalBridge,
    traffic: TrafficSource,
    duration: float,
    solver: SolverSettings = SolverSettings(),
    sensors: Sequence[Sensor] = (),
    road: RoadProfile | None = None,
    output_every: int = 1,
    progress: Callable[[float], None] | None = None,
    block_steps: int = 200,
    observers: Sequence[BlockObserver] = (),
    collect: bool = True,
    overlap: bool = True,
    join_blocks: bool = True,
) -> SimulationResult:
    """Simulate ``duration`` seconds of traffic on the bridge.

    Args:
        bridge: the structural model: a beam (its Rayleigh damping is used), or a deck given by its modes
            (:class:`cosim.core.modal_bridge.ModalBridge`: solved on its modes, whatever ``solver.basis``
            says; ``solver.modes``/``cutoff_hz`` keep the first of them).
        traffic: where the vehicles are at each time (scripted or SUMO).
        duration: simulated time, s.
        solver: time step, scheme and basis.
        sensors: deck sensors to sample.
        road: road profiles (default smooth).
        output_every: sample every this many steps.
        progress: called with the fraction done after every block of steps.
        block_steps: steps handed to the compiled loop at once.
        observers: also shown every block (e.g. a log writer), in order.
        collect: keep the sampled histories in the result; without it memory
            stays constant however long the run (extremes are still reported).
        overlap: compute the next block of traffic (SUMO, in this thread) while
            the compiled loop, which releases the GIL, advances the bridge over
            the current one in a worker thread: two cores work at once. The
            numbers are the same either way (the traffic does not depend on the
            bridge, and the blocks are advanced in order). A quasi-static run
            never overlaps (its step holds the GIL).
        join_blocks: consecutive blocks of the same fleet (same vehicles and lateral offsets) are advanced
            in one call of at most :data:`JOINED_STEPS` steps: each call costs the solver thread, the
            observers and the log a fixed amount of Python. The numbers are the same to the bit.
    """
    finite(duration, "duration", above=0.0)
    if duration < solver.dt:
        raise ConfigError(f"`duration` must be at least one time step, dt = {solver.dt:g} s (got {duration!r})")
    if isinstance(output_every, bool) or not isinstance(output_every, int) or output_every < 1:
        raise ConfigError(f"`output_every` must be an integer >= 1 (got {output_every!r})")
    if isinstance(block_steps, bool) or not isinstance(block_steps, int) or block_steps < 1:
        raise ConfigError(f"`block_steps` must be an integer >= 1 (got {block_steps!r})")
    names = [s.name for s in sensors]
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise ConfigError(f"sensor names must be unique (got {', '.join(duplicated)} more than once)")
    check_traffic_fits(bridge, traffic)
    check_paths_on_deck(bridge, traffic)
    if road is not None:
        check_road_covers(bridge, road)
    scheme = solver.make_scheme()
    system: CoupledSystem | QuasiStaticSystem
    if isinstance(bridge, ModalBridge):
        if solver.method == "quasi-static":
            raise ConfigError('[solver] method = "quasi-static" needs the beam model\'s influence lines; a deck given '
                              'by its modes runs with method = "dynamic"')
        bridge = bridge.keep(solver.modes, solver.cutoff_hz)
        traffic.follow_paths()  # a curved lane's wheels load the mode surface where they are at every step
        solver = replace(solver, basis="modal", modes=None, cutoff_hz=None)
    if solver.method == "quasi-static":
        assert isinstance(bridge, BridgeModel)
        system = QuasiStaticSystem(bridge, tuple(sensors), solver.gravity)
        info = {"basis": "quasi-static (influence lines)", "n_reduced": len(sensors), "scheme": "none",
                "dt": solver.dt}
    else:
        basis = make_basis(bridge, solver.dt, scheme, solver.basis, solver.modes, solver.cutoff_hz)
        system = CoupledSystem(bridge, basis, scheme, solver.dt, road=road, gravity=solver.gravity,
                               sensors=tuple(sensors))
        info = {"basis": basis.name, "n_reduced": basis.n, "scheme": scheme.name, "dt": solver.dt}
    n_steps = int(round(duration / solver.dt))
    if solver.method == "quasi-static":
        # The static step is numpy and Python under the GIL: handing blocks to the worker thread and back cost more
        # than it saved (an empty day at dt = 0.1 s took 0.47 s with the overlap, 0.12 s without).
        overlap = False
    collector = _Collector(len(sensors)) if collect else None
    extremes = _Extremes([s.name for s in sensors])
    weights = _Weights()
    watchers: list = [extremes, weights] + ([collector] if collector else []) + list(observers)
    # A zero-step call compiles (or loads from cache) the kernel outside the timed run.
    empty = np.zeros((0, 0))
    system.advance(TrafficBlock((), (), empty, empty, empty, np.zeros(0)))
    started = time.perf_counter()

    def finish(pending: tuple[Future[BlockReport], np.ndarray, np.ndarray]) -> None:
        future, steps, times = pending
        report = future.result()
        keep = steps % output_every == 0
        for w in watchers:
            w.on_block(times, keep, report)
        if progress is not None:
            progress(int(steps[-1]) / n_steps)

    failed: list[BaseException] = []

    def advance(block: TrafficBlock) -> BlockReport:
        if failed:  # a block queued behind one that failed (diverged) does not run on its state
            raise failed[0]
        try:
            return system.advance(block)
        except BaseException as exc:
            failed.append(exc)
            raise

    # Two blocks in flight: the worker starts the next block as soon as it ends one, while this thread shows
    # the one before to the observers (the log) and asks the traffic for the one after. The worker takes them
    # in order, so the numbers are those of one block at a time.
    in_flight: collections.deque[tuple[Future[BlockReport], np.ndarray, np.ndarray]] = collections.deque()
    group: list[tuple[TrafficBlock, np.ndarray]] = []  # traffic blocks of one fleet, not yet handed over
    switch_interval = sys.getswitchinterval()
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="cosim-solver") as solver_thread:

        def hand_over() -> None:
            blocks = [b for b, _ in group]
            steps = group[0][1] if len(group) == 1 else np.concatenate([s for _, s in group])
            group.clear()
            block = blocks[0] if len(blocks) == 1 else TrafficBlock.join(blocks)
            if overlap:
                future = solver_thread.submit(advance, block)
            else:  # in this thread: nothing to overlap, and a hand-off to the worker and back costs
                future = Future()
                try:
                    future.set_result(advance(block))
                except BaseException as exc:  # noqa: BLE001 - raised again by finish(), as the worker's would be
                    future.set_exception(exc)
            in_flight.append((future, steps, steps * solver.dt))
            while len(in_flight) > (1 if overlap else 0):
                finish(in_flight.popleft())

        quiet = getattr(traffic, "quiet_until", None)  # wrapped sources (a log's) pass it on
        empty_blocks = _EmptyBlocks()
        try:
            if overlap:
                sys.setswitchinterval(min(switch_interval, SWITCH_INTERVAL))
            done = 0
            joined = 0
            while done < n_steps:
                k = min(block_steps, n_steps - done)
                free = _quiet_steps(quiet, done, n_steps, solver.dt) if quiet is not None and done else 0
                if free >= k:  # nothing on the deck for a while: empty blocks, without asking the traffic
                    k = min(free, JOINED_STEPS)
                    steps = np.arange(done + 1, done + k + 1)
                    block = empty_blocks(k)
                else:
                    steps = np.arange(done + 1, done + k + 1)
                    block = traffic.block(steps * solver.dt)  # while the worker advances the blocks before
                if group and not (join_blocks and joined + k <= JOINED_STEPS and block.same_fleet(group[-1][0])):
                    hand_over()
                    joined = 0
                group.append((block, steps))
                joined += k
                done += k
            if group:
                hand_over()
            while in_flight:
                finish(in_flight.popleft())
        finally:
            sys.setswitchinterval(switch_interval)
            # Interrupted: blocks not begun are dropped; the one running ends before the state is read.
            running = [future for future, _, _ in in_flight if not future.cancel()]
            wait(running)
    if collector is not None:
        vehicle_table = {k: (np.concatenate(v) if v else np.zeros(0)) for k, v in collector.table.items()}
        vehicle_table["vehicle"] = vehicle_table["vehicle"].astype(np.int64)
        t_out = np.concatenate(collector.t_parts)
        s_out = np.concatenate(collector.s_parts)
        vehicle_ids = collector.vehicle_ids
    else:
        vehicle_table, t_out, s_out, vehicle_ids = {}, np.zeros(0), np.zeros((0, len(sensors))), list(extremes.force)
    return SimulationResult(
        t=t_out,
        sensors={s.name: s_out[:, i].copy() for i, s in enumerate(sensors)},
        vehicle_ids=vehicle_ids,
        vehicle_table=vehicle_table,
        liftoff_events=system.liftoff_events,
        liftoff_steps=system.liftoff_steps,
        offdeck_events=system.offdeck_events,
        offdeck_steps=system.offdeck_steps,
        factorizations=system.factorizations,
        steps=system.n_steps,
        wall_time=time.perf_counter() - started,
        info=info,
        sensor_min=dict(zip(extremes.names, extremes.s_min.tolist())),
        sensor_max=dict(zip(extremes.names, extremes.s_max.tolist())),
        contact_force_range={k: (v[0], v[1]) for k, v in extremes.force.items()},
        max_on_deck=extremes.max_on_deck,
        weights=weights.stats(),
    )
