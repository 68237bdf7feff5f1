"""WIM records as traffic: each record drives over the deck at its recorded time, lane and speed, with its
recorded axles (docs/loads.md#records-as-traffic).

The exact replay of a measured day (or year) without SUMO. A record's time is
when its first axle reaches the deck's entry end (x = 0 for a lane driven
along ``+x``, x = L along ``-x``: BTLS's time datum), in seconds from midnight
of the file's first day; the run's t = 0 is ``begin`` of that clock. Lanes
are BTLS's lane numbers (direction 1's lanes, then direction 2's from the far
side: :func:`cosim.core.loads.btls_lane`), each mapped to a wheel path (its
``y`` on the deck) and a direction of travel on the bridge by the lanes table
(:class:`RecordLane`). A record has no id of its own: its vehicle is
``"<file stem>:<line>"``.

Each vehicle is one contact column per axle (``<id>#k``, front first, each
its spacing behind the one before), each with its own one-contact model
carrying that axle's load (moving forces by default; the run may give
quarter-cars). The file is streamed: only the vehicles on the deck, and the
next record, are held, so a year of records runs in constant memory, and a
block of steps with no vehicle within reach costs a comparison.

:func:`check_records` reads the whole file once before a run (every line
checked, the lanes mapped by the table, times never going backwards) and
says what the run's window holds: a bad record is one :class:`ConfigError`
naming the file and the line before anything is written.

Part of the numerical core: numpy, the standard library and the core's own
loads, traffic and vehicle models only.
"""
from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .loads import RecordsSummary, VehicleRecord, btls_lane, lane_wander, read_records, survey
from .loads.draws import G
from .traffic import AXLE_SEPARATOR, LoadRecord, TrafficBlock, TrafficSource
from .vehicles import MovingForce, VehicleModel

__all__ = ["LIGHT_WEIGHT", "RecordLane", "RecordTraffic", "RecordsCheck", "check_records", "moving_forces",
           "record_class", "record_id_prefix"]

#: Gross weight below which a record is a light vehicle (``car``), N: 3500 kg, the largest gross mass of a
#: category B licence's vehicle (Directive 2006/126/EC Art. 4(4)) and of category N1 (Regulation (EU)
#: 2018/858); heavier records are ``truck-N`` (N its axles).
LIGHT_WEIGHT = 3500.0 * G


@dataclass(frozen=True)
class RecordLane:
    """One lane of a record file on the deck.

    Attributes:
        lane: BTLS's lane number (from 1; a file's direction 2 / lane 1 is lane 2 with one lane each way).
        y: the lateral offset of its wheel path on the deck, m (the lane's centre line).
        direction: +1: its vehicles drive along +x (enter at x = 0); -1: along -x (enter at x = L).
    """

    lane: int
    y: float
    direction: int

    def __post_init__(self) -> None:
        if isinstance(self.lane, bool) or not isinstance(self.lane, int) or self.lane < 1:
            raise ConfigError(f"`lane` must be an integer >= 1 (got {self.lane!r})")
        if isinstance(self.y, bool) or not isinstance(self.y, (int, float)) or not math.isfinite(self.y):
            raise ConfigError(f"lane {self.lane}: `y` must be a finite number (got {self.y!r})")
        if self.direction not in (1, -1):
            raise ConfigError(f"lane {self.lane}: `direction` must be +1 or -1 (got {self.direction!r})")


def record_class(record: VehicleRecord) -> str:
    """The record's class as logs give it: ``car`` below :data:`LIGHT_WEIGHT`, else ``truck-N`` (N axles)."""
    return "car" if record.gross_weight < LIGHT_WEIGHT else f"truck-{record.axle_count}"


def moving_forces(record: VehicleRecord) -> tuple[VehicleModel, ...]:
    """One moving force per axle, each of its axle's load (mass = load / 9.81 m/s^2, the records' gravity)."""
    return tuple(_moving_force(w) for w in record.axle_loads)


