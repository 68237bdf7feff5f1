"""What an engineer decides with the responses: fatigue damage and characteristic extremes (layer 2).

- :mod:`cosim.analysis.fatigue`: rainflow counting (the ``rainflow`` package,
  ASTM E1049-85), S-N curves by name (EN 1993-1-9 detail categories, EN
  1992-1-1 reinforcing and prestressing steel) or given, Miner damage, damage
  per year and the equivalent stress range;
- :mod:`cosim.analysis.extremes`: block maxima (GEV, Gumbel) and peaks over
  threshold (GPD) by ``scipy.stats``, return levels with bootstrap confidence
  bounds.

Pure functions of arrays: they import :mod:`cosim.errors` and libraries only.
"""
from cosim.analysis.extremes import (
    DISTRIBUTIONS,
    ReturnLevel,
    block_maxima,
    fit_block_maxima,
    fit_peaks_over_threshold,
    peaks_over_threshold,
)
from cosim.analysis.fatigue import (
    SECONDS_PER_YEAR,
    Cycles,
    FatigueResult,
    SNCurve,
    count_cycles,
    fatigue,
    miner_damage,
    sn_curve,
    sn_curve_names,
    turning_points,
)

__all__ = [
    "DISTRIBUTIONS",
    "SECONDS_PER_YEAR",
    "Cycles",
    "FatigueResult",
    "ReturnLevel",
    "SNCurve",
    "block_maxima",
    "count_cycles",
    "fatigue",
    "fit_block_maxima",
    "fit_peaks_over_threshold",
    "miner_damage",
    "peaks_over_threshold",
    "sn_curve",
    "sn_curve_names",
    "turning_points",
]
