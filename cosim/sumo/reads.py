"""The libsumo getters the adapter (:mod:`cosim.sumo.adapter`) calls at every SUMO step."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

__all__ = ["SumoReads"]


class SumoReads(NamedTuple):
    """The libsumo getters the adapter calls at every step, for every watched lane and followed vehicle.

    Why not ``libsumo.vehicle.getPosition`` and its kind: each is a Python function that calls the SWIG
    extension's function of the same name (``_libsumo.vehicle_getPosition``); calling those directly saves
    that layer, about 0.1 us a call and 40 calls a step (benchmarks/README.md, "Where the time goes"). A libsumo without
    them (another build) is read through its public getters.
    """

    lane_vehicles: Callable[[str], tuple[str, ...]]
    position: Callable[[str], tuple[float, float]]
    angle: Callable[[str], float]
    speed: Callable[[str], float]
    acceleration: Callable[[str], float]

    @classmethod
    def of(cls, libsumo: Any) -> SumoReads:
        public = (libsumo.lane.getLastStepVehicleIDs, libsumo.vehicle.getPosition, libsumo.vehicle.getAngle,
                  libsumo.vehicle.getSpeed, libsumo.vehicle.getAcceleration)
        raw = getattr(libsumo, "_libsumo", None)
        names = ("lane_getLastStepVehicleIDs", "vehicle_getPosition", "vehicle_getAngle", "vehicle_getSpeed",
                 "vehicle_getAcceleration")
        if raw is None or not all(callable(getattr(raw, name, None)) for name in names):
            return cls(*public)
        return cls(*(getattr(raw, name) for name in names))
