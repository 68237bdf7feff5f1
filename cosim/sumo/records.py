"""WIM records inserted into a SUMO network: ``[traffic.records] via = "sumo"`` (docs/loads.md#records-through-sumo).

Each record becomes a SUMO vehicle of its own, on a route that starts upstream
of the deck on the lane its BTLS lane maps to and runs beyond the deck. It is
inserted at a time, a position and a speed chosen so that, driving undisturbed
at its recorded speed, its first axle reaches the deck's entry end (x = 0 along
``+x``, x = L along ``-x``) at the record's time. From then on SUMO drives it:
car following, lane changes, queues. A vehicle that SUMO cannot insert when
asked (the lane is blocked there) waits and enters later, as any SUMO vehicle
does, and so reaches the deck late; one held up on the way reaches it late too.

Two parts:

- :func:`record_routes`, before SUMO starts (sumolib, through
  :mod:`cosim.sumo.network`; no libsumo): each lane of the lanes table matched
  to a lane of the deck (same direction, its wheel path within the lane) and
  its way through the network: the lanes that lead to it followed upstream
  (the straightest predecessor at each junction) up to :data:`APPROACH` m
  before the deck, the network's edge, or the first lane that heads against
  the deck's direction (a lane fed by a turn starts on the road that turns
  in), and downstream at least :data:`EXIT` m past it.
- :class:`RecordFeed`, during the run: the file streamed (constant memory, the
  records read :data:`LOOKAHEAD` s ahead of SUMO's clock), each record added to
  SUMO through libsumo (``vehicle.add``), its length set to fit its axles, its
  speed factor set so that its desired speed on the deck's lane is its
  recorded speed, and its vehicle type and load record (:class:`RecordVehicle`)
  kept for the adapter until the vehicle is gone.

The SUMO clock is the records' clock: a record's time, s from midnight of the
file's first day, is SUMO's time (``[traffic] begin`` and ``end`` choose the
part of the file that runs). Record vehicles are ``<file stem>:<line>``, as
with ``via = "scripted"``.
"""
from __future__ import annotations

import bisect
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.loads import VehicleLoad, VehicleRecord, read_records
from cosim.core.loads.draws import lane_wander
from cosim.core.records_traffic import LIGHT_WEIGHT, RecordLane, record_class, record_id_prefix
from cosim.core.traffic import LoadRecord
from cosim.errors import ConfigError, SumoError, first_line

from .loads import FRONT_OVERHANG, REAR_OVERHANG
from .network import BridgeAxis, is_vehicle_lane, lane_graph, lane_sense, polyline_samples, read_network
from .vtypes import VehicleType, loaded_vehicle_type

__all__ = ["APPROACH", "EXIT", "LOOKAHEAD", "MAX_SPEED", "RECORD_VTYPES", "RecordFeed", "RecordRoute",
           "RecordVehicle", "RecordsPlan", "deck_lanes", "record_routes", "vehicle_length"]

#: A record's route starts at most this far (m, along its lanes) before the deck's entry end, or where the
#: network begins if that is nearer.
APPROACH = 500.0
#: A record's route runs at least this far (m) past the deck's far end, or to where the network ends.
EXIT = 200.0
#: Records are read and added to SUMO this long (s of SUMO time) before their time at the deck: a record whose
#: drive from the route's start takes longer (below APPROACH / LOOKAHEAD, about 4 m/s) starts nearer the deck.
LOOKAHEAD = 120.0
#: The records' vTypes' ``maxSpeed``, m/s: above any recorded speed, so that each vehicle's own speed factor
#: (its recorded speed over the deck lane's speed limit) sets its desired speed.
MAX_SPEED = 70.0
#: Each record's SUMO vType by its kind: (vType id, vClass, SUMO's defaults of that vClass: length m, minGap m,
#: accel, decel, emergencyDecel m/s^2, width m), as SUMO 1.28 gives a vType that sets only its vClass
#: (sumo.dlr.de/docs/Vehicle_Type_Parameter_Defaults.html; tests/integration/test_records_sumo.py reads them
#: from SUMO). A record below :data:`~cosim.core.records_traffic.LIGHT_WEIGHT` is a car, one of 2 or 3 axles a
#: truck, one of 4 or more an articulated lorry (SUMO's ``trailer``). Their drivers do not dawdle (sigma 0) and
#: keep their speed factor (speedDev 0): a record's speed is known.
RECORD_VTYPES: dict[str, tuple[str, str, tuple[float, float, float, float, float, float]]] = {
    "car": ("cosim-records-car", "passenger", (5.0, 2.5, 2.6, 4.5, 9.0, 1.8)),
    "truck": ("cosim-records-truck", "truck", (7.1, 2.5, 1.3, 4.0, 7.0, 2.4)),
    "trailer": ("cosim-records-trailer", "trailer", (16.5, 2.5, 1.1, 4.0, 7.0, 2.55)),
}


