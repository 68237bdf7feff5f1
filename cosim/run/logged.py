"""A scenario's time simulation streamed into an MCAP log: :func:`run_logged`.

The log embeds everything needed to run it again (the scenario text, its
input files, the resolved parameters, section constants and frequencies).
Ctrl-C or a failing solver still leave a finished log whose last status says
why. Nothing here prints; :mod:`cosim.cli` reports. What can be done with a
log afterwards: :mod:`cosim.run.replay`, :mod:`cosim.run.export`,
:mod:`cosim.run.figures` and the reader :mod:`cosim.log.reader`.
"""
from __future__ import annotations

import contextlib
import dataclasses
import datetime
import json
import os
import platform
import secrets
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cosim import __version__
from cosim.analysis.fatigue import FatigueResult
from cosim.bridges.files import read_modes, write_modes
from cosim.core.bases import DirectBasis
from cosim.core.bridge import BridgeModel
from cosim.core.checks import one_of
from cosim.core.limits import MAX_STEPS
from cosim.core.modal_bridge import ModalBridge
from cosim.core.roughness import RoadProfile
from cosim.core.sensors import Sensor
from cosim.core.simulation import SimulationResult, SolverSettings, simulate
from cosim.core.traffic import AXLE_SEPARATOR, Frame, FrameSink, ScriptedTraffic, TrafficSource
from cosim.core.vehicles import VehicleModel
from cosim.errors import (
    ConfigError,
    CosimError,
    Interrupted,
    LogError,
    LogWriteError,
    ModelError,
    interruption,
    interruption_message,
)
from cosim.log.layout import inputs_from_metadata, layout_bytes, make_layout
from cosim.log.process import LogProcess, fork_possible
from cosim.log.scene import ScenePlan, plan_scene, scene_sensors, scene_wanted
from cosim.log.schemas import (
    LAYOUT_ATTACHMENT,
    METADATA_NAME,
    REPLAY_METADATA_NAME,
    SCENARIO_ATTACHMENT,
    TOPIC_SENSORS,
)
from cosim.log.writer import BlockLogger, LogRecorder

from .engineering import FatigueRecorder, fatigue_payload, stress_curves
from .inputs import input_files
from .outputs import check_new_file
from .payloads import damping_payload, jsonable, modal_deck_payload, modes_payload, section_payload
from .scenario import RING_DOWN, Scenario
from .signals import StopGuard, stop_signals
from .simulate import SOLVER_FAILURES, SumoPlan, build_traffic, likely_cause, plan_sumo, scripted_traffic

#: The metadata record holding the fatigue of the stress sensors (sensor name -> JSON of its damage).
FATIGUE_METADATA_NAME = "fatigue"
#: Modes whose frequencies and kinds are stored in the log (``modes.json``).
LOGGED_MODES = 20
#: How often a "running" status is logged, s of simulated time.
STATUS_EVERY = 10.0
#: The log is written in pieces of this much simulated time (at least LOG_PIECE_STEPS steps), s: the solver
#: hands over blocks of up to JOINED_STEPS steps (cosim.core.simulation), and each topic's messages of a
#: piece go into the log together.
LOG_PIECE_SECONDS = 1.0
LOG_PIECE_STEPS = 200
#: Who encodes and writes the log: "process" (a child process, :mod:`cosim.log.process`), "thread" (a thread
#: of the run's process), or "auto" (the process where that is possible, else the thread).
LOG_WRITERS = ("auto", "process", "thread")


class RunFailed(ModelError):
    """The time integration failed (e.g. diverged) after the log was created; the log says so.

    Attributes:
        log_path: the finished log, whose last status is "error".
    """

    def __init__(self, message: str, log_path: Path) -> None:
        super().__init__(message)
        self.log_path = log_path


class LogCutShort(RunFailed):
    """Writing the log failed during the run (a full disk, a file-size limit): the file is cut short, without a
    final status; it can be read up to ``readable_until``.

    Attributes:
        log_path: the log, as far as it was written.
        readable_until: the simulated time of its last readable message, s; None when nothing of it can be read.
    """

    def __init__(self, message: str, log_path: Path, readable_until: float | None) -> None:
        super().__init__(message, log_path)
        self.readable_until = readable_until


