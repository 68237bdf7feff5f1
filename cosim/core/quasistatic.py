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
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .bridge import BridgeModel
from .coupling import BlockReport
from .element import ELEMENT_DOFS, NODE_DOFS
from .jit import compiled
from .sensors import Sensor, check_sensor_on, sensor_row
from .traffic import AXLE_SEPARATOR, TrafficBlock, TrafficSource, vehicle_of

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


def column_weights(ids: tuple[str, ...], models: tuple[Any, ...], gravity: float) -> npt.NDArray[np.float64]:
    """Each contact column's static load, N (compression positive): a one-contact model's weight; column k of a
    vehicle on several contacts (``id#k`` of one body) that body's k-th static axle load."""
    out = np.empty(len(models))
    cache: dict[int, np.ndarray] = {}
    for j, (cid, model) in enumerate(zip(ids, models)):
        if model.contacts == 1:
            out[j] = model.total_mass * gravity
            continue
        loads = cache.get(id(model))
        if loads is None:
            loads = cache[id(model)] = np.asarray(model.static_axle_loads(gravity), dtype=float)
        k = int(cid.rsplit(AXLE_SEPARATOR, 1)[1]) if AXLE_SEPARATOR in cid else 0
        out[j] = loads[k]
    return out


@dataclass(frozen=True)
class InfluencePolynomials:
    """The sensors' influence ordinates (:func:`influence`) as one cubic in the element's xi per sensor and
    element: ``bend[s, e] . xi^p + (y - y_S) twist[s, e] . xi^p`` (the deck's w at the shear centre and its
    twist, docs/theory.md §5.1, dotted with ``g_s`` once for every element). A point's ordinate is then 16
    numbers, not a 14-term row of the element's shape functions built per point: the same values (to the
    rounding), at a few tens of nanoseconds a point.

    Attributes:
        nodes_x: the element ends, m (n_el + 1); lengths: each element's, m.
        bend, twist: (n_sensors, n_el, 4) coefficients of xi^0 ... xi^3 (NaN rows of ``g`` as 0).
        y_s: the shear centre's y, m.
    """

    nodes_x: npt.NDArray[np.float64]
    lengths: npt.NDArray[np.float64]
    bend: npt.NDArray[np.float64]
    twist: npt.NDArray[np.float64]
    y_s: float


def influence_polynomials(bridge: BridgeModel, g: npt.NDArray[np.float64]) -> InfluencePolynomials:
    """The :class:`InfluencePolynomials` of influence vectors ``g`` (rows as from :func:`influence_vectors`)."""
    c_w, c_t, lengths = bridge.deck_coefficients
    n_el = len(lengths)
    dofs = NODE_DOFS * np.arange(n_el)[:, None] + np.arange(ELEMENT_DOFS)[None, :]
    g_el = np.where(np.isnan(g), 0.0, g)[:, dofs]  # (s, e, 14)
    return InfluencePolynomials(np.asarray(bridge.nodes_x, dtype=float), np.asarray(lengths, dtype=float),
                                np.ascontiguousarray(np.einsum("edp,sed->sep", c_w, g_el)),
                                np.ascontiguousarray(np.einsum("edp,sed->sep", c_t, g_el)), float(bridge.section.y_s))


@compiled(nogil=True)
def _static_values(x: np.ndarray, y: np.ndarray, weight: np.ndarray, on: np.ndarray, nodes_x: np.ndarray,
                   lengths: np.ndarray, bend: np.ndarray, twist: np.ndarray, y_s: float, values: np.ndarray) -> None:
    """``values[k, s] -= weight[j] * ordinate_s(x[k, j], y[j])`` over the columns on the deck (``on``), columns
    in order at each step (the order numpy's sums took)."""
    steps, q = x.shape
    n_el = lengths.shape[0]
    n_sensors = bend.shape[0]
    for j in range(q):
        lever = y[j] - y_s
        w = weight[j]
        for k in range(steps):
            if not on[k, j]:
                continue
            xx = x[k, j]
            lo, hi = 0, n_el  # the element: nodes_x[e] <= xx < nodes_x[e + 1] (the last holds x = L)
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if nodes_x[mid] <= xx:
                    lo = mid
                else:
                    hi = mid
            e = lo
            xi = (xx - nodes_x[e]) / lengths[e]
            xi = min(max(xi, 0.0), 1.0)
            for s in range(n_sensors):
                b = bend[s, e]
                t = twist[s, e]
                ordinate = (b[0] + xi * (b[1] + xi * (b[2] + xi * b[3]))
                            + lever * (t[0] + xi * (t[1] + xi * (t[2] + xi * t[3]))))
                values[k, s] -= w * ordinate  # the weight acts downwards