@functools.lru_cache(maxsize=4096)
def _moving_force(load: float) -> MovingForce:
    """The moving force of an axle load, N (the formats' loads are whole units: a few hundred values)."""
    return MovingForce(load / G)


def record_id_prefix(path: str | Path) -> str:
    """What a file's vehicles are called before ``:<line>``: its name without ``.gz`` and one suffix (letters,
    digits, ``_``, ``.`` and ``-`` kept, anything else ``_``)."""
    name = Path(path).name
    if name.lower().endswith(".gz"):
        name = name[:-3]
    stem = Path(name).stem or name
    return re.sub(r"[^A-Za-z0-9_.-]", "_", stem) or "records"


@dataclass(frozen=True)
class RecordsCheck:
    """What :func:`check_records` found: the whole file checked, and the run's window.

    Attributes:
        path, format: the file and its format.
        summary: the whole file (:func:`cosim.core.loads.survey`): lanes per direction, count, first day.
        begin, end: the window, s from midnight of the file's first day (records ``begin <= time < end``).
        count: records in the window; per_lane: (BTLS lane, records) in the window, by lane.
        first, last: the window's first and last record times, s from midnight (NaN without records).
        leave: when the window's last vehicle has left the deck (its last axle past the far end), s of run
            time (from ``begin``); 0 without records.
        heaviest: the largest gross weight in the window, N (0 without records).
    """

    path: Path
    format: str
    summary: RecordsSummary
    begin: float
    end: float
    count: int
    per_lane: tuple[tuple[int, int], ...]
    first: float
    last: float
    leave: float
    heaviest: float

    @property
    def lanes_per_direction(self) -> tuple[int, int]:
        return self.summary.lanes_per_direction


def check_records(path: str | Path, format: str, lanes: Sequence[RecordLane], length: float, begin: float = 0.0,
                  end: float = math.inf, key: str = "lanes") -> RecordsCheck:
    """Read and check the whole file once (every line, in constant memory) for a run of its records in
    ``[begin, end)`` on a deck ``length`` m long.

    Args:
        lanes: the lanes table; every lane a record of the window drives on must be in it.
        key: how messages name the lanes table (a scenario's ``traffic.records.lanes``).

    Raises:
        ConfigError: the first bad line, naming the file and the line (a record the file's format refuses,
            times going backwards, a lane the table does not map); an empty file.
    """
    path = Path(path)
    by_lane = _lane_table(lanes, key)
    pairs: dict[tuple[int, int], list[int]] = {}  # (direction, local lane) -> [first line, records] in the window
    state = {"count": 0, "first": math.nan, "last": math.nan, "leave": 0.0, "heaviest": 0.0}

    def visit(record: VehicleRecord) -> None:
        if not begin <= record.time < end:
            return
        entry = pairs.setdefault((record.direction, record.local_lane), [record.line, 0])
        entry[1] += 1
        if state["count"] == 0:
            state["first"] = record.time
        state["count"] += 1
        state["last"] = record.time
        # The front axle enters at its time; the last one leaves L + wheelbase later.
        travel = (length + math.fsum(record.axle_spacings)) / record.speed
        state["leave"] = max(state["leave"], record.time - begin + travel)
        state["heaviest"] = max(state["heaviest"], record.gross_weight)

    summary = survey(path, format, visit)
    counts = summary.lanes_per_direction
    per_lane: dict[int, int] = {}
    unmapped = []
    for (direction, local), (line, n) in pairs.items():
        lane = btls_lane(direction, local, counts)
        per_lane[lane] = per_lane.get(lane, 0) + n
        if lane not in by_lane:
            unmapped.append((line, direction, local, lane))
    if unmapped:
        line, direction, local, lane = min(unmapped)
        raise ConfigError(
            f"{path}: line {line}: direction {direction} / lane {local} is lane {lane} as BTLS numbers them "
            f"({counts[0]} lane(s) in direction 1, {counts[1]} in direction 2), which {key} does not map "
            f"(it maps lane(s) {', '.join(str(k) for k in sorted(by_lane))}); add {{lane = {lane}, y = ..., "
            "direction = ...} to it")
    return RecordsCheck(path, str(format), summary, float(begin), float(end), int(state["count"]),
                        tuple(sorted(per_lane.items())), state["first"], state["last"], state["leave"],
                        state["heaviest"])


