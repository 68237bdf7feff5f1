"""Traffic seen by the bridge: which vehicles are where, how fast, at a given time (docs/theory.md §6.10).

A :class:`TrafficSource` answers :meth:`TrafficSource.block` for the times of
a block of beam steps: the vehicles in the simulation with their contact point
``x`` (m, on the bridge axis), speed ``v`` and acceleration ``a`` along +x
(negative when driving towards x = 0), lateral offset ``y`` and model.
Vehicles that appear are put on the deck at static equilibrium; vehicles that
disappear are gone. Every source has one life cycle: :meth:`~TrafficSource.start`
before the first block, :meth:`~TrafficSource.close` after the last (or use it
as a context manager); a live traffic simulation holds a process and files in
between. :class:`ScriptedTraffic` is the source for runs without SUMO;
:class:`FrameTraffic` follows frames at a fixed step (SUMO's, or a log's),
and a live source hands every frame to the :class:`FrameSink` it was built
with (a log).
"""
from __future__ import annotations

import abc
import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple, Protocol

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .fields import AXLE_SEPARATOR, vehicle_of
from .jit import compiled
from .vehicles import VehicleModel, model_classes

#: A load record waits this long (s of traffic time) for its vehicle to come into a block, then is dropped.
LOAD_RECORD_WAIT = 60.0


def on_deck(x, length):  # noqa: ANN001, ANN201 - scalars or arrays; also compiled as is by cosim.core.kernels
    """The one rule for "on the deck": a contact point at ``0 <= x <= length`` (m) along the axis.

    Off the deck a vehicle rides on rigid ground and loads nothing. The block
    loop compiles this very function; traffic sources use it to decide which
    vehicles a block of steps carries.
    """
    return (x >= 0.0) & (x <= length)


@dataclass(frozen=True)
class TrafficFrame:
    """Vehicles present at one instant (parallel arrays, one entry per vehicle).

    Attributes:
        ids: vehicle identifiers.
        x: contact-point positions along the axis, m.
        v: speeds along +x, m/s.
        a: accelerations along +x, m/s^2.
        y: lateral offsets of the wheel paths, m.
        models: the vehicle model of each vehicle.
    """

    ids: tuple[str, ...]
    x: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    a: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    models: tuple[VehicleModel, ...]


@dataclass(frozen=True)
class LoadRecord:
    """What loaded the deck, one per vehicle, as the log records it at the vehicle's entry onto the deck
    (``/cosim/vehicle_loads``; docs/logs.md). SI units.

    Attributes:
        id: the vehicle (its contact points are ``id`` or ``id#k``).
        vehicle_class: its class: ``car``, ``truck-N`` (a truck of N axles, Grave's classes), a SUMO vClass, or
            the model's name for a scripted vehicle.
        lane: the lane it drove onto the deck on: SUMO's lane id, a WIM record's (BTLS) lane number; "" if none.
        speed: its speed at entry, m/s (filled in at entry when given as NaN).
        gvw: gross weight, N.
        axle_loads: each axle's static load, N, front first (they add up to ``gvw``).
        axle_spacings: each axle to the next, m (one fewer than the axles).
        y: its path's lateral offset on the deck, m (the lane's, plus ``wander``).
        wander: its lateral offset within its lane, m (0 without wander).
        source: where its loads came from (a WIM site model, "records: FILE", "vType params", "cosim default",
            "scripted").
    """

    id: str
    vehicle_class: str
    lane: str
    speed: float
    gvw: float
    axle_loads: tuple[float, ...]
    axle_spacings: tuple[float, ...]
    y: float
    wander: float
    source: str

    @property
    def n_axles(self) -> int:
        return len(self.axle_loads)

    @classmethod
    def of_model(cls, vehicle_id: str, model: VehicleModel, y: float, speed: float, gravity: float,
                 source: str = "scripted") -> LoadRecord:
        """The record of a vehicle whose loads are its model's: its static contact loads at ``gravity`` (m/s^2)
        and the spacings of its contact points, class the model's name."""
        loads = tuple(float(v) for v in model.static_axle_loads(gravity))
        behind = [p.behind for p in model.contact_points]
        return cls(id=vehicle_id, vehicle_class=model.kind, lane="", speed=float(speed), gvw=float(sum(loads)),
                   axle_loads=loads, axle_spacings=tuple(b - a for a, b in zip(behind, behind[1:])), y=float(y),
                   wander=0.0, source=source)


