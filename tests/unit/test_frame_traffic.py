"""Traffic from frames (cosim.core.traffic.FrameTraffic): SUMO's ballistic motion between its steps."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.traffic import Frame, FrameTraffic
from cosim.core.vehicles import QuarterCar

CAR = QuarterCar(m_v=1500.0, m_w=150.0, k_v=6e4, c_v=4e3)
STEP = 0.05


def frames_of(traffic: FrameTraffic, rows: list[list[tuple[str, float, float, float, float]]]) -> None:
    """Add frames at STEP, 2 STEP, ...: each a list of (id, x, y, v, a)."""
    for k, row in enumerate(rows, start=1):
        ids = tuple(r[0] for r in row)
        x, y, v, a = (np.array([r[i] for r in row], dtype=float) for i in range(1, 5))
        traffic.add_frame(Frame(k * STEP, ids, x, y, v, a, tuple("car" for _ in ids)))


def test_constant_acceleration_is_followed_exactly_between_frames() -> None:
    x0, v0, acc = 3.0, 20.0, -1.5
    def x(t: float) -> float: return x0 + v0 * t + 0.5 * acc * t * t
    traffic = FrameTraffic(STEP, 40.0, {"car": CAR})
    frames_of(traffic, [[("c", x(k * STEP), 1.5, v0 + acc * k * STEP, acc)] for k in range(1, 21)])
    times = np.arange(1, 181) * 0.005 + 2 * STEP  # between frames 2 and 20, dt = 5 ms
    block = traffic.block(times)
    # Reference: the closed-form motion x0 + v0 t + a t^2 / 2, v0 + a t (SUMO's ballistic update is exact for it).
    np.testing.assert_allclose(block.x[:, 0], [x(t) for t in times], rtol=0, atol=1e-12)
    np.testing.assert_allclose(block.v[:, 0], v0 + acc * times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(block.a[:, 0], acc, rtol=0, atol=1e-9)
    assert block.ids == ("c",) and block.y.tolist() == [1.5]


def test_a_vehicle_first_seen_is_traced_back_and_one_gone_is_far_before_the_deck() -> None:
    traffic = FrameTraffic(STEP, 40.0, {"car": CAR})
    frames_of(traffic, [[("a", 10.0, 0.0, 10.0, 0.0)],
                        [("a", 10.5, 0.0, 10.0, 0.0), ("b", 1.0, -1.5, 20.0, 2.0)],
                        [("b", 2.0 + 0.0025, -1.5, 20.1, 2.0)]])
    times = np.array([0.06, 0.075, 0.1, 0.11, 0.15])
    block = traffic.block(times)
    a, b = block.ids.index("a"), block.ids.index("b")
    # b appears at frame 2 (t = 0.1 s): before it, its motion is traced back at its acceleration, v0 = 20 - 2 STEP,
    # x0 = 1 - STEP (v0 + 20) / 2 at t = 0.05 s; 0.01 s later: x0 + v0 0.01 + 2 0.01^2 / 2 (hand-computed).
    v_back = 20.0 - 2.0 * STEP
    assert block.x[0, b] == pytest.approx(1.0 - STEP * 0.5 * (v_back + 20.0) + v_back * 0.01 + 0.5 * 2.0 * 0.01**2,
                                          abs=1e-12)
    assert block.v[0, b] == pytest.approx(v_back + 2.0 * 0.01, abs=1e-12)
    # a is missing from frame 3 (t = 0.15 s): gone for the interval that ends there, at rest far before the deck.
    assert block.x[3, a] == -1e6 and block.v[3, a] == 0.0 and block.a[3, a] == 0.0
    assert block.x[2, a] == 10.5


def test_block_is_numpys_formula_bit_for_bit() -> None:
    rng = np.random.default_rng(5)
    traffic = FrameTraffic(STEP, 40.0, {"car": CAR})
    rows = []
    for _k in range(30):
        rows.append([(f"v{i}", rng.uniform(-5, 45), rng.uniform(-2, 2), rng.uniform(0, 30), rng.uniform(-3, 3))
                     for i in range(6) if rng.random() < 0.8])
    frames_of(traffic, rows)
    times = np.arange(1, 251) * 0.005 + STEP
    block = traffic.block(times)
    # Reference: the same motion as numpy array operations (the implementation this kernel replaced).
    frames = traffic.frames[1:]
    ids = list(dict.fromkeys(i for f in frames for i in f.ids))
    FX, FV, FA = (np.zeros((len(frames), len(ids))) for _ in range(3))
    seen = np.zeros((len(frames), len(ids)), dtype=bool)
    for r, f in enumerate(frames):
        cols = [ids.index(i) for i in f.ids]
        FX[r, cols], FV[r, cols], FA[r, cols], seen[r, cols] = f.x, f.v, f.a, True
    v1, a1, x1, had = FV[1:], FA[1:], FX[1:], seen[:-1]
    v0 = np.where(had, FV[:-1], v1 - a1 * STEP)
    x0 = np.where(had, FX[:-1], x1 - STEP * 0.5 * (v0 + v1))
    acc = (v1 - v0) / STEP
    gap = x1 - (x0 + STEP * 0.5 * (v0 + v1))
    r_of = np.ceil(times / STEP - 1e-9).astype(np.int64) - 2
    tau = (times - np.array([f.t for f in frames])[r_of])[:, None]
    X = x0[r_of] + v0[r_of] * tau + 0.5 * acc[r_of] * tau**2 + gap[r_of] * tau / STEP
    V = v0[r_of] + acc[r_of] * tau + gap[r_of] / STEP
    present = seen[1:][r_of]
    cols = [ids.index(i) for i in block.ids]
    assert np.array_equal(block.x, np.where(present, X, -1e6)[:, cols])
    assert np.array_equal(block.v, np.where(present, V, 0.0)[:, cols])
    assert np.array_equal(block.a, np.where(present, acc[r_of], 0.0)[:, cols])


def test_a_vehicle_turning_off_the_deck_keeps_the_lane_it_had_on_it_for_the_block() -> None:
    # One lateral offset per block and contact point: where it was at its last frame on the deck's length, not
    # where it turned to after it (x = 40.3 m, 2.5 m to the side, is past the deck's end).
    traffic = FrameTraffic(STEP, 40.0, {"car": CAR})
    frames_of(traffic, [[("c", 39.0, -1.6, 10.0, 0.0)], [("c", 39.5, -1.6, 10.0, 0.0)],
                        [("c", 40.0, -1.7, 10.0, 0.0)], [("c", 40.3, -4.1, 6.0, 0.0)]])
    block = traffic.block(np.arange(1, 41) * 0.005)
    assert block.y.tolist() == [-1.7]


def test_paths_are_the_quadratic_through_three_frames_exact_on_a_parabola_and_a_straight_lane() -> None:
    """Followed paths (a deck given by its modes): between frames r and r + 1 the lane is the quadratic in x
    through frames r - 1, r and r + 1 (docs/theory.md §13.4), so a parabolic lane y = c0 + c1 x + c2 x^2 comes
    out exactly (value, slope, curvature: closed form, to round-off 1e-12) and a straight lane as its y with
    zero slope and curvature, to the bit."""
    c0, c1, c2 = 1.2, 0.05, 0.004
    def lane(x: float) -> float: return c0 + c1 * x + c2 * x * x
    traffic = FrameTraffic(STEP, 40.0, {"car": CAR})
    traffic.follow_paths()
    frames_of(traffic, [[("c", 20.0 * k * STEP, lane(20.0 * k * STEP), 20.0, 0.0),
                         ("s", 15.0 * k * STEP, -1.6, 15.0, 0.0)] for k in range(1, 21)])
    times = np.arange(1, 181) * 0.005 + 2 * STEP
    block = traffic.block(times)
    assert block.path is not None and block.path.shape == (180, 2, 5)
    x = block.x[:, 0]
    np.testing.assert_allclose(block.path[:, 0, 0], lane(x), rtol=0, atol=1e-12)
    np.testing.assert_allclose(block.path[:, 0, 2], c1 + 2 * c2 * x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(block.path[:, 0, 4], 2 * c2, rtol=0, atol=1e-10)
    assert np.all(block.path[:, :, 1] == 1.0) and np.all(block.path[:, :, 3] == 0.0)
    assert np.all(block.path[:, 1, 0] == -1.6) and np.all(block.path[:, 1, [2, 4]] == 0.0)
    traffic_plain = FrameTraffic(STEP, 40.0, {"car": CAR})  # not asked: no paths, the same block otherwise
    frames_of(traffic_plain, [[("c", 20.0 * k * STEP, lane(20.0 * k * STEP), 20.0, 0.0),
                               ("s", 15.0 * k * STEP, -1.6, 15.0, 0.0)] for k in range(1, 21)])
    plain = traffic_plain.block(times)
    assert plain.path is None and np.array_equal(plain.x, block.x) and np.array_equal(plain.y, block.y)
