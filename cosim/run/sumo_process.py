"""SUMO in a child process: the run's process keeps its GIL for the bridge and its observers.

libsumo runs SUMO inside the calling process and holds the GIL for every
step; the adapter's Python per step (:class:`cosim.sumo.adapter.SumoTraffic`)
needs it too. In the run's process they took turns with the solver thread's
Python and the observers: an hour of the default config without a log took
1.98x SUMO alone there, and 1.51x with SUMO in a child (benchmarks/bench_day.py,
side by side). A logged run uses it when its log has no 3D scene; with the
scene, the log writer process needs the cores' slack and SUMO stays in the
run's process (:func:`cosim.run.logged._sumo_process` has the measurements).
:class:`SumoProcess` forks a child that owns
the :class:`~cosim.sumo.adapter.SumoTraffic`, steps SUMO ahead of the run and
sends its frames through a pipe, a second of SUMO time at a time; the pipe's
size bounds how far ahead it runs. The run takes the frames one at a time
exactly as it would step SUMO itself (the same frames, the same frame sink
calls in the same order), so its numbers are the same to the bit.

The child ignores the stop signals (a terminal's Ctrl-C reaches the whole
process group: the run decides how to stop and closes SUMO through the pipe);
when the run's process dies, the pipe breaks and the child closes SUMO and
removes its scratch folder. An error in the child (SUMO failed, a vType that
cannot be modelled) is raised in the run as the same :mod:`cosim.errors` type
with the same message, at the frame where it happened.

Only where forking is safe (:func:`cosim.log.process.fork_possible`); elsewhere
(Dask worker threads, macOS, Windows) SUMO runs in the run's process as before.
"""
from __future__ import annotations

import collections
import contextlib
import multiprocessing
from collections.abc import Mapping
from multiprocessing.connection import Connection
from typing import Any

from cosim import errors
from cosim.core.traffic import Frame, pack_frames, unpack_frames
from cosim.core.vehicles import VehicleModel
from cosim.log.process import fork_child, signals_held
from cosim.sumo.adapter import VEHICLE_TYPES_ATTACHMENT, LiveSumo, SumoSettings, SumoTraffic

__all__ = ["AHEAD_SECONDS", "SumoProcess"]

#: SUMO time sent to the run at once, s (the child steps SUMO ahead of the run by a few of these at most).
AHEAD_SECONDS = 1.0
#: How long closing waits for the child to close SUMO, s.
CLOSE_TIMEOUT = 60.0


def _error(kind: str, message: str) -> errors.CosimError:
    """The child's error as the run raises it: the same cosim error type, else a SUMO error."""
    cls = getattr(errors, kind, None)
    if not (isinstance(cls, type) and issubclass(cls, errors.CosimError)):
        cls = errors.SumoError
    return cls(message)


class _Documents:
    """The child's frame sink: it keeps the documents SUMO's start and close give (the run's sink gets the
    frames and the documents in the run); the child steps SUMO itself, so no frame comes here."""

    def __init__(self) -> None:
        self.documents: dict[str, bytes | str] = {}

    def __call__(self, frame: Frame, new_models: Mapping[str, VehicleModel]) -> None:
        raise AssertionError("the child steps SUMO with advance(), not through its sink")

    def attach(self, name: str, data: bytes | str, media_type: str) -> None:
        self.documents[name] = data


def _serve(settings: SumoSettings, out: Connection, control: Connection) -> None:
    documents = _Documents()
    traffic = SumoTraffic(settings=settings, frame_sink=documents)
    try:
        traffic.start()
        table = documents.documents[VEHICLE_TYPES_ATTACHMENT]
    except BaseException as exc:  # noqa: BLE001 - reported to the run, which raises it
        out.send(("error", type(exc).__name__, str(exc)))
        return
    try:
        out.send(("started", {
            "edges": traffic.edges, "lanes": traffic.lanes, "deck_lanes": traffic.deck_lanes, "reach": traffic.reach,
            "types": dict(traffic.types), "models": dict(traffic.models), "table": table}))
        per_message = max(1, int(round(AHEAD_SECONDS / traffic.step)))
        sent_types: set[str] = set(traffic.types)
        traffic.take_new_models()  # those of the start went with "started"
        while not control.poll():
            batch: list[Frame] = []
            error: tuple[str, str] | None = None
            while len(batch) < per_message and \
                    traffic.begin + (traffic.sumo_steps + 1) * traffic.step <= traffic.end + 1e-9:
                try:
                    batch.append(traffic.advance())
                except BaseException as exc:  # noqa: BLE001 - after the frames before it
                    error = (type(exc).__name__, str(exc))
                    break
            new_types = {k: v for k, v in traffic.types.items() if k not in sent_types}  # a few vTypes
            new_models = traffic.take_new_models()  # not every model so far: a day makes tens of thousands
            sent_types.update(new_types)
            out.send(("frames", pack_frames(batch), new_types, new_models, traffic.teleports))
            if error is not None:
                out.send(("error", *error))
                break
            if not batch:  # SUMO's end: nothing more to step, wait for the run to close
                control.poll(None)
                break
        if control.poll():
            control.recv()
    finally:
        traffic.close()
        with contextlib.suppress(OSError):
            out.send(("closed", traffic.messages, traffic.teleports))