def record_kind(record: VehicleRecord) -> str:
    """The key of :data:`RECORD_VTYPES` for a record."""
    if record.gross_weight < LIGHT_WEIGHT:
        return "car"
    return "truck" if record.axle_count <= 3 else "trailer"


def vehicle_length(record: VehicleRecord) -> tuple[float, float]:
    """(length, front overhang) of a record's SUMO vehicle, m: its first axle :data:`FRONT_OVERHANG` behind the
    bumper (a quarter of a short vehicle's wheelbase less), its last :data:`REAR_OVERHANG` ahead of its rear, or
    the recorded length if that is longer."""
    wheelbase = math.fsum(record.axle_spacings)
    front = FRONT_OVERHANG if wheelbase >= 4 * FRONT_OVERHANG else max(0.25 * wheelbase, 0.5)
    return max(front + wheelbase + REAR_OVERHANG, record.length), front


# --------------------------------------------------------------------------- routes (before SUMO starts)


@dataclass(frozen=True)
class DeckLaneLine:
    """A lane of the network on the deck: id, lateral position of its centre line (m from the axis, median over
    the deck), width (m), direction (+1 along +x)."""

    id: str
    y: float
    width: float
    direction: int


@dataclass(frozen=True)
class RecordRoute:
    """The way a lane's records take through the network.

    Attributes:
        lane: BTLS's lane number; direction: +1 along +x.
        deck_lane: the network's lane on the deck the lane maps to.
        lanes: the lanes followed, upstream first (internal junction lanes included), with their ``lengths``
            (SUMO's, m) and speed ``limits`` (m/s).
        edges: the route's edges (the normal edges of ``lanes``, in order).
        edge_of: per lane, its edge's index in ``edges`` and its index on that edge, or (-1, -1) for an internal
            junction lane (no vehicle is inserted there).
        entry: where the deck's entry end is, m along ``lanes`` from the start of the first.
        entry_limit: the speed limit of the lane at the entry, m/s (a record drives its speed there).
    """

    lane: int
    direction: int
    deck_lane: str
    lanes: tuple[str, ...]
    lengths: tuple[float, ...]
    limits: tuple[float, ...]
    edges: tuple[str, ...]
    edge_of: tuple[tuple[int, int], ...]
    entry: float
    entry_limit: float

    @property
    def starts(self) -> tuple[float, ...]:
        """Where each lane starts, m along the route."""
        out, at = [], 0.0
        for length in self.lengths:
            out.append(at)
            at += length
        return tuple(out)

    def route_id(self, k: int) -> str:
        """The SUMO route from edge ``k`` on."""
        return f"cosim-records-lane{self.lane}-{k}"

    def start_for(self, target: float, tau: float, factor: float) -> float | None:
        """Where (m along the route) a vehicle must be to reach ``target`` in ``tau`` s (``tau`` < 0: to have
        passed it ``-tau`` s ago), driving each lane at ``factor`` times its limit (at most :data:`MAX_SPEED`);
        None if that is before the route's start or past its end."""
        starts = self.starts
        i = min(max(bisect.bisect_right(starts, target) - 1, 0), len(starts) - 1)
        p = target
        if tau >= 0.0:
            while True:
                speed = min(factor * self.limits[i], MAX_SPEED)
                room = p - starts[i]
                if tau * speed <= room:
                    return p - tau * speed
                tau -= room / speed
                p = starts[i]
                i -= 1
                if i < 0:
                    return None if tau > 1e-9 else 0.0
        end = starts[-1] + self.lengths[-1]
        while True:
            speed = min(factor * self.limits[i], MAX_SPEED)
            room = starts[i] + self.lengths[i] - p
            if -tau * speed <= room:
                return p - tau * speed
            tau += room / speed
            p = starts[i] + self.lengths[i]
            i += 1
            if i >= len(starts):
                return None if -tau > 1e-9 else end