def static_block(bridge: BridgeModel, g: npt.NDArray[np.float64], block: TrafficBlock, gravity: float,
                 y_range: tuple[float, float], polynomials: InfluencePolynomials | None = None,
                 weights: npt.NDArray[np.float64] | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The static response of a block of traffic: sensor values (K, s), and per contact column (K, q) on the
    deck (its length and its surface), its static load there (N; 0 elsewhere) and beside the surface over the
    deck's length (it loads nothing there). ``g``: the sensors' influence vectors (NaN rows as 0);
    ``polynomials``: theirs (:func:`influence_polynomials`) and ``weights``: the block's
    :func:`column_weights`, when already made (a run makes the polynomials once, and a fleet's weights once
    for the blocks it stays the same in)."""
    k, q = block.x.shape
    values = np.zeros((k, len(g)))
    if not q:
        empty = np.zeros((k, 0), dtype=bool)
        return values, empty, np.zeros((k, 0)), empty
    span = (block.x >= 0.0) & (block.x <= bridge.length)
    surface = (block.y >= y_range[0]) & (block.y <= y_range[1])
    on = span & surface[None, :]
    weight = weights if weights is not None else column_weights(block.ids, block.models, gravity)
    force = np.where(on, weight[None, :], 0.0)
    if len(g) and on.any():
        p = polynomials if polynomials is not None else influence_polynomials(bridge, g)
        _static_values(np.ascontiguousarray(block.x, dtype=np.float64), np.ascontiguousarray(block.y, dtype=np.float64),
                       weight, on, p.nodes_x, p.lengths, p.bend, p.twist, p.y_s, values)
    return values, on, force, span & ~surface[None, :]


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
    where they stood in the dynamic run. Each contact point on the deck loads it with
    its static load downwards (:func:`column_weights`).

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
    polynomials = influence_polynomials(bridge, g)
    names = [s.name for s in sensors]
    n_steps = int(round(duration / dt))
    peak = np.zeros(len(sensors))
    kept_t: list[np.ndarray] = [np.zeros(1)]
    kept_s: list[np.ndarray] = [np.zeros((1, len(sensors)))]
    seen: dict[str, None] = {}
    heaviest, heaviest_id, max_on = 0.0, "", 0
    everywhere = (-np.inf, np.inf)
    done = 0
    while done < n_steps:
        k = min(block_steps, n_steps - done)
        steps = np.arange(done + 1, done + k + 1)
        times = steps * dt
        block = traffic.block(times)
        values, on, _, _ = static_block(bridge, g, block, gravity, everywhere, polynomials)
        if on.any():
            # Vehicles, not contact points: the axles of one vehicle ("id#k") count once, masses add up.
            rows, cols = np.nonzero(on)
            owner = np.array([vehicle_of(v) for v in block.ids])
            names_u, col_owner = np.unique(owner, return_inverse=True)
            on_vehicle = np.zeros((k, len(names_u)), dtype=bool)
            on_vehicle[rows, col_owner[cols]] = True
            max_on = max(max_on, int(on_vehicle.sum(axis=1).max()))
            present = np.flatnonzero(on.any(axis=0))
            mass = column_weights(block.ids, block.models, gravity) / gravity if gravity > 0 else \
                np.array([m.total_mass for m in block.models])
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


class QuasiStaticSystem:
    """The deck's static response at every step of a run, block by block (``[solver] method = "quasi-static"``):
    the same interface as :class:`cosim.core.coupling.CoupledSystem` for :func:`cosim.core.simulation.simulate`.

    Each contact point on the deck presses with its static load (:func:`column_weights`); sensors read the
    static response by reciprocity (:func:`influence`). No inertia, no vehicle dynamics, no road roughness: the
    contact force is the static load, the bodies do not move.

    Raises:
        ConfigError: a sensor whose quantity has no static counterpart (velocity, acceleration).
    """

    def __init__(self, bridge: BridgeModel, sensors: tuple[Sensor, ...], gravity: float) -> None:
        for sensor in sensors:
            if sensor.quantity not in STATIC_QUANTITIES:
                raise ConfigError(f"sensor {sensor.name}: quantity = {sensor.quantity!r} has no quasi-static value "
                                  f"(only {', '.join(STATIC_QUANTITIES)}); remove the sensor or use "
                                  "method = \"dynamic\"")
            check_sensor_on(bridge, sensor)
        self.bridge, self.sensors, self.gravity = bridge, sensors, float(gravity)
        self._g = influence_vectors(bridge, sensors)
        self._polynomials = influence_polynomials(bridge, self._g)
        y_min, y_max = bridge.section.deck_y
        tol = 1e-9 * max(y_max - y_min, 1.0)
        self._y_range = (y_min - tol, y_max + tol)
        self.n_steps = 0
        self.factorizations = 1  # the stiffness, once, for the sensors' influence vectors
        self.liftoff_events = self.liftoff_steps = 0
        self.offdeck_events = self.offdeck_steps = 0
        self._off: dict[str, bool] = {}
        self._fleet: tuple[Any, Any, np.ndarray] = ((), (), np.zeros(0))  # the last block's ids, models, weights

    def advance(self, block: TrafficBlock) -> BlockReport:
        """The static response at the block's steps, as a :class:`cosim.core.coupling.BlockReport`."""
        k, q = block.x.shape
        if not q:  # nothing on the deck: at rest (long runs of records are mostly this)
            self.n_steps += k
            self._off = {}
            none = np.zeros((k, 0))
            flags = np.zeros((k, 0), dtype=bool)
            return BlockReport(block.ids, block.models, block.x, block.y, block.v, block.a, flags, none, none, none,
                               np.zeros((k, len(self.sensors))), flags, flags, block.loads)
        fleet = self._fleet
        if fleet[0] is not block.ids or fleet[1] is not block.models:
            fleet = self._fleet = (block.ids, block.models, column_weights(block.ids, block.models, self.gravity))
        values, on, force, off = static_block(self.bridge, self._g, block, self.gravity, self._y_range,
                                              self._polynomials, fleet[2])
        if off.any():
            before = np.array([self._off.get(i, False) for i in block.ids])
            self.offdeck_events += int((np.diff(np.vstack([before[None, :], off]).astype(np.int8), axis=0) > 0).sum())
            self.offdeck_steps += int(off.sum())
        self._off = {block.ids[j]: bool(off[-1, j]) for j in range(q) if off[-1, j]} if k else self._off
        self.n_steps += k
        zeros = np.zeros((k, q))
        return BlockReport(block.ids, block.models, block.x, block.y, block.v, block.a, on, force, zeros, zeros,
                           values, np.zeros((k, q), dtype=bool), off, block.loads)


def daf(dynamic_peak: float, static_peak: float) -> float:
    """Dynamic amplification factor ``dynamic_peak / static_peak`` (NaN when the static peak is 0 or NaN)."""
    if not np.isfinite(static_peak) or static_peak <= 0.0:
        return float("nan")
    return float(dynamic_peak) / float(static_peak)


__all__ = ["InfluencePolynomials", "QuasiStaticResult", "STATIC_QUANTITIES", "column_weights", "daf", "influence",
           "influence_polynomials", "influence_vectors", "QuasiStaticSystem", "quasi_static", "static_block"]