def _cut_short(exc: LogWriteError, log_path: Path, partial: Path, duration: float) -> LogCutShort:
    """What a run whose log could not be written says: the error, and up to which simulated time the file can
    be read (read back from the file itself, as any reader would)."""
    from cosim.log import open_log

    text = str(exc).replace(str(partial), str(log_path))
    try:
        overview = open_log(log_path)
        until: float | None = overview.end_time if sum(overview.counts.values()) else None
    except (LogError, OSError):
        until = None
    if until is None:
        where = "nothing of it can be read"
    else:
        where = f"it can be read up to t = {until:g} s of the {duration:g} s simulated (and has no final status)"
    return LogCutShort(f"{text}; the log {log_path} is cut short: {where}", log_path, until)


@dataclass
class RunOutcome:
    """A finished logged run.

    Attributes:
        scenario: what ran.
        log_path: the MCAP log.
        result: extremes and counters of the run (histories are not kept: they are in the log).
        duration: simulated time, s; every: steps per logged sample; rate_hz: logging rate.
        on_deck: vehicle id -> (first, last) time on the deck, s (at every step).
        samples: sensor samples in the log (t = 0 included).
        wall_time: wall time of the whole logged run, s (time stepping and logging).
        log_bytes: size of the finished log.
        fatigue: sensor name -> rainflow count and Miner damage of its logged samples (stress sensors with an
            S-N curve; the damage per year for the run's traffic all year).
    """

    scenario: Scenario
    log_path: Path
    result: SimulationResult
    duration: float
    every: int
    rate_hz: float
    on_deck: dict[str, tuple[float, float]]
    samples: int
    wall_time: float
    log_bytes: int
    fatigue: dict[str, FatigueResult] = field(default_factory=dict)


class _DeckTimes:
    """First and last time each vehicle is on the deck (every step; constant memory per vehicle)."""

    def __init__(self) -> None:
        self.spans: dict[str, list[float]] = {}

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001 - the simulate() observer protocol
        if not report.ids:
            return
        on = report.on_deck
        present = np.flatnonzero(on.any(axis=0))
        for j in present.tolist():
            column = on[:, j]
            first = float(times[int(np.argmax(column))])
            last = float(times[len(column) - 1 - int(np.argmax(column[::-1]))])
            span = self.spans.setdefault(report.ids[j], [first, last])
            span[0], span[1] = min(span[0], first), max(span[1], last)


class _Samples:
    def __init__(self) -> None:
        self.count = 0

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001
        self.count += int(np.count_nonzero(keep))


class RunInterrupted(Interrupted):
    """A logged run stopped by a signal (SIGINT, SIGTERM or SIGHUP).

    Attributes:
        log_path: the finished log (last status "interrupted"), or None when the run had not
            started and no log was written.
    """

    def __init__(self, signum: int, name: str, log_path: Path | None) -> None:
        super().__init__(signum, name)
        self.log_path = log_path


class _StartsOnFirstBlock:
    """A traffic source that calls ``on_start`` when the time stepping asks for its first block.

    Everything before that (the basis, the coupled system, SUMO) can still fail
    on bad input; from then on the run has started and its log is kept.
    """

    def __init__(self, traffic: Any, on_start: Callable[[], None]) -> None:
        self.traffic = traffic
        self._on_start: Callable[[], None] | None = on_start

    def block(self, times):  # noqa: ANN001, ANN201 - the TrafficSource protocol
        if self._on_start is not None:
            on_start, self._on_start = self._on_start, None
            on_start()
        return self.traffic.block(times)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.traffic, name)