def deck_lanes(net_file: str | Path, axis: BridgeAxis, y_range: tuple[float, float]) -> tuple[DeckLaneLine, ...]:
    """The network's lanes on the deck (normal edges' vehicle lanes whose centre line runs over it, 0 < x < L
    within ``y_range``), each with its lateral position, width and direction."""
    net = read_network(net_file)
    lo, hi = y_range
    e, _ = axis.unit()
    found = []
    for edge in net.getEdges(withInternal=False):
        for lane in edge.getLanes():
            if not is_vehicle_lane(lane):
                continue
            pts = polyline_samples(lane.getShape())
            x, y = axis.project(pts[:, 0], pts[:, 1])
            over = (x > 0.0) & (x < axis.length) & (y >= lo) & (y <= hi)
            if not over.any():
                continue
            found.append(DeckLaneLine(lane.getID(), float(np.median(y[over])), float(lane.getWidth()),
                                      lane_sense(lane, e)))
    return tuple(found)


def record_routes(net_file: str | Path, axis: BridgeAxis, lanes: Sequence[RecordLane], y_range: tuple[float, float],
                  key: str = "lanes") -> tuple[RecordRoute, ...]:
    """Each lane of the lanes table matched to the network's lane on the deck and its way through the network
    (this module's docstring).

    Raises:
        ConfigError: a lane of the table that no deck lane of its direction carries (its ``y`` more than half
            a lane width from every such lane's centre line), naming ``key[i]`` and the deck's lanes.
    """
    candidates = deck_lanes(net_file, axis, y_range)
    net = read_network(net_file)
    out = []
    for i, lane in enumerate(lanes):
        same = [c for c in candidates if c.direction == lane.direction]
        best = min(same, key=lambda c: abs(c.y - lane.y), default=None)
        if best is None or abs(best.y - lane.y) > 0.5 * best.width + 1e-6:
            listed = "; ".join(f"{c.id} at y = {c.y:+.3f} m, {'+x' if c.direction > 0 else '-x'}, "
                               f"{c.width:g} m wide" for c in candidates) or "none"
            way = "+x" if lane.direction > 0 else "-x"
            raise ConfigError(f"{key}[{i}]: lane {lane.lane} (y = {lane.y:+.3f} m, {way}) lies on no lane of "
                              f"{Path(net_file).name} that drives {way} over the deck (within half its width); the "
                              f"deck's lanes: {listed}. Give each lane the y of a network lane of its direction")
        out.append(_route(net, axis, lane, best))
    return tuple(out)


def _heading(shape: Any, last: bool) -> np.ndarray:
    pts = np.asarray(shape, dtype=float)[:, :2]
    d = pts[-1] - pts[-2] if last else pts[1] - pts[0]
    n = float(np.linalg.norm(d))
    return d / n if n > 0 else d


def _walk(net: Any, start: str, graph: dict[str, list[str]], length: dict[str, float], limit: float,
          along: np.ndarray | None = None) -> list[str]:
    """Lanes from ``start`` (excluded) along ``graph``, the straightest at each branch, until ``limit`` m are
    covered or the network ends. Upstream (``graph`` the predecessors, ``along`` the way the deck's lane drives):
    also up to the first lane that heads against ``along`` (the road that turns in; farther back, a loop around
    a block would lead round to it); returned upstream first."""
    upstream = along is not None
    out: list[str] = []
    seen = {start}
    current, covered = start, 0.0
    while covered < limit:
        options = [lane for lane in graph.get(current, ()) if lane not in seen]
        if not options:
            break
        here = _heading(net.getLane(current).getShape(), last=not upstream)
        current = max(options, key=lambda lane: float(np.dot(here, _heading(net.getLane(lane).getShape(),
                                                                              last=upstream))))
        seen.add(current)
        out.append(current)
        covered += length.get(current, 0.0)
        if along is not None:
            shape = np.asarray(net.getLane(current).getShape(), dtype=float)[:, :2]
            if float(np.dot(shape[-1] - shape[0], along)) < 0.0:
                break
    return out[::-1] if upstream else out


