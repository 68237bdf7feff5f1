"""Lateral wander and the per-vehicle random numbers (issue 25, items 3 and 8).

Reference: EN 1991-2:2003 4.6.1(5), Figure 4.6, the frequency distribution of the transverse location of the
centre line of vehicles: 50 % on the lane's centre line, 18 % at each of +-0.1 m, 7 % at each of +-0.2 m.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from cosim.core.loads import EN1991_2_FREQUENCIES, EN1991_2_OFFSETS, uniforms, wander
from cosim.errors import ConfigError

DRAWS = 10_000


def test_en1991_2_wander_has_the_standards_frequencies():
    # chi-square on 10,000 draws against Figure 4.6's frequencies, p > 0.01; each within 3 standard errors
    drawn = [wander(9, f"lorry{i}") for i in range(DRAWS)]
    counts = np.array([drawn.count(x) for x in EN1991_2_OFFSETS])
    assert counts.sum() == DRAWS
    expected = np.array(EN1991_2_FREQUENCIES) * DRAWS
    assert stats.chisquare(counts, expected).pvalue > 0.01
    p = np.array(EN1991_2_FREQUENCIES)
    assert np.all(np.abs(counts / DRAWS - p) < 3 * np.sqrt(p * (1 - p) / DRAWS))
    assert EN1991_2_FREQUENCIES == (0.07, 0.18, 0.50, 0.18, 0.07) and sum(EN1991_2_FREQUENCIES) == pytest.approx(1)


def test_normal_wander_has_its_standard_deviation():
    drawn = np.array([wander(9, f"car{i}", "normal", sd=0.25) for i in range(DRAWS)])
    assert stats.kstest(drawn, stats.norm(0.0, 0.25).cdf).pvalue > 0.01
    limited = np.array([wander(9, f"car{i}", "normal", sd=0.25, limit=0.3) for i in range(DRAWS)])
    assert np.abs(limited).max() <= 0.3
    assert stats.kstest(limited, stats.truncnorm(-1.2, 1.2, scale=0.25).cdf).pvalue > 0.01


def test_wander_is_its_own_stream_independent_of_the_load():
    ids = [f"v{i}" for i in range(DRAWS)]
    load = np.array([uniforms(4, v, "load", 1)[0] for v in ids])
    side = np.array([uniforms(4, v, "wander", 1)[0] for v in ids])
    assert abs(stats.pearsonr(load, side).statistic) < 3 / np.sqrt(DRAWS)
    assert wander(4, "v1") == wander(4, "v1")


def test_the_uniforms_are_uniform_and_fixed():
    u = np.array([uniforms(0, f"id{i}", "load", 4) for i in range(DRAWS)])
    assert all(stats.kstest(u[:, k], "uniform").pvalue > 0.01 for k in range(4))
    # SHAKE-256 (FIPS 202) of b"cosim-loads\0" b"0\0" b"load\0" b"id0": fixed by the standard, in every process
    assert uniforms(0, "id0", "load", 1)[0] == pytest.approx(FIRST, abs=0)


FIRST = 0.5391882476938504  # (word >> 11) / 2**53 of the first 8 bytes, little-endian


def test_bad_wander_arguments():
    with pytest.raises(ConfigError, match="wander: unknown kind 'uniform'"):
        wander(1, "v", "uniform")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="wander: sd must be a number > 0 m"):
        wander(1, "v", "normal")
    with pytest.raises(ConfigError, match="wander: limit must be a number > 0 m"):
        wander(1, "v", "normal", sd=0.2, limit=-1.0)
    with pytest.raises(ConfigError, match="seed: expected an integer >= 0"):
        wander(1.5, "v")  # type: ignore[arg-type]
