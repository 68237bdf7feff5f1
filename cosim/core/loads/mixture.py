"""Truncated normal mixtures: the distribution behind every property of Grave's model (docs/loads.md).

BTLS draws each property from a mixture of up to three normals and redraws
(mode and value) until the value falls inside physical bounds
(``VehicleGenGrave.cpp``: GVW in [35, 1000] x 100 kg, spacings in [0.5, 200] dm,
...). That rejection loop samples exactly the mixture truncated to the bounds:
the density ``sum_k w_k phi_k(x) / Z`` on ``[lower, upper]``. cosim samples
the same distribution without a loop, from two uniforms: the mode with
probability ``w_k P_k([lower, upper]) / Z``, then the value by the inverse
CDF of that mode truncated to the bounds. So a draw uses a fixed number of
uniforms (it never depends on how many tries a rejection would take) and
always ends.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from statistics import NormalDist

import numpy as np
import numpy.typing as npt
from scipy.special import ndtr

_STANDARD = NormalDist()

#: Probability inside the bounds below which a mode is treated as having none (it is never drawn).
NEGLIGIBLE = 1e-12


@dataclass(frozen=True)
class Mode:
    """One normal of a mixture.

    Attributes:
        weight: its weight in the mixture as written (before truncation), in [0, 1].
        mean, sd: mean and standard deviation, in the mixture's unit; sd 0 is a point mass.
    """

    weight: float
    mean: float
    sd: float


@dataclass(frozen=True)
class Mixture:
    """A mixture of normals truncated to ``[lower, upper]``, in one unit (N, m, m/s or a share).

    Attributes:
        modes: the normals (weights as written; zero-weight modes are kept but never drawn).
        lower, upper: the truncation bounds (``-inf``/``inf`` for none).
        unit: the unit of values ("N", "m", "m/s", "1").
    """

    modes: tuple[Mode, ...]
    lower: float
    upper: float
    unit: str

    def mode_probabilities(self) -> npt.NDArray[np.float64]:
        """Probability of each mode after truncation (they add up to 1), from its weight and its mass
        inside the bounds."""
        mass = np.array([m.weight * _inside(m, self.lower, self.upper) for m in self.modes])
        total = mass.sum()
        if not total > 0.0:
            raise ValueError("the mixture has no probability inside its bounds")
        return mass / total

    def mass_inside(self) -> float:
        """Probability of the untruncated mixture (weights normalised) inside ``[lower, upper]``."""
        weights = sum(m.weight for m in self.modes)
        if weights <= 0.0:
            return 0.0
        return sum(m.weight * _inside(m, self.lower, self.upper) for m in self.modes) / weights

    def cdf(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The truncated mixture's CDF at ``x`` (what a Kolmogorov-Smirnov test compares draws with)."""
        x = np.asarray(x, dtype=float)
        out = np.zeros_like(x)
        for p, mode in zip(self.mode_probabilities(), self.modes):
            if p == 0.0:
                continue
            if mode.sd == 0.0:
                out += p * (x >= mode.mean)
                continue
            lo, hi = ndtr((self.lower - mode.mean) / mode.sd), ndtr((self.upper - mode.mean) / mode.sd)
            inner = (ndtr((np.clip(x, self.lower, self.upper) - mode.mean) / mode.sd) - lo) / (hi - lo)
            out += p * np.clip(inner, 0.0, 1.0)
        return np.clip(out, 0.0, 1.0)

    def moments(self) -> tuple[float, float]:
        """Mean and standard deviation of the truncated mixture (for the tests' checks of draws)."""
        probabilities = self.mode_probabilities()
        means, second = 0.0, 0.0
        for p, mode in zip(probabilities, self.modes):
            if p == 0.0:
                continue
            m, v = _truncated_moments(mode, self.lower, self.upper)
            means += p * m
            second += p * (v + m * m)
        return float(means), math.sqrt(max(float(second - means * means), 0.0))

    def sampler(self) -> MixtureSampler:
        """The precomputed form that draws from two uniforms (built once per mixture and kept)."""
        return _sampler(self)


@lru_cache(maxsize=4096)
def _sampler(mixture: Mixture) -> MixtureSampler:
    return MixtureSampler.of(mixture)


def _inside(mode: Mode, lower: float, upper: float) -> float:
    """Probability of one normal inside [lower, upper]."""
    if mode.sd == 0.0:
        return 1.0 if lower <= mode.mean <= upper else 0.0
    a, b = (lower - mode.mean) / mode.sd, (upper - mode.mean) / mode.sd
    if a > 0.0:  # both bounds in the upper tail: the lower tail of the mirror image keeps the precision
        return float(ndtr(-a) - ndtr(-b))
    return float(ndtr(b) - ndtr(a))


