"""Static point loads on a scenario's bridge: ``cosim static`` and the static case of ``cosim run`` without vehicles.

:func:`static_response` solves any number of vertical point loads anywhere on
the deck (docs/theory.md §4.3) and reads the deck displacement under each load
and at every sensor. :func:`static_cases` is ``cosim run``'s fixed case on the
same code: a :data:`STATIC_LOAD_N` downward point load at mid-span of the
longest span, once on the bridge axis (y = 0) and once at the left deck edge
(largest y).

Importing this module loads neither numpy nor the scenario machinery (the
command line's help quotes :data:`STATIC_LOAD_N`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from cosim.errors import ConfigError

if TYPE_CHECKING:  # the bridge and the scenario load numpy, scipy and pydantic: only when solving
    from cosim.core.bridge import BridgeModel, PointLoad

    from .scenario import Scenario

#: The static load of ``cosim run`` without vehicles, N (downward).
STATIC_LOAD_N = 100e3

#: Units of the numbers in a static response (SI).
STATIC_UNITS = {"x": "m", "y": "m", "Fz": "N (positive up)", "w": "m (positive up)", "bending_moment": "N m (sagging)"}


def check_loads(bridge: BridgeModel, loads: Sequence[PointLoad]) -> None:
    """Raise :class:`ConfigError` for the first load that is not finite or lies off the deck.

    The message names the load (1-based, as given) and where the deck is.
    """
    y_min, y_max = bridge.section.deck_y
    tol_x = 1e-9 * bridge.length
    tol_y = 1e-9 * max(y_max - y_min, 1.0)
    if not loads:
        raise ConfigError("no load given: give at least one point load (x, y, Fz)")
    for i, load in enumerate(loads, start=1):
        where = f"load {i} (x = {load.x:g} m, y = {load.y:g} m, Fz = {load.Fz:g} N)"
        if not all(math.isfinite(v) for v in (load.x, load.y, load.Fz)):
            raise ConfigError(f"{where}: x, y and Fz must be finite numbers")
        if not -tol_x <= load.x <= bridge.length + tol_x:
            raise ConfigError(f"{where} is off the bridge: x must lie in 0 <= x <= {bridge.length:g} m")
        if not y_min - tol_y <= load.y <= y_max + tol_y:
            raise ConfigError(f"{where} is off the deck: y must lie in {y_min:g} <= y <= {y_max:g} m")


def static_response(scenario: Scenario, bridge: BridgeModel, loads: Sequence[PointLoad]) -> dict[str, Any]:
    """Displacements of the deck under vertical point loads acting together.

    Args:
        scenario: the scenario (its sensors are read).
        bridge: its bridge model.
        loads: the point loads, each on the deck (``Fz`` in N, positive up).

    Returns:
        ``{"loads": [{"x", "y", "Fz", "w"}], "sensors": [{"name", "x", "y", "quantity", "w"}]}``: ``w`` is
        the deck displacement (m, positive up) under each load and at each sensor's point; a bending-moment
        sensor also gets ``bending_moment`` (N m, sagging positive) at its ``x``.

    Raises:
        ConfigError: a load is not finite or lies off the deck (:func:`check_loads`).
    """
    from cosim.core.bridge import PointLoad

    check_loads(bridge, loads)
    on_deck = [PointLoad(min(max(p.x, 0.0), bridge.length), p.y, p.Fz) for p in loads]
    result = bridge.static(on_deck)
    sensors = []
    for s in scenario.sensors:
        entry: dict[str, Any] = {"name": s.name, "x": s.x, "y": s.y, "quantity": s.quantity,
                                 "w": result.deck_displacement(s.x, s.y)}
        if s.quantity == "bending_moment":
            entry["bending_moment"] = float(result.field("bending_moment", [s.x])[0])
        sensors.append(entry)
    return {
        "loads": [{"x": p.x, "y": p.y, "Fz": p.Fz, "w": result.deck_displacement(p.x, p.y)} for p in on_deck],
        "sensors": sensors,
    }


def static_cases(scenario: Scenario, bridge: BridgeModel) -> list[dict[str, Any]]:
    """The load on the axis ("axis") and at the left edge ("left_edge"): per case the load (x, y, Fz, span),
    the deck displacement under it (``w_load_point``, m, positive up) and at each sensor (``sensors``)."""
    from cosim.core.bridge import PointLoad

    spans = scenario.bridge.spans
    longest = max(range(len(spans)), key=lambda i: spans[i])
    x_load = sum(spans[:longest]) + 0.5 * spans[longest]
    y_left = float(bridge.section.deck_y[1])
    cases = []
    for name, y_load in (("axis", 0.0), ("left_edge", y_left)):
        response = static_response(scenario, bridge, [PointLoad(x=x_load, y=y_load, Fz=-STATIC_LOAD_N)])
        cases.append(
            {
                "name": name,
                "load": {"x": x_load, "y": y_load, "Fz": -STATIC_LOAD_N, "span": longest + 1},
                "w_load_point": response["loads"][0]["w"],
                "sensors": {s["name"]: s["w"] for s in response["sensors"]},
            }
        )
    return cases
