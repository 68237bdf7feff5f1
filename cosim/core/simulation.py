"""Run a vehicle-bridge simulation and collect named results.

:func:`simulate` drives a :class:`~cosim.core.coupling.CoupledSystem` with any
traffic source and samples the sensors (deck displacement, velocity,
acceleration including the twist contribution, bending moment) and every
vehicle (contact force, body displacement and acceleration).
"""
from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Protocol, Sequence

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .bridge import BridgeModel
from .coupling import BlockReport, CoupledSystem
from .integrator import Scheme, make_basis
from .roughness import RoadProfile
from .traffic import TrafficBlock, TrafficSource, vehicle_of

SENSOR_QUANTITIES = ("displacement", "velocity", "acceleration", "bending_moment")


@dataclass(frozen=True)
class Sensor:
    """A virtual sensor on the deck.

    Args:
        name: channel name.
        x, y: position on the deck, m (y is ignored for the bending moment).
        quantity: displacement (m) | velocity (m/s) | acceleration (m/s^2) of
            the deck point, vertical, twist included; or bending_moment (N m,
            sagging positive) of the section at x.
    """

    name: str
    x: float
    y: float = 0.0
    quantity: str = "displacement"

    def __post_init__(self) -> None:
        if self.quantity not in SENSOR_QUANTITIES:
            raise ConfigError(f"sensor {self.name}: `quantity` must be one of {', '.join(SENSOR_QUANTITIES)}")


@dataclass(frozen=True)
class SolverSettings:
    """Time step (s), scheme, basis and modal truncation."""

    dt: float = 0.005
    scheme: str = "newmark"
    hht_alpha: float = -0.05
    basis: str = "direct"
    modes: int | None = None
    cutoff_hz: float | None = None
    gravity: float = 9.81

    def make_scheme(self) -> Scheme:
        if self.scheme == "newmark":
            return Scheme.newmark()
        if self.scheme == "hht":
            return Scheme.hht(self.hht_alpha)
        raise ConfigError(f"`scheme` must be 'newmark' or 'hht' (got {self.scheme!r})")


@dataclass
class SimulationResult:
    """Time histories of a run, as numpy arrays with names.

    Attributes:
        t: sample times, s.
        sensors: sensor name -> samples (unit of its quantity).
        vehicle_ids: every vehicle that was on the deck.
        vehicle_table: long-format vehicle samples, column name -> array; one
            row per vehicle on the deck per sample: ``t``, ``vehicle`` (index
            into ``vehicle_ids``), ``x``, ``y``, ``v``, ``contact_force`` (N,
            compression positive), ``body_displacement`` (m),
            ``body_acceleration`` (m/s^2).
        liftoff_events: how many times a wheel's contact force turned negative.
        liftoff_steps: vehicle-steps with a negative contact force.
        factorizations: effective-matrix factorisations done (1 per run).
        steps: time steps taken; wall_time: s.
        sensor_min, sensor_max: extremes per sensor over every step (not only the samples).
        contact_force_range: (min, max) contact force per vehicle while on the deck, N.
        max_on_deck: most vehicles on the deck at once (a vehicle's axles count once).
    """

    t: npt.NDArray[np.float64]
    sensors: dict[str, npt.NDArray[np.float64]]
    vehicle_ids: list[str]
    vehicle_table: dict[str, npt.NDArray[np.float64]]
    liftoff_events: int = 0
    liftoff_steps: int = 0
    factorizations: int = 0
    steps: int = 0
    wall_time: float = 0.0
    info: dict = field(default_factory=dict)
    sensor_min: dict[str, float] = field(default_factory=dict)
    sensor_max: dict[str, float] = field(default_factory=dict)
    contact_force_range: dict[str, tuple[float, float]] = field(default_factory=dict)
    max_on_deck: int = 0

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

    COLUMNS = ("t", "vehicle", "x", "y", "v", "contact_force", "body_displacement", "body_acceleration")

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
        tab = self.table
        tab["t"].append(times[rows])
        tab["vehicle"].append(vidx[cols].astype(float))
        tab["x"].append(report.x[rows, cols])
        tab["y"].append(report.y[cols])
        tab["v"].append(report.v[rows, cols])
        tab["contact_force"].append(report.contact_force[rows, cols])
        tab["body_displacement"].append(report.body_displacement[rows, cols])
        tab["body_acceleration"].append(report.body_acceleration[rows, cols])