def _route(net: Any, axis: BridgeAxis, lane: RecordLane, deck: DeckLaneLine) -> RecordRoute:
    succ, pred, length = lane_graph(net)
    before = _walk(net, deck.id, pred, length, APPROACH, lane.direction * axis.unit()[0])
    while before and net.getLane(before[0]).getEdge().getFunction() == "internal":
        before.pop(0)  # a vehicle departs on a normal edge
    after = _walk(net, deck.id, succ, length, EXIT + axis.length)
    chain = [*before, deck.id, *after]
    while net.getLane(chain[-1]).getEdge().getFunction() == "internal":
        chain.pop()  # and arrives on one
    lengths = tuple(length[lane_id] for lane_id in chain)
    limits = tuple(float(net.getLane(lane_id).getSpeed()) for lane_id in chain)
    edges: list[str] = []
    edge_of = []
    for lane_id in chain:
        sumo_lane = net.getLane(lane_id)
        edge = sumo_lane.getEdge()
        if edge.getFunction() == "internal":
            edge_of.append((-1, -1))
            continue
        if not edges or edges[-1] != edge.getID():
            edges.append(edge.getID())
        edge_of.append((len(edges) - 1, int(sumo_lane.getIndex())))
    # The deck's entry end along the lanes: where a lane's centre line first crosses x = 0 (+x) or x = L (-x).
    x_entry = 0.0 if lane.direction > 0 else axis.length
    entry, entry_limit, at = None, limits[0], 0.0
    for lane_id, lane_length, lane_limit in zip(chain, lengths, limits):
        pts = np.asarray(net.getLane(lane_id).getShape(), dtype=float)[:, :2]
        steps = np.hypot(*np.diff(pts, axis=0).T)
        along = np.concatenate([[0.0], np.cumsum(steps)])
        scale = lane_length / along[-1] if along[-1] > 0 else 1.0
        x, _ = axis.project(pts[:, 0], pts[:, 1])
        ahead = lane.direction * (x - x_entry)
        for k in range(len(pts) - 1):
            if ahead[k] <= 0.0 <= ahead[k + 1] and ahead[k + 1] > ahead[k]:
                f = -ahead[k] / (ahead[k + 1] - ahead[k])
                entry, entry_limit = float(at + (along[k] + f * steps[k]) * scale), lane_limit
                break
        if entry is not None:
            break
        at += lane_length
    if entry is None:
        raise ConfigError(f"lane {lane.lane}: the network's lane {deck.id} does not cross the deck's entry end "
                          f"(x = {x_entry:g} m); check [traffic] axis")
    return RecordRoute(lane=lane.lane, direction=lane.direction, deck_lane=deck.id, lanes=tuple(chain),
                       lengths=lengths, limits=limits, edges=tuple(edges), edge_of=tuple(edge_of), entry=entry,
                       entry_limit=entry_limit)


@dataclass(frozen=True)
class RecordsPlan:
    """``[traffic.records]`` with ``via = "sumo"``, as the SUMO run takes it.

    Attributes:
        path, format: the record file and its format; lanes_per_direction: its lane counts (BTLS's numbering).
        begin, end: the records inserted: ``begin <= time < end``, s of the records' (and SUMO's) clock.
        routes: one per lane of the lanes table (:func:`record_routes`).
        wander, seed: each vehicle's lateral offset within its lane (``"none"``, ``"en1991-2"`` or a normal's
            sd, m) and its seed.
    """

    path: Path
    format: str
    lanes_per_direction: tuple[int, int]
    begin: float
    end: float
    routes: tuple[RecordRoute, ...]
    wander: str | float = "none"
    seed: int = 0

    @property
    def source(self) -> str:
        """The loads' source as load records give it (as ``via = "scripted"`` does)."""
        return f"records: {self.path.name}"


