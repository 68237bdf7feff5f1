"""SUMO: the traffic side of the co-simulation.

- :mod:`cosim.sumo.adapter`: :class:`SumoTraffic` drives SUMO through libsumo
  (the only libsumo importer, and only once a simulation starts) and turns its
  vehicles into frames for the beam; :mod:`cosim.sumo.install`: the SUMO binary and the bundled networks.
- :mod:`cosim.sumo.network`: the network around the bridge, read with sumolib:
  :class:`BridgeAxis`, the bridge located from its edges, the lanes to watch,
  candidate bridges.
- :mod:`cosim.sumo.vtypes`: a vType's vehicle model and axles, and where each
  number came from; :mod:`cosim.sumo.library`: cosim's vehicle library.
- :mod:`cosim.sumo.files`: the one reader and editor of SUMO configs and the
  files they name (file lists, relative paths, gzip, the demand's vTypes, the
  study's demand edits).

Importing this package loads none of its modules: each name loads its module on first use
(``cosim info`` reads a SUMO run's log without loading the adapter's compiled kernels), and
nothing loads libsumo before a simulation starts.
"""
from __future__ import annotations

import importlib
from typing import Any

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    "WATCH_MARGIN": "cosim.sumo.adapter", "SumoTraffic": "cosim.sumo.adapter",
    "bundled_networks": "cosim.sumo.install", "sumo_binary": "cosim.sumo.install",
    "Demand": "cosim.sumo.files", "SumoConfig": "cosim.sumo.files", "SumoSet": "cosim.sumo.files",
    "VTypeEntry": "cosim.sumo.files", "distribution_ids": "cosim.sumo.files", "read_config": "cosim.sumo.files",
    "read_demand": "cosim.sumo.files", "read_input": "cosim.sumo.files", "read_sumo_set": "cosim.sumo.files",
    "set_speed_limit": "cosim.sumo.files", "set_truck_share": "cosim.sumo.files",
    "set_vehicles_per_hour": "cosim.sumo.files", "split_file_list": "cosim.sumo.files",
    "sumo_input_files": "cosim.sumo.files",
    "HEAVY_VCLASSES": "cosim.sumo.library",
    "BridgeAxis": "cosim.sumo.network", "BridgeCandidate": "cosim.sumo.network",
    "BridgeLocation": "cosim.sumo.network", "bridge_candidates": "cosim.sumo.network",
    "locate_bridge": "cosim.sumo.network",
    "PARAM_PREFIX": "cosim.sumo.vtypes", "VehicleType": "cosim.sumo.vtypes",
    "axles_from_parameters": "cosim.sumo.vtypes", "model_from_parameters": "cosim.sumo.vtypes",
    "scaled_model": "cosim.sumo.vtypes", "vehicle_type": "cosim.sumo.vtypes",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'cosim.sumo' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
