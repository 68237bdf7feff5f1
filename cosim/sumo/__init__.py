"""SUMO: the traffic side of the co-simulation.

- :mod:`cosim.sumo.adapter`: :class:`SumoTraffic` drives SUMO through libsumo
  (the only libsumo importer, and only once a simulation starts) and turns its
  vehicles into frames for the beam; the bundled networks.
- :mod:`cosim.sumo.network`: the network around the bridge, read with sumolib:
  :class:`BridgeAxis`, the bridge located from its edges, the lanes to watch,
  candidate bridges.
- :mod:`cosim.sumo.vtypes`: a vType's vehicle model and axles, and where each
  number came from; :mod:`cosim.sumo.library`: cosim's vehicle library.
- :mod:`cosim.sumo.files`: the one reader and editor of SUMO configs and the
  files they name (file lists, relative paths, gzip, the demand's vTypes, the
  study's demand edits).

Importing this package does not load libsumo.
"""
from cosim.sumo.adapter import WATCH_MARGIN, SumoTraffic, bundled_networks, sumo_binary
from cosim.sumo.files import (
    Demand,
    SumoConfig,
    SumoSet,
    VTypeEntry,
    distribution_ids,
    read_config,
    read_demand,
    read_input,
    read_sumo_set,
    set_speed_limit,
    set_truck_share,
    set_vehicles_per_hour,
    split_file_list,
    sumo_input_files,
)
from cosim.sumo.network import BridgeAxis, BridgeCandidate, BridgeLocation, bridge_candidates, locate_bridge
from cosim.sumo.vtypes import (
    HEAVY_VCLASSES,
    PARAM_PREFIX,
    VehicleType,
    axles_from_parameters,
    model_from_parameters,
    scaled_model,
    vehicle_type,
)

__all__ = [
    "HEAVY_VCLASSES",
    "PARAM_PREFIX",
    "WATCH_MARGIN",
    "BridgeAxis",
    "BridgeCandidate",
    "BridgeLocation",
    "Demand",
    "SumoConfig",
    "SumoSet",
    "SumoTraffic",
    "VTypeEntry",
    "VehicleType",
    "axles_from_parameters",
    "bridge_candidates",
    "bundled_networks",
    "distribution_ids",
    "locate_bridge",
    "model_from_parameters",
    "read_config",
    "read_demand",
    "read_input",
    "read_sumo_set",
    "scaled_model",
    "set_speed_limit",
    "set_truck_share",
    "set_vehicles_per_hour",
    "split_file_list",
    "sumo_binary",
    "sumo_input_files",
    "vehicle_type",
]
