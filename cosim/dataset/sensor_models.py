"""Monitoring sensors: what a real instrument makes of the simulated response (docs/analysis.md §4).

A sensor samples the logged history at its own rate after an anti-aliasing
low-pass filter (``scipy.signal.resample_poly``: a Kaiser-windowed FIR filter
at the new Nyquist frequency, applied with zero phase), adds white Gaussian
noise of a given RMS from a seeded generator and rounds to its resolution
(quantisation). Each instrument type reads one quantity.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

__all__ = ["SENSOR_TYPES", "measure"]

#: Instrument types and the quantity each reads.
SENSOR_TYPES: dict[str, str] = {"accelerometer": "acceleration", "strain_gauge": "strain",
                                "displacement": "displacement"}


def measure(values: npt.ArrayLike, rate_in: float, rate_out: float, noise: float, resolution: float,
            rng: np.random.Generator) -> npt.NDArray[np.float64]:
    """The instrument's samples of a history sampled at ``rate_in`` (Hz): filtered, resampled, noisy, quantised.

    Args:
        values: the history (SI unit of the quantity), evenly sampled.
        rate_in, rate_out: the history's and the instrument's sampling rates, Hz (rate_out <= rate_in).
        noise: RMS of the white Gaussian noise, same unit (0: none).
        resolution: quantisation step, same unit (0: none).
        rng: the generator of the noise (seeded by the caller).

    Raises:
        ConfigError: rate_out above rate_in, or a negative noise or resolution.
    """
    x = np.asarray(values, dtype=float)
    if not 0 < rate_out <= rate_in * (1 + 1e-12):
        raise ConfigError(f"a sensor's rate_hz must be > 0 and at most the simulation's logging rate, "
                          f"{rate_in:g} Hz (got {rate_out:g})")
    if noise < 0 or resolution < 0:
        raise ConfigError("a sensor's noise and resolution must be >= 0")
    ratio = Fraction(rate_out / rate_in).limit_denominator(1000)
    if ratio != 1:
        from scipy.signal import resample_poly

        x = resample_poly(x, ratio.numerator, ratio.denominator)
    if noise > 0:
        x = x + rng.normal(0.0, noise, size=len(x))
    if resolution > 0:
        x = np.round(x / resolution) * resolution
    return x
