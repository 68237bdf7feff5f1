"""Fatigue of a stress history: rainflow counting, S-N curves, Miner damage, equivalent stress range.

Cycles are counted by the ``rainflow`` package (ASTM E1049-85, four-point
rule; the residue counts as half cycles). S-N curves are characteristic
curves by name, from EN 1993-1-9 (steel details: Table 8.1 categories with
slope 3 to ``N_C = 2e6``, the constant-amplitude limit at ``N_D = 5e6``, slope
5 to the cut-off at ``N_L = 1e8``, Figure 7.1) and EN 1992-1-1 (reinforcing
steel, Table 6.3N; prestressing steel, Table 6.4N: slopes ``k1``, ``k2``
meeting at ``N*``, no cut-off), or given by the user. docs/analysis.md
documents every rule used.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.checks import finite
from cosim.errors import ConfigError

__all__ = [
    "EN1992_CURVES",
    "EN1993_CATEGORIES",
    "SECONDS_PER_YEAR",
    "Cycles",
    "FatigueResult",
    "SNCurve",
    "count_cycles",
    "fatigue",
    "miner_damage",
    "sn_curve",
    "sn_curve_names",
    "turning_points",
]

#: A Julian year, s: what "per year" means here.
SECONDS_PER_YEAR = 365.25 * 86400.0
#: EN 1993-1-9, Table 8.1 (and Figure 7.1): detail categories, the reference strength at 2e6 cycles, MPa.
EN1993_CATEGORIES: tuple[int, ...] = (160, 140, 125, 112, 100, 90, 80, 71, 63, 56, 50, 45, 40, 36)
#: EN 1992-1-1, Table 6.3N (reinforcing steel) and Table 6.4N (prestressing steel): N*, k1, k2, the
#: characteristic stress range at N* (MPa).
EN1992_CURVES: dict[str, tuple[float, float, float, float]] = {
    "reinforcing-straight": (1e6, 5.0, 9.0, 162.5),  # straight and bent bars
    "reinforcing-welded": (1e7, 3.0, 5.0, 58.5),  # welded bars including tack welds, wire fabrics
    "reinforcing-splicing": (1e7, 3.0, 5.0, 35.0),  # splicing devices
    "pretensioning": (1e6, 5.0, 9.0, 185.0),
    "post-tensioning-single-strands": (1e6, 5.0, 9.0, 185.0),  # single strands in plastic ducts
    "post-tensioning-plastic-ducts": (1e6, 5.0, 10.0, 150.0),  # straight tendons, curved tendons in plastic ducts
    "post-tensioning-steel-ducts": (1e6, 5.0, 7.0, 120.0),  # curved tendons in steel ducts
    "prestressing-splicing": (1e6, 5.0, 5.0, 80.0),  # splicing devices
}
_MPA = 1e6


@dataclass(frozen=True)
class SNCurve:
    """A characteristic S-N curve with up to two slopes and an optional cut-off (stress ranges in Pa).

    ``N(ds) = n_ref (ds_ref / ds)^m1`` above the knee ``ds_knee`` (reached at ``n_knee``
    cycles), ``N(ds) = n_knee (ds_knee / ds)^m2`` below it, and infinitely many
    cycles below the cut-off reached at ``n_cutoff`` (none: the second slope goes on).

    Args:
        name: how reports name it.
        ds_ref: reference stress range, Pa (the detail category of EN 1993-1-9, Delta sigma_Rsk of EN 1992-1-1).
        n_ref: cycles at ``ds_ref``.
        m1, m2: slopes above and below the knee (m2 = m1: one slope).
        n_knee: cycles at the knee (the constant-amplitude limit of EN 1993-1-9, N* of EN 1992-1-1).
        n_cutoff: cycles at the cut-off, or None.
        partial_factor: gamma_Mf: the strengths are divided by it (1: characteristic).

    Raises:
        ConfigError: a non-positive or non-finite value, or n_cutoff <= n_knee.
    """

    name: str
    ds_ref: float
    n_ref: float
    m1: float
    m2: float
    n_knee: float
    n_cutoff: float | None = None
    partial_factor: float = 1.0

    def __post_init__(self) -> None:
        for key in ("ds_ref", "n_ref", "m1", "m2", "n_knee", "partial_factor"):
            finite(getattr(self, key), key, f"S-N curve {self.name}: ", above=0.0)
        if self.n_cutoff is not None and not (math.isfinite(self.n_cutoff) and self.n_cutoff > self.n_knee):
            raise ConfigError(f"S-N curve {self.name}: `n_cutoff` must be finite and > n_knee = {self.n_knee:g} "
                              f"(got {self.n_cutoff!r})")

    @property
    def ds_knee(self) -> float:
        """Stress range at the knee, Pa (after the partial factor)."""
        return self.ds_ref / self.partial_factor * (self.n_ref / self.n_knee) ** (1.0 / self.m1)

    @property
    def ds_cutoff(self) -> float:
        """Stress range at the cut-off, Pa (0 without one)."""
        if self.n_cutoff is None:
            return 0.0
        return self.ds_knee * (self.n_knee / self.n_cutoff) ** (1.0 / self.m2)

    def cycles_to_failure(self, stress_range: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Endurance N per stress range (Pa); infinite below the cut-off and for a zero range."""
        ds = np.abs(np.asarray(stress_range, dtype=float))
        knee = self.ds_knee
        with np.errstate(divide="ignore"):
            upper = self.n_knee * (knee / ds) ** self.m1
            lower = self.n_knee * (knee / ds) ** self.m2
        n = np.where(ds >= knee, upper, lower)
        return np.where((ds > 0) & (ds >= self.ds_cutoff), n, np.inf)


