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
import datetime
import json
import platform
import signal
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from cosim import __version__
from cosim.core.bridge import BridgeModel
from cosim.core.simulation import SimulationResult, simulate
from cosim.errors import ConfigError, CosimError, LogError, ModelError, SumoError
from cosim.log.schemas import (
    METADATA_NAME,
    REPLAY_METADATA_NAME,
    SCENARIO_ATTACHMENT,
    TOPIC_SENSORS,
)
from cosim.log.writer import BlockLogger, LogRecorder, TrafficLogger

from .inputs import input_files
from .outputs import check_new_file
from .payloads import damping_payload, jsonable, modes_payload, section_payload
from .scenario import Scenario
from .simulate import build_traffic, plan_sumo

#: Modes whose frequencies and kinds are stored in the log (``modes.json``).
LOGGED_MODES = 20
#: How often a "running" status is logged, s of simulated time.
STATUS_EVERY = 10.0


class RunFailed(ModelError):
    """The time integration failed (e.g. diverged) after the log was created; the log says so.

    Attributes:
        log_path: the finished log, whose last status is "error".
    """

    def __init__(self, message: str, log_path: Path) -> None:
        super().__init__(message)
        self.log_path = log_path


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


class _InterruptOnce:
    """Ctrl-C stops the run once; while the log is being finished, further Ctrl-C are held back.

    Installed only over Python's default SIGINT handler, in the main thread.
    """

    def __init__(self) -> None:
        self.closing = False
        self._old: Any = None

    def __enter__(self) -> "_InterruptOnce":
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._old = signal.signal(signal.SIGINT, self._handle)
        return self

    def _handle(self, signum, frame) -> None:  # noqa: ANN001
        if self.closing:
            return
        self.closing = True
        raise KeyboardInterrupt

    def __exit__(self, *exc: object) -> None:
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
            self._old = None


