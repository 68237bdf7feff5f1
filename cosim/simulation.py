"""Run a vehicle-bridge simulation and collect named results.

:func:`simulate` drives a :class:`~cosim.coupling.CoupledSystem` with any
traffic source and samples the sensors (deck displacement, velocity,
acceleration including the twist contribution, bending moment) and every
vehicle (contact force, body displacement and acceleration).
"""
from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import numpy.typing as npt

from .bridge import BridgeModel
from .coupling import CoupledSystem
from .errors import ConfigError
from .integrator import Scheme, make_basis
from .roughness import RoadProfile
from .traffic import TrafficSource

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
    t_parts, s_parts = [np.zeros(1)], [np.zeros((1, len(sensors)))]  # sample 0: at rest
    vehicle_ids: list[str] = []
    index_of: dict[str, int] = {}
    columns = ("t", "vehicle", "x", "y", "v", "contact_force", "body_displacement", "body_acceleration")
    table: dict[str, list[np.ndarray]] = {k: [] for k in columns}
    started = time.perf_counter()
    done = 0
    while done < n_steps:
        k = min(block_steps, n_steps - done)
        steps = np.arange(done + 1, done + k + 1)
        times = steps * solver.dt
        report = system.advance(traffic.block(times))
        keep = steps % output_every == 0
        t_parts.append(times[keep])
        s_parts.append(report.sensors[keep])
        if report.ids:
            for vid in report.ids:
                if vid not in index_of:
                    index_of[vid] = len(vehicle_ids)
                    vehicle_ids.append(vid)
            rows, cols = np.nonzero(report.on_deck & keep[:, None])
            vidx = np.array([index_of[v] for v in report.ids], dtype=np.int64)
            table["t"].append(times[rows])
            table["vehicle"].append(vidx[cols].astype(float))
            table["x"].append(report.x[rows, cols])
            table["y"].append(report.y[cols])
            table["v"].append(report.v[rows, cols])
            table["contact_force"].append(report.contact_force[rows, cols])
            table["body_displacement"].append(report.body_displacement[rows, cols])
            table["body_acceleration"].append(report.body_acceleration[rows, cols])
        done += k
        if progress is not None:
            progress(done / n_steps)
    vehicle_table = {k: (np.concatenate(v) if v else np.zeros(0)) for k, v in table.items()}
    vehicle_table["vehicle"] = vehicle_table["vehicle"].astype(np.int64)
    t_out = np.concatenate(t_parts)
    s_out = np.concatenate(s_parts)
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
    )