def sn_curve_names() -> list[str]:
    """Every S-N curve name :func:`sn_curve` knows."""
    return [f"EN1993-1-9:{c}" for c in EN1993_CATEGORIES] + [f"EN1992-1-1:{k}" for k in EN1992_CURVES]


def sn_curve(name: str, partial_factor: float = 1.0) -> SNCurve:
    """The characteristic S-N curve of that name (``EN1993-1-9:71``, ``EN1992-1-1:reinforcing-straight``, ...).

    Raises:
        ConfigError: an unknown name (the message lists the known ones).
    """
    standard, _, detail = str(name).partition(":")
    if standard == "EN1993-1-9" and detail.isdigit() and int(detail) in EN1993_CATEGORIES:
        # EN 1993-1-9, 7.1 and Figure 7.1: m = 3 to N_C = 2e6 and to the constant-amplitude limit at
        # N_D = 5e6, m = 5 below it to the cut-off at N_L = 1e8.
        return SNCurve(name, int(detail) * _MPA, 2e6, 3.0, 5.0, 5e6, 1e8, partial_factor)
    if standard == "EN1992-1-1" and detail in EN1992_CURVES:
        n_star, k1, k2, ds = EN1992_CURVES[detail]
        return SNCurve(name, ds * _MPA, n_star, k1, k2, n_star, None, partial_factor)
    raise ConfigError(f"unknown S-N curve {name!r}: expected one of {', '.join(sn_curve_names())}, "
                      "or give the curve's constants")


@dataclass(frozen=True)
class Cycles:
    """Rainflow cycles: ranges (Pa or the history's unit), means and counts (1 or 0.5 for the residue)."""

    ranges: npt.NDArray[np.float64]
    means: npt.NDArray[np.float64]
    counts: npt.NDArray[np.float64]

    @property
    def total(self) -> float:
        """Number of cycles (half cycles count 0.5)."""
        return float(self.counts.sum())


def count_cycles(history: npt.ArrayLike) -> Cycles:
    """Rainflow cycles of a history (ASTM E1049-85 by the ``rainflow`` package).

    Raises:
        ConfigError: a non-finite value in the history.
    """
    import rainflow

    values = np.asarray(history, dtype=float).ravel()
    if not np.all(np.isfinite(values)):
        raise ConfigError("the stress history holds a non-finite value: no cycles can be counted")
    rows = [(rng, mean, count) for rng, mean, count, _, _ in rainflow.extract_cycles(values)] if len(values) > 2 \
        else []
    if not rows:
        return Cycles(np.zeros(0), np.zeros(0), np.zeros(0))
    array = np.array(rows, dtype=float)
    return Cycles(array[:, 0], array[:, 1], array[:, 2])


def miner_damage(cycles: Cycles, curve: SNCurve) -> float:
    """Palmgren-Miner damage ``sum n_i / N(ds_i)`` of the cycles on the curve."""
    if len(cycles.ranges) == 0:
        return 0.0
    return float(np.sum(cycles.counts / curve.cycles_to_failure(cycles.ranges)))


