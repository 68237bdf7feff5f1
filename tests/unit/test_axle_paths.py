"""Axles on the path their vehicle drove (cosim.core.axle_paths): closed forms on straight roads, arcs and lane
changes, and the seed from a lane's centre line."""
from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.axle_paths import (
    MIN_SPACING,
    AxisFrame,
    AxleTrails,
    axles_on_path,
    contact_settings,
    contact_step,
    lane_line,
    path_behind,
    record_fronts,
    trail_capacity,
)

AXIS = AxisFrame(np.zeros(2), np.array([1.0, 0.0]), np.array([0.0, 1.0]))  # the network's x axis
WIDE = (-1e6, 1e6)
STEP = 0.05  # s, the traffic step the drives below are recorded at


def _sumo_angle(dx: float, dy: float) -> float:
    """SUMO's heading of a direction: degrees clockwise from north."""
    return math.degrees(math.atan2(dx, dy)) % 360.0


def _drive(trails: AxleTrails, states: list[tuple[float, float, float]], back: list[float],
           speed: float = 10.0) -> list[tuple[np.ndarray, ...]]:
    """Record each (x, y, SUMO angle) bumper state of one vehicle "v" in turn; the axles' bridge coordinates
    (axis = network x axis) after each."""
    if "v" not in trails.slot_of:
        trails.add("v")
    out = []
    back_a = np.array(back, dtype=float)
    owner = np.zeros(len(back), dtype=np.int64)
    for x, y, angle in states:
        num = np.array([[x, y, angle, speed, 0.5, 20.0]])
        slots = trails.slots(["v"])
        record_fronts(num, slots, trails.arrays, STEP)
        out.append(axles_on_path(num, slots, trails.arrays, back_a, owner, AXIS, WIDE, WIDE, (0.0, 0.0, 0.0)))
    return out


def test_axles_are_projected_onto_a_rotated_axis_and_kept_with_their_vehicle() -> None:
    angle = np.radians(30.0)  # the axis runs 30 degrees north of east from (100, 50)
    along, left = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    origin = np.array([100.0, 50.0])
    # A truck driving along the axis (SUMO heading 60 degrees: clockwise from north) with its bumper 20 m along and
    # 1.5 m to the left, axles 1.2 and 8.0 m behind it; a car driving against the axis, outside the region.
    bumper = origin + 20.0 * along + 1.5 * left
    car = origin + 70.0 * along - 1.5 * left
    vehicles = np.array([[*bumper, 60.0, 15.0, 0.5], [*car, 240.0, 12.0, -1.0]])
    back, owner = np.array([1.2, 8.0, 2.25]), np.array([0, 0, 1])
    trails = AxleTrails(30.0)
    trails.add("truck")
    trails.add("car")
    slots = trails.slots(["truck", "car"])
    record_fronts(vehicles, slots, trails.arrays, STEP)
    args = (vehicles, slots, trails.arrays, back, owner, AxisFrame(origin, along, left), (-5.0, 5.0))
    x, y, v, a, keep = axles_on_path(*args, (-12.0, 52.0), (0.0, 0.0, 0.0))
    # Reference: by hand, the axles lie on the axis at 20 - 1.2 and 20 - 8 m, the car's contact at 70 + 2.25 m.
    np.testing.assert_allclose(x, [18.8, 12.0, 72.25], atol=1e-12)
    np.testing.assert_allclose(y, [1.5, 1.5, -1.5], atol=1e-12)
    np.testing.assert_allclose(v, [15.0, 15.0, -12.0], atol=1e-12)
    np.testing.assert_allclose(a, [0.5, 0.5, 1.0], atol=1e-12)
    assert keep.tolist() == [True, True, False]
    # The truck with its front axle past the region's end: its rear axle still in it keeps both.
    x, _, _, _, keep = axles_on_path(*args, (-12.0, 15.0), (0.0, 0.0, 0.0))
    assert keep.tolist() == [True, True, False] and x[0] > 15.0
    # The car beside the deck (y = -1.5 m, the region from y = -1 m) over the deck's span is kept with a margin.
    args = args[:-1] + ((-1.0, 2.0),)
    _, _, _, _, keep = axles_on_path(*args, (-12.0, 100.0), (0.0, 100.0, 0.6))
    assert keep.tolist() == [True, True, True]
    _, _, _, _, keep = axles_on_path(*args, (-12.0, 100.0), (0.0, 100.0, 0.4))
    assert keep.tolist() == [True, True, False]


