"""SUMO: the traffic side of the co-simulation.

- :mod:`cosim.sumo.adapter`: :class:`SumoTraffic` drives SUMO through libsumo
  (the only libsumo importer, and only once a simulation starts) and turns its
  vehicles into frames for the beam; :class:`BridgeAxis` places the bridge in
  the network; the bundled networks.
- :mod:`cosim.sumo.vtypes`: a vType's vehicle model and axles from its params.
- :mod:`cosim.sumo.files`: the one reader and editor of SUMO configs and the
  files they name (file lists, relative paths, gzip, the study's demand edits).

Importing this package does not load libsumo.
"""
from cosim.sumo.adapter import WATCH_MARGIN, BridgeAxis, SumoTraffic, bundled_networks, sumo_binary
from cosim.sumo.files import (
    SumoConfig,
    SumoSet,
    distribution_ids,
    read_config,
    read_input,
    read_sumo_set,
    set_speed_limit,
    set_truck_share,
    set_vehicles_per_hour,
    split_file_list,
    sumo_input_files,
)
from cosim.sumo.vtypes import (
    HEAVY_VCLASSES,
    PARAM_PREFIX,
    VCLASS_DEFAULTS,
    axles_from_parameters,
    model_from_parameters,
    scaled_model,
)

__all__ = [
    "HEAVY_VCLASSES",
    "PARAM_PREFIX",
    "VCLASS_DEFAULTS",
    "WATCH_MARGIN",
    "BridgeAxis",
    "SumoConfig",
    "SumoSet",
    "SumoTraffic",
    "axles_from_parameters",
    "bundled_networks",
    "distribution_ids",
    "model_from_parameters",
    "read_config",
    "read_input",
    "read_sumo_set",
    "scaled_model",
    "set_speed_limit",
    "set_truck_share",
    "set_vehicles_per_hour",
    "split_file_list",
    "sumo_binary",
    "sumo_input_files",
]