def _contact_ids(traffic: Any) -> list[str] | None:
    """The contact points of scripted vehicles (``id``, or ``id#k`` per axle), known before the run; else None."""
    if not isinstance(traffic, ScriptedTraffic):
        return None
    ids: list[str] = []
    for vehicle in traffic.vehicles:
        axles = len(vehicle.model.contact_offsets)
        ids += [f"{vehicle.id}{AXLE_SEPARATOR}{k}" for k in range(axles)] if axles > 1 else [vehicle.id]
    return ids


def _scene_plan(scenario: Scenario, bridge: BridgeModel | ModalBridge, sensors: list, solver: Any, duration: float,
                traffic: Any, by_default: bool = True) -> ScenePlan | None:
    """The run's 3D scene (``[output].scene``; unset: on for runs of at most an hour unless not
    ``by_default``), or None. A deck given by its modes has no scene yet (its shape is not a beam's)."""
    setting = scenario.output.scene
    if isinstance(bridge, ModalBridge):
        if setting not in (None, False):
            raise ConfigError(f"{scenario.source}: output.scene: the 3D scene draws a beam's deck; a deck given by "
                              "its modes is not drawn yet: remove scene (its sensors and traffic are logged)")
        return None
    if setting is None and not by_default:
        return None
    if not scene_wanted(setting, duration):
        return None
    exaggeration = None if setting is None or isinstance(setting, bool) else float(setting)
    weight = contact = None
    paths: list[float] = []
    if isinstance(traffic, ScriptedTraffic) and traffic.vehicles:  # the heaviest is known: the scales follow it
        g = solver.gravity
        weight = max(v.model.total_mass for v in traffic.vehicles) * g or None
        contact = max(v.model.total_mass / v.model.contacts for v in traffic.vehicles) * g or None
        paths = [v.y for v in traffic.vehicles]
    return plan_scene(bridge, sensors, solver.dt, exaggeration=exaggeration, reference_weight=weight,
                      reference_contact=contact, paths=paths, taken=[s.name for s in sensors])


def _named_only(result: SimulationResult, names: list[str]) -> SimulationResult:
    """The result without the scene's hidden sensors."""
    return dataclasses.replace(
        result, sensors={n: result.sensors[n] for n in names},
        sensor_min={n: result.sensor_min[n] for n in names}, sensor_max={n: result.sensor_max[n] for n in names})


def _check_size(scenario: Scenario, bridge: BridgeModel | ModalBridge, solver: Any, duration: float, given: bool,
                modal: Any) -> None:
    """Bounds that the run itself would only hit after its log exists: time steps, the basis."""
    if given:
        key = "the replayed log's duration"
    elif scenario.solver.duration is not None:
        key = f"{scenario.source}: solver.duration"
    elif scenario.scripted_records is not None:
        key = (f"{scenario.source}: solver.duration (default: the last record's vehicle leaves the deck + "
               f"{RING_DOWN:g} s)")
    elif scenario.traffic is not None:
        key = f"{scenario.source}: traffic.end"
    else:
        key = f"{scenario.source}: solver.duration (default: the last vehicle leaves the deck + {RING_DOWN:g} s)"
    MAX_STEPS.check(duration / solver.dt, key, f"{duration:g} s at solver.dt = {solver.dt:g} s")
    if modal is None:  # a deck given by its modes: its modes were checked when the scenario was read
        return
    assert isinstance(bridge, BridgeModel)
    if solver.basis == "direct" and len(bridge.free) > DirectBasis.MAX_DIRECT_DOFS:
        raise ConfigError(
            f"{scenario.source}: solver.basis: the direct basis keeps a dense {len(bridge.free)} x "
            f"{len(bridge.free)} inverse; above {DirectBasis.MAX_DIRECT_DOFS} free DOFs use basis = \"modal\" "
            "(or fewer bridge.elements_per_span)")
    if solver.basis == "modal" and solver.cutoff_hz is not None and len(modal.f_hz) and \
            solver.cutoff_hz < modal.f_hz[0]:
        raise ConfigError(f"{scenario.source}: solver.cutoff_hz: no mode below {solver.cutoff_hz:g} Hz (the first "
                          f"is at {modal.f_hz[0]:.4g} Hz); raise cutoff_hz or give modes")