def run_logged(
    scenario: Scenario,
    log_path: Path,
    *,
    force: bool = False,
    bridge: BridgeModel | None = None,
    progress: Callable[[float], None] | None = None,
    replay: dict[str, str] | None = None,
    attachments: dict[str, bytes] | None = None,
    started: datetime.datetime | None = None,
    traffic: Any = None,
    duration: float | None = None,
) -> RunOutcome:
    """Run ``scenario``'s vehicles over its bridge and stream everything into the MCAP log ``log_path``.

    Everything that can fail on bad input (bridge, road, vehicles, modes) is
    built before the log file is created. The log then holds the scenario
    text and input files, ``resolved.json``, ``section.json``, ``modes.json``,
    a "cosim" metadata record, the sensor samples (from t = 0, at rest), the
    vehicles on the deck, traffic events and status messages.

    Args:
        scenario: a scenario with [[vehicles]].
        log_path: the log to write (its folder is created).
        force: overwrite an existing log.
        bridge: the scenario's model, if already built.
        progress: called with the fraction done after every block of steps.
        replay: for a replay, what was replayed (stored as the "replay" metadata record).
        attachments: more documents to store (name -> bytes).
        started: wall-clock start time for the metadata (default now).
        traffic: a traffic source to use instead of the scenario's (replay of logged SUMO frames).
        duration: simulated time instead of the scenario's, s.

    Raises:
        KeyboardInterrupt: Ctrl-C; the log is finished first, with status "interrupted".
        RunFailed: the solution diverged; the log is finished first, with status "error".
        ConfigError, ModelError, LogError: bad input, before the log is created.
    """
    if not scenario.vehicles and scenario.traffic is None and traffic is None:
        raise ConfigError(f"{scenario.source}: the scenario has no [[vehicles]] and no [traffic]: "
                          "nothing to simulate in time")
    started = started or datetime.datetime.now().astimezone()
    if bridge is None:
        bridge = scenario.build_bridge()
    live_sumo = traffic is None and scenario.traffic is not None
    plan = plan_sumo(scenario) if live_sumo else None  # a wrong edge or vType: an error before the log exists
    if traffic is None and not live_sumo:
        traffic = scenario.build_vehicles()
    road = scenario.build_road()
    solver = scenario.solver_settings()
    sensors = scenario.sensors_core()
    duration = duration if duration is not None else scenario.duration
    every = scenario.output_every
    rate_hz = scenario.output_rate_hz
    names = [s.name for s in sensors]
    modal = bridge.modes(count=LOGGED_MODES)
    inputs = input_files(scenario)
    files = {}
    for item in inputs:
        try:
            files[item.attachment] = item.path.read_bytes()
        except OSError as exc:
            raise ConfigError(f"{scenario.source}: {item.key}: cannot read {item.path} ({exc.strerror})") from None
    check_new_file(log_path, "log", force)
    meta = {
        "version": __version__,
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
        "sensors": json.dumps(names),
        "quantities": json.dumps([s.quantity for s in sensors]),
        "vehicles": json.dumps([v.id for v in scenario.vehicles]),
        "traffic": "sumo" if (live_sumo or scenario.traffic is not None) else (
            "replayed frames" if traffic is not None and not scenario.vehicles else "scripted"),
        "inputs": json.dumps({item.key: item.attachment for item in inputs if item.key}),
        "python": platform.python_version(),
    }
    resolved = {
        "scenario": scenario.model_dump(mode="json", by_alias=True, warnings=False),
        "derived": {"duration": duration, "output_every": every, "rate_hz": rate_hz,
                    "leave_time": jsonable(scenario.leave_time)},
    }
    extremes = _DeckTimes()
    samples = _Samples()
    wall_start = time.perf_counter()
    with _InterruptOnce() as guard, LogRecorder(log_path, names, force=force) as rec:
        rec.attach(SCENARIO_ATTACHMENT, scenario.text, "application/toml")
        for name, data in {**files, **(attachments or {})}.items():
            media = {".csv": "text/csv", ".toml": "application/toml"}.get(Path(name).suffix.lower(),
                                                                          "application/octet-stream")
            rec.attach(name, data, media)
        rec.attach("resolved.json", json.dumps(jsonable(resolved), indent=1), "application/json")
        rec.attach("section.json", json.dumps(section_payload(bridge.section), indent=1), "application/json")
        rec.attach("modes.json", json.dumps({"modes": modes_payload(modal), "damping": damping_payload(bridge)},
                                            indent=1), "application/json")
        rec.metadata(METADATA_NAME, meta)
        if replay:
            rec.metadata(REPLAY_METADATA_NAME, replay)
        rec.status(0.0, "started", f"{scenario.title}: {duration:g} s simulated, dt = {solver.dt:g} s, "
                                   f"logging at {rate_hz:g} Hz", progress=0.0)
        rec.write(TOPIC_SENSORS, 0.0, {"t": 0.0, **{n: 0.0 for n in names}})  # at rest
        try:
            with contextlib.ExitStack() as stack, \
                    BlockLogger(rec, names, duration, status_every=STATUS_EVERY) as logger:
                if live_sumo:  # SUMO starts inside the log: a SUMO failure is the log's final status
                    traffic = stack.enter_context(build_traffic(scenario, frame_sink=TrafficLogger(rec), plan=plan))
                result = simulate(bridge, logger.paced(traffic), duration, solver=solver, sensors=sensors, road=road,
                                  output_every=every, progress=progress, observers=[extremes, samples, logger],
                                  collect=False)
                guard.closing = True  # a Ctrl-C from here on must not cut the log's ending short
        except KeyboardInterrupt:
            guard.closing = True
            rec.close("interrupted", "interrupted by the user (SIGINT)", wall_time=time.perf_counter() - wall_start)
            raise
        except CosimError as exc:
            guard.closing = True
            try:
                rec.close("error", f"{type(exc).__name__}: {exc}", wall_time=time.perf_counter() - wall_start)
            except (OSError, ValueError, LogError):
                pass  # the log itself failed (e.g. disk full): report the first error
            if isinstance(exc, ModelError):
                raise RunFailed(f"{scenario.source}: {exc}", log_path) from exc
            if isinstance(exc, SumoError) and getattr(traffic, "sumo_steps", 0) > 0:
                raise RunFailed(f"{scenario.source}: {exc}", log_path) from exc  # SUMO failed mid-run
            raise
        wall = time.perf_counter() - wall_start
        rec.close("finished", f"{duration:g} s simulated in {wall:.3g} s", wall_time=wall)
    return RunOutcome(
        scenario=scenario, log_path=log_path, result=result, duration=duration, every=every, rate_hz=rate_hz,
        on_deck={k: (v[0], v[1]) for k, v in extremes.spans.items()}, samples=samples.count + 1,
        wall_time=wall, log_bytes=log_path.stat().st_size,
    )