class SumoProcess(LiveSumo):
    """SUMO stepped in a forked child (a :class:`cosim.sumo.adapter.SumoTraffic` there), as a traffic source
    with the same frames, frame sink and documents as SUMO in this process (:class:`~cosim.sumo.adapter.LiveSumo`).

    Args:
        traffic: the SUMO traffic, not started: its settings run in the child, its frame sink stays here.
    """

    def __init__(self, traffic: SumoTraffic) -> None:
        super().__init__(traffic.settings, traffic.frame_sink)
        self._waiting: collections.deque[Frame] = collections.deque()
        self._failed: errors.CosimError | None = None
        self._process: Any = None
        self._out: Connection | None = None
        self._control: Connection | None = None

    # ------------------------------------------------------------- lifecycle
    def _start_sumo(self) -> str:
        context = multiprocessing.get_context("fork")
        out_recv, out_send = context.Pipe(duplex=False)
        control_recv, control_send = context.Pipe(duplex=False)
        self._process = fork_child("cosim-sumo", _serve, (self.settings, out_send, control_recv),
                                   child_ends=(out_send, control_recv), parent_ends=(out_recv, control_send))
        self._out, self._control = out_recv, control_send
        try:
            message = self._receive()
        except BaseException:  # a stop signal while SUMO starts: stop the child, leave nothing behind
            self.close()
            raise
        if message[0] != "started":
            self.close()
            raise self._failed or errors.SumoError(f"{self.config}: SUMO's process did not start")
        state = message[1]
        self.edges, self.lanes, self.deck_lanes, self.reach = (state["edges"], state["lanes"], state["deck_lanes"],
                                                               state["reach"])
        self.types.update(state["types"])
        self._known(state["models"])
        return str(state["table"])

    def _close_sumo(self) -> bool:
        """Close SUMO in the child; its messages come back."""
        if self._process is None:
            return False
        process, self._process = self._process, None
        closed = False
        try:
            with signals_held():
                assert self._control is not None
                with contextlib.suppress(OSError):
                    self._control.send(("close",))
                while self._out is not None and self._out.poll(CLOSE_TIMEOUT):
                    message = self._out.recv()
                    if message[0] == "closed":
                        self.messages, self.teleports = message[1], message[2]
                        closed = True
                        break
        except (EOFError, OSError):
            pass
        finally:
            for end in (self._out, self._control):
                if end is not None:
                    end.close()
            self._out = self._control = None
            process.join(CLOSE_TIMEOUT if closed else 1.0)
            if process.is_alive():
                process.kill()
                process.join()
        return True

    # --------------------------------------------------------------- frames
    def _receive(self) -> tuple:
        if self._out is None:
            raise errors.SumoError(f"{self.config}: SUMO is not running")
        try:
            with signals_held():
                message = self._out.recv()
        except (EOFError, OSError):
            code = self._process.exitcode if self._process is not None else None
            raise errors.SumoError(f"{self.config}: SUMO's process ended unexpectedly (exit status {code})") \
                from None
        if message[0] == "error":
            self._failed = _error(message[1], message[2])
            raise self._failed
        return message

    def _next_frame(self) -> Frame:
        while not self._waiting:
            if self._failed is not None:
                raise self._failed
            message = self._receive()
            if message[0] == "frames":
                _, packed, new_types, models, self.teleports = message
                self.types.update(new_types)
                self._known(models)
                self._waiting.extend(unpack_frames(packed))
        self.sumo_steps += 1
        return self._waiting.popleft()
