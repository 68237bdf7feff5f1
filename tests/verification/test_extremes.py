"""Return levels against fits of synthetic data with known distributions (docs/analysis.md).

The true return level of a known law is its quantile; the fitted one must be
near it, the bootstrap interval must hold it, and for the Gumbel law the
interval's width must match the maximum-likelihood asymptotic variance
(Kite 1977: var x_T = beta^2/n (1.1087 + 0.5140 y + 0.6079 y^2), y = -ln(-ln(1 - 1/T))).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from cosim.analysis import (
    SECONDS_PER_YEAR,
    block_maxima,
    fit_block_maxima,
    fit_peaks_over_threshold,
    peaks_over_threshold,
)
from cosim.errors import ConfigError

DAY = 86400.0


def test_gumbel_daily_maxima_give_the_1000_year_value_within_its_interval():
    mu, beta, n = 100.0, 10.0, 400
    maxima = stats.gumbel_r.rvs(loc=mu, scale=beta, size=n, random_state=np.random.default_rng(3))
    fit = fit_block_maxima(maxima, DAY, 1000.0, distribution="gumbel", bootstrap=300, seed=5)
    blocks = 1000.0 * SECONDS_PER_YEAR / DAY
    y = -np.log(-np.log(1 - 1 / blocks))
    truth = mu + beta * y
    se = beta / np.sqrt(n) * np.sqrt(1.1087 + 0.5140 * y + 0.6079 * y**2)
    assert abs(fit.value - truth) < 2.5 * se  # a fit of 400 maxima: within 2.5 standard errors
    assert fit.lower < truth < fit.upper
    assert (fit.upper - fit.lower) / (2 * 1.96 * se) == pytest.approx(1.0, abs=0.2)  # bootstrap vs asymptotics
    assert fit.level([1000.0])[0] == pytest.approx(fit.value)


def test_gev_maxima_give_a_known_quantile():
    xi, loc, scale = 0.1, 50.0, 5.0
    maxima = stats.genextreme.rvs(-xi, loc=loc, scale=scale, size=500, random_state=np.random.default_rng(11))
    # One block a year: the 50-year level is the 1 - 1/50 quantile.
    fit = fit_block_maxima(maxima, SECONDS_PER_YEAR, 50.0, distribution="gev", bootstrap=40, seed=2)
    truth = stats.genextreme.ppf(1 - 1 / 50, -xi, loc=loc, scale=scale)
    assert fit.parameters["xi"] == pytest.approx(xi, abs=0.08)  # 500 maxima: the shape's standard error is ~0.04
    assert fit.value == pytest.approx(truth, rel=0.05)
    assert fit.lower < truth < fit.upper


def test_peaks_over_threshold_give_the_known_return_level():
    xi, sigma, u = -0.1, 5.0, 30.0
    record = 200 * DAY  # 2 peaks a day above the threshold
    excess = stats.genpareto.rvs(xi, scale=sigma, size=400, random_state=np.random.default_rng(4))
    fit = fit_peaks_over_threshold(excess, u, record, 1.0, bootstrap=60, seed=3)
    rate = 400 * SECONDS_PER_YEAR / record
    truth = u + stats.genpareto.ppf(1 - 1 / (rate * 1.0), xi, scale=sigma)  # 730 peaks a year
    assert fit.rate == pytest.approx(rate)
    assert fit.value == pytest.approx(truth, rel=0.05)
    assert fit.lower < truth < fit.upper


def test_block_maxima_and_clusters_of_a_record():
    t = np.arange(0.0, 10.0, 0.5)
    values = np.arange(len(t), dtype=float) % 7
    assert block_maxima(t, values, 2.5).tolist() == [4.0, 6.0, 6.0]  # the last partial block is dropped
    # Two passages above 5: 5.5, 6, 5.2 close together, then 7 far away: two clusters.
    t = np.array([0.0, 1.0, 1.1, 1.2, 5.0, 9.0])
    x = np.array([0.0, 5.5, 6.0, 5.2, 1.0, 7.0])
    assert peaks_over_threshold(t, x, 5.0, separation=0.5).tolist() == pytest.approx([1.0, 2.0])
    with pytest.raises(ConfigError, match="at least 5"):
        fit_block_maxima([1.0, 2.0, 3.0], DAY)
    with pytest.raises(ConfigError, match="gev or gumbel"):
        fit_block_maxima(np.arange(10.0), DAY, distribution="gpd")