@dataclass(frozen=True)
class TrafficBlock:
    """Vehicles over K consecutive beam steps: one fleet, kinematics per step.

    Attributes:
        ids, models: the vehicles (q).
        x, v, a: arrays (K, q): contact point (m), speed and acceleration along +x.
            A vehicle whose x lies outside [0, L] at a step is off the deck then
            (on the approach road, rigid ground).
        y: lateral offsets (q,), m.
        loads: the :class:`LoadRecord` of each vehicle that comes onto the deck for the first time in the block.
        path: None (each contact point keeps ``y`` through the block), or (K, q, 5) its path at every step when
            the source follows paths (:meth:`TrafficSource.follow_paths`): y (m), the tangent d(x, y)/dx and its
            derivative d2(x, y)/dx2 (1/m), for a deck whose surface reads them (a deck given by its modes).
    """

    ids: tuple[str, ...]
    models: tuple[VehicleModel, ...]
    x: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    a: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    loads: tuple[LoadRecord, ...] = ()
    path: npt.NDArray[np.float64] | None = None

    @classmethod
    def from_frame(cls, frame: TrafficFrame) -> TrafficBlock:
        return cls(frame.ids, frame.models, frame.x[None, :], frame.v[None, :], frame.a[None, :], frame.y)

    def same_fleet(self, other: TrafficBlock) -> bool:
        """The same vehicles, models and lateral offsets (to the bit): the two blocks can be advanced as one."""
        return self.ids == other.ids and self.models == other.models and (
            self.y is other.y or np.array_equal(self.y, other.y)) and (self.path is None) == (other.path is None)

    @staticmethod
    def join(blocks: list[TrafficBlock]) -> TrafficBlock:
        """Consecutive blocks of one fleet (:meth:`same_fleet`) as one block of all their steps."""
        first = blocks[0]
        return TrafficBlock(first.ids, first.models, np.concatenate([b.x for b in blocks]),
                            np.concatenate([b.v for b in blocks]), np.concatenate([b.a for b in blocks]), first.y,
                            tuple(r for b in blocks for r in b.loads),
                            None if first.path is None else np.concatenate([b.path for b in blocks
                                                                            if b.path is not None]))


class TrafficSource(abc.ABC):
    """Anything that can say where the vehicles are at the times of a block of steps (s).

    Started before the first block and closed after the last, whatever happens in between (``with source:``):
    a live traffic simulation holds a process and scratch files until it is closed. Sources that hold
    nothing inherit the no-op :meth:`start` and :meth:`close`.
    """

    def start(self) -> TrafficSource:
        """Get ready for the first block; returns the source."""
        return self

    def close(self) -> None:  # noqa: B027 - a no-op by default, not abstract: most sources hold nothing
        """Release what the source holds (idempotent)."""

    def __enter__(self) -> TrafficSource:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @abc.abstractmethod
    def block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        """The vehicles on the deck at any of ``times`` (s, increasing), with their kinematics at each."""

    def follow_paths(self) -> None:  # noqa: B027 - a no-op by default: most sources' wheels keep their y
        """From now on, blocks carry each contact point's lateral path at every step (a deck given by its
        modes reads a curved lane's path: docs/theory.md §13.8). Sources whose vehicles keep their lateral
        offset (scripted vehicles, records) have nothing more to say and ignore it; sources of frames
        (:class:`FramedSource`) follow."""

    def quiet_until(self, t: float) -> float:
        """A time (s) such that no block of times after ``t`` and before it holds a vehicle: the run may step
        through that stretch with empty blocks without asking (a stream of records between two vehicles). The
        next block asked for then starts later than the one before ended. By default ``t``: nothing promised."""
        return t


class FramedSource(TrafficSource):
    """A source of vehicles sampled in frames (SUMO's steps, live or logged): between frames a wheel may change
    its lateral offset, so its blocks can carry each wheel's path (:attr:`TrafficBlock.path`) when asked."""

    #: Whether blocks carry each contact point's path at every step.
    follows_paths: bool = False

    def follow_paths(self) -> None:
        self.follows_paths = True


