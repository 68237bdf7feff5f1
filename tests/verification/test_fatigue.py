"""Rainflow counting, S-N curves and Miner damage against hand calculations and an independent library.

The independent count is fatpack's rainflow (its own four-point algorithm) on
the reversals of the same history, with fatpack's own EN 1993-1-9 tri-linear
curve for the damage.
"""
from __future__ import annotations

import math

import fatpack
import numpy as np
import pytest

from cosim.analysis import SECONDS_PER_YEAR, SNCurve, count_cycles, fatigue, miner_damage, sn_curve, sn_curve_names
from cosim.errors import ConfigError

MPA = 1e6


def _reversals(y):
    """Turning points of a history (the first and last samples included)."""
    y = np.asarray(y, float)
    keep = [0]
    for i in range(1, len(y) - 1):
        if (y[i] - y[keep[-1]]) * (y[i + 1] - y[i]) < 0:
            keep.append(i)
        elif y[i] == y[keep[-1]]:
            continue
    keep.append(len(y) - 1)
    return y[keep]


def _fatpack_cycles(y):
    """(ranges, counts) by fatpack: full cycles count 1, the residue's ranges 1/2."""
    cycles, residue = fatpack.find_rainflow_cycles(_reversals(y))
    ranges = np.abs(cycles[:, 1] - cycles[:, 0]) if len(cycles) else np.zeros(0)
    half = np.abs(np.diff(residue))
    return np.concatenate([ranges, half]), np.concatenate([np.ones(len(ranges)), 0.5 * np.ones(len(half))])


def test_the_astm_example_history_has_its_published_cycles():
    # ASTM E1049-85 (2017), Fig. 6 / §5.4.4: ranges 3 (0.5), 4 (1.5), 6 (0.5), 8 (1.0), 9 (0.5).
    cycles = count_cycles([-2, 1, -3, 5, -1, 3, -4, 4, -2])
    found: dict[float, float] = {}
    for r, n in zip(cycles.ranges, cycles.counts):
        found[float(r)] = found.get(float(r), 0.0) + float(n)
    assert found == {3.0: 0.5, 4.0: 1.5, 6.0: 0.5, 8.0: 1.0, 9.0: 0.5}


def test_en1993_curve_has_its_knee_and_cut_off():
    curve = sn_curve("EN1993-1-9:71")
    # EN 1993-1-9 Fig. 7.1: Delta sigma_D = (2/5)^(1/3) Delta sigma_C = 52.3 MPa at 5e6, Delta sigma_L =
    # (5/100)^(1/5) Delta sigma_D = 28.7 MPa at 1e8.
    assert curve.ds_knee == pytest.approx(71 * MPA * (2 / 5) ** (1 / 3), rel=1e-12)
    assert curve.ds_cutoff == pytest.approx(curve.ds_knee * 0.05 ** 0.2, rel=1e-12)
    n = curve.cycles_to_failure([71 * MPA, curve.ds_knee, 1.0001 * curve.ds_cutoff, 0.999 * curve.ds_cutoff])
    assert n[0] == pytest.approx(2e6, rel=1e-12)
    assert n[1] == pytest.approx(5e6, rel=1e-12)
    assert n[2] == pytest.approx(1e8 / 1.0001**5, rel=1e-9)
    assert n[3] == math.inf
    # EN 1992-1-1 Table 6.3N, straight bars: N* = 1e6 at 162.5 MPa, k1 = 5 above, k2 = 9 below, no cut-off.
    bars = sn_curve("EN1992-1-1:reinforcing-straight")
    assert bars.cycles_to_failure([162.5 * MPA, 2 * 162.5 * MPA, 0.5 * 162.5 * MPA]) == pytest.approx(
        [1e6, 1e6 / 2**5, 1e6 * 2**9], rel=1e-12)
    assert len(sn_curve_names()) == 14 + 8
    with pytest.raises(ConfigError, match="unknown S-N curve"):
        sn_curve("EN1993-1-9:72")


def test_block_loading_has_the_hand_calculated_damage():
    curve = sn_curve("EN1993-1-9:80")
    # 1000 cycles of 100 MPa, 20000 of 50 MPa (below the knee, 58.9 MPa), 1e5 of 20 MPa (below the cut-off).
    blocks = [(100.0, 1000), (50.0, 20000), (20.0, 100000)]
    history = np.concatenate([np.tile([0.0, a], n) for a, n in blocks] + [[0.0]]) * MPA
    cycles = count_cycles(history)
    # Hand: N = 2e6 (80/100)^3 above the knee; N = 5e6 (ds_D/50)^5 below it with ds_D = 80 (2/5)^(1/3).
    ds_d = 80 * (2 / 5) ** (1 / 3)
    expected = 1000 / (2e6 * (80 / 100) ** 3) + 20000 / (5e6 * (ds_d / 50) ** 5)
    assert miner_damage(cycles, curve) == pytest.approx(expected, rel=1e-3)  # the residue adds half a cycle
    result = fatigue(history, curve, duration=3600.0)
    assert result.damage_per_year == pytest.approx(result.damage * SECONDS_PER_YEAR / 3600.0, rel=1e-12)
    by_volume = fatigue(history, curve, duration=3600.0, vehicles=50, vehicles_per_year=2e6)
    assert by_volume.damage_per_year == pytest.approx(result.damage * 2e6 / 50, rel=1e-12)
    # Equivalent range with slope 3: (sum n ds^3 / sum n)^(1/3).
    counts, ranges = cycles.counts, cycles.ranges
    assert result.equivalent_stress_range == pytest.approx((np.sum(counts * ranges**3) / counts.sum()) ** (1 / 3))


def test_the_same_damage_from_fatpacks_independent_count():
    rng = np.random.default_rng(7)
    # A bridge-like history: quiet traffic noise plus passages of vehicles of random weight.
    t = np.arange(0, 600, 0.01)
    history = 2 * MPA * rng.standard_normal(len(t))
    for t0 in rng.uniform(0, 590, 60):
        history += rng.uniform(20, 90) * MPA * np.exp(-((t - t0) / 0.8) ** 2)
    ranges, counts = _fatpack_cycles(history)
    reference = fatpack.TriLinearEnduranceCurve(71.0).find_miner_sum(np.column_stack([ranges / MPA, counts]))
    ours = fatigue(history, sn_curve("EN1993-1-9:71"), duration=600.0)
    assert ours.cycles == pytest.approx(counts.sum(), rel=1e-12)
    assert ours.damage == pytest.approx(reference, rel=1e-9)


def test_a_user_curve_and_bad_curves():
    one_slope = SNCurve("mine", 100 * MPA, 1e6, 4.0, 4.0, 1e6)
    assert one_slope.cycles_to_failure([50 * MPA])[0] == pytest.approx(1e6 * 2**4)
    with pytest.raises(ConfigError, match="n_cutoff"):
        SNCurve("bad", 100 * MPA, 1e6, 3.0, 5.0, 5e6, 1e6)
    with pytest.raises(ConfigError, match="m1"):
        SNCurve("bad", 100 * MPA, 1e6, -3.0, 5.0, 5e6)
    assert sn_curve("EN1993-1-9:71", partial_factor=1.35).ds_knee == pytest.approx(
        sn_curve("EN1993-1-9:71").ds_knee / 1.35)
