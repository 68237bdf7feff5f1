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
from typing import Any, Callable

from cosim.core.bridge import BridgeModel
from cosim.core.simulation import SimulationResult, simulate
from cosim.errors import ConfigError, ModelError

from .scenario import Scenario


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