def _lane_table(lanes: Sequence[RecordLane], key: str) -> dict[int, RecordLane]:
    table: dict[int, RecordLane] = {}
    for lane in lanes:
        if not isinstance(lane, RecordLane):
            raise ConfigError(f"{key}: expected RecordLane objects (got {type(lane).__name__})")
        if lane.lane in table:
            raise ConfigError(f"{key}: lane {lane.lane} is given twice; give each of the file's lanes once")
        table[lane.lane] = lane
    if not table:
        raise ConfigError(f"{key}: no lanes; map each of the file's lanes to a wheel path y and a direction")
    return table


class _Vehicle:
    """A record on its way over the deck: its columns' numbers, held while it can load the deck."""

    __slots__ = ("id", "t0", "leave", "speed", "direction", "behind", "models", "columns", "y", "load", "logged")

    def __init__(self, vid: str, t0: float, speed: float, direction: int, spacings: Sequence[float],
                 models: tuple[VehicleModel, ...], y: float, load: LoadRecord, length: float) -> None:
        self.id = vid
        self.t0 = t0
        self.speed = speed
        self.direction = direction
        behind = [0.0]
        for s in spacings:
            behind.append(behind[-1] + s)
        self.behind = behind
        self.leave = t0 + (length + behind[-1]) / speed  # the last axle at the far end
        self.models = models
        n = len(models)
        self.columns = tuple(f"{vid}{AXLE_SEPARATOR}{k}" for k in range(n)) if n > 1 else (vid,)
        self.y = y
        self.load = load
        self.logged = False


@dataclass
class _Fleet:
    """The columns of the vehicles of a block (reused while the same vehicles are in the blocks)."""

    vehicles: tuple[_Vehicle, ...]
    ids: tuple[str, ...]
    models: tuple[VehicleModel, ...]
    y: npt.NDArray[np.float64]
    t0: npt.NDArray[np.float64]
    along: npt.NDArray[np.float64]  # signed speed along +x per column
    speed: npt.NDArray[np.float64]
    behind: npt.NDArray[np.float64]
    forward: npt.NDArray[np.bool_]


