"""Where a vehicle's axles stand: on the path its front bumper drove (docs/theory.md §6.11).

A traffic simulation reports each vehicle's front bumper (position and
heading) at every step. An axle ``b`` metres behind the bumper stands where
the bumper was when the vehicle had driven ``b`` metres less: on the
vehicle's own trail, not on a straight line behind the bumper along its
present heading. The two differ wherever the heading changes within the
vehicle's length: at a junction at a deck end, a vehicle turning off the
bridge swings its bumper (and with it the straight line behind it) across
the road while its rear axles are still on their lane on the deck.

:class:`AxleTrails` keeps, per followed vehicle, a trail of bumper
positions with the distance driven at each (``s``, m) in
fixed arrays that one compiled pass appends to (:func:`record_fronts`) and
one compiled pass reads (:func:`axles_on_path`); a traffic adapter runs both,
with each contact point's offsets, in one call per step (:func:`contact_step`). The distance driven between
two steps is the bumper's move, but never more than the travel its speeds
give (SUMO's ballistic update: the mean speed times the step), so that an
instant lane change's sideways jump adds no distance. (SUMO's heading is the
body's, from its back to its front: it lags the direction of travel by tens
of degrees after a turn, so the move is not projected on it.) Where the trail under an
axle is straight to :data:`STRAIGHT_TOLERANCE`, the axle stands on the
straight line behind the bumper, computed exactly as before the trails
existed (so a straight road gives the same numbers to the bit); elsewhere it
is interpolated linearly on the trail. A vehicle seen for the first time
has its trail seeded with the lane it is on (the caller's
:meth:`AxleTrails.seed`): a vehicle inserted on the deck has its axles on
its lane behind it.

Error of the method (docs/theory.md §6.11): the trail is a polyline through
bumper positions at least :data:`MIN_SPACING` and at most one step's travel
``h`` (or MIN_SPACING, if larger) apart. On a path of radius ``R`` an axle
lies off the true path by at most the chord's sag ``h^2 / (8 R)`` across it
and ``b h^2 / (24 R^2)`` along it (the chords' shortfall against the arc
over the axle's distance ``b``): 5 mm and 2 mm for h = 0.7 m (14 m/s at
SUMO's 0.05 s step), R = 12 m (a tight junction turn), b = 14 m.
"""
from __future__ import annotations

import bisect
import math
from collections import namedtuple
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from .jit import compiled

#: An axle's trail counts as straight while every trail point under it lies this close to the line behind the
#: bumper along its heading, m: the axle then stands on that line (as before the trails, to the bit).
STRAIGHT_TOLERANCE = 1e-3
#: Kept trail points are at least this far apart along the trail, m (the newest is always the bumper itself).
MIN_SPACING = 0.25
#: Trail points beyond those that cover the reach, per vehicle (a seeded lane's vertices).
SPARE_POINTS = 64


#: The trails as the compiled passes take them: per slot (vehicle) the bumper points px, py (m, network) and the
#: distance driven to each, s (m), in a ring of ``capacity`` points (``head``: the newest, ``count``: how many),
#: and the speed at the newest, m/s.
TrailArrays = namedtuple("TrailArrays", ["px", "py", "s", "head", "count", "speed"])
#: The bridge axis in network coordinates: its start (m), the unit vectors along it and to its left.
AxisFrame = namedtuple("AxisFrame", ["origin", "along", "left"])


def trail_capacity(reach: float) -> int:
    """Points per vehicle trail that cover ``reach`` m behind the bumper at :data:`MIN_SPACING`."""
    return int(math.ceil(reach / MIN_SPACING)) + SPARE_POINTS


