"""Fatigue of a run's stress sensors: their S-N curves, the rainflow count of the logged samples, Miner damage.

A stress sensor with ``sn_curve`` gets its logged samples reduced to turning
points block by block while the run goes (:class:`FatigueRecorder`, constant
memory per cycle, not per sample), and at the end a rainflow count and the
Miner damage (:func:`cosim.analysis.fatigue.fatigue`). The damage per year of
a run scales its traffic to a year (the run's traffic all year, or a stated
number of vehicles per year; docs/analysis.md).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from cosim.analysis.fatigue import FatigueResult, SNCurve, fatigue, turning_points

from .scenario import Scenario

__all__ = ["FatigueRecorder", "fatigue_payload", "stress_curves"]


def stress_curves(scenario: Scenario) -> dict[str, SNCurve]:
    """Sensor name -> S-N curve of every sensor that has one, in the scenario's order."""
    return {s.name: curve for s in scenario.sensors if (curve := s.curve()) is not None}


class FatigueRecorder:
    """A block observer of :func:`cosim.core.simulation.simulate`: the turning points of the logged samples of
    the sensors with an S-N curve."""

    def __init__(self, names: list[str], curves: dict[str, SNCurve]) -> None:
        self.curves = curves
        self._columns = {name: names.index(name) for name in curves}
        self._parts: dict[str, list[np.ndarray]] = {name: [np.zeros(1)] for name in curves}  # t = 0: at rest

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001 - the simulate() observer protocol
        if not self.curves:
            return
        logged = report.sensors[keep]
        for name, column in self._columns.items():
            self._parts[name].append(turning_points(logged[:, column]))

    def results(self, duration: float, vehicles: int, vehicles_per_year: float | None = None
                ) -> dict[str, FatigueResult]:
        """Rainflow count and Miner damage per sensor (the damage per year by the rule of ``vehicles_per_year``)."""
        return {name: fatigue(np.concatenate(self._parts[name]), curve, duration, vehicles=vehicles,
                              vehicles_per_year=vehicles_per_year)
                for name, curve in self.curves.items()}


def fatigue_payload(results: dict[str, FatigueResult]) -> dict[str, dict[str, Any]]:
    """Per sensor: the curve, cycles, damage, damage per year, equivalent and largest range (SI), the rule."""
    out = {}
    for name, r in results.items():
        out[name] = {
            "sn_curve": r.curve.name, "cycles": r.cycles, "damage": r.damage, "damage_per_year": r.damage_per_year,
            "life_years": r.life_years if math.isfinite(r.life_years) else None,
            "equivalent_stress_range": r.equivalent_stress_range, "max_stress_range": r.max_stress_range,
            "per_year": r.rule,
        }
    return out
