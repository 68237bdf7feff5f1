"""Running a scenario in memory: its traffic source (SUMO started here) and its time simulation.

:class:`cosim.run.scenario.Scenario` is configuration and its lowering to
core objects; what starts processes and runs lives here::

    from cosim.run.scenario import load_scenario
    from cosim.run.simulate import simulate_scenario

    scenario = load_scenario("paper-double-tee")
    result = simulate_scenario(scenario)            # cosim.core.simulation.SimulationResult

Runs with a log: :func:`cosim.run.logged.run_logged`.
"""
from __future__ import annotations

import contextlib
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from cosim.core.bridge import BridgeModel
from cosim.core.simulation import SimulationResult, simulate
from cosim.errors import ConfigError, ModelError

from .scenario import Scenario

#: Exceptions of the compiled solver (numba, numpy) when non-finite values reach it: a diverged solution.
SOLVER_FAILURES = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError, OverflowError)

#: Vehicle parameters beyond these (SI units) are out of any road vehicle's range.
_PLAUSIBLE = {"mass": (1.0, 1e6), "m_v": (1.0, 1e6), "m_w": (0.1, 1e5), "k_v": (1.0, 1e9), "c_v": (0.0, 1e8),
              "k_t": (1.0, 1e10), "c_t": (0.0, 1e8)}


def likely_cause(scenario: Scenario, road: Any, solver: Any) -> str:
    """The likeliest reason a run diverged, from its inputs: a parameter out of range, else the step."""
    for i, vehicle in enumerate(scenario.vehicles):
        for key, value in vehicle.parameters.items():
            low, high = _PLAUSIBLE.get(key, (-math.inf, math.inf))
            if not low <= value <= high:
                return (f"vehicles[{i}] ({vehicle.id}): {key} = {value:g} is outside any road vehicle's range "
                        f"({low:g} to {high:g})")
    peak = float(np.max(np.abs(road.r))) if road.r.size else 0.0
    if not peak <= 1.0:
        return f"road: the profile's elevations reach {peak:g} m (a road profile is a few cm at most)"
    return (f"a parameter out of range, or a time step too large for the vehicles' and the bridge's dynamics "
            f"(solver.dt = {solver.dt:g} s; try a smaller dt, or the modal basis with fewer modes)")


def build_traffic(scenario: Scenario, frame_sink: Callable[..., None] | None = None) -> Any:
    """The scenario's traffic source: :class:`cosim.sumo.adapter.SumoTraffic` (not started) for
    ``[traffic]``, else its scripted vehicles (:meth:`Scenario.build_vehicles`).

    Args:
        frame_sink: with SUMO, called with every frame (e.g. to log it).
    """
    if scenario.traffic is None:
        return scenario.build_vehicles()
    from cosim.sumo.adapter import (  # only SUMO runs load libsumo
        BridgeAxis,
        SumoTraffic,
    )

    t = scenario.traffic
    length = scenario.bridge.length
    axis = BridgeAxis(*t.axis) if t.axis is not None else BridgeAxis((0.0, 0.0), (length, 0.0))
    y_min, y_max = scenario.bridge.section.deck_y
    path = scenario.sumo_config_path
    assert path is not None
    with scenario.named("traffic"):
        return SumoTraffic(path, axis, step=t.step, begin=t.begin, end=t.end, edges=t.edges or None,
                           seed=t.seed, half_width=max(abs(y_min), abs(y_max)), frame_sink=frame_sink)


def simulate_scenario(
    scenario: Scenario,
    progress: Callable[[float], None] | None = None,
    *,
    bridge: BridgeModel | None = None,
) -> SimulationResult:
    """Run a scenario in memory: its bridge, traffic (scripted or SUMO), road, solver and sensors.

    Args:
        scenario: what to run.
        progress: called with the fraction done from time to time.
        bridge: the model from :meth:`Scenario.build_bridge`, if already built.

    Returns:
        The sensor and vehicle time histories, sampled every :attr:`Scenario.output_every` steps.

    Raises:
        ConfigError: the scenario cannot be run as given (e.g. no duration).
        ModelError: the model cannot be built, or the solution diverges.
    """
    if bridge is None:
        bridge = scenario.build_bridge()
    traffic = build_traffic(scenario)
    road = scenario.build_road()
    duration = scenario.duration
    solver = scenario.solver_settings()
    sensors = scenario.sensors_core()
    try:
        with contextlib.ExitStack() as stack:
            if hasattr(traffic, "start"):  # SUMO: one simulation, closed whatever happens
                stack.enter_context(traffic)
            return simulate(
                bridge, traffic, duration, solver=solver, sensors=sensors, road=road,
                output_every=scenario.output_every, progress=progress,
            )
    except (ConfigError, ModelError) as exc:
        raise type(exc)(f"{scenario.source}: {exc}") from exc
    except SOLVER_FAILURES as exc:  # non-finite values reached the compiled solver: the solution diverged
        raise ModelError(f"{scenario.source}: the solution diverged: the solver met non-finite values "
                         f"({type(exc).__name__}: {exc}); likely cause: {likely_cause(scenario, road, solver)}"
                         ) from exc