def test_one_contact_step_gives_what_the_separate_passes_and_the_offsets_give_to_the_bit() -> None:
    # Reference: record_fronts and axles_on_path one after the other, then the sideways offsets, the wander and
    # the "gone" rule as numpy operations (the adapter's before contact_step merged them): equal to the bit.
    rng = np.random.default_rng(7)
    angle = np.radians(-20.0)
    along, left = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    axis = AxisFrame(np.array([30.0, -10.0]), along, left)
    length, reach, deck_y, beside = 40.0, 26.5, (-6.0, 6.0), 3.75
    settings = contact_settings(deck_y, reach, length, beside, STEP)
    names = [f"v{k}" for k in range(5)]
    owner = np.array([0, 0, 1, 2, 2, 2, 3, 4], dtype=np.int64)
    back = rng.uniform(0.5, 14.0, owner.size)
    side = rng.uniform(-1.0, 1.0, owner.size)
    wander = rng.uniform(-0.3, 0.3, 5)[owner]
    at = rng.uniform(-80.0, 120.0, 5)  # bumpers along the axis (m): some far before or after the deck
    lateral = rng.uniform(-9.0, 9.0, 5)
    heading = np.where(rng.random(5) < 0.5, 1.0, -1.0)  # each drives along the axis or against it
    sumo_angle = [_sumo_angle(*(h * along)) for h in heading]
    merged, separate = AxleTrails(reach), AxleTrails(reach)
    for trails in (merged, separate):
        for name in names:
            trails.add(name)
    for k in range(30):
        bumper = axis.origin + np.outer(at + heading * 12.0 * STEP * k, along) + np.outer(lateral, left)
        num = np.column_stack([bumper, sumo_angle, np.full(5, 12.0), rng.normal(0.0, 0.5, 5),
                               rng.uniform(4.0, 16.0, 5)])
        slots = merged.slots(names)
        xyva, marks, kept, on_deck = contact_step(num, slots, merged.arrays, back, owner, side, wander, axis,
                                                  settings)
        record_fronts(num, slots, separate.arrays, STEP)
        x, y, v, a, keep = axles_on_path(num, slots, separate.arrays, back, owner, axis, deck_y,
                                         (-reach, length + reach), (0.0, length, beside))
        h = np.radians(num[:, 2])
        ahead = np.where(np.sin(h) * along[0] + np.cos(h) * along[1] >= 0.0, 1.0, -1.0)
        y = y + ahead[owner] * side + wander
        front = (num[:, 0] - axis.origin[0]) * along[0] + (num[:, 1] - axis.origin[1]) * along[1]
        forward = np.sin(h) * along[0] + np.cos(h) * along[1]
        rear = front - num[:, 5] * forward
        gone = ((forward > 0) & (np.minimum(front, rear) > length + reach)) | \
            ((forward < 0) & (np.maximum(front, rear) < -reach))
        assert np.array_equal(xyva, np.vstack([x, y, v, a]))
        assert marks.tolist() == keep.tolist() + gone.tolist()
        assert kept == keep.sum() and on_deck == bool(((x >= 0.0) & (x <= length)).any())
    assert 0 < kept < owner.size and gone.any() and not gone.all()  # the draw covers kept, dropped and gone
    # Without sideways offsets or wander (empty arrays) y is axles_on_path's own.
    xyva, _, _, _ = contact_step(num, slots, merged.arrays, back, owner, np.zeros(0), np.zeros(0), axis, settings)
    record_fronts(num, slots, separate.arrays, STEP)
    _, y, _, _, _ = axles_on_path(num, slots, separate.arrays, back, owner, axis, deck_y, (-reach, length + reach),
                                  (0.0, length, beside))
    assert np.array_equal(xyva[1], y)


def test_on_a_straight_road_the_axles_stand_exactly_where_the_straight_rule_puts_them() -> None:
    # A vehicle driving 300 m along a skewed straight line (the trail wraps its ring buffer): every axle is at
    # bumper - b * heading, computed with the same expression (bit for bit), and so exactly as before trails.
    trails = AxleTrails(20.0)
    direction = np.array([math.cos(0.3), math.sin(0.3)])
    angle = _sumo_angle(*direction)
    back = [1.0, 4.5, 15.0]
    states = [(*(5.0 + 0.7 * k * direction), angle) for k in range(430)]
    heading = angle * (math.pi / 180.0)
    hx, hy = math.sin(heading), math.cos(heading)
    for (fx, fy, _), (x, y, _, _, _) in zip(states, _drive(trails, states, back, speed=0.7 / STEP)):
        expected_x = [(fx - b * hx - 0.0) * 1.0 + (fy - b * hy - 0.0) * 0.0 for b in back]
        expected_y = [(fx - b * hx - 0.0) * 0.0 + (fy - b * hy - 0.0) * 1.0 for b in back]
        assert x.tolist() == expected_x and y.tolist() == expected_y


