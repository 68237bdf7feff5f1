"""cosim: co-simulation of road traffic (SUMO) and bridge vibration (a 7-DOF Timoshenko-Vlasov beam).

The documented Python API is importable from here (``from cosim import
simulate, build_bridge``); names load on first use, so ``import cosim`` stays
cheap and importing the numerical core never pulls in SUMO, MCAP, plotting or
configuration libraries. The layers, from the bottom: ``cosim.core``
(numerics), ``cosim.sumo`` and ``cosim.log`` (adapters), ``cosim.run``
(scenarios, logged runs, replay), ``cosim.study`` and ``cosim.validation``,
``cosim.testing`` (scripted scenario tests) and ``cosim.cli``.
"""
from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    # errors
    "CosimError": "cosim.errors", "ConfigError": "cosim.errors", "ModelError": "cosim.errors",
    "SumoError": "cosim.errors", "LogError": "cosim.errors",
    # the bridge
    "Material": "cosim.core.section", "Plate": "cosim.core.section", "SectionProperties": "cosim.core.section",
    "section_from_plates": "cosim.core.section", "section_from_constants": "cosim.core.section",
    "BridgeModel": "cosim.core.bridge", "build_bridge": "cosim.core.bridge", "PointLoad": "cosim.core.bridge",
    "RayleighDamping": "cosim.core.bridge", "ExplicitDamping": "cosim.core.bridge", "BeamTheory": "cosim.core.element",
    "ModalResult": "cosim.core.bridge", "StaticResult": "cosim.core.bridge",
    # vehicles, traffic, road, sensors
    "MovingForce": "cosim.core.vehicles", "QuarterCar": "cosim.core.vehicles",
    "TyreQuarterCar": "cosim.core.vehicles", "VEHICLE_MODELS": "cosim.core.vehicles",
    "ScriptedVehicle": "cosim.core.traffic", "ScriptedTraffic": "cosim.core.traffic",
    "TrafficBlock": "cosim.core.traffic", "TrafficFrame": "cosim.core.traffic",
    "RoadProfile": "cosim.core.roughness", "iso8608_profile": "cosim.core.roughness",
    "profile_from_csv": "cosim.core.roughness", "smooth_road": "cosim.core.roughness",
    "Sensor": "cosim.core.sensors",
    # time integration
    "Scheme": "cosim.core.schemes", "make_basis": "cosim.core.bases", "CoupledSystem": "cosim.core.coupling",
    "SolverSettings": "cosim.core.simulation", "SimulationResult": "cosim.core.simulation",
    "simulate": "cosim.core.simulation", "quasi_static": "cosim.core.quasistatic", "daf": "cosim.core.quasistatic",
    # scenarios
    "Scenario": "cosim.run.scenario", "load_scenario": "cosim.run.scenario", "parse_scenario": "cosim.run.scenario",
}
#: Public aliases whose name differs from the defining module's.
_ALIASES: dict[str, str] = {"VEHICLE_MODELS": "MODELS"}

__all__ = ["__version__", *sorted(_EXPORTS)]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), _ALIASES.get(name, name))
        globals()[name] = value
        return value
    raise AttributeError(f"module 'cosim' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