class FrameRelay:
    """The frame sink a live traffic source is built with, before the log it feeds exists.

    SUMO starts before the log (its network, edges and vTypes are inputs too: a wrong one must leave nothing
    written), and says what it runs (the vehicle-type table) as it starts: documents given before
    :meth:`connect` wait for it. Frames only come with blocks, after it.
    """

    def __init__(self) -> None:
        self._sink: FrameSink | None = None
        self._held: list[tuple[str, bytes | str, str]] = []

    def connect(self, sink: FrameSink) -> None:
        """From now on everything goes to ``sink`` (a log's), the documents held first."""
        self._sink = sink
        held, self._held = self._held, []
        for document in held:
            sink.attach(*document)

    def __call__(self, frame: Frame, new_models: Mapping[str, VehicleModel]) -> None:
        if self._sink is None:
            raise LogError("a traffic frame came before the run's log was open")
        self._sink(frame, new_models)

    def attach(self, name: str, data: bytes | str, media_type: str = "text/plain") -> None:
        if self._sink is None:
            self._held.append((name, data, media_type))
        else:
            self._sink.attach(name, data, media_type)


@dataclass(frozen=True)
class RunPlan:
    """A logged run as it will be, worked out once from the scenario before anything is written
    (:func:`plan_run`); the stream that writes the log takes it whole.

    Attributes:
        scenario: what runs; log_path: the log to write; force: overwrite an existing one.
        bridge, road, solver: the model, the road profiles and the solver settings.
        sensors: the scenario's sensors (the scene's hidden ones are added by the stream).
        duration: simulated time, s; every: steps per logged sample; rate_hz: logging rate, Hz.
        scene: the log's 3D scene, or None.
        sumo: the SUMO run to start (its network, edges and vTypes read), or None (scripted or given traffic).
        writer_child: the log is encoded and written by a child process (else a thread).
        metadata: the "cosim" metadata record; replay: the "replay" record of a replay, or None.
        documents: the attachments (input files, resolved parameters, section, modes, layout), name -> bytes.
    """

    scenario: Scenario
    log_path: Path
    force: bool
    bridge: BridgeModel | ModalBridge
    road: RoadProfile
    solver: SolverSettings
    sensors: tuple[Sensor, ...]
    duration: float
    every: int
    rate_hz: float
    scene: ScenePlan | None
    sumo: SumoPlan | None
    writer_child: bool
    metadata: Mapping[str, str]
    replay: Mapping[str, str] | None
    documents: Mapping[str, bytes]

    @property
    def names(self) -> list[str]:
        """The logged sensors' names."""
        return [s.name for s in self.sensors]


def _metadata(scenario: Scenario, plan_scene_: ScenePlan | None, solver: SolverSettings, sensors: list[Sensor],
              duration: float, every: int, rate_hz: float, traffic: TrafficSource | None, live_sumo: bool,
              inputs: list, started: datetime.datetime, replay: bool) -> dict[str, str]:
    """The "cosim" metadata record of a run's log."""
    contacts = _contact_ids(traffic)
    return {
        "version": __version__,
        "encoding": "protobuf",  # the messages' (cosim.log.proto); logs without this key are JSON
        "kind": "replay" if replay else "run",
        "scenario": scenario.title,
        "source": scenario.source,
        "started": started.isoformat(timespec="seconds"),
        "dt": repr(solver.dt),
        "scheme": solver.scheme,
        "basis": solver.basis,
        "duration": repr(duration),
        "every": str(every),
        "rate_hz": repr(rate_hz),
        "sensors": json.dumps([s.name for s in sensors]),
        "quantities": json.dumps([s.quantity for s in sensors]),
        "vehicles": json.dumps([v.id for v in scenario.vehicles]),
        "traffic": "sumo" if (live_sumo or scenario.sumo) else "records" if scenario.scripted_records else (
            "replayed frames" if traffic is not None and not scenario.vehicles else "scripted"),
        "inputs": json.dumps({item.key: item.attachment for item in inputs if item.key}),
        "python": platform.python_version(),
        **({"contacts": json.dumps(contacts)} if contacts is not None else {}),
        **(plan_scene_.metadata() if plan_scene_ is not None else {}),
    }