@dataclass(frozen=True)
class FatigueResult:
    """The fatigue of one stress history.

    Attributes:
        curve: the S-N curve used.
        cycles: the number of rainflow cycles (half cycles count 0.5).
        damage: Miner damage of the history.
        damage_per_year: the damage of a year of this traffic (see :func:`fatigue` for the rule); None
            when the history saw no vehicle under the vehicle-count rule.
        equivalent_stress_range: ``(sum n_i ds_i^m1 / sum n_i)^(1/m1)``, Pa: the constant range that,
            repeated as many times, does the same damage on a one-slope curve of slope m1.
        max_stress_range: the largest range, Pa.
        scale_per_year: the factor from the history to a year.
        rule: how the year was scaled, in words.
    """

    curve: SNCurve
    cycles: float
    damage: float
    damage_per_year: float | None
    equivalent_stress_range: float
    max_stress_range: float
    scale_per_year: float | None
    rule: str

    @property
    def life_years(self) -> float:
        """Years to a damage of 1 (infinite without damage)."""
        if not self.damage_per_year:
            return math.inf
        return 1.0 / self.damage_per_year


def fatigue(history: npt.ArrayLike, curve: SNCurve, duration: float, *, vehicles: int | None = None,
            vehicles_per_year: float | None = None) -> FatigueResult:
    """Rainflow count, Miner damage, damage per year and equivalent range of one stress history (Pa).

    The year is scaled from the history by one of two rules:

    - ``vehicles_per_year`` given (a stated traffic volume, e.g. EN 1991-2 Table
      4.5's N_obs): ``D_year = D * vehicles_per_year / vehicles``, with ``vehicles``
      the vehicles that crossed the deck in the history (each passage does its
      damage, whatever the flow);
    - otherwise: the history's traffic goes on all year,
      ``D_year = D * SECONDS_PER_YEAR / duration``.

    Args:
        history: stress samples, Pa.
        curve: the S-N curve.
        duration: the time the history covers, s (> 0).
        vehicles: vehicles on the deck during the history (needed with ``vehicles_per_year``).
        vehicles_per_year: the stated traffic volume.

    Raises:
        ConfigError: a non-positive duration or volume, or a volume without the vehicle count.
    """
    if not (math.isfinite(duration) and duration > 0):
        raise ConfigError(f"fatigue: `duration` must be > 0 s (got {duration!r})")
    cycles = count_cycles(history)
    damage = miner_damage(cycles, curve)
    scale: float | None
    if vehicles_per_year is not None:
        if not (math.isfinite(vehicles_per_year) and vehicles_per_year > 0):
            raise ConfigError(f"fatigue: `vehicles_per_year` must be > 0 (got {vehicles_per_year!r})")
        if vehicles is None:
            raise ConfigError("fatigue: scaling to `vehicles_per_year` needs the number of vehicles of the history")
        scale = vehicles_per_year / vehicles if vehicles > 0 else None
        rule = f"{vehicles_per_year:g} vehicles per year over the {vehicles} vehicles of the run"
    else:
        scale = SECONDS_PER_YEAR / duration
        rule = f"the run's traffic all year ({SECONDS_PER_YEAR:g} s over {duration:g} s)"
    total = cycles.total
    eq = float((np.sum(cycles.counts * cycles.ranges**curve.m1) / total) ** (1.0 / curve.m1)) if total > 0 else 0.0
    return FatigueResult(
        curve=curve, cycles=total, damage=damage, damage_per_year=damage * scale if scale is not None else None,
        equivalent_stress_range=eq, max_stress_range=float(cycles.ranges.max()) if len(cycles.ranges) else 0.0,
        scale_per_year=scale, rule=rule,
    )


def damage_of_ranges(ranges: Sequence[float], counts: Sequence[float], curve: SNCurve) -> float:
    """Miner damage of given (range, count) pairs: what a hand calculation does."""
    return miner_damage(Cycles(np.asarray(ranges, float), np.zeros(len(ranges)), np.asarray(counts, float)), curve)


def turning_points(values: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The first and last values and every local extremum in between: all a rainflow count needs.

    Reducing consecutive pieces of a history this way and joining them keeps
    every reversal of the whole (a reversal is either inside a piece or at its
    ends), so a long run's history never has to be held in memory.
    """
    y = np.asarray(values, dtype=float).ravel()
    if len(y) <= 2:
        return y.copy()
    d = np.diff(y)
    nonzero = np.flatnonzero(d != 0)
    if len(nonzero) == 0:
        return y[[0, -1]]
    signs = np.sign(d[nonzero])
    # A sample is a reversal where the sign of the next non-zero step changes.
    flips = nonzero[1:][signs[1:] != signs[:-1]]
    return np.concatenate([[y[0]], y[flips], [y[-1]]])
