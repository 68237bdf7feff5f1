"""``[traffic.records]`` lowered to the core's objects: the lanes table, each axle's model, the traffic source.

The file itself is read by :mod:`cosim.core.loads` and driven by
:class:`cosim.core.records_traffic.RecordTraffic` (``via = "scripted"``) or
inserted into SUMO by :mod:`cosim.sumo.records` (``via = "sumo"``);
docs/loads.md#records-as-traffic says what each does.
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.core.loads import VehicleRecord
from cosim.core.records_traffic import LIGHT_WEIGHT, RecordLane, moving_forces
from cosim.core.vehicles import VehicleModel
from cosim.errors import ConfigError
from cosim.sumo.library import GOLDEN_CAR, ROAD_FRIENDLY
from cosim.sumo.network import BridgeAxis
from cosim.sumo.records import RecordsPlan, record_routes
from cosim.sumo.vtypes import LOADS_G, library_model

from .tables import DIRECTIONS, RecordsConfig

if TYPE_CHECKING:
    from .scenario import Scenario

__all__ = ["axle_models", "record_lanes", "records_plan"]


def record_lanes(records: RecordsConfig) -> tuple[RecordLane, ...]:
    """The lanes table as the core takes it."""
    return tuple(RecordLane(lane.lane, lane.y, DIRECTIONS[lane.direction]) for lane in records.lanes)


def axle_models(kind: str) -> Callable[[VehicleRecord], tuple[VehicleModel, ...]]:
    """Each record's axle models for ``[traffic.records] model``: ``"moving-force"`` (each axle its load), or
    ``"tyre-quarter-car"``: each axle a tyre quarter-car of its load on cosim's library suspension, the IRI golden
    car's for a light vehicle (below 3.5 t) and the road-friendly heavy axle's (Directive 96/53/EC: 2 Hz, 20 %)
    for the others (:mod:`cosim.sumo.library`): the same frequencies and damping ratios at any load."""
    return moving_forces if kind == "moving-force" else _quarter_cars


def _quarter_cars(record: VehicleRecord) -> tuple[VehicleModel, ...]:
    light = record.gross_weight < LIGHT_WEIGHT
    return tuple(_quarter_car(w, light) for w in record.axle_loads)


@functools.lru_cache(maxsize=8192)
def _quarter_car(load: float, light: bool) -> VehicleModel:
    """An axle of ``load`` N (the formats' loads are whole units: a few hundred values)."""
    return library_model(GOLDEN_CAR if light else ROAD_FRIENDLY, load / LOADS_G)


def records_plan(scenario: Scenario, net: Path, axis: BridgeAxis) -> RecordsPlan:
    """``[traffic.records]`` with ``via = "sumo"`` for the SUMO run on ``net`` with the bridge on ``axis``: the file
    read and checked (:meth:`Scenario.records_check`) and each lane of the lanes table given its route through
    the network (:func:`cosim.sumo.records.record_routes`), before SUMO starts.

    Raises:
        ConfigError: a bad record (naming the file and the line), a lane the table does not map, a lane of the
            table that lies on no lane of the network's deck in its direction (naming the key).
    """
    records = scenario.records
    assert records is not None and records.via == "sumo"
    check = scenario.records_check()
    try:
        routes = record_routes(net, axis, record_lanes(records), scenario.bridge.deck_y,
                               key="traffic.records.lanes")
    except ConfigError as exc:
        raise ConfigError(f"{scenario.source}: {exc}") from None
    begin, end = scenario.records_window
    return RecordsPlan(path=check.path, format=records.format, lanes_per_direction=check.lanes_per_direction,
                       begin=begin, end=end, routes=routes, wander=records.wander,
                       seed=records.seed if records.seed is not None else 0)