def _input_bytes(path: Path) -> bytes:
    """An input file's bytes; a folder of modes CSV files as the .npz it reads as (docs/modal-decks.md)."""
    if not path.is_dir():
        return path.read_bytes()
    with tempfile.TemporaryDirectory(prefix="cosim-modes-") as scratch:
        return write_modes(Path(scratch) / "modes.npz", read_modes(path)).read_bytes()


def _documents(scenario: Scenario, bridge: BridgeModel | ModalBridge, modal: Any, inputs: list,
               attachments: dict[str, bytes], layout: Any, duration: float, every: int,
               rate_hz: float) -> dict[str, bytes]:
    """The log's attachments besides the scenario text: its input files (read now: an unreadable one is an
    error before the log exists), the resolved parameters, the section, the modes and the Foxglove layout."""
    files = {}
    for item in inputs:
        try:
            files[item.attachment] = _input_bytes(item.path)
        except OSError as exc:
            raise ConfigError(f"{scenario.source}: {item.key or item.attachment}: cannot read {item.path} "
                              f"({exc.strerror})") from None
    resolved = {
        "scenario": scenario.model_dump(mode="json", by_alias=True, warnings=False),
        "derived": {"duration": duration, "output_every": every, "rate_hz": rate_hz,
                    "leave_time": jsonable(scenario.leave_time)},
    }
    if isinstance(bridge, ModalBridge):
        structure = {"modes.json": json.dumps(modal_deck_payload(bridge), indent=1).encode()}
    else:
        structure = {"section.json": json.dumps(section_payload(bridge.section), indent=1).encode(),
                     "modes.json": json.dumps({"modes": modes_payload(modal), "damping": damping_payload(bridge)},
                                              indent=1).encode()}
    return {
        **files, **attachments,
        "resolved.json": json.dumps(jsonable(resolved), indent=1).encode(),
        **structure,
        LAYOUT_ATTACHMENT: layout_bytes(layout),
    }


def plan_run(
    scenario: Scenario,
    log_path: Path,
    *,
    force: bool = False,
    bridge: BridgeModel | ModalBridge | None = None,
    replay: dict[str, str] | None = None,
    attachments: dict[str, bytes] | None = None,
    started: datetime.datetime | None = None,
    traffic: TrafficSource | None = None,
    duration: float | None = None,
    scene_by_default: bool = True,
    writer: str = "auto",
) -> RunPlan:
    """Work out a logged run (:func:`run_logged`'s arguments, which it documents) without writing anything.

    Raises:
        ConfigError, ModelError, LogError, SumoError: bad input (the bridge, road, vehicles, modes, limits, SUMO's
            network, edges and vehicle types, an existing log without ``force``).
    """
    if not scenario.vehicles and scenario.traffic is None and traffic is None:
        raise ConfigError(f"{scenario.source}: the scenario has no [[vehicles]] and no [traffic]: "
                          "nothing to simulate in time")
    one_of(writer, LOG_WRITERS, "writer", "run_logged: ")
    writer_child = writer == "process" or (writer == "auto" and fork_possible())
    if writer_child and not fork_possible():
        raise ConfigError("run_logged: writer = \"process\" needs Linux and the main thread of a process that "
                          "may start children; use \"thread\" or \"auto\"")
    started = started or datetime.datetime.now().astimezone()
    if bridge is None:
        bridge = scenario.build_bridge()
    live_sumo = traffic is None and scenario.sumo
    sumo_plan = plan_sumo(scenario) if live_sumo else None  # a wrong edge or vType: an error before the log exists
    if traffic is None and not live_sumo:
        traffic = scripted_traffic(scenario)  # records: the whole file checked here, before the log exists
    road = scenario.build_road()
    solver = scenario.solver_settings()
    sensors = scenario.sensors_core()
    given = duration is not None
    duration = duration if duration is not None else scenario.duration
    every = scenario.output_every
    rate_hz = scenario.output_rate_hz
    names = [s.name for s in sensors]
    modal = bridge.modes(count=LOGGED_MODES) if isinstance(bridge, BridgeModel) else None
    _check_size(scenario, bridge, solver, duration, given, modal)
    scene = _scene_plan(scenario, bridge, sensors, solver, duration, traffic, scene_by_default)
    inputs = input_files(scenario)
    meta = _metadata(scenario, scene, solver, sensors, duration, every, rate_hz, traffic, live_sumo, inputs,
                     started, bool(replay))
    layout = make_layout(inputs_from_metadata(meta, names, [s.quantity for s in sensors], str(log_path)))
    documents = _documents(scenario, bridge, modal, inputs, attachments or {}, layout, duration, every, rate_hz)
    check_new_file(log_path, "log", force)
    return RunPlan(scenario=scenario, log_path=log_path, force=force, bridge=bridge, road=road, solver=solver,
                   sensors=tuple(sensors), duration=duration, every=every, rate_hz=rate_hz, scene=scene,
                   sumo=sumo_plan, writer_child=writer_child, metadata=meta, replay=replay, documents=documents)