# --------------------------------------------------------------------------- insertion (during the run)


@dataclass(frozen=True)
class RecordVehicle:
    """A record in SUMO: its vehicle type (its axles, loads and the library suspension of its vClass), the
    SUMO vType it was added with, its load record (lane, speed and path filled in at its entry), its wander."""

    vehicle_type: VehicleType
    base: str
    load: LoadRecord
    wander: float


class RecordFeed:
    """Streams a :class:`RecordsPlan`'s file into a running SUMO (this module's docstring).

    Args:
        plan: the records and their routes.
        step: SUMO's step, s; begin: SUMO's begin, s (insertion times are on its grid).
    """

    def __init__(self, plan: RecordsPlan, step: float, begin: float) -> None:
        self.plan = plan
        self.step = float(step)
        self.begin = float(begin)
        self.routes = {route.lane: route for route in plan.routes}
        self.prefix = record_id_prefix(plan.path)
        self.live: dict[str, RecordVehicle] = {}  # added to SUMO and not gone yet
        self.added = 0  # records added to SUMO
        self.skipped = 0  # records of the window read too late to reach the deck in this run
        self.longest = 0.0
        self._records: Iterator[VehicleRecord] | None = None
        self._next: VehicleRecord | None = None
        self._routes_added: set[str] = set()
        self._base: dict[str, VehicleType] = {}

    def define_types(self, ls: Any) -> None:
        """Add the records' vTypes to SUMO (before the adapter models the vTypes SUMO knows)."""
        vt = ls.vehicletype
        for type_id, vclass, (length, gap, accel, decel, emergency, width) in RECORD_VTYPES.values():
            vt.copy("DEFAULT_VEHTYPE", type_id)
            vt.setVehicleClass(type_id, vclass)
            vt.setLength(type_id, length)
            vt.setMinGap(type_id, gap)
            vt.setAccel(type_id, accel)
            vt.setDecel(type_id, decel)
            vt.setApparentDecel(type_id, decel)
            vt.setEmergencyDecel(type_id, emergency)
            vt.setWidth(type_id, width)
            vt.setMaxSpeed(type_id, MAX_SPEED)
            vt.setImperfection(type_id, 0.0)
            vt.setSpeedDeviation(type_id, 0.0)

    def start(self, base_types: dict[str, VehicleType]) -> None:
        """Open the file; ``base_types``: the records' vTypes as the adapter modelled them (id -> type)."""
        self.close()
        self._base = {kind: base_types[type_id] for kind, (type_id, _, _) in RECORD_VTYPES.items()}
        self._records = read_records(self.plan.path, self.plan.format, self.plan.lanes_per_direction)
        self._advance()

    def close(self) -> None:
        records, self._records = self._records, None
        if records is not None and hasattr(records, "close"):
            records.close()
        self._next = None

    def _advance(self) -> None:
        records = self._records
        if records is not None:
            for record in records:
                if record.time < self.plan.begin:
                    continue
                if record.time < self.plan.end:
                    self._next = record
                    return
                break
        self.close()

    def insert(self, ls: Any, now: float) -> list[RecordVehicle]:
        """Add to SUMO every record due by ``now`` + :data:`LOOKAHEAD` (``now``: SUMO's time of the coming step).

        Raises:
            SumoError: SUMO refused a vehicle (an id its demand uses too), naming the file and the line.
        """
        added = []
        while self._next is not None and self._next.time <= now + LOOKAHEAD:
            record = self._next
            self._advance()
            vehicle = self._add(ls, record, now)
            if vehicle is not None:
                added.append(vehicle)
        return added

    def _add(self, ls: Any, record: VehicleRecord, now: float) -> RecordVehicle | None:
        route = self.routes.get(record.lane)
        if route is None:  # checked before the run (check_records): a lane the table maps
            raise SumoError(f"{self.plan.path}: line {record.line}: lane {record.lane} has no route")
        length, front = vehicle_length(record)
        factor = record.speed / route.entry_limit
        where = self.departure(route, record.time, factor, front, now)
        if where is None:  # its first axle past the route's end already (read after its time): not in this run
            self.skipped += 1
            return None
        depart, index, position = where
        edge, lane_index = route.edge_of[index]
        route_id = route.route_id(edge)
        vid = f"{self.prefix}:{record.line}"
        try:
            if route_id not in self._routes_added:
                ls.route.add(route_id, list(route.edges[edge:]))
                self._routes_added.add(route_id)
            ls.vehicle.add(vid, route_id, typeID=RECORD_VTYPES[record_kind(record)][0], depart=f"{depart:.3f}",
                           departLane=str(lane_index), departPos=f"{position:.4f}", departSpeed="desired")
            ls.vehicle.setLength(vid, length)  # before the speed factor: a new length resets it
            ls.vehicle.setSpeedFactor(vid, factor)
        except Exception as exc:  # noqa: BLE001 - libsumo's TraCIException and others
            raise SumoError(f"{self.plan.path}: line {record.line}: SUMO refused vehicle {vid}: {first_line(exc)}"
                            ) from None
        vehicle = self._vehicle(vid, record, front)
        self.live[vid] = vehicle
        self.added += 1
        self.longest = max(self.longest, length)
        return vehicle

    def departure(self, route: RecordRoute, time: float, factor: float, front: float,
                  now: float) -> tuple[float, int, float] | None:
        """(SUMO depart time on the step grid, index of the lane, position on it) that brings the first axle to
        the deck's entry end at ``time`` undisturbed: a vehicle added with depart ``d`` stands at its departure
        position at SUMO's time ``d + step`` (libsumo's clock after the step that inserts it)."""
        target = route.entry + front  # the bumper's position when the first axle is at the entry
        grid = self.step
        # From the route's start, on the step grid (rounded up: the start itself or a little after it).
        depart = self.begin + math.ceil((time - grid - travel_time(route, 0.0, target, factor) - self.begin) / grid
                                        - 1e-9) * grid
        depart = max(depart, now)
        starts = route.starts
        while True:
            p = route.start_for(target, time - grid - depart, factor)
            if p is None:
                return None
            i = min(bisect.bisect_right(starts, p) - 1, len(starts) - 1)
            if route.edge_of[i][0] >= 0 and p - starts[i] < route.lengths[i]:
                return round(depart, 3), i, max(p - starts[i], 0.0)
            depart += grid  # on a junction's internal lane: a step later, a little further on

    def _vehicle(self, vid: str, record: VehicleRecord, front: float) -> RecordVehicle:
        base = self._base[record_kind(record)]
        load = VehicleLoad(vehicle_id=vid, truck_class=record.axle_count, direction=record.direction,
                           gross_weight=record.gross_weight, axle_loads=record.axle_loads,
                           axle_spacings=record.axle_spacings, track_widths=record.track_widths)
        length, _ = vehicle_length(record)
        own = replace(loaded_vehicle_type(base, f"{base.id}@{vid}", load, front, self.plan.source), length=length)
        wander = lane_wander(self.plan.seed, vid, self.plan.wander) if self.plan.wander != "none" else 0.0
        template = LoadRecord(id=vid, vehicle_class=record_class(record), lane="", speed=record.speed,
                              gvw=record.gross_weight, axle_loads=record.axle_loads,
                              axle_spacings=record.axle_spacings, y=0.0, wander=wander, source=self.plan.source)
        return RecordVehicle(own, base.id, template, wander)

    def gone(self, ids: Sequence[str]) -> None:
        """Vehicles that left SUMO (arrived or removed): forgotten."""
        for vid in ids:
            self.live.pop(vid, None)


def travel_time(route: RecordRoute, p: float, q: float, factor: float) -> float:
    """Seconds from ``p`` to ``q`` (m along the route, ``p <= q``) at ``factor`` times each lane's limit."""
    total, starts = 0.0, route.starts
    for start, length, limit in zip(starts, route.lengths, route.limits):
        a, b = max(p, start), min(q, start + length)
        if b > a:
            total += (b - a) / min(factor * limit, MAX_SPEED)
    return total