class AxleTrails:
    """The trails of the followed vehicles' front bumpers (network coordinates, m), one slot per vehicle.

    Args:
        reach: how far behind a bumper an axle can be, m (the longest vehicle plus slack).
    """

    def __init__(self, reach: float) -> None:
        self.capacity = trail_capacity(reach)
        self.slot_of: dict[str, int] = {}
        self._free: list[int] = []
        self._allocate(16)

    def _allocate(self, slots: int) -> None:
        h = self.capacity
        self.px = np.zeros((slots, h))
        self.py = np.zeros((slots, h))
        self.s = np.zeros((slots, h))
        self.head = np.zeros(slots, dtype=np.int64)
        self.count = np.zeros(slots, dtype=np.int64)
        self.speed = np.zeros(slots)  # at the last point, m/s
        #: The trails for the compiled passes (new arrays after a resize: take them anew each time).
        self.arrays = TrailArrays(self.px, self.py, self.s, self.head, self.count, self.speed)
        self._free = list(range(slots - 1, -1, -1))

    def _resize(self, slots: int, capacity: int) -> None:
        """Room for ``slots`` vehicles of ``capacity`` points each, the trails kept (oldest point first)."""
        old = (self.px, self.py, self.s, self.head, self.count, self.speed)
        used = dict(self.slot_of)
        self.capacity = capacity
        self._allocate(slots)
        self._free = [k for k in range(slots - 1, -1, -1) if k not in used.values()]
        for k in used.values():
            n = min(int(old[4][k]), capacity)
            order = (old[3][k] - np.arange(n - 1, -1, -1)) % old[0].shape[1]
            self.px[k, :n], self.py[k, :n], self.s[k, :n] = old[0][k, order], old[1][k, order], old[2][k, order]
            self.head[k], self.count[k], self.speed[k] = n - 1, n, old[5][k]

    def ensure_reach(self, reach: float) -> None:
        """Longer trails for a longer vehicle than any before (the trails kept)."""
        wanted = trail_capacity(reach)
        if wanted > self.capacity:
            self._resize(self.px.shape[0], wanted)

    def add(self, vehicle: str) -> int:
        """A slot for a vehicle seen for the first time (an empty trail)."""
        if not self._free:
            self._resize(2 * self.px.shape[0], self.capacity)
        k = self._free.pop()
        self.slot_of[vehicle] = k
        self.count[k] = 0
        return k

    def drop(self, vehicle: str) -> None:
        """Forget a vehicle no longer followed."""
        k = self.slot_of.pop(vehicle, None)
        if k is not None:
            self.count[k] = 0
            self._free.append(k)

    def seed(self, vehicle: str, points: npt.NDArray[np.float64], behind: npt.NDArray[np.float64],
             speed: float) -> None:
        """Start a vehicle's trail with the path behind its bumper: ``points`` (n, 2), oldest first, the last
        the bumper itself, each ``behind`` (n,) metres of driving before it (decreasing to 0); ``speed``: its
        speed now, m/s."""
        k = self.slot_of[vehicle]
        n = min(len(points), self.capacity)
        self.px[k, :n] = points[-n:, 0]
        self.py[k, :n] = points[-n:, 1]
        self.s[k, :n] = -np.asarray(behind[-n:], dtype=float)
        self.head[k], self.count[k], self.speed[k] = n - 1, n, speed

    def slots(self, vehicles: Sequence[str]) -> npt.NDArray[np.int64]:
        """The slot of each vehicle (all added)."""
        return np.array([self.slot_of[v] for v in vehicles], dtype=np.int64)


def record_fronts(vehicles: np.ndarray, slots: np.ndarray, trails: TrailArrays, step: float) -> None:
    """Append every vehicle's bumper (``vehicles`` rows: x, y (m), heading, speed (m/s), ...) to its trail, one
    traffic step (``step``, s) after the last: the distance driven since the last point is the bumper's move,
    at most the travel of the mean speed over the step (a lane change's sideways jump adds nothing; on a
    curve it is the chord). The newest point is always the bumper; it replaces the newest kept point while
    that lies less than :data:`MIN_SPACING` after the one before it."""
    # The arrays go in one by one: numba's dispatch of a named tuple of six arrays costs about 1.5 us more a
    # call than of the arrays themselves (measured: 3.1 against 1.5 us).
    _record_fronts(vehicles, slots, *trails, step)


@compiled
def _record_fronts(vehicles: np.ndarray, slots: np.ndarray, px: np.ndarray, py: np.ndarray, s: np.ndarray,
                   head: np.ndarray, count: np.ndarray, speed: np.ndarray, step: float) -> None:
    cap = px.shape[1]
    for r in range(vehicles.shape[0]):
        k = slots[r]
        x, y, v = vehicles[r, 0], vehicles[r, 1], vehicles[r, 3]
        if count[k] == 0:
            head[k], count[k] = 0, 1
            px[k, 0], py[k, 0], s[k, 0], speed[k] = x, y, 0.0, v
            continue
        h = head[k]
        moved = math.sqrt((x - px[k, h]) ** 2 + (y - py[k, h]) ** 2)
        travel = 0.5 * (speed[k] + v) * step
        s_new = s[k, h] + min(moved, travel)
        provisional = count[k] >= 2 and s[k, h] - s[k, (h - 1) % cap] < MIN_SPACING
        if not provisional:
            h = (h + 1) % cap
            head[k] = h
            count[k] = min(count[k] + 1, cap)
        px[k, h], py[k, h], s[k, h], speed[k] = x, y, s_new, v