def _truncated_moments(mode: Mode, lower: float, upper: float) -> tuple[float, float]:
    """Mean and variance of one normal truncated to [lower, upper], in closed form (Johnson, Kotz and
    Balakrishnan, Continuous Univariate Distributions 1, 2nd ed., 13.10.1): with the standardised bounds a, b,
    Z = Phi(b) - Phi(a), the mean is mu + sd (phi(a) - phi(b)) / Z and the variance
    sd^2 (1 + (a phi(a) - b phi(b)) / Z - ((phi(a) - phi(b)) / Z)^2). Bounds in the upper tail are mirrored
    to the lower one, where Phi keeps its precision. (scipy.stats' truncnorm gives the same, but importing
    scipy.stats costs half a second of every run that draws loads.)"""
    if mode.sd == 0.0:
        return mode.mean, 0.0
    a, b = (lower - mode.mean) / mode.sd, (upper - mode.mean) / mode.sd
    sign = 1.0
    if a > 0.0:
        a, b, sign = -b, -a, -1.0
    z = float(ndtr(b) - ndtr(a))
    pdf_a, pdf_b = _STANDARD.pdf(a) if math.isfinite(a) else 0.0, _STANDARD.pdf(b) if math.isfinite(b) else 0.0
    shift = (pdf_a - pdf_b) / z
    spread = ((a * pdf_a if pdf_a else 0.0) - (b * pdf_b if pdf_b else 0.0)) / z
    return mode.mean + sign * mode.sd * shift, mode.sd**2 * max(1.0 + spread - shift * shift, 0.0)


@dataclass(frozen=True)
class MixtureSampler:
    """A :class:`Mixture` ready to draw: cumulative mode probabilities and each mode's truncated CDF
    bounds, so a draw is one search and one inverse normal CDF.

    Attributes:
        cumulative: cumulative mode probabilities (last = 1).
        means, sds: each mode's mean and sd.
        flipped: per mode, whether it is sampled in its mirror image (bounds in its upper tail).
        cdf_lo, cdf_hi: per mode, the standard normal CDF at its (mirrored) standardised bounds.
        lower, upper: the truncation bounds.
    """

    cumulative: tuple[float, ...]
    means: tuple[float, ...]
    sds: tuple[float, ...]
    flipped: tuple[bool, ...]
    cdf_lo: tuple[float, ...]
    cdf_hi: tuple[float, ...]
    lower: float
    upper: float

    @classmethod
    def of(cls, mixture: Mixture) -> MixtureSampler:
        probabilities = mixture.mode_probabilities()
        flipped, lo, hi = [], [], []
        for mode in mixture.modes:
            if mode.sd == 0.0:
                flipped.append(False)
                lo.append(0.0)
                hi.append(1.0)
                continue
            a, b = (mixture.lower - mode.mean) / mode.sd, (mixture.upper - mode.mean) / mode.sd
            flip = a > 0.0
            if flip:
                a, b = -b, -a
            flipped.append(flip)
            lo.append(float(ndtr(a)))
            hi.append(float(ndtr(b)))
        cumulative = np.cumsum(probabilities)
        cumulative[int(np.flatnonzero(probabilities > 0.0)[-1]):] = 1.0  # rounding never reaches a null mode
        return cls(tuple(float(c) for c in cumulative), tuple(m.mean for m in mixture.modes),
                   tuple(m.sd for m in mixture.modes), tuple(flipped), tuple(lo), tuple(hi),
                   mixture.lower, mixture.upper)

    def draw(self, u_mode: float, u_value: float) -> float:
        """The value for two uniforms in [0, 1): ``u_mode`` picks the mode, ``u_value`` the quantile."""
        k = 0
        last = len(self.cumulative) - 1
        while k < last and (self.cumulative[k] <= u_mode or self.cumulative[k] == 0.0):
            k += 1
        sd = self.sds[k]
        if sd == 0.0:
            return self.means[k]
        p = self.cdf_lo[k] + u_value * (self.cdf_hi[k] - self.cdf_lo[k])
        z = _STANDARD.inv_cdf(min(max(p, 1e-300), 1.0 - 1e-16))
        value = self.means[k] + sd * (-z if self.flipped[k] else z)
        return min(max(value, self.lower), self.upper)