class RecordTraffic(TrafficSource):
    """A WIM record file as scripted traffic on a deck ``length`` m long (the module's docstring).

    Args:
        path, format: the record file (plain or gzip) and its format (``castor``, ``bedit``, ``ditis``, ``mon``).
        lanes: the lanes table: each BTLS lane the records drive on, its wheel path and direction.
        length: the deck's length, m.
        begin, end: the records run, s from midnight of the file's first day: ``begin <= time < end``; the
            run's t = 0 is ``begin``.
        lanes_per_direction: the file's lane counts for BTLS's numbering (:func:`check_records` found them);
            None: surveyed when started.
        models: each record's axle models, one one-contact model per axle, front first (default
            :func:`moving_forces`).
        wander: each vehicle's offset within its lane: ``"none"``, ``"en1991-2"`` or a normal's sd, m
            (:func:`cosim.core.loads.lane_wander`), drawn from ``seed`` and its id.
        seed: the wander's seed.
    """

    def __init__(self, path: str | Path, format: str, lanes: Sequence[RecordLane], length: float, *,
                 begin: float = 0.0, end: float = math.inf, lanes_per_direction: tuple[int, int] | None = None,
                 models: Callable[[VehicleRecord], tuple[VehicleModel, ...]] | None = None,
                 wander: str | float = "none", seed: int = 0) -> None:
        if isinstance(length, bool) or not isinstance(length, (int, float)) or not (
                math.isfinite(length) and length > 0):
            raise ConfigError(f"`length` must be the bridge's length, a finite number > 0 m (got {length!r})")
        if not (math.isfinite(begin) and begin >= 0.0) or not end > begin:
            raise ConfigError(f"`begin` must be >= 0 s and `end` after it (got {begin!r}, {end!r})")
        self.path = Path(path)
        self.format = str(format)
        self.length = float(length)
        self.begin, self.end = float(begin), float(end)
        self.lanes: Mapping[int, RecordLane] = _lane_table(lanes, "lanes")
        self.lanes_per_direction = lanes_per_direction
        self.models = models or moving_forces
        self.wander, self.seed = wander, seed
        self.prefix = record_id_prefix(self.path)
        self.source = f"records: {self.path.name}"
        self.read = 0  # records of the window read so far
        self._records: Iterator[VehicleRecord] | None = None
        self._next: VehicleRecord | None = None
        self._active: list[_Vehicle] = []
        self._fleet: _Fleet | None = None
        self._empty: dict[int, TrafficBlock] = {}
        self._spans: tuple[np.ndarray, np.ndarray] | None = None  # the active vehicles' entry and leaving times
        self._started = False

    # ------------------------------------------------------------- lifecycle
    def start(self) -> RecordTraffic:
        """Open the file (survey it first when the lane counts were not given)."""
        self.close()
        counts = self.lanes_per_direction or survey(self.path, self.format).lanes_per_direction
        self.lanes_per_direction = counts
        self._records = read_records(self.path, self.format, counts)
        self._next = None
        self._active, self._fleet, self._spans, self.read = [], None, None, 0
        self._started = True
        self._advance()
        return self

    def close(self) -> None:
        records, self._records = self._records, None
        if records is not None and hasattr(records, "close"):
            records.close()  # the generator's file
        self._next = None

    # --------------------------------------------------------------- records
    def _advance(self) -> None:
        """The next record of the window, or None when there is none (the file is closed then)."""
        records = self._records
        if records is None:
            self._next = None
            return
        for record in records:
            if record.time < self.begin:
                continue
            if record.time >= self.end:
                break
            self._next = record
            return
        self.close()

    def _admit(self, until: float) -> None:
        """Every record whose front axle enters by ``until`` (s of run time) on its way over the deck."""
        while self._next is not None and self._next.time - self.begin <= until:
            self._active.append(self._vehicle(self._next))
            self._spans = None
            self.read += 1
            self._advance()

    def _vehicle(self, record: VehicleRecord) -> _Vehicle:
        lane = self.lanes.get(record.lane)
        if lane is None:
            raise ConfigError(f"{self.path}: line {record.line}: lane {record.lane} (direction {record.direction} / "
                              f"lane {record.local_lane} as BTLS numbers them) is not in the lanes table; map it")
        vid = f"{self.prefix}:{record.line}"
        models = tuple(self.models(record))
        if len(models) != record.axle_count or any(m.contacts != 1 for m in models):
            raise ConfigError(f"{self.path}: line {record.line}: the axle models must be one one-contact model per "
                              f"axle ({record.axle_count}; got {len(models)})")
        offset = lane_wander(self.seed, vid, self.wander) if self.wander != "none" else 0.0
        y = lane.y + lane.direction * offset  # the wander is to the vehicle's own left
        load = LoadRecord(id=vid, vehicle_class=record_class(record), lane=str(record.lane), speed=record.speed,
                          gvw=record.gross_weight, axle_loads=record.axle_loads, axle_spacings=record.axle_spacings,
                          y=y, wander=offset, source=self.source)
        return _Vehicle(vid, record.time - self.begin, record.speed, lane.direction, record.axle_spacings, models, y,
                        load, self.length)

    @property
    def next_entry(self) -> float:
        """When the next record not yet on its way enters the deck, s of run time (inf: none left)."""
        return math.inf if self._next is None else self._next.time - self.begin

    # --------------------------------------------------------------- blocks
    def quiet_until(self, t: float) -> float:
        """With no vehicle on its way over the deck after ``t`` (s): the next record's entry (inf: none left)."""
        if self._active and max(v.leave for v in self._active) >= t:
            return t
        return self.next_entry

    def block(self, times: npt.NDArray[np.floating]) -> TrafficBlock:
        """The vehicles with an axle on the deck at any of ``times`` (s, increasing), their kinematics at each.

        A block with no vehicle within reach costs a comparison (the next record's entry after the block's last
        step, none on the deck before its first)."""
        times = np.asarray(times, dtype=float)
        k = len(times)
        first, last = float(times[0]), float(times[-1])
        if not self._started:  # asked without start(): the file is opened now (and closed by close())
            self.start()
        if self._next is not None and self._next.time - self.begin <= last:
            self._admit(last)
        active = self._active
        if not active:
            return self._empty_block(k)
        if self._spans is None or len(self._spans[0]) != len(active):
            self._spans = (np.fromiter((v.t0 for v in active), float, len(active)),
                           np.fromiter((v.leave for v in active), float, len(active)))
        t0, leave = self._spans
        if leave.min() < first:  # gone before this block: forgotten
            keep = leave >= first
            active = self._active = [v for v, kept in zip(active, keep.tolist()) if kept]
            self._spans = (t0[keep], leave[keep])
            t0, leave = self._spans
            if not active:
                return self._empty_block(k)
        # A vehicle is in the block when one of its steps falls between its entry and its leaving.
        at = np.searchsorted(times, t0, side="left")
        inside = at < k
        inside[inside] &= times[at[inside]] <= leave[inside]
        if inside.all():
            chosen = tuple(active)
        else:
            chosen = tuple(v for v, kept in zip(active, inside.tolist()) if kept)
            if not chosen:
                return self._empty_block(k)
        fleet = self._fleet
        if fleet is None or fleet.vehicles != chosen:
            fleet = self._fleet = _fleet(chosen)
        tau = times[:, None] - fleet.t0[None, :]
        s = fleet.speed[None, :] * tau - fleet.behind[None, :]  # each axle's way past the entry end
        x = np.where(fleet.forward[None, :], s, self.length - s)
        v = np.repeat(fleet.along[None, :], k, axis=0)
        loads = []
        for vehicle in chosen:
            if not vehicle.logged:
                vehicle.logged = True
                loads.append(vehicle.load)
        return TrafficBlock(fleet.ids, fleet.models, x, v, np.zeros_like(x), fleet.y, tuple(loads))

    def _empty_block(self, k: int) -> TrafficBlock:
        block = self._empty.get(k)
        if block is None:
            empty = np.zeros((k, 0))
            block = self._empty[k] = TrafficBlock((), (), empty, empty, empty, np.zeros(0))
        return block


def _fleet(vehicles: tuple[_Vehicle, ...]) -> _Fleet:
    ids: list[str] = []
    models: list[VehicleModel] = []
    y: list[float] = []
    t0: list[float] = []
    speed: list[float] = []
    behind: list[float] = []
    forward: list[bool] = []
    for v in vehicles:
        n = len(v.columns)
        ids += v.columns
        models += v.models
        y += [v.y] * n
        t0 += [v.t0] * n
        speed += [v.speed] * n
        behind += v.behind
        forward += [v.direction > 0] * n
    speeds = np.array(speed)
    ahead = np.array(forward)
    return _Fleet(vehicles, tuple(ids), tuple(models), np.array(y), np.array(t0), np.where(ahead, speeds, -speeds),
                  speeds, np.array(behind), ahead)