def axles_on_path(vehicles: np.ndarray, slots: np.ndarray, trails: TrailArrays, back: np.ndarray, owner: np.ndarray,
                  axis: AxisFrame, y_range: tuple[float, float], x_range: tuple[float, float],
                  span: tuple[float, float, float]
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Contact points of vehicles in bridge coordinates, each axle on its vehicle's trail (module docstring).

    Args:
        vehicles: (n, 5 or more) per vehicle: front bumper x, y (m, network), heading (degrees, 0 = north,
            clockwise: SUMO's angle), speed (m/s), acceleration (m/s^2), both along the heading; columns after
            these are not read.
        slots, trails: each vehicle's slot and the trails (:class:`AxleTrails`, its bumper recorded).
        back: (m,) each contact point's distance behind the bumper, m; owner: (m,) its vehicle's row.
        axis: the bridge axis' start (network, m) and the unit vectors along it and to its left.
        y_range, x_range: the region kept, m (bridge coordinates: the deck's width, the watched reach).
        span: (x_min, x_max, margin): over this stretch of the axis (the deck's length), contact points up to
            ``margin`` m beyond ``y_range`` are kept too (a wheel beside the deck is seen, not lost).

    Returns:
        x, y (m), speed and acceleration along +x (m/s, m/s^2) of each contact point (those along its trail's
        direction there), and whether it is kept: every contact point of a vehicle with any contact point in
        the region (one body on several axles).
    """
    px, py, s, head, count, _ = trails
    origin, along, left = axis
    return _axles_on_path(vehicles, slots, px, py, s, head, count, back, owner, origin, along, left,  # as above
                          float(y_range[0]), float(y_range[1]), float(x_range[0]), float(x_range[1]),
                          float(span[0]), float(span[1]), float(span[2]))


@compiled
def _axles_on_path(vehicles: np.ndarray, slots: np.ndarray, px: np.ndarray, py: np.ndarray, s: np.ndarray,
                   head: np.ndarray, count: np.ndarray, back: np.ndarray, owner: np.ndarray, origin: np.ndarray,
                   along: np.ndarray, left: np.ndarray, y_lo: float, y_hi: float, x_lo: float, x_hi: float,
                   span_lo: float, span_hi: float, margin: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    m = len(back)
    cap = px.shape[1]
    x, y, v, a = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    keep = np.empty(m, dtype=np.bool_)
    kept_vehicle = np.zeros(vehicles.shape[0], dtype=np.bool_)
    for i in range(m):
        r = owner[i]
        k = slots[r]
        heading = vehicles[r, 2] * (math.pi / 180.0)
        hx, hy = math.sin(heading), math.cos(heading)
        fx, fy = vehicles[r, 0], vehicles[r, 1]
        h = head[k]
        target = s[k, h] - back[i]
        straight = True
        found = -1
        oldest = h
        for step in range(count[k]):
            j = (h - step) % cap
            oldest = j
            if abs((px[k, j] - fx) * hy - (py[k, j] - fy) * hx) > STRAIGHT_TOLERANCE:
                straight = False
            if s[k, j] <= target:
                found = j
                break
        if straight:  # as before the trails: on the line behind the bumper
            dx = fx - back[i] * hx - origin[0]
            dy = fy - back[i] * hy - origin[1]
            tx, ty = hx, hy
        else:
            if found >= 0:
                base = found
                nxt = (found + 1) % cap
                ds = s[k, nxt] - s[k, found]
                f = (target - s[k, found]) / ds if ds > 0.0 else 0.0
            else:  # the trail is shorter than the axle's distance: on from its oldest point, straight
                base = oldest
                nxt = (oldest + 1) % cap
                f = target - s[k, oldest]  # negative: metres before the oldest point
            ex, ey = px[k, nxt] - px[k, base], py[k, nxt] - py[k, base]
            norm = math.sqrt(ex * ex + ey * ey)
            if base == h or norm == 0.0:
                tx, ty = hx, hy
            else:
                tx, ty = ex / norm, ey / norm
            if found >= 0:
                qx, qy = px[k, base] + f * ex, py[k, base] + f * ey
            else:
                qx, qy = px[k, base] + f * tx, py[k, base] + f * ty
            dx = qx - origin[0]
            dy = qy - origin[1]
        x[i] = dx * along[0] + dy * along[1]
        y[i] = dx * left[0] + dy * left[1]
        ahead = tx * along[0] + ty * along[1]
        v[i] = vehicles[r, 3] * ahead
        a[i] = vehicles[r, 4] * ahead
        in_box = y_lo <= y[i] <= y_hi and x_lo <= x[i] <= x_hi
        beside = span_lo <= x[i] <= span_hi and y_lo - margin <= y[i] <= y_hi + margin
        if in_box or beside:
            kept_vehicle[r] = True
    for i in range(m):
        keep[i] = kept_vehicle[owner[i]]
    return x, y, v, a, keep


def contact_settings(deck_y: tuple[float, float], reach: float, length: float, beside: float, step: float
                     ) -> np.ndarray:
    """What :func:`contact_step` takes of a run, as one array: the region in which it keeps contact points
    (bridge coordinates, m: the deck's width ``deck_y`` within ``reach`` before and after the deck, ``length``
    long, or up to ``beside`` beyond the width over the deck's length: :func:`axles_on_path`'s ``y_range``,
    ``x_range`` and ``span``: the span is the deck's length) and the traffic step (s)."""
    return np.array([deck_y[0], deck_y[1], -reach, length + reach, 0.0, length, beside, step], dtype=float)


def contact_step(vehicles: np.ndarray, slots: np.ndarray, trails: TrailArrays, back: np.ndarray, owner: np.ndarray,
                 left: np.ndarray, wander: np.ndarray, axis: AxisFrame, settings: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """One traffic step of the followed vehicles in one compiled pass: :func:`record_fronts`, then
    :func:`axles_on_path`, each contact point moved ``left`` of its path (m, to the left looking along the
    vehicle's heading; an empty array: none is) and by its vehicle's ``wander`` (m, to the left of the bridge
    axis; empty: none), and which vehicles have driven away beyond the region for good.

    Args:
        vehicles: (n, 6) per vehicle: front bumper x, y (m, network), heading (degrees, SUMO's), speed (m/s),
            acceleration (m/s^2) and length (m).
        slots, trails, back, owner, axis: as :func:`record_fronts` and :func:`axles_on_path` take them.
        settings: :func:`contact_settings`.

    Returns:
        (4, m): x, y, v and a of :func:`axles_on_path` (y with the offsets); (m + n,): its ``keep`` for each
        contact point, then for each vehicle whether it is gone (its whole length beyond the region along the
        axis, driving away from the deck); how many contact points are kept; whether any is on the deck's
        length (0 <= x <= length).
    """
    # One call instead of four numba calls and a dozen numpy operations on arrays of a few vehicles, and two
    # arrays out instead of six: each cost about a microsecond at every SUMO step, more than the arithmetic.
    return _contact_step(vehicles, slots, *trails, back, owner, left, wander, *axis, settings)


@compiled
def _contact_step(vehicles: np.ndarray, slots: np.ndarray, px: np.ndarray, py: np.ndarray, s: np.ndarray,
                  head: np.ndarray, count: np.ndarray, speed: np.ndarray, back: np.ndarray, owner: np.ndarray,
                  left: np.ndarray, wander: np.ndarray, origin: np.ndarray, along: np.ndarray,
                  left_of_axis: np.ndarray, settings: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, bool]:
    _record_fronts(vehicles, slots, px, py, s, head, count, speed, settings[7])
    x, y, v, a, keep = _axles_on_path(vehicles, slots, px, py, s, head, count, back, owner, origin, along,
                                      left_of_axis, settings[0], settings[1], settings[2], settings[3],
                                      settings[4], settings[5], settings[6])
    n, m = vehicles.shape[0], back.shape[0]
    if left.shape[0] > 0:  # wheels beside the path: to the left of the vehicle, whichever way it drives
        for i in range(m):
            heading = vehicles[owner[i], 2] * (math.pi / 180.0)
            ahead = 1.0 if math.sin(heading) * along[0] + math.cos(heading) * along[1] >= 0.0 else -1.0
            y[i] = y[i] + ahead * left[i]
    if wander.shape[0] > 0:
        for i in range(m):
            y[i] = y[i] + wander[i]
    out = np.empty((4, m))
    marks = np.empty(m + n, dtype=np.bool_)
    kept = 0
    on_deck = False
    for i in range(m):
        out[0, i], out[1, i], out[2, i], out[3, i] = x[i], y[i], v[i], a[i]
        marks[i] = keep[i]
        if keep[i]:
            kept += 1
        if 0.0 <= x[i] <= settings[5]:  # on the deck's length (the span's end)
            on_deck = True
    for r in range(n):
        heading = vehicles[r, 2] * (math.pi / 180.0)
        hx, hy = math.sin(heading), math.cos(heading)
        front = (vehicles[r, 0] - origin[0]) * along[0] + (vehicles[r, 1] - origin[1]) * along[1]
        ahead = hx * along[0] + hy * along[1]
        rear = front - vehicles[r, 5] * ahead
        marks[m + r] = (ahead > 0.0 and min(front, rear) > settings[3]) or \
            (ahead < 0.0 and max(front, rear) < settings[2])
    return out, marks, kept, on_deck


class LaneLine(NamedTuple):
    """A lane's centre line as :func:`path_behind` reads it (:func:`lane_line`): its vertices (m, network), the
    distance along the line to each (m, from its start), the line's length, the lane's length as the traffic
    simulation counts it (m; SUMO scales positions on the line by their ratio) and the unit vector of its first
    segment of nonzero length (zero if none)."""

    x: tuple[float, ...]
    y: tuple[float, ...]
    along: tuple[float, ...]
    total: float
    lane_length: float
    start_dir: tuple[float, float]


def lane_line(shape: npt.ArrayLike, lane_length: float) -> LaneLine:
    """A lane's centre line ``shape`` ((n, 2) network coordinates, m; at least two points) with the lane's
    length as the traffic simulation counts it (m), prepared once per lane for :func:`path_behind`."""
    pts = np.asarray(shape, dtype=float)[:, :2]
    seg = np.hypot(*np.diff(pts, axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    first = np.flatnonzero(seg > 0.0)
    start_dir = (0.0, 0.0)
    if len(first):
        f = int(first[0])
        start_dir = (float((pts[f + 1, 0] - pts[f, 0]) / seg[f]), float((pts[f + 1, 1] - pts[f, 1]) / seg[f]))
    return LaneLine(tuple(pts[:, 0].tolist()), tuple(pts[:, 1].tolist()), tuple(along.tolist()), float(along[-1]),
                    float(lane_length), start_dir)


def _interp(g: float, along: Sequence[float], values: Sequence[float]) -> float:
    """``np.interp(g, along, values)`` to the bit, for one number (numpy's arr_interp, its steps in order):
    numpy's call on arrays of a few points cost most of a seeded trail's time, at every vehicle's first sight."""
    if g != g:
        return g
    j = bisect.bisect_right(along, g) - 1  # numpy's search: the last vertex at or before g
    if j < 0:
        return values[0]
    if j >= len(along) - 1:  # at or after the last vertex
        return values[-1]
    if along[j] == g:
        return values[j]
    slope = (values[j + 1] - values[j]) / (along[j + 1] - along[j])
    out = slope * (g - along[j]) + values[j]
    if out != out:
        out = slope * (g - along[j + 1]) + values[j + 1]
        if out != out and values[j] == values[j + 1]:
            out = values[j]
    return out


def path_behind(lane: LaneLine, position: float, front: npt.NDArray[np.float64] | Sequence[float],
                reach: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The path behind a bumper along its lane, to seed a trail (:meth:`AxleTrails.seed`).

    Args:
        lane: the lane's centre line (:func:`lane_line`).
        position: the bumper's position on the lane, m from its start (in the lane's length's measure).
        front: the bumper (network, m): the centre line is moved onto it (a vehicle off its lane's centre).
        reach: how far back the path is wanted, m; before the lane's start it goes on straight, along the
            lane's first segment.

    Returns:
        The points (m, 2), oldest first, the last the bumper, and each one's distance before it along the
        path (m, decreasing to 0).
    """
    px, py, along, total = lane.x, lane.y, lane.along, lane.total
    g = position * total / lane.lane_length if lane.lane_length > 0 else position
    g = min(max(g, 0.0), total)
    at = (_interp(g, along, px), _interp(g, along, py))
    fx, fy = float(front[0]), float(front[1])
    shift = (fx - at[0], fy - at[1])
    inner = [j for j, s in enumerate(along) if s < g and g - s < reach]
    points = [(px[j], py[j]) for j in inner]
    behind = [g - along[j] for j in inner]
    if g - reach <= 0.0 or not inner:  # on, straight, before the lane's start (or its first segment)
        if g >= reach:
            start = (_interp(g - reach, along, px), _interp(g - reach, along, py))
        else:
            start = (px[0] - (reach - g) * lane.start_dir[0], py[0] - (reach - g) * lane.start_dir[1])
        points.insert(0, start)
        behind.insert(0, reach)
    elif along[inner[0]] > g - reach:  # the oldest vertex is within reach: the point at the reach before it
        points.insert(0, (_interp(g - reach, along, px), _interp(g - reach, along, py)))
        behind.insert(0, reach)
    points.append(at)
    out = np.array([(x + shift[0], y + shift[1]) for x, y in points])
    behind.append(0.0)
    return out, np.array(behind)