def test_on_an_arc_each_axle_is_on_the_arc_within_the_chord_error() -> None:
    # A bumper driving a circle of radius R = 12 m (a tight junction turn) at h = 0.7 m a step: an axle b behind
    # it lies on the circle b of arc length behind the bumper. Bounds (docs/theory.md §6.11): across the path
    # the chord's sag, h^2 / (8 R) = 5.1 mm; along it the chords' shortfall against the arc, b h^2 / (24 R^2)
    # (2.0 mm at b = 14.3 m).
    R, h = 12.0, 0.7
    trails = AxleTrails(20.0)
    back = [1.2, 8.0, 14.3]
    phis = np.arange(0.0, 2.5, h / R)  # bumper at angle phi on the circle, driving counter-clockwise
    states = [(R * math.cos(p), R * math.sin(p), _sumo_angle(-math.sin(p), math.cos(p))) for p in phis]
    results = _drive(trails, states, back, speed=h / STEP)  # the arc's length per step
    worst = 0.0
    for p, (x, y, v, _, _) in zip(phis, results):
        for j, b in enumerate(back):
            if R * p < b:  # the trail does not reach back that far yet (it starts at the first state)
                continue
            q = p - b / R
            error = math.hypot(x[j] - R * math.cos(q), y[j] - R * math.sin(q))
            bound = math.hypot(h * h / (8 * R), b * h * h / (24 * R * R))
            assert error <= bound * 1.01, (b, error, bound)
            worst = max(worst, error)
            # Speed along +x: the path's direction there (the tangent at q), within the chord's angle h / R.
            assert abs(v[j] - h / STEP * -math.sin(q)) <= h / STEP * h / R
    assert worst > 1e-3  # the bound is approached, not vacuous
    # The straight line behind the bumper (the rule before trails) is metres off at the rear axle.
    p = phis[-1]
    straight = np.array([R * math.cos(p), R * math.sin(p)]) - 14.3 * np.array([-math.sin(p), math.cos(p)])
    q = p - 14.3 / R
    assert math.dist(straight, (R * math.cos(q), R * math.sin(q))) > 5.0


def test_an_instant_lane_change_moves_each_axle_when_it_reaches_the_change_point() -> None:
    # SUMO's lane change (without the sublane model) puts the bumper 3.2 m to the side in one step. The distance
    # driven does not count the jump: an axle b behind keeps its lane until it has driven b more, crosses in one
    # step's travel, and its x never jumps back or forward.
    trails = AxleTrails(20.0)
    back = [2.0, 9.0]
    states = [(0.5 * k, 0.0 if k < 40 else 3.2, 90.0) for k in range(80)]
    results = _drive(trails, states, back, speed=0.5 / STEP)
    for k, (x, y, _, _, _) in enumerate(results):
        front_x = 0.5 * k
        np.testing.assert_allclose(x, [front_x - 2.0, front_x - 9.0], atol=1e-12)  # on their straight lanes
        for j, b in enumerate(back):
            crossed = front_x - b >= 0.5 * 40  # past the point where the bumper changed lanes
            within = front_x - b > 0.5 * 39  # on the step's diagonal
            lane = 3.2 if crossed else 0.0
            assert abs(y[j] - lane) <= 1e-12 or (within and 0.0 <= y[j] <= 3.2), (k, j, y[j])


def test_a_seeded_trail_puts_the_axles_on_the_lane_behind_and_straight_before_its_start() -> None:
    # An L-shaped lane: 10 m east from (0, 0), then 20 m north; lane length 30 m as on its line. A bumper 5 m up
    # the northern leg (position 15 m): an axle 3 m behind is on that leg, 8 m behind on the eastern leg, and 17 m
    # behind 2 m before the lane's start, on the straight line of its first segment (x = -2).
    shape = [(0.0, 0.0), (10.0, 0.0), (10.0, 20.0)]
    front = np.array([10.0, 5.0])
    points, behind = path_behind(lane_line(shape, 30.0), 15.0, front, 20.0)
    assert behind[0] == 20.0 and behind[-1] == 0.0 and np.all(np.diff(behind) < 0)
    np.testing.assert_allclose(points[-1], front)
    trails = AxleTrails(20.0)
    trails.add("v")
    trails.seed("v", points, behind, 0.0)
    (x, y, _, _, _), = _drive(trails, [(10.0, 5.0, 0.0)], [3.0, 8.0, 17.0])
    np.testing.assert_allclose(x, [10.0, 7.0, -2.0], atol=1e-12)
    np.testing.assert_allclose(y, [2.0, 0.0, 0.0], atol=1e-12)
    # A lane whose length differs from its line's (SUMO scales positions): position 15 of 60 m is 7.5 m along.
    points, behind = path_behind(lane_line(shape, 60.0), 15.0, np.array([7.5, 0.3]), 4.0)
    np.testing.assert_allclose(points, [[3.5, 0.3], [7.5, 0.3]], atol=1e-12)  # moved onto the bumper (0.3 left)
    np.testing.assert_allclose(behind, [4.0, 0.0])


