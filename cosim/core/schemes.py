"""Time-integration schemes of the Newmark family (docs/theory.md §6.1).

Newmark average acceleration (``beta = 1/4, gamma = 1/2``: unconditionally
stable, no numerical damping, second order) and HHT-alpha (``alpha`` in
[-1/3, 0], ``beta = (1 - alpha)^2 / 4``, ``gamma = 1/2 - alpha``), which damps
spurious high modes while staying second order (Hilber, Hughes & Taylor 1977).
"""
from __future__ import annotations

from dataclasses import dataclass

from cosim.errors import ConfigError


@dataclass(frozen=True)
class Scheme:
    """A member of the Newmark/HHT family: ``alpha`` (HHT), ``beta``, ``gamma``."""

    name: str
    alpha: float
    beta: float
    gamma: float

    @classmethod
    def newmark(cls) -> Scheme:
        """Average acceleration: unconditionally stable, no numerical damping."""
        return cls("newmark", 0.0, 0.25, 0.5)

    @classmethod
    def hht(cls, alpha: float = -0.05) -> Scheme:
        """HHT-alpha with ``alpha`` in [-1/3, 0] (0 is Newmark)."""
        if not -1.0 / 3.0 <= alpha <= 0.0:
            raise ConfigError(f"`hht_alpha` must be in [-1/3, 0] (got {alpha})")
        return cls("hht", alpha, (1.0 - alpha) ** 2 / 4.0, 0.5 - alpha)
