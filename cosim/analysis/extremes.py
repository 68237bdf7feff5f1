"""Characteristic extremes: block maxima (GEV, Gumbel) and peaks over threshold (GPD) with return levels.

The fits are maximum likelihood by ``scipy.stats``; confidence bounds come
from a parametric bootstrap (samples drawn from the fitted distribution with a
recorded seed and refitted). Return periods are in years (EN 1990 / EN
1991-2: the characteristic traffic load effect has a return period of 1000
years, a 10 % probability of exceedance in 100 years). The assumptions
(stationary traffic, independent maxima, a block long enough for the
asymptotic law) are the user's to judge; docs/analysis.md states them.

Sign: maxima of the values given; for the largest sagging moment give the
moment, for the largest compression give ``-stress``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .fatigue import SECONDS_PER_YEAR

__all__ = [
    "DISTRIBUTIONS",
    "ReturnLevel",
    "block_maxima",
    "fit_block_maxima",
    "fit_peaks_over_threshold",
    "peaks_over_threshold",
]

#: Block-maximum laws and the peaks-over-threshold law.
DISTRIBUTIONS: tuple[str, ...] = ("gev", "gumbel", "gpd")
#: Fewest maxima or exceedances a fit accepts.
MIN_SAMPLES = 5


@dataclass(frozen=True)
class ReturnLevel:
    """A fitted extreme-value law and its value at a return period.

    Attributes:
        method: "block maxima" or "peaks over threshold".
        distribution: gev | gumbel | gpd.
        parameters: the fitted parameters by name (GEV/GPD shape ``xi`` in the climate convention:
            xi > 0 heavy tail; scipy's ``c`` is ``-xi`` for the GEV, ``xi`` for the GPD).
        return_period: years.
        value: the return level (the value exceeded once per return period on average).
        lower, upper: the bounds of the ``confidence`` interval (parametric bootstrap).
        confidence: e.g. 0.95.
        samples: the maxima (block maxima) or exceedances (peaks over threshold) fitted.
        block: block length, s (block maxima) or the record's length, s (peaks over threshold).
        rate: exceedances per year (peaks over threshold); blocks per year (block maxima).
        threshold: the threshold (peaks over threshold), else None.
        seed: the bootstrap's seed.
    """

    method: str
    distribution: str
    parameters: dict[str, float]
    return_period: float
    value: float
    lower: float
    upper: float
    confidence: float
    samples: npt.NDArray[np.float64]
    block: float
    rate: float
    threshold: float | None
    seed: int

    def level(self, return_period: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The fitted law's return level at other return periods (years)."""
        return _level(self.distribution, self.parameters, np.asarray(return_period, float), self.rate,
                      self.threshold)


def _level(distribution: str, p: dict[str, float], years: np.ndarray, rate: float,
           threshold: float | None) -> np.ndarray:
    from scipy import stats

    if distribution == "gpd":
        assert threshold is not None
        m = np.maximum(rate * years, 1.0)  # exceedances in the period (fewer than one: the threshold itself)
        return threshold + stats.genpareto.ppf(1.0 - 1.0 / m, p["xi"], loc=0.0, scale=p["scale"])
    blocks = rate * years  # the return period in blocks
    prob = 1.0 - 1.0 / np.maximum(blocks, 1.0 + 1e-12)
    if distribution == "gumbel":
        return stats.gumbel_r.ppf(prob, loc=p["loc"], scale=p["scale"])
    return stats.genextreme.ppf(prob, -p["xi"], loc=p["loc"], scale=p["scale"])


def _check(return_period: float, confidence: float, n_boot: int) -> None:
    if not (math.isfinite(return_period) and return_period > 0):
        raise ConfigError(f"extremes: `return_period` must be > 0 years (got {return_period!r})")
    if not 0 < confidence < 1:
        raise ConfigError(f"extremes: `confidence` must lie in (0, 1) (got {confidence!r})")
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 10:
        raise ConfigError(f"extremes: `bootstrap` must be an integer >= 10 (got {n_boot!r})")


def _fit(distribution: str, data: np.ndarray) -> dict[str, float]:
    from scipy import stats

    if distribution == "gumbel":
        loc, scale = stats.gumbel_r.fit(data)
        return {"loc": float(loc), "scale": float(scale)}
    if distribution == "gev":
        c, loc, scale = stats.genextreme.fit(data)
        return {"xi": float(-c), "loc": float(loc), "scale": float(scale)}
    c, _, scale = stats.genpareto.fit(data, floc=0.0)
    return {"xi": float(c), "scale": float(scale)}


def _draw(distribution: str, p: dict[str, float], n: int, rng: np.random.Generator) -> np.ndarray:
    from scipy import stats

    if distribution == "gumbel":
        return stats.gumbel_r.rvs(loc=p["loc"], scale=p["scale"], size=n, random_state=rng)
    if distribution == "gev":
        return stats.genextreme.rvs(-p["xi"], loc=p["loc"], scale=p["scale"], size=n, random_state=rng)
    return stats.genpareto.rvs(p["xi"], loc=0.0, scale=p["scale"], size=n, random_state=rng)


def _bootstrap(distribution: str, p: dict[str, float], n: int, years: float, rate: float, threshold: float | None,
               confidence: float, n_boot: int, seed: int) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    levels = np.empty(n_boot)
    for k in range(n_boot):
        levels[k] = float(_level(distribution, _fit(distribution, _draw(distribution, p, n, rng)),
                                 np.array([years]), rate, threshold)[0])
    levels = levels[np.isfinite(levels)]
    tail = (1.0 - confidence) / 2.0 * 100.0
    return float(np.percentile(levels, tail)), float(np.percentile(levels, 100.0 - tail))


def block_maxima(t: npt.ArrayLike, values: npt.ArrayLike, block: float) -> npt.NDArray[np.float64]:
    """The maximum of ``values`` in each whole block of ``block`` seconds of the record (a partial last block is
    dropped: its maximum belongs to a shorter block)."""
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    if not (math.isfinite(block) and block > 0):
        raise ConfigError(f"extremes: `block` must be > 0 s (got {block!r})")
    if len(t) == 0:
        return np.zeros(0)
    index = np.floor((t - t[0]) / block).astype(np.int64)
    whole = int(np.floor((t[-1] - t[0]) / block + 1e-9))
    out = np.full(whole, -np.inf)
    keep = index < whole
    np.maximum.at(out, index[keep], values[keep])
    return out[np.isfinite(out)]


def fit_block_maxima(maxima: npt.ArrayLike, block: float, return_period: float = 1000.0, *,
                     distribution: str = "gumbel", confidence: float = 0.95, bootstrap: int = 200,
                     seed: int = 1) -> ReturnLevel:
    """Fit a GEV or Gumbel law to block maxima (each of ``block`` seconds) and give its return level.

    The return period of ``R`` years is ``R * SECONDS_PER_YEAR / block`` blocks,
    and the return level is the quantile ``1 - 1/blocks`` of the fitted law. The
    maxima of a study's seeds are block maxima with the run's duration as block.

    Raises:
        ConfigError: fewer than 5 maxima, non-finite ones, or a bad setting.
    """
    data = np.asarray(maxima, dtype=float).ravel()
    if distribution not in ("gev", "gumbel"):
        raise ConfigError(f"extremes: block maxima need `distribution` gev or gumbel (got {distribution!r})")
    if not (math.isfinite(block) and block > 0):
        raise ConfigError(f"extremes: `block` must be > 0 s (got {block!r})")
    _check(return_period, confidence, bootstrap)
    if len(data) < MIN_SAMPLES or not np.all(np.isfinite(data)):
        raise ConfigError(f"extremes: need at least {MIN_SAMPLES} finite block maxima (got {len(data)}); "
                          "use shorter blocks, a longer record or more seeds")
    if np.ptp(data) == 0:
        raise ConfigError("extremes: every block maximum is the same: nothing to fit")
    params = _fit(distribution, data)
    rate = SECONDS_PER_YEAR / block
    value = float(_level(distribution, params, np.array([return_period]), rate, None)[0])
    lower, upper = _bootstrap(distribution, params, len(data), return_period, rate, None, confidence, bootstrap, seed)
    return ReturnLevel("block maxima", distribution, params, return_period, value, lower, upper, confidence, data,
                       block, rate, None, seed)


def peaks_over_threshold(t: npt.ArrayLike, values: npt.ArrayLike, threshold: float,
                         separation: float) -> npt.NDArray[np.float64]:
    """Cluster peaks above ``threshold``: exceedances closer than ``separation`` seconds form one cluster
    (one vehicle's passage, say), which keeps its largest value. Returns the peaks' excesses over the threshold."""
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    above = np.flatnonzero(values > threshold)
    if len(above) == 0:
        return np.zeros(0)
    breaks = np.flatnonzero(np.diff(t[above]) > separation) + 1
    return np.array([values[group].max() - threshold for group in np.split(above, breaks)])


def fit_peaks_over_threshold(excesses: npt.ArrayLike, threshold: float, record: float, return_period: float = 1000.0,
                             *, confidence: float = 0.95, bootstrap: int = 200, seed: int = 1) -> ReturnLevel:
    """Fit a generalised Pareto law to cluster-peak excesses over ``threshold`` in ``record`` seconds.

    With ``lambda`` exceedances per year (``len(excesses) * SECONDS_PER_YEAR / record``)
    the ``R``-year return level is the level exceeded once in ``lambda R``
    exceedances: ``u + GPD^-1(1 - 1/(lambda R))``.

    Raises:
        ConfigError: fewer than 5 excesses, or a bad setting.
    """
    data = np.asarray(excesses, dtype=float).ravel()
    _check(return_period, confidence, bootstrap)
    if not (math.isfinite(record) and record > 0):
        raise ConfigError(f"extremes: the record's length must be > 0 s (got {record!r})")
    if len(data) < MIN_SAMPLES or not np.all(np.isfinite(data)) or np.any(data < 0):
        raise ConfigError(f"extremes: need at least {MIN_SAMPLES} finite peaks over the threshold (got {len(data)}); "
                          "lower the threshold or give a longer record")
    params = _fit("gpd", data)
    rate = len(data) * SECONDS_PER_YEAR / record
    value = float(_level("gpd", params, np.array([return_period]), rate, threshold)[0])
    lower, upper = _bootstrap("gpd", params, len(data), return_period, rate, threshold, confidence, bootstrap, seed)
    return ReturnLevel("peaks over threshold", "gpd", params, return_period, value, lower, upper, confidence, data,
                       record, rate, threshold, seed)
