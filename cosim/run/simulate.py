"""Running a scenario in memory: its traffic source (SUMO started here) and its time simulation.

:class:`cosim.run.scenario.Scenario` is configuration and its lowering to
core objects; what starts processes and runs lives here::

    from cosim.run.scenario import load_scenario
    from cosim.run.simulate import simulate_scenario

    scenario = load_scenario("paper-double-tee")
    result = simulate_scenario(scenario)            # cosim.core.simulation.SimulationResult

Runs with a log: :func:`cosim.run.logged.run_logged`. Before a SUMO run
starts (and before its log is created), :func:`plan_sumo` reads the network
and the demand files: it places the bridge (the axis given, or derived from
``[traffic] edges``), checks that the lanes fit the deck, and turns every
vType into its vehicle model, so that a wrong edge or vType is an error
before anything is written.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cosim.core.bridge import BridgeModel
from cosim.core.modal_bridge import ModalBridge
from cosim.core.simulation import SimulationResult, simulate
from cosim.core.traffic import FrameSink, TrafficSource
from cosim.errors import ConfigError, ModelError, SumoError

from .deck_placement import check_lanes_covered
from .scenario import Scenario

if TYPE_CHECKING:
    from cosim.sumo.adapter import SumoSettings
    from cosim.sumo.loads import LoadSettings

#: Exceptions of the compiled solver (numba, numpy) when non-finite values reach it: a diverged solution.
SOLVER_FAILURES = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError, OverflowError)

#: Vehicle parameters beyond these (SI units) are out of any road vehicle's range.
_PLAUSIBLE = {"mass": (1.0, 1e6), "m_v": (1.0, 1e6), "m_w": (0.1, 1e5), "k_v": (1.0, 1e9), "c_v": (0.0, 1e8),
              "k_t": (1.0, 1e10), "c_t": (0.0, 1e8)}


def likely_cause(scenario: Scenario, road: Any, solver: Any) -> str:
    """The likeliest reason a run diverged, from its inputs: a parameter out of range, else the step."""
    for i, vehicle in enumerate(scenario.vehicles):
        for key, value in vehicle.parameters.items():
            if key not in _PLAUSIBLE:  # a half-car's axles and pitch switch: checked by the model
                continue
            low, high = _PLAUSIBLE[key]
            if not low <= value <= high:
                return (f"vehicles[{i}] ({vehicle.id}): {key} = {value:g} is outside any road vehicle's range "
                        f"({low:g} to {high:g})")
    peak = float(np.max(np.abs(road.r))) if road.r.size else 0.0
    if not peak <= 1.0:
        return f"road: the profile's elevations reach {peak:g} m (a road profile is a few cm at most)"
    return (f"a parameter out of range, or a time step too large for the vehicles' and the bridge's dynamics "
            f"(solver.dt = {solver.dt:g} s; try a smaller dt, or the modal basis with fewer modes)")


#: The carriageway may overhang the deck's edges by this much, m (round-off of lane geometry).
DECK_FIT_TOLERANCE = 1e-3


@dataclass(frozen=True)
class SumoPlan:
    """A SUMO run as it will be, found before SUMO starts.

    Attributes:
        config: the SUMO config; net: its network.
        axis: the bridge axis in network coordinates (a :class:`cosim.sumo.network.BridgeAxis`).
        axis_from: how the axis was found (given, derived from the edges, or the default).
        location: the bridge located from ``[traffic] edges`` (a :class:`cosim.sumo.network.BridgeLocation`),
            or None.
        deck_y: the deck's lateral extent, m.
        demand: what the demand files hold (:class:`cosim.sumo.files.Demand`).
        types: every vType's vehicle model (:class:`cosim.sumo.vtypes.VehicleType`), as the files say it;
            a vType without a ``length`` has its library vehicle's here and SUMO's own in the run.
        settings: the SUMO run itself (:class:`cosim.sumo.adapter.SumoSettings`: config, axis, times, seed).
    """

    config: Path
    net: Path
    axis: Any
    axis_from: str
    location: Any
    deck_y: tuple[float, float]
    demand: Any
    types: tuple[Any, ...]
    settings: SumoSettings


def plan_sumo(scenario: Scenario) -> SumoPlan:
    """Read the network and demand of ``scenario``'s ``[traffic]`` and place the bridge (nothing runs).

    The axis: ``[traffic] axis`` if given; else derived from ``[traffic] edges``
    (:func:`cosim.sumo.network.locate_bridge`, with the bridge's length); else
    (0, 0) -> (L, 0). The lanes of the named edges must lie on the deck.

    Raises:
        ConfigError: naming the scenario and the key: an edge the network lacks, lanes off the deck, a
            length that does not match, no lane on the axis, a vType with an unknown or impossible param.
    """
    from cosim.sumo.adapter import SumoSettings
    from cosim.sumo.files import read_demand
    from cosim.sumo.network import BridgeAxis, lanes_across, locate_bridge, net_path
    from cosim.sumo.vtypes import vehicle_type

    t = scenario.traffic
    if t is None or not t.sumo:
        raise ConfigError(f"{scenario.source}: the scenario has no SUMO traffic ([traffic] sumo_config)")
    config = scenario.sumo_config_path
    assert config is not None
    length = scenario.bridge.length
    deck_y = scenario.bridge.deck_y
    with scenario.named("traffic.sumo_config"):
        demand = read_demand(config)
        net = net_path(config)
    location = None
    network_axis = scenario.bridge.network_axis if scenario.bridge.is_modal else None
    with scenario.named("traffic.edges"):
        if t.edges:
            location = locate_bridge(net, t.edges, length=length if t.axis is None and network_axis is None
                                     else None)
    if network_axis is not None:
        axis = BridgeAxis(*network_axis)
        axis_from = (f"the deck's points (frame = \"network\"), along {'[traffic] axis' if t.axis else 'the lanes'}"
                     f" from its first point")
    elif t.axis is not None:
        axis, axis_from = BridgeAxis(*t.axis), "given ([traffic] axis)"
    elif location is not None:
        axis, axis_from = location.axis, f"derived from edges {', '.join(t.edges)}"
        lo, hi = location.carriageway
        if lo < deck_y[0] - DECK_FIT_TOLERANCE or hi > deck_y[1] + DECK_FIT_TOLERANCE:
            raise ConfigError(
                f"{scenario.source}: traffic.edges: the vehicle lanes of {', '.join(t.edges)} reach y = {lo:.3f} "
                f"to {hi:.3f} m from the derived axis; the deck (bridge.section) spans y = {deck_y[0]:g} to "
                f"{deck_y[1]:g} m: widen the section's deck, or give [traffic] axis (sidewalks need not be "
                "covered: cosim models no pedestrians)")
    else:
        axis, axis_from = BridgeAxis((0.0, 0.0), (length, 0.0)), "the default (0, 0) -> (L, 0)"
    if location is not None and scenario.bridge.is_modal:  # the mode surface, not a width, says where the deck is
        check_lanes_covered(scenario.build_modal_bridge(), net, location.lanes, axis, scenario.source)
    if location is None:
        with scenario.named("traffic"):
            if not lanes_across(net, axis, deck_y):
                raise ConfigError(
                    f"no lane of {net.name} runs along the bridge axis {axis.start} -> {axis.end} ({axis_from}) "
                    "within the deck: name the bridge's edges in [traffic] edges (cosim bridge "
                    f"{config.name} lists candidates), or give axis")
    types = []
    for type_id in [v for v in demand.vtypes if v not in demand.distributions] + (
            ["DEFAULT_VEHTYPE"] if demand.untyped else []):
        entry = demand.vtypes.get(type_id)
        vclass = (entry.vclass if entry is not None else None) or "passenger"
        own_length = entry.length if entry is not None else None
        try:
            types.append(vehicle_type(type_id, vclass, own_length, entry.mass if entry is not None else None,
                                      entry.params if entry is not None else {}))
        except SumoError as exc:
            where = f"{entry.file}: " if entry is not None else ""
            raise ConfigError(f"{scenario.source}: traffic.sumo_config: {where}{exc}") from None
    loads = _load_settings(scenario, demand) if t.loads is not None else None
    records = None
    if t.records is not None:  # via = "sumo": the file checked and each lane's route found before SUMO starts
        from .records import records_plan

        records = records_plan(scenario, net, axis)
    with scenario.named("traffic"):
        settings = SumoSettings(config, axis, step=t.step, begin=t.begin, end=t.end, edges=t.edges or None,
                                seed=t.seed, deck_y=deck_y, demand=demand, loads=loads, records=records)
    return SumoPlan(config=config, net=net, axis=axis, axis_from=axis_from, location=location, deck_y=deck_y,
                    demand=demand, types=tuple(types), settings=settings)


def _load_settings(scenario: Scenario, demand: Any) -> LoadSettings:
    """``[traffic.loads]`` lowered: the site's model read (its files checked), the vTypes it maps checked."""
    import difflib

    from cosim.core.loads import load_model
    from cosim.sumo.loads import LoadSettings

    t = scenario.traffic
    assert t is not None and t.loads is not None
    try:
        model = load_model(t.loads.model, scenario.base_dir)
    except ConfigError as exc:
        text = str(exc)
        where = "" if text.startswith("traffic.loads.model") else "traffic.loads.model: "
        raise ConfigError(f"{scenario.source}: {where}{text}") from None
    known = [v for v in demand.vtypes if v not in demand.distributions]
    for vtype in t.loads.vtype_classes:
        if vtype not in known:
            near = difflib.get_close_matches(vtype, known, n=1)
            hint = f"did you mean {near[0]!r}? " if near else ""
            raise ConfigError(f"{scenario.source}: traffic.loads.vtype_classes.{vtype}: the demand has no vType "
                              f"{vtype!r} ({hint}its vTypes: {', '.join(known)})")
    return LoadSettings(model=model, site=model.name, seed=t.loads.seed, vtype_classes=dict(t.loads.vtype_classes),
                        wander=t.loads.wander)


def build_traffic(scenario: Scenario, frame_sink: FrameSink | None = None, plan: SumoPlan | None = None,
                  process: bool | None = None) -> TrafficSource:
    """The scenario's traffic source, not started: for ``[traffic]`` with SUMO, SUMO in a child process
    (:class:`cosim.run.sumo_process.SumoProcess`) or in this one (:class:`cosim.sumo.adapter.SumoTraffic`);
    else its scripted traffic (:func:`scripted_traffic`).

    Args:
        frame_sink: with SUMO, where every frame and the run's documents go (e.g. a log).
        plan: with SUMO, the run's :func:`plan_sumo` if already made.
        process: SUMO in a child process (the same frames; the run's process keeps its GIL); None: where a
            child can be forked (:func:`cosim.log.process.fork_possible`).
    """
    if not scenario.sumo:
        return scripted_traffic(scenario)
    from cosim.sumo.adapter import SumoTraffic  # only SUMO runs load libsumo

    plan = plan or plan_sumo(scenario)
    traffic = SumoTraffic(settings=plan.settings, frame_sink=frame_sink)
    from cosim.log.process import fork_possible

    if process or (process is None and fork_possible()):
        from .sumo_process import SumoProcess

        return SumoProcess(traffic)
    return traffic


def scripted_traffic(scenario: Scenario) -> TrafficSource:
    """The traffic of a scenario without SUMO, not started: its WIM records driven as recorded
    (``[traffic.records] via = "scripted"``: :meth:`Scenario.build_records`, the file checked first) or its
    ``[[vehicles]]`` (:meth:`Scenario.build_vehicles`)."""
    if scenario.scripted_records is not None:
        return scenario.build_records()
    return scenario.build_vehicles()


def simulate_scenario(
    scenario: Scenario,
    progress: Callable[[float], None] | None = None,
    *,
    bridge: BridgeModel | ModalBridge | None = None,
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
        with traffic:  # SUMO: one simulation, closed whatever happens
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
