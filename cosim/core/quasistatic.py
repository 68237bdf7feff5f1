"""Quasi-static response of the bridge to moving traffic: the same loads, no inertia (docs/theory.md §7.4).

The dynamic amplification factor (DAF) of a sensor is its dynamic peak over
the peak of a quasi-static run of the same traffic: every vehicle on the deck
presses with its weight ``m g`` at its contact point, and the bridge responds
statically (no mass, no damping, no vehicle dynamics, no road roughness).

Influence surfaces by reciprocity (Maxwell-Betti): a sensor reads
``s = r_s . d`` with ``r_s`` its row (the deck point's ``w_deck`` row, or the
bending-moment row at its x). Under a vertical force ``F_z`` at deck point
``(x, y)``, ``d = K^-1 F_z r(x, y)^T``, so

    s = F_z r(x, y) . g_s,      g_s = K^-1 r_s^T

One static solve per sensor gives ``g_s``, and then the sensor's influence
ordinate at *any* deck point is one 14-term dot product with the element's
shape functions: exact for the finite-element model, no grid to interpolate.
Velocity and acceleration sensors have no quasi-static counterpart here (their
ordinates are NaN).

This module is part of the numerical core: it imports numpy and the bridge and
traffic types only.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from .bridge import BridgeModel
from .sensors import Sensor, sensor_row
from .traffic import TrafficSource, vehicle_of

#: Sensor quantities that have a quasi-static response (and hence a DAF).
STATIC_QUANTITIES = ("displacement", "bending_moment", "stress", "strain", "shear_stress_xy", "shear_stress_xz")


def influence_vectors(bridge: BridgeModel, sensors: Sequence[Sensor]) -> npt.NDArray[np.float64]:
    """``g_s = K^-1 r_s^T`` per sensor, as rows of an (n_sensors, ndof) array (NaN rows for velocity/acceleration).

    The sensor row is the one the time integration samples: ``w_deck`` at
    ``(x, y)`` for displacements, ``bending_moment`` at ``x``.
    """
    out = np.full((len(sensors), bridge.ndof), np.nan)
    for i, sensor in enumerate(sensors):
        if sensor.quantity not in STATIC_QUANTITIES:
            continue
        row = sensor_row(bridge, sensor)
        f = np.zeros(bridge.ndof)
        np.add.at(f, row.dofs, row.values[0])
        out[i] = bridge.static(f=f).d
    return out


def influence(bridge: BridgeModel, g: npt.NDArray[np.float64], x: npt.ArrayLike, y: npt.ArrayLike
              ) -> npt.NDArray[np.float64]:
    """Influence ordinates (n_sensors, n_points): sensor reading per unit *upward* force at deck points (x, y).

    Points with x outside the bridge read 0; sensors without a static counterpart (NaN rows of ``g``) read NaN.
    """
    x = np.atleast_1d(np.asarray(x, dtype=float))
    y = np.broadcast_to(np.asarray(y, dtype=float), x.shape)
    on = (x >= 0.0) & (x <= bridge.length)
    out = np.zeros((len(g), len(x)))
    if on.any():
        dofs, values = bridge.deck_rows(np.clip(x[on], 0.0, bridge.length), y[on])
        out[:, on] = np.einsum("pk,spk->sp", values[:, 0, :], g[:, dofs])
    out[np.isnan(g).any(axis=1)] = np.nan
    return out


@dataclass
class QuasiStaticResult:
    """The quasi-static run of a traffic source.

    Attributes:
        t: sample times, s (t = 0 and every ``output_every``-th step, like the dynamic run's samples).
        sensors: sensor name -> quasi-static samples (SI units; NaN for velocity/acceleration sensors).
        peak: sensor name -> largest absolute value over *every* step (NaN without a static counterpart).
        vehicles: ids of the vehicles that were on the deck (0 <= x <= L) at any step, in order of appearance.
        heaviest: the largest total mass of a vehicle on the deck, kg (0 without vehicles).
        heaviest_id: its id ("" without vehicles).
        max_on_deck: most vehicles on the deck at one step.
        steps: time steps evaluated.
    """

    t: npt.NDArray[np.float64]
    sensors: dict[str, npt.NDArray[np.float64]]
    peak: dict[str, float]
    vehicles: list[str] = field(default_factory=list)
    heaviest: float = 0.0
    heaviest_id: str = ""
    max_on_deck: int = 0
    steps: int = 0


def quasi_static(
    bridge: BridgeModel,
    traffic: TrafficSource,
    duration: float,
    dt: float,
    sensors: Sequence[Sensor],
    gravity: float = 9.81,
    output_every: int = 1,
    block_steps: int = 400,
) -> QuasiStaticResult:
    """Quasi-static sensor readings under ``traffic`` at every time step of a run.

    The traffic is asked for the same times as :func:`cosim.core.simulation.simulate`
    asks (``k dt``, k = 1 ... round(duration / dt)), so the vehicles stand exactly
    where they stood in the dynamic run. Each vehicle on the deck loads it with
    ``total_mass * gravity`` downwards.

    Args:
        bridge: the structural model (its stiffness only).
        traffic: a traffic source (scripted vehicles, or frames replayed from a log).
        duration: simulated time, s; dt: the time step, s.
        sensors: the sensors to evaluate.
        gravity: m/s^2.
        output_every: keep every this many steps in the returned samples (peaks use every step).
        block_steps: steps asked from the traffic source at once.
    """
    g = influence_vectors(bridge, sensors)
    static = ~np.isnan(g[:, 0]) if len(sensors) else np.zeros(0, dtype=bool)
    g = np.where(np.isnan(g), 0.0, g)
    names = [s.name for s in sensors]
    n_steps = int(round(duration / dt))
    length = bridge.length
    peak = np.zeros(len(sensors))
    kept_t: list[np.ndarray] = [np.zeros(1)]
    kept_s: list[np.ndarray] = [np.zeros((1, len(sensors)))]
    seen: dict[str, None] = {}
    heaviest, heaviest_id, max_on = 0.0, "", 0
    done = 0
    while done < n_steps:
        k = min(block_steps, n_steps - done)
        steps = np.arange(done + 1, done + k + 1)
        times = steps * dt
        block = traffic.block(times)
        q = len(block.ids)
        values = np.zeros((k, len(sensors)))
        if q:
            on = (block.x >= 0.0) & (block.x <= length)
            mass = np.array([m.total_mass for m in block.models], dtype=float)
            weight = mass * gravity
            rows, cols = np.nonzero(on)
            if len(rows):
                ordinates = influence(bridge, g, block.x[rows, cols], block.y[cols])  # (s, p)
                contrib = -weight[cols][None, :] * ordinates  # downward weight
                for s in range(len(sensors)):
                    values[:, s] = np.bincount(rows, weights=contrib[s], minlength=k)
                # Vehicles, not contact points: the axles of one vehicle ("id#k") count once, masses add up.
                owner = np.array([vehicle_of(v) for v in block.ids])
                names_u, col_owner = np.unique(owner, return_inverse=True)
                on_vehicle = np.zeros((k, len(names_u)), dtype=bool)
                on_vehicle[rows, col_owner[cols]] = True
                max_on = max(max_on, int(on_vehicle.sum(axis=1).max()))
                present = np.flatnonzero(on.any(axis=0))
                vehicle_mass = np.bincount(col_owner, weights=mass, minlength=len(names_u))
                for j in present:
                    seen.setdefault(owner[j], None)
                u = np.unique(col_owner[present])
                u_max = u[int(np.argmax(vehicle_mass[u]))]
                if vehicle_mass[u_max] > heaviest:
                    heaviest, heaviest_id = float(vehicle_mass[u_max]), str(names_u[u_max])
        if len(sensors):
            peak = np.maximum(peak, np.abs(values).max(axis=0))
        keep = steps % output_every == 0
        kept_t.append(times[keep])
        kept_s.append(values[keep])
        done += k
    samples = np.concatenate(kept_s)
    return QuasiStaticResult(
        t=np.concatenate(kept_t),
        sensors={n: (samples[:, i].copy() if static[i] else np.full(len(samples), np.nan))
                 for i, n in enumerate(names)},
        peak={n: (float(peak[i]) if static[i] else float("nan")) for i, n in enumerate(names)},
        vehicles=list(seen), heaviest=heaviest, heaviest_id=heaviest_id, max_on_deck=max_on, steps=n_steps,
    )


def daf(dynamic_peak: float, static_peak: float) -> float:
    """Dynamic amplification factor ``dynamic_peak / static_peak`` (NaN when the static peak is 0 or NaN)."""
    if not np.isfinite(static_peak) or static_peak <= 0.0:
        return float("nan")
    return float(dynamic_peak) / float(static_peak)


__all__ = ["QuasiStaticResult", "STATIC_QUANTITIES", "daf", "influence", "influence_vectors", "quasi_static"]
