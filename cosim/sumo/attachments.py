"""What a run with SUMO attaches to its log, by name: SUMO's messages and the vehicle types of the run.

A module of its own so that a log's readers (``cosim info``) know the names without loading the adapter,
whose compiled kernels take a second to load.
"""
from __future__ import annotations

__all__ = ["MESSAGES_FILE", "VEHICLE_TYPES_ATTACHMENT"]

#: SUMO's messages (its log, warnings and errors) in the scratch folder, and the log's attachment of them.
MESSAGES_FILE = "sumo-messages.log"
#: The log's attachment with the vehicle types of the run (model, mass, axles and their sources).
VEHICLE_TYPES_ATTACHMENT = "vehicle-types.json"
