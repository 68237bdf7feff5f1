"""The static load case of a scenario without vehicles (``cosim run`` on a bridge alone).

A :data:`STATIC_LOAD_N` downward point load at mid-span of the longest span,
once on the bridge axis (y = 0) and once at the left deck edge (largest y),
with every sensor's deck displacement for both.
"""
from __future__ import annotations

from typing import Any

from cosim.core.bridge import BridgeModel, PointLoad

from .scenario import Scenario

#: The static load, N (downward).
STATIC_LOAD_N = 100e3


def static_cases(scenario: Scenario, bridge: BridgeModel) -> list[dict[str, Any]]:
    """The load on the axis ("axis") and at the left edge ("left_edge"): per case the load (x, y, Fz, span),
    the deck displacement under it (``w_load_point``, m, positive up) and at each sensor (``sensors``)."""
    spans = scenario.bridge.spans
    longest = max(range(len(spans)), key=lambda i: spans[i])
    x_load = sum(spans[:longest]) + 0.5 * spans[longest]
    y_left = float(bridge.section.deck_y[1])
    cases = []
    for name, y_load in (("axis", 0.0), ("left_edge", y_left)):
        result = bridge.static([PointLoad(x=x_load, y=y_load, Fz=-STATIC_LOAD_N)])
        cases.append(
            {
                "name": name,
                "load": {"x": x_load, "y": y_load, "Fz": -STATIC_LOAD_N, "span": longest + 1},
                "w_load_point": result.deck_displacement(x_load, y_load),
                "sensors": {s.name: result.deck_displacement(s.x, s.y) for s in scenario.sensors},
            }
        )
    return cases