class FrameSink(Protocol):
    """Where a live traffic source sends what it produces (a log): every frame, with the vehicle models of the
    types that became known since the frame before (each type once, before any frame names it; the sink keeps
    what it needs of them), and its documents (the vehicle-type table at the start, the simulator's messages
    at the end)."""

    def __call__(self, frame: Frame, new_models: Mapping[str, VehicleModel]) -> None: ...

    def attach(self, name: str, data: bytes | str, media_type: str) -> None: ...


@dataclass(frozen=True)
class ScriptedVehicle:
    """A vehicle driven by a script.

    Args:
        id: name used in results.
        model: the vehicle model.
        y: lateral offset of the wheel path from the bridge axis, m.
        speed: constant speed, m/s (> 0), used when ``profile`` is empty.
        entry_time: time at which the contact point reaches the deck's start, s.
        direction: +1 drives along +x (enters at x = 0), -1 along -x (enters at x = L).
        profile: optional ((t, speed), ...) pairs, t relative to ``entry_time``;
            speed is linear between them and held after the last.
        load: what the log records of its loads at its entry (:class:`LoadRecord`), or None.
    """

    id: str
    model: VehicleModel
    y: float
    speed: float
    entry_time: float = 0.0
    direction: int = 1
    profile: tuple[tuple[float, float], ...] = ()
    load: LoadRecord | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.id, str) or not self.id:
            raise ConfigError(f"vehicle {self.id!r}: `id` must be a non-empty string")
        if not isinstance(self.model, VehicleModel):
            raise ConfigError(f"vehicle {self.id}: `model` must be one of the vehicle models "
                              f"({', '.join(c.__name__ for c in model_classes().values())}), "
                              f"got {type(self.model).__name__}")
        for key in ("y", "speed", "entry_time"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ConfigError(f"vehicle {self.id}: `{key}` must be a finite number (got {value!r})")
        if self.direction not in (1, -1):
            raise ConfigError(f"vehicle {self.id}: `direction` must be +1 or -1 (got {self.direction!r})")
        if not self.profile and not self.speed > 0:
            raise ConfigError(f"vehicle {self.id}: `speed` must be > 0 m/s (got {self.speed!r})")
        if self.entry_time < 0:
            raise ConfigError(f"vehicle {self.id}: `entry_time` must be >= 0 s (got {self.entry_time!r})")
        if self.profile:
            if not all(len(p) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                           and math.isfinite(v) for v in p) for p in self.profile):
                raise ConfigError(f"vehicle {self.id}: `profile` must be (t, speed) pairs of finite numbers")
            ts = [p[0] for p in self.profile]
            if ts[0] != 0.0 or any(b <= a for a, b in zip(ts, ts[1:])):
                raise ConfigError(f"vehicle {self.id}: `profile` times must start at 0 and increase")
            if any(p[1] < 0 for p in self.profile):
                raise ConfigError(f"vehicle {self.id}: `profile` speeds must be >= 0 m/s")

    def distance(self, tau: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distance travelled since entry, speed and acceleration at ``tau = t - entry_time``."""
        tau = np.asarray(tau, dtype=float)
        if not self.profile:
            return self.speed * tau, np.full_like(tau, self.speed), np.zeros_like(tau)
        ts = np.array([p[0] for p in self.profile])
        vs = np.array([p[1] for p in self.profile])
        acc = np.append(np.diff(vs) / np.diff(ts), 0.0)  # constant speed after the last point
        dist_at = np.concatenate([[0.0], np.cumsum((vs[:-1] + vs[1:]) / 2 * np.diff(ts))])
        k = np.clip(np.searchsorted(ts, tau, side="right") - 1, 0, len(ts) - 1)
        dt = tau - ts[k]
        before = tau < 0  # on the approach: the entry speed, held
        dist = np.where(before, vs[0] * tau, dist_at[k] + vs[k] * dt + 0.5 * acc[k] * dt**2)
        return dist, np.where(before, vs[0], vs[k] + acc[k] * dt), np.where(before, 0.0, acc[k])


@dataclass(frozen=True)
class ScriptedTraffic(TrafficSource):
    """Scripted vehicles on a bridge of length ``length`` m; each is present while on the deck."""

    vehicles: tuple[ScriptedVehicle, ...]
    length: float
    _ids: frozenset = field(init=False, repr=False, default=frozenset())

    def __post_init__(self) -> None:
        if isinstance(self.length, bool) or not isinstance(self.length, (int, float)) or \
                not (math.isfinite(self.length) and self.length > 0):
            raise ConfigError(f"`length` must be the bridge's length, a finite number > 0 m (got {self.length!r})")
        for v in self.vehicles:
            if not isinstance(v, ScriptedVehicle):
                raise ConfigError(f"`vehicles` must be ScriptedVehicle objects (got {type(v).__name__})")
        ids = [v.id for v in self.vehicles]
        repeated = sorted({i for i in ids if ids.count(i) > 1})
        if repeated:
            raise ConfigError(f"vehicle ids must be unique (got {', '.join(repeated)} more than once)")
        object.__setattr__(self, "_ids", frozenset(ids))

    def block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        """The vehicles on the deck at any of ``times`` (s), with their kinematics at each.

        A vehicle with several contact points (a :class:`~cosim.core.vehicles.HalfCar`'s axles) is
        one column per point, ``<id>#<k>``, each its distance behind the front one and its offset to
        the left of the path (the vehicle's own left: -y when it drives along -x); it is in the block,
        all points together, while any of them is on the deck.
        """
        times = np.asarray(times, dtype=float)
        block = self._axle_block(times) if any(veh.model.contacts > 1 for veh in self.vehicles) else \
            self._point_block(times)
        loads = self._entering(times)
        return replace(block, loads=loads) if loads else block

    def _entering(self, times: npt.NDArray[np.floating]) -> tuple[LoadRecord, ...]:
        """The load records of the vehicles whose front contact reaches the deck in the block: at an entry
        time in [t_k - dt, t_k) for one of its steps t_k (each time belongs to one step, blocks follow on)."""
        if len(times) < 2:
            return ()
        start = times[0] - (times[1] - times[0])
        return tuple(veh.load for veh in self.vehicles
                     if veh.load is not None and start <= veh.entry_time < times[-1])

    def _point_block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        """:meth:`block` for vehicles of one contact point each."""
        n = len(self.vehicles)
        s = np.empty((len(times), n))
        v = np.empty_like(s)
        a = np.empty_like(s)
        for j, veh in enumerate(self.vehicles):
            s[:, j], v[:, j], a[:, j] = veh.distance(times - veh.entry_time)
        entered = times[:, None] >= np.array([veh.entry_time for veh in self.vehicles])[None, :]
        s = np.where(entered, s, np.minimum(s, -1e-9))  # not yet entered: still before the deck
        x_all = np.where(np.array([veh.direction for veh in self.vehicles]) > 0, s, self.length - s)
        on = entered & on_deck(x_all, self.length)
        present = np.flatnonzero(on.any(axis=0))
        direction = np.array([self.vehicles[j].direction for j in present], dtype=float)
        s, v, a = s[:, present], v[:, present], a[:, present]
        x = np.where(direction > 0, s, self.length - s)
        return TrafficBlock(
            ids=tuple(self.vehicles[j].id for j in present),
            models=tuple(self.vehicles[j].model for j in present),
            x=x, v=direction * v, a=direction * a,
            y=np.array([self.vehicles[j].y for j in present], dtype=float),
        )

    def _axle_block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        """:meth:`block` with a column per contact point (models with several)."""
        ids: list[str] = []
        models: list[VehicleModel] = []
        xs, vs, accs, ys = [], [], [], []
        for veh in self.vehicles:
            dist, speed, acc = veh.distance(times - veh.entry_time)
            entered = times >= veh.entry_time
            points = veh.model.contact_points
            cols = []
            for point in points:  # contact k is `behind` the front one
                s = np.where(entered, dist - point.behind, np.minimum(dist - point.behind, -1e-9))
                cols.append(s if veh.direction > 0 else self.length - s)
            x_axles = np.stack(cols, axis=1)
            if not on_deck(x_axles, self.length).any():
                continue
            n = len(points)
            ids += [f"{veh.id}{AXLE_SEPARATOR}{k}" for k in range(n)] if n > 1 else [veh.id]
            models += [veh.model] * n
            xs.append(x_axles)
            vs.append(np.repeat((veh.direction * speed)[:, None], n, axis=1))
            accs.append(np.repeat((veh.direction * acc)[:, None], n, axis=1))
            ys += [veh.y + veh.direction * p.left if p.left else veh.y for p in points]
        k = len(times)
        stack = (lambda parts: np.concatenate(parts, axis=1)) if xs else (lambda parts: np.zeros((k, 0)))
        return TrafficBlock(tuple(ids), tuple(models), stack(xs), stack(vs), stack(accs), np.array(ys, dtype=float))

    def frame(self, t: float) -> TrafficFrame:
        """The vehicles on the deck at time ``t`` (s)."""
        b = self.block(np.array([t]))
        on = on_deck(b.x[0], self.length)
        keep = np.flatnonzero(on)
        return TrafficFrame(
            ids=tuple(b.ids[j] for j in keep), x=b.x[0, keep], v=b.v[0, keep], a=b.a[0, keep], y=b.y[keep],
            models=tuple(b.models[j] for j in keep),
        )

    def end_time(self) -> float:
        """Time when the last vehicle (its last axle) leaves the deck, s (inf if one stops on it)."""
        latest = 0.0
        for veh in self.vehicles:
            travel = self.length + max(veh.model.contact_offsets)  # the front axle's way until the last leaves
            if not veh.profile:
                latest = max(latest, veh.entry_time + travel / veh.speed)
                continue
            if veh.profile[-1][1] <= 0:
                return float("inf")
            t_last, _ = veh.profile[-1]
            s_last, _, _ = veh.distance(t_last)
            remaining = max(travel - float(s_last), 0.0)
            latest = max(latest, veh.entry_time + t_last + remaining / veh.profile[-1][1])
        return latest


class Frame(NamedTuple):
    """Vehicles near the deck at one traffic-simulation step (bridge coordinates).

    A named tuple, not a frozen dataclass: one is made per SUMO step on each side of a process boundary, and a
    frozen dataclass of eight fields cost 4.4 us to make, this 1.2 us (by keywords).

    Attributes:
        t: time, s (simulation time of the co-simulation, from 0).
        ids: vehicle ids; x (m, contact point along the axis), y (m), v, a (along +x).
        types: the vehicle type of each vehicle (key into the model table).
        loads: the :class:`LoadRecord` of each vehicle that came onto the deck since the frame before.
    """

    t: float
    ids: tuple[str, ...]
    x: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    a: npt.NDArray[np.float64]
    types: tuple[str, ...]
    loads: tuple[LoadRecord, ...] = ()


def pack_frames(frames: list[Any]) -> tuple[Any, ...]:
    """Frames as a few flat columns, to send to another process: pickling each frame's four small arrays cost
    the run's thread more than all its blocks (0.19 s of 0.28 s in 10 min of the default run)."""
    if not frames:
        return ()
    return ([f.t for f in frames], [len(f.ids) for f in frames],
            tuple(itertools.chain.from_iterable(f.ids for f in frames)),
            tuple(itertools.chain.from_iterable(f.types for f in frames)),
            *(np.concatenate([getattr(f, c) for f in frames]) for c in ("x", "y", "v", "a")),
            {k: f.loads for k, f in enumerate(frames) if f.loads})


def unpack_frames(packed: tuple[Any, ...]) -> list[Any]:
    """The frames of :func:`pack_frames`, equal to those packed (the same numbers, bit for bit)."""
    if not packed:
        return []
    times, counts, ids, types, x, y, v, a, loads = packed
    out = []
    start = 0
    for k, (t, n) in enumerate(zip(times, counts)):
        end = start + n
        out.append(Frame(t=t, ids=ids[start:end], x=x[start:end], y=y[start:end], v=v[start:end], a=a[start:end],
                         types=types[start:end], loads=loads.get(k, ())))
        start = end
    return out


class FrameTraffic(FramedSource):
    """Traffic given as frames at a fixed step (from SUMO, or replayed from a log).

    Between two frames a vehicle moves with constant acceleration, as SUMO's
    ballistic position update does: from frame k, ``x = x_k + v_k tau + a tau^2 / 2``
    with ``a = (v_{k+1} - v_k) / step``, plus a linear correction that closes
    any gap to ``x_{k+1}`` (a vehicle that stopped within the step), so the path
    passes through every frame. A vehicle first seen at frame k+1 is traced
    back along that same motion; one missing from frame k+1 (it left the
    watched edges, arrived or was teleported) is gone for that step.

    Args:
        step: time between frames, s.
        length: bridge length, m.
        models: vehicle type -> vehicle model, those known at the start (more come with
            :meth:`add_models` or :meth:`add_frame`); the source keeps its own table.
    """

    def __init__(self, step: float, length: float, models: Mapping[str, VehicleModel] | None = None) -> None:
        if not step > 0:
            raise ConfigError(f"traffic `step` must be > 0 s (got {step})")
        self.step = float(step)
        self.length = float(length)
        self._models: dict[str, VehicleModel] = dict(models or {})
        self.frames: list[Frame] = [Frame(0.0, (), *(np.zeros(0),) * 4, ())]
        self._first = 0  # index in self.frames of frames[0]; older frames are dropped
        self._loads: dict[str, tuple[LoadRecord, float]] = {}  # vehicle -> its record and its frame's time

    def add_models(self, models: Mapping[str, VehicleModel]) -> None:
        """Vehicle types (type -> model) that frames may name from now on."""
        self._models.update(models)

    def add_load_record(self, record: LoadRecord, t: float) -> None:
        """A vehicle's load record (known at time ``t``, s), to go with the first block that carries it."""
        self._loads[record.id] = (record, float(t))

    def add_frame(self, frame: Frame, new_models: Mapping[str, VehicleModel] | None = None) -> None:
        """Append the next frame (its time one ``step`` after the last), and the vehicle types that became known
        with it (``new_models``: type -> model)."""
        expected = self.frames[-1].t + self.step
        if abs(frame.t - expected) > 1e-6 * self.step:
            raise ConfigError(f"traffic frames must be {self.step} s apart (got t = {frame.t}, expected {expected})")
        own = self._models
        if new_models:
            own.update(new_models)
        for typ in frame.types:
            if typ not in own:
                raise ConfigError(f"no vehicle model for vehicle type {typ!r}")
        for record in frame.loads:
            self._loads[record.id] = (record, frame.t)
        self.frames.append(frame)

    @property
    def last_time(self) -> float:
        return self.frames[-1].t

    def _frame_at(self, k: int) -> Frame:
        return self.frames[k - self._first]

    def forget_before(self, t: float) -> None:
        """Drop frames no longer needed for times after ``t`` (constant memory in long runs)."""
        k_keep = int(np.floor(t / self.step + 1e-9)) - 1
        drop = min(k_keep - self._first, len(self.frames) - 2)
        if drop > 0:
            del self.frames[:drop]
            self._first += drop
        if self._loads:  # a record whose vehicle never came into a block (it never reached the deck's steps)
            stale = t - LOAD_RECORD_WAIT
            self._loads = {k: v for k, v in self._loads.items() if v[1] >= stale}

    def block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        times = np.asarray(times, dtype=float)
        if times[-1] > self.last_time + 1e-9:
            raise ConfigError(f"no traffic frames after t = {self.last_time} s (asked for {times[-1]} s)")
        # Interval k covers (t_k, t_{k+1}]; a time on a frame belongs to the interval ending there.
        k_of = np.ceil(times / self.step - 1e-9).astype(np.int64) - 1
        k_of = np.maximum(k_of, self._first)
        k_lo, k_hi = int(k_of.min()), int(k_of.max())
        frames = [self._frame_at(k) for k in range(k_lo, k_hi + 2)]  # frames k_lo .. k_hi + 1
        # One column per vehicle seen in any frame of the block; rows = frames. Filled in one scatter per
        # column, not one per frame: a block holds tens of frames of a few vehicles each.
        index: dict[str, int] = {}
        type_of: dict[int, str] = {}
        frame_of: list[int] = []
        column_of: list[int] = []
        for r, f in enumerate(frames):
            for vid, typ in zip(f.ids, f.types):
                c = index.setdefault(vid, len(index))
                type_of[c] = typ
                frame_of.append(r)
                column_of.append(c)
        q_all = len(index)
        n_f = len(frames)
        FX = np.zeros((n_f, q_all))
        FV = np.zeros((n_f, q_all))
        FA = np.zeros((n_f, q_all))
        FY = np.zeros((n_f, q_all))
        seen = np.zeros((n_f, q_all), dtype=bool)
        if frame_of:
            at = (np.array(frame_of), np.array(column_of))
            FX[at], FV[at], FA[at], FY[at] = (np.concatenate([getattr(f, c) for f in frames]) for c in "xvay")
            seen[at] = True
        r_of = k_of - k_lo
        frame_t = np.array([f.t for f in frames])
        X, V, A, present = _ballistic_between_frames(FX, FV, FA, seen, frame_t, times, r_of, self.step)
        on = present & on_deck(X, self.length)
        ids = list(index)
        wanted = on.any(axis=0)
        models = self._models
        if any(models[type_of[c]].contacts > 1 for c in np.flatnonzero(wanted).tolist()):
            wanted = self._whole_vehicles(ids, wanted)
        keep = np.flatnonzero(wanted)
        loads = self._records_of([ids[c] for c in keep.tolist()]) if self._loads else ()
        X, V, A = X[:, keep], V[:, keep], A[:, keep]
        # One lateral offset per block: where the contact point was at its last frame in the block on the deck's
        # length (a vehicle turning off the deck at its end keeps the lane it had on it), else at its last frame.
        rows = present[:, keep]
        on_kept = on[:, keep]
        rows = np.where(on_kept.any(axis=0), on_kept, rows)
        last = rows.shape[0] - 1 - np.argmax(rows[::-1], axis=0)
        Y = FY[1:][r_of][last, keep] if len(keep) else np.zeros(0)
        path = None
        if self.follows_paths:
            before = self._frame_at(k_lo - 1) if k_lo - 1 >= self._first else None
            path = lateral_paths(FX[:, keep], FY[:, keep], seen[:, keep], np.ascontiguousarray(X), r_of,
                                 *_frame_before(before, ids, keep))
        return TrafficBlock(
            tuple(ids[c] for c in keep.tolist()), tuple(models[type_of[c]] for c in keep.tolist()),
            np.ascontiguousarray(X), np.ascontiguousarray(V), np.ascontiguousarray(A), Y, loads, path,
        )

    def _records_of(self, contact_ids: list[str]) -> tuple[LoadRecord, ...]:
        """The waiting load records of the vehicles these contact points belong to, taken (each once)."""
        out = []
        for owner in dict.fromkeys(vehicle_of(c) for c in contact_ids):
            entry = self._loads.pop(owner, None)
            if entry is not None:
                out.append(entry[0])
        return tuple(out)

    @staticmethod
    def _whole_vehicles(ids: list[str], wanted: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """All axle columns (``veh#k``) of a vehicle when any of them is wanted: one body on several contacts
        loads the deck through all its axles, those still on the approach included (on rigid ground)."""
        owners = [vehicle_of(i) for i in ids]
        chosen = {o for o, w in zip(owners, wanted.tolist()) if w}
        return np.array([o in chosen for o in owners], dtype=bool)


def _frame_before(frame: Frame | None, ids: list[str], keep: npt.NDArray[np.int64]
                  ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    """x, y and presence of the kept contact points in the frame before the block's first (for the first
    interval's quadratic)."""
    q = len(keep)
    x, y, seen = np.zeros(q), np.zeros(q), np.zeros(q, dtype=bool)
    if frame is not None and q:
        where = {vid: i for i, vid in enumerate(frame.ids)}
        for j, c in enumerate(keep.tolist()):
            i = where.get(ids[c])
            if i is not None:
                x[j], y[j], seen[j] = frame.x[i], frame.y[i], True
    return x, y, seen


@compiled(nogil=True)
def lateral_paths(FX: np.ndarray, FY: np.ndarray, seen: np.ndarray, X: np.ndarray, r_of: np.ndarray,
                  x_before: np.ndarray, y_before: np.ndarray, seen_before: np.ndarray) -> np.ndarray:
    """Each contact point's path at every step, (K, q, 5): y, 1, dy/dx, 0, d2y/dx2 (docs/theory.md §13.8).

    Between frames r and r + 1 the lateral offset is the quadratic in x through the frames r - 1, r and r + 1
    (the frame before the block for r = 0): exact on a parabola, O(h^3) times the lane's third derivative on any
    smooth lane, h the distance driven in a frame; a straight lane gives its y and zero slope and curvature
    exactly. Without a frame r - 1 (the vehicle just appeared) the path is the straight line through r and
    r + 1; without r + 1 (it left) it keeps frame r's y."""
    K, q = X.shape
    out = np.zeros((K, q, 5))
    for k in range(K):
        r = r_of[k]
        for j in range(q):
            out[k, j, 1] = 1.0
            if not seen[r, j]:
                out[k, j, 0] = FY[r + 1, j] if seen[r + 1, j] else 0.0
                continue
            x0, y0 = FX[r, j], FY[r, j]
            if not seen[r + 1, j] or FX[r + 1, j] == x0:
                out[k, j, 0] = y0
                continue
            x1, y1 = FX[r + 1, j], FY[r + 1, j]
            s1 = (y1 - y0) / (x1 - x0)
            if r > 0:
                has_m, xm, ym = seen[r - 1, j], FX[r - 1, j], FY[r - 1, j]
            else:
                has_m, xm, ym = seen_before[j], x_before[j], y_before[j]
            curv = 0.0
            if has_m and xm != x0 and xm != x1:
                sm = (y0 - ym) / (x0 - xm)
                curv = 2.0 * (s1 - sm) / (x1 - xm)  # the quadratic's second derivative
            xx = X[k, j]
            out[k, j, 0] = y0 + (xx - x0) * (s1 + 0.5 * curv * (xx - x1))
            out[k, j, 2] = s1 + 0.5 * curv * (2.0 * xx - x0 - x1)
            out[k, j, 4] = curv
    return out


@compiled(nogil=True)
def _ballistic_between_frames(FX: np.ndarray, FV: np.ndarray, FA: np.ndarray, seen: np.ndarray, frame_t: np.ndarray,
                              times: np.ndarray, r_of: np.ndarray, step: float
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Position, speed and acceleration (steps, vehicles) at ``times`` from the frames (rows; step ``r_of[k]``
    lies between frames r and r + 1), as :class:`FrameTraffic` describes; a vehicle absent from frame r + 1 is
    far before the deck (x = -1e6, at rest) and not ``present``. Compiled: as numpy array operations these
    were three dozen passes over small arrays per block, in the thread that runs SUMO. The expressions keep
    numpy's order of operations, so the numbers are the same to the bit."""
    steps, q = len(times), FX.shape[1]
    # The motion over each interval (frame r to r + 1), once per interval: a block has tens of steps in each.
    intervals = FX.shape[0] - 1
    v0s, x0s = np.empty((intervals, q)), np.empty((intervals, q))
    accs, gaps = np.empty((intervals, q)), np.empty((intervals, q))
    for r in range(intervals):
        for j in range(q):
            v1, a1, x1 = FV[r + 1, j], FA[r + 1, j], FX[r + 1, j]
            if seen[r, j]:
                v0, x0 = FV[r, j], FX[r, j]
            else:  # first seen at frame r + 1: traced back along the same motion
                v0 = v1 - a1 * step
                x0 = x1 - step * 0.5 * (v0 + v1)
            v0s[r, j], x0s[r, j] = v0, x0
            accs[r, j] = (v1 - v0) / step
            gaps[r, j] = x1 - (x0 + step * 0.5 * (v0 + v1))  # zero when the frames follow the ballistic rule
    X = np.empty((steps, q))
    V = np.empty((steps, q))
    A = np.empty((steps, q))
    present = np.empty((steps, q), dtype=np.bool_)
    for k in range(steps):
        r = r_of[k]
        tau = times[k] - frame_t[r]
        for j in range(q):
            if not seen[r + 1, j]:
                X[k, j], V[k, j], A[k, j], present[k, j] = -1e6, 0.0, 0.0, False
                continue
            v0, x0, acc, gap = v0s[r, j], x0s[r, j], accs[r, j], gaps[r, j]
            X[k, j] = x0 + v0 * tau + 0.5 * acc * (tau * tau) + gap * tau / step
            V[k, j] = v0 + acc * tau + gap / step
            A[k, j] = acc
            present[k, j] = True
    return X, V, A, present