def _path_behind_by_numpy(shape: np.ndarray, lane_length: float, position: float, front: np.ndarray,
                          reach: float) -> tuple[np.ndarray, np.ndarray]:
    """The seeded path computed with numpy's np.interp on whole arrays (path_behind before it went scalar)."""
    pts = np.asarray(shape, dtype=float)[:, :2]
    seg = np.hypot(*np.diff(pts, axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    total = float(along[-1])
    g = min(max(position * total / lane_length if lane_length > 0 else position, 0.0), total)
    at = np.array([np.interp(g, along, pts[:, 0]), np.interp(g, along, pts[:, 1])])
    inner = np.flatnonzero((along < g) & (g - along < reach))
    points, behind = [pts[j] for j in inner], [g - along[j] for j in inner]
    if g - reach <= 0.0 or not len(inner):
        first = np.flatnonzero(seg > 0.0)
        start_dir = (pts[first[0] + 1] - pts[first[0]]) / seg[first[0]] if len(first) else np.zeros(2)
        start = np.array([np.interp(g - reach, along, pts[:, 0]), np.interp(g - reach, along, pts[:, 1])]) \
            if g >= reach else pts[0] - (reach - g) * start_dir
        points.insert(0, start)
        behind.insert(0, reach)
    elif along[inner[0]] > g - reach:
        points.insert(0, np.array([np.interp(g - reach, along, pts[:, 0]), np.interp(g - reach, along, pts[:, 1])]))
        behind.insert(0, reach)
    return np.array(points + [at]) + (np.asarray(front, dtype=float)[:2] - at), np.array(behind + [0.0])


_COORD = st.floats(-500.0, 500.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(vertices=st.lists(st.tuples(_COORD, _COORD), min_size=2, max_size=9), repeat=st.integers(0, 8),
       scale=st.floats(0.5, 2.0), at=st.floats(-0.2, 1.2), front=st.tuples(_COORD, _COORD),
       reach=st.floats(0.1, 400.0))
def test_a_seeded_path_is_numpys_interpolation_to_the_bit(vertices: list[tuple[float, float]], repeat: int,
                                                          scale: float, at: float, front: tuple[float, float],
                                                          reach: float) -> None:
    # Reference: np.interp over whole arrays (_path_behind_by_numpy); a repeated vertex gives a zero-length segment.
    if repeat < len(vertices):
        vertices = vertices[:repeat + 1] + vertices[repeat:]
    shape = np.array(vertices)
    line_length = float(np.hypot(*np.diff(shape, axis=0).T).sum())
    lane_length, position = line_length * scale, line_length * scale * at
    got = path_behind(lane_line(shape, lane_length), position, np.array(front), reach)
    want = _path_behind_by_numpy(shape, lane_length, position, np.array(front), reach)
    np.testing.assert_array_equal(got[0], want[0])  # tolerance 0: the same operations in the same order
    np.testing.assert_array_equal(got[1], want[1])


def test_trails_grow_for_longer_vehicles_and_keep_what_they_hold() -> None:
    trails = AxleTrails(10.0)
    assert trails.capacity == trail_capacity(10.0)
    for k in range(20):  # more vehicles than the first allocation
        trails.add(f"v{k}")
    states = [(MIN_SPACING * 2 * k, 0.0, 90.0) for k in range(10)]
    for k in range(20):
        slot = trails.slots([f"v{k}"])
        for x, y, angle in states:
            record_fronts(np.array([[x, y, angle, 2 * MIN_SPACING / STEP]]), slot, trails.arrays, STEP)
    before = trails.s[trails.slot_of["v7"], :10].copy()
    trails.ensure_reach(60.0)
    assert trails.capacity == trail_capacity(60.0)
    k = trails.slot_of["v7"]
    np.testing.assert_array_equal(trails.s[k, :10], before)
    assert trails.head[k] == 9 and trails.count[k] == 10
    trails.drop("v7")
    assert "v7" not in trails.slot_of and trails.add("new") == k
