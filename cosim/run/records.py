"""``[traffic.records]`` lowered to the core's objects: the lanes table, each axle's model, the traffic source.

The file itself is read by :mod:`cosim.core.loads` and driven by
:class:`cosim.core.records_traffic.RecordTraffic` (``via = "scripted"``) or
inserted into SUMO by :mod:`cosim.sumo.records` (``via = "sumo"``);
docs/loads.md#records-as-traffic says what each does.
"""
from __future__ import annotations

import functools
from collections.abc import Callable

from cosim.core.loads import VehicleRecord
from cosim.core.records_traffic import LIGHT_WEIGHT, RecordLane, moving_forces
from cosim.core.vehicles import VehicleModel
from cosim.sumo.library import GOLDEN_CAR, ROAD_FRIENDLY
from cosim.sumo.vtypes import LOADS_G, library_model

from .tables import DIRECTIONS, RecordsConfig

__all__ = ["axle_models", "record_lanes"]


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