def run_logged(
    scenario: Scenario,
    log_path: Path,
    *,
    force: bool = False,
    bridge: BridgeModel | ModalBridge | None = None,
    progress: Callable[[float], None] | None = None,
    replay: dict[str, str] | None = None,
    attachments: dict[str, bytes] | None = None,
    started: datetime.datetime | None = None,
    traffic: TrafficSource | None = None,
    duration: float | None = None,
    scene_by_default: bool = True,
    writer: str = "auto",
) -> RunOutcome:
    """Run ``scenario``'s vehicles over its bridge and stream everything into the MCAP log ``log_path``.

    Everything that can fail on bad input (bridge, road, vehicles, modes,
    limits, SUMO: its network, edges and vehicle types) is checked before the
    log file is created (:func:`plan_run`). The log is written under a temporary name in the same
    folder and takes its name when the time stepping starts: a run that fails
    or is stopped before that leaves nothing (and an existing ``log_path``
    untouched, even with ``force``). From then on the log is kept, and finished
    whatever ends the run: its last status says why. The log holds the
    scenario text and input files, ``resolved.json``, ``section.json``,
    ``modes.json``, a "cosim" metadata record, the sensor samples (from t = 0,
    at rest), the vehicles on the deck, traffic events and status messages.

    SIGINT, SIGTERM and SIGHUP stop the run (in the main thread, unless the
    program installed its own handlers): the log ends with status
    "interrupted" and the signal's name.

    Args:
        scenario: a scenario with [[vehicles]] or [traffic].
        log_path: the log to write (its folder is created).
        force: overwrite an existing log (once the run has started).
        bridge: the scenario's model, if already built.
        progress: called with the fraction done after every block of steps.
        replay: for a replay, what was replayed (stored as the "replay" metadata record).
        attachments: more documents to store (name -> bytes).
        started: wall-clock start time for the metadata (default now).
        traffic: a traffic source to use instead of the scenario's (replay of logged SUMO frames).
        duration: simulated time instead of the scenario's, s.
        scene_by_default: draw the 3D scene when ``[output].scene`` is unset (studies: no).
        writer: who encodes and writes the log (:data:`LOG_WRITERS`): a child process keeps that work off
            the GIL of the thread that runs SUMO; "auto" uses one on Linux in the main thread.

    Raises:
        RunInterrupted: a signal; ``log_path`` is the finished log (status "interrupted"), or None if
            the run had not started (nothing written).
        RunFailed: the run failed after it started (e.g. diverged); the log ends with status "error".
        ConfigError, ModelError, LogError, SumoError: bad input, before any file is written.
    """
    plan = plan_run(scenario, log_path, force=force, bridge=bridge, replay=replay, attachments=attachments,
                    started=started, traffic=traffic, duration=duration, scene_by_default=scene_by_default,
                    writer=writer)
    relay = FrameRelay()
    with stop_signals() as guard, contextlib.ExitStack() as sumo:
        try:
            if plan.sumo is not None:  # SUMO starts before the log: its network, edges and vTypes are inputs too
                traffic = sumo.enter_context(build_traffic(
                    scenario, frame_sink=relay, plan=plan.sumo, process=_sumo_process(plan.scene, plan.writer_child)))
            elif traffic is None:
                traffic = scripted_traffic(scenario)
        except KeyboardInterrupt as exc:
            guard.closing = True
            raise RunInterrupted(*interruption(exc), None) from None
        return _stream(plan, guard, traffic, relay if plan.sumo is not None else None, progress)