class _Extremes:
    """Running extremes for summaries, in constant memory whatever the run's length."""

    def __init__(self, names: Sequence[str]) -> None:
        self.names = list(names)
        self.s_min = np.zeros(len(names))
        self.s_max = np.zeros(len(names))
        self.force: dict[str, list[float]] = {}
        self.max_on_deck = 0

    def on_block(self, times, keep, report) -> None:
        if len(report.sensors):
            self.s_min = np.minimum(self.s_min, report.sensors.min(axis=0))
            self.s_max = np.maximum(self.s_max, report.sensors.max(axis=0))
        if not report.ids:
            return
        # Vehicles, not contact points: the axles of one vehicle ("id#k") count once.
        owners = np.array([vehicle_of(v) for v in report.ids])
        _, col_owner = np.unique(owners, return_inverse=True)
        on_vehicle = np.zeros((len(report.on_deck), col_owner.max() + 1), dtype=bool)
        rows, cols = np.nonzero(report.on_deck)
        on_vehicle[rows, col_owner[cols]] = True
        self.max_on_deck = max(self.max_on_deck, int(on_vehicle.sum(axis=1).max()))
        on = report.on_deck.any(axis=0)
        masked_min = np.where(report.on_deck, report.contact_force, np.inf).min(axis=0)
        masked_max = np.where(report.on_deck, report.contact_force, -np.inf).max(axis=0)
        for j in np.flatnonzero(on):
            lo_hi = self.force.setdefault(report.ids[j], [np.inf, -np.inf])
            lo_hi[0] = min(lo_hi[0], float(masked_min[j]))
            lo_hi[1] = max(lo_hi[1], float(masked_max[j]))


def simulate(
    bridge: BridgeModel,
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
) -> SimulationResult:
    """Simulate ``duration`` seconds of traffic on the bridge.

    Args:
        bridge: the structural model (its Rayleigh damping is used).
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
    """
    if not duration > 0:
        raise ConfigError(f"`duration` must be > 0 s (got {duration})")
    if output_every < 1:
        raise ConfigError("`output_every` must be >= 1")
    scheme = solver.make_scheme()
    basis = make_basis(bridge, solver.dt, scheme, solver.basis, solver.modes, solver.cutoff_hz)
    system = CoupledSystem(
        bridge, basis, scheme, solver.dt, road=road, gravity=solver.gravity,
        sensors=tuple((s.x, s.y, s.quantity) for s in sensors),
    )
    n_steps = int(round(duration / solver.dt))
    collector = _Collector(len(sensors)) if collect else None
    extremes = _Extremes([s.name for s in sensors])
    watchers: list = [extremes] + ([collector] if collector else []) + list(observers)
    # A zero-step call compiles (or loads from cache) the kernel outside the timed run.
    empty = np.zeros((0, 0))
    system.advance(TrafficBlock((), (), empty, empty, empty, np.zeros(0)))
    started = time.perf_counter()
    done = 0
    while done < n_steps:
        k = min(block_steps, n_steps - done)
        steps = np.arange(done + 1, done + k + 1)
        times = steps * solver.dt
        report = system.advance(traffic.block(times))
        keep = steps % output_every == 0
        for w in watchers:
            w.on_block(times, keep, report)
        done += k
        if progress is not None:
            progress(done / n_steps)
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
        factorizations=basis.n_factorizations,
        steps=system.n_steps,
        wall_time=time.perf_counter() - started,
        info={"basis": basis.name, "n_reduced": basis.n, "scheme": scheme.name, "dt": solver.dt},
        sensor_min=dict(zip(extremes.names, extremes.s_min.tolist())),
        sensor_max=dict(zip(extremes.names, extremes.s_max.tolist())),
        contact_force_range={k: (v[0], v[1]) for k, v in extremes.force.items()},
        max_on_deck=extremes.max_on_deck,
    )