def _sumo_process(plan: ScenePlan | None, writer_child: bool) -> bool | None:
    """Where SUMO runs in a logged run: its own process (None: where one can be forked) for a log without the 3D
    scene written by the log writer process, else the run's process (False).

    Measured side by side on two cores, 1 h of the default config, 5 pairs: without the scene, SUMO's own process
    took direct + log from 2.14x to 1.75x SUMO alone and modal + log from 1.79x to 1.46x. With the scene (about
    a third of the log writer's CPU) the writer process, SUMO's and the solver no longer fit on the two cores:
    0-15 % slower.
    """
    return None if plan is None and writer_child else False


def _stream(run: RunPlan, guard: StopGuard, traffic: TrafficSource, relay: FrameRelay | None,
            progress: Callable[[float], None] | None) -> RunOutcome:
    """The log itself: written under a temporary name until the stepping starts, then as ``log_path``.
    ``relay``: the frame sink live SUMO was built with (connected to the log here), or None."""
    scenario, log_path, force, plan = run.scenario, run.log_path, run.force, run.scene
    solver, road, duration, rate_hz = run.solver, run.road, run.duration, run.rate_hz
    names = run.names
    live_sumo = relay is not None
    partial = log_path.with_name(f".{log_path.name}.{secrets.token_hex(4)}.part")
    extremes = _DeckTimes()
    samples = _Samples()
    fatigue = FatigueRecorder(names, stress_curves(scenario))
    wall_start = time.perf_counter()
    state = {"started": False}

    def on_start() -> None:
        try:
            if log_path.exists() and not force:
                raise LogError(f"{log_path}: already exists; refusing to overwrite the log (use --force)")
            os.replace(partial, log_path)
        except OSError as exc:
            raise LogError(f"{log_path}: cannot create the log ({exc.strerror or exc})") from None
        state["started"] = True

    rec: LogRecorder | LogProcess | None = None

    def discard() -> None:
        if rec is not None:
            with contextlib.suppress(Exception):
                rec.close("error", "the run did not start")
        with contextlib.suppress(OSError):
            partial.unlink()

    def sumo_said() -> None:
        # SUMO is closed before the log is finished, so that all it said goes into the log (the adapter
        # attaches its messages through its frame sink when it closes).
        if live_sumo and rec is not None:
            with contextlib.suppress(Exception):
                traffic.close()

    try:
        try:
            rec = (LogProcess(partial, names, scene=plan is not None) if run.writer_child else
                   LogRecorder(partial, names, force=False, scene=plan is not None))
        except LogError as exc:  # name the log the user asked for, not its temporary name
            raise LogError(str(exc).replace(str(partial), str(log_path))) from None
        rec.attach(SCENARIO_ATTACHMENT, scenario.text, "application/toml")
        for name, data in run.documents.items():
            media = {".csv": "text/csv", ".toml": "application/toml", ".json": "application/json"}.get(
                Path(name).suffix.lower(), "application/octet-stream")
            rec.attach(name, data, media)
        rec.metadata(METADATA_NAME, dict(run.metadata))
        if run.replay:
            rec.metadata(REPLAY_METADATA_NAME, dict(run.replay))
        rec.status(0.0, "started", f"{scenario.title}: {duration:g} s simulated, dt = {solver.dt:g} s, "
                                   f"logging at {rate_hz:g} Hz", progress=0.0)
        rec.write(TOPIC_SENSORS, 0.0, {"t": 0.0, **{n: 0.0 for n in names}})  # at rest
        blocks: Any
        piece = max(LOG_PIECE_STEPS, int(round(LOG_PIECE_SECONDS / solver.dt)))
        if isinstance(rec, LogProcess):
            blocks = rec.block_logger(duration, STATUS_EVERY, plan, len(names), piece)
        else:
            blocks = BlockLogger.for_run(rec, names, duration, status_every=STATUS_EVERY, plan=plan,
                                         first_column=len(names), piece_steps=piece, threaded=True)
        with blocks as logger:
            if relay is not None:
                relay.connect(logger.traffic_sink())
            result = simulate(run.bridge, logger.paced(_StartsOnFirstBlock(traffic, on_start)), duration,
                              solver=solver, sensors=[*run.sensors, *(scene_sensors(plan) if plan is not None else [])],
                              road=road, output_every=run.every, progress=progress,
                              observers=[extremes, samples, fatigue, logger], collect=False)
            guard.closing = True  # a signal from here on must not cut the log's ending short
    except KeyboardInterrupt as exc:
        guard.closing = True
        signum, name = interruption(exc)
        if not state["started"] or rec is None:
            discard()
            raise RunInterrupted(signum, name, None) from None
        sumo_said()
        rec.close("interrupted", interruption_message(exc), wall_time=time.perf_counter() - wall_start)
        raise RunInterrupted(signum, name, log_path) from None
    except (CosimError, *SOLVER_FAILURES) as exc:
        guard.closing = True
        if not state["started"] or rec is None:
            discard()
            if isinstance(exc, CosimError):
                raise
            raise ModelError(f"{scenario.source}: {exc}") from None
        if isinstance(exc, LogWriteError):
            sumo_said()
            with contextlib.suppress(Exception):
                rec.close("error", str(exc))  # whatever still can be written; the first error is the one said
            raise _cut_short(exc, log_path, partial, duration) from None
        if isinstance(exc, CosimError) and not isinstance(exc, ModelError):
            message = str(exc)
        else:
            text = str(exc) if isinstance(exc, ModelError) else \
                f"the solution diverged: the solver met non-finite values ({type(exc).__name__}: {exc})"
            message = f"{text}; likely cause: {likely_cause(scenario, road, solver)}"
        sumo_said()
        try:
            rec.close("error", message, wall_time=time.perf_counter() - wall_start)
        except (OSError, ValueError, LogError):
            pass  # the log itself failed (e.g. disk full): report the first error
        raise RunFailed(f"{scenario.source}: {message}", log_path) from None
    except BaseException as exc:  # a defect: the log still says so, and the traceback is not hidden
        guard.closing = True
        if not state["started"] or rec is None:
            discard()
        else:
            with contextlib.suppress(Exception):
                rec.close("error", f"{type(exc).__name__}: {exc}", wall_time=time.perf_counter() - wall_start)
        raise
    damage = fatigue.results(duration, len(result.vehicle_ids))
    if damage:
        payload = fatigue_payload(damage)
        rec.metadata(FATIGUE_METADATA_NAME, {k: json.dumps(jsonable(v)) for k, v in payload.items()})
    sumo_said()
    wall = time.perf_counter() - wall_start
    try:
        rec.close("finished", f"{duration:g} s simulated in {wall:.3g} s", wall_time=wall)
    except LogWriteError as exc:
        raise _cut_short(exc, log_path, partial, duration) from None
    if plan is not None:
        result = _named_only(result, names)
    return RunOutcome(
        scenario=scenario, log_path=log_path, result=result, duration=duration, every=run.every, rate_hz=rate_hz,
        on_deck={k: (v[0], v[1]) for k, v in extremes.spans.items()}, samples=samples.count + 1,
        wall_time=wall, log_bytes=log_path.stat().st_size, fatigue=damage,
    )
