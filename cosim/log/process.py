"""A run's log written by a child process: encoding and compression off the simulation's GIL.

Encoding a run's log (JSON of every sample, the 3D scene, zstd chunks) is
Python work. In a thread it took the GIL from the thread that runs SUMO and
the adapter, which sets the pace of a run: logging was most of what a logged
run cost over an unlogged one (benchmarks/results/day.md). Here a child
process holds the :class:`cosim.log.writer.LogRecorder` (with its
:class:`~cosim.log.writer.BlockLogger`, :class:`~cosim.log.writer.TrafficLogger`
and :class:`~cosim.log.scene.SceneWriter`) and the run sends it what to write
through a pipe: the same objects, so the file is the same as a thread would
write it.

:class:`LogProcess` has the recorder's methods (``attach``, ``metadata``,
``write``, ``status``, ``flush``, ``close``) and :meth:`LogProcess.block_logger`
gives the observer that streams the blocks. The child is forked (it starts in
milliseconds with everything imported); it ignores the stop signals (SIGINT,
SIGTERM, SIGHUP reach a whole process group: the run decides how its log
ends), and when the run's process dies without closing the log (SIGKILL, the
out-of-memory killer) the child still finishes it, with status "error" and
:data:`ORPHANED`. An error in the child (a full disk) is raised in the run at
its next block as a :class:`cosim.errors.LogError`.

Only where forking is safe: Linux, the main thread of a process that may have
children (:func:`fork_possible`); elsewhere runs log from a thread.
"""
from __future__ import annotations

import contextlib
import fcntl
import multiprocessing
import os
import signal
import sys
import threading
import traceback
import weakref
from collections.abc import Callable, Iterable, Iterator
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

try:  # signal's C module (signals_held says why); signal itself where an interpreter has no such module
    import _signal as _raw_signal
except ImportError:  # pragma: no cover - CPython has it
    _raw_signal = signal

from cosim.core.traffic import pack_frames, unpack_frames
from cosim.errors import LogError, LogWriteError

__all__ = ["ORPHANED", "STOP_SIGNALS", "WRITER_NICENESS", "LogProcess", "fork_child", "fork_possible",
           "signals_held"]

#: The final status message of a log whose run's process died before it closed the log.
ORPHANED = "the run's process ended without finishing its log (killed, e.g. SIGKILL or out of memory)"
#: Bytes the pipe to the child holds (Linux's F_SETPIPE_SZ; the default is 64 KiB, about one block): the run
#: goes on while the child encodes a burst of blocks, and waits only when the child falls this far behind.
PIPE_BYTES = 1 << 20
#: How long closing waits for the child to finish the file, s.
CLOSE_TIMEOUT = 120.0
#: How much nicer (lower priority) the writer process is than the run.
WRITER_NICENESS = 10
_F_SETPIPE_SZ = getattr(fcntl, "F_SETPIPE_SZ", 1031)
STOP_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))
_STOP_NUMBERS = tuple(int(s) for s in STOP_SIGNALS)


def fork_possible() -> bool:
    """Whether work can go to a forked child here (the log writer, SUMO): Linux, the main thread, a process
    allowed children."""
    return (sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods()
            and threading.current_thread() is threading.main_thread()
            and not multiprocessing.current_process().daemon)


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """The stop signals wait until a message is wholly in or out of a pipe: a signal handler raising in the
    middle of one would leave the child reading the rest of a message never sent (both sides then wait on
    each other for ever).

    Blocking the signals in this thread is not enough: the kernel hands a process's signal to any thread
    that does not block it (SUMO's reader, numba's workers), and Python then runs the handler in the main
    thread at its next instruction, mask or not. So in the main thread the handlers are also swapped for
    a recorder, and a signal that came in the meantime goes to its own handler once the message is through.

    Through ``_signal``, the C module ``signal`` wraps: ``signal``'s own functions turn every handler and mask
    they return into enums (a failed enum lookup, an exception, for each Python handler), which made this 52 µs
    against 6 µs, at every message of a run (11 000 an hour).
    """
    old_mask = _raw_signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_NUMBERS)
    arrived: list[int] = []
    swapped: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for signum in _STOP_NUMBERS:
            if _raw_signal.getsignal(signum) is not None:  # None: a handler not set from Python, left alone
                swapped[signum] = _raw_signal.signal(signum, lambda number, _frame: arrived.append(number))
    try:
        yield
    finally:
        for signum, handler in swapped.items():
            _raw_signal.signal(signum, handler)
        _raw_signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
        for signum in arrived[:1]:  # the first is the one that stops; its handler holds back any later one
            handler = swapped[signum]
            if callable(handler):
                handler(signum, None)
            elif handler == signal.SIG_DFL:
                signal.raise_signal(signum)


def fork_child(name: str, target: Callable[..., None], args: tuple, child_ends: tuple[Connection, ...],
               parent_ends: tuple[Connection, ...], niceness: int = 0) -> Any:
    """Fork ``target(*args)`` as the started process ``name``, for the run's helpers (the log writer, SUMO).

    The child ignores SIGINT, SIGTERM and SIGHUP (blocked around the fork, so none arrives before): a terminal's
    Ctrl-C reaches the whole process group, and the run decides how its helpers stop. Each side closes the
    other's pipe ends (``child_ends`` stay open in the child only), so that either side's death ends the pipes
    (EOF) for the other. Whatever ``target`` raises is the run's to report through the pipes, or nobody's: it
    leaves no traceback on the terminal.
    """
    def child() -> None:
        for signum in STOP_SIGNALS:
            signal.signal(signum, signal.SIG_IGN)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
        if niceness:
            with contextlib.suppress(OSError):
                os.nice(niceness)
        for end in parent_ends:
            end.close()
        with contextlib.suppress(BaseException):
            target(*args)

    process = multiprocessing.get_context("fork").Process(target=child, name=name, daemon=False)
    old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        process.start()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
    for end in child_ends:
        end.close()
    return process


def _where_and_what(exc: BaseException) -> str:
    """The child's error for the run: its type, message and where it was raised (file:line)."""
    where = traceback.extract_tb(exc.__traceback__)
    at = f" ({Path(where[-1].filename).name}:{where[-1].lineno})" if where else ""
    return f"{type(exc).__name__}: {exc}{at}"


def _serve(commands: Connection, replies: Connection, path: Path, names: list[str], scene: bool) -> None:
    from .writer import BlockLogger, LogRecorder, TrafficLogger

    try:
        rec = LogRecorder(path, names, force=False, scene=scene)
    except BaseException as exc:  # noqa: BLE001 - reported to the run, which raises it
        replies.send(("error", str(exc) if isinstance(exc, LogError) else _where_and_what(exc)))
        return
    replies.send(("ready", None))
    logger: BlockLogger | None = None
    sink: TrafficLogger | None = None  # SUMO frames, handed to the logger, which writes them between its pieces
    error: str | None = None
    while True:
        try:
            message = commands.recv()
        except (EOFError, OSError):  # the run's process is gone: finish the file for whoever reads it
            with contextlib.suppress(BaseException):
                rec.close("error", ORPHANED)
            return
        op = message[0]
        if op == "close":
            try:
                if logger is not None and error is None:
                    logger.close()
                rec.close(*message[1:])
            except BaseException as exc:  # noqa: BLE001
                error = error or _where_and_what(exc)
            replies.send(("closed", error))
            return
        if error is not None:
            continue  # the first error is reported; the rest is read and dropped so that the run never blocks
        try:
            if op == "block":
                _, times, keep, report, frames, new_models = message
                assert logger is not None and sink is not None, "blocks before the block logger"
                first = True
                for frame in unpack_frames(frames):
                    sink(frame, new_models if first else {})
                    first = False
                if times is not None:
                    logger.on_block(times, keep, report)
            elif op == "logger":
                _, total_time, status_every, plan, first_column, piece_steps = message
                logger = BlockLogger.for_run(rec, names, total_time, status_every=status_every, plan=plan,
                                             first_column=first_column, piece_steps=piece_steps, threaded=False)
                sink = logger.traffic_sink()
            else:
                getattr(rec, op)(*message[1:])
        except BaseException as exc:  # noqa: BLE001 - reported to the run at its next block
            error = _where_and_what(exc)
            with contextlib.suppress(OSError):
                replies.send(("error", error))


class LogProcess:
    """A :class:`cosim.log.writer.LogRecorder` in a child process (same arguments but ``chunk_size``).

    Raises:
        LogError: the child could not create the file (the recorder's own message).
    """

    def __init__(self, path: str | Path, sensor_names: Iterable[str], scene: bool = False) -> None:
        self.path = Path(path)
        self.sensor_names = list(sensor_names)
        self.final_state: str | None = None
        self._closed = False
        self._error: str | None = None
        context = multiprocessing.get_context("fork")
        commands_in, commands_out = context.Pipe(duplex=False)
        replies_in, replies_out = context.Pipe(duplex=False)
        with contextlib.suppress(OSError):  # a smaller pipe only makes the run wait sooner
            fcntl.fcntl(commands_out.fileno(), _F_SETPIPE_SZ, PIPE_BYTES)
        # The run's threads set its pace; the writer has the pipe's slack and catches up when a core is free. On
        # two cores a nicer writer took 5-10 % off a logged run's wall time (10 minutes of the default run).
        self._process = fork_child("cosim-log-writer", _serve,
                                   (commands_in, replies_out, self.path, self.sensor_names, scene),
                                   child_ends=(commands_in, replies_out), parent_ends=(commands_out, replies_in),
                                   niceness=WRITER_NICENESS)
        self._commands, self._replies = commands_out, replies_in
        # At the run's exit the pipe closes even if the log was not (a defect): the child then finishes the
        # file (ORPHANED) and ends, instead of waiting for commands while multiprocessing waits for it.
        weakref.finalize(self, commands_out.close)
        try:
            kind, text = self._reply()
        except BaseException:  # a stop signal while the child starts: it is stopped before the run cleans up
            self._closed = True
            self._process.kill()
            self._process.join()
            commands_out.close()
            replies_in.close()
            raise
        if kind != "ready":
            self._process.join(CLOSE_TIMEOUT)
            self._closed = True
            raise LogError(text or f"{self.path}: the log writer process failed to start")
        self._sent_types: set[str] = set()

    def _reply(self) -> tuple[str, str | None]:
        try:
            with signals_held():
                return self._replies.recv()
        except (EOFError, OSError):
            return "error", f"{self.path}: the log writer process ended unexpectedly " \
                            f"(exit status {self._process.exitcode})"

    def _send(self, *message: Any) -> None:
        if self._closed:
            raise LogError(f"{self.path}: the log is already closed")
        self.check()
        try:
            with signals_held():
                self._commands.send(message)
        except OSError as exc:
            raise LogError(f"{self.path}: the log writer process is gone ({exc.strerror or exc})") from None

    def check(self) -> None:
        """Raise the child's first error (e.g. a full disk), if it reported one."""
        while self._error is None and self._replies.poll():
            kind, text = self._reply()
            if kind == "error":
                self._error = text
        if self._error is not None:
            raise LogWriteError(f"{self.path}: writing the log failed: {self._error}")

    # ------------------------------------------------- the recorder's methods
    def attach(self, name: str, data: bytes | str, media_type: str = "text/plain") -> None:
        self._send("attach", name, data, media_type)

    def metadata(self, name: str, values: dict[str, str]) -> None:
        self._send("metadata", name, dict(values))

    def write(self, topic: str, t: float, message: dict[str, Any]) -> None:
        self._send("write", topic, t, message)

    def status(self, t: float, state: str, message: str = "", progress: float | None = None,
               wall_time: float | None = None) -> None:
        self._send("status", t, state, message, progress, wall_time)

    def flush(self) -> None:
        self._send("flush")

    def close(self, state: str = "finished", message: str = "", wall_time: float | None = None) -> None:
        """Finish the log (its last status ``state``) and wait for the child; idempotent.

        Raises:
            LogError: the child failed to write (its first error), or did not finish in time.
        """
        if self._closed:
            return
        self._closed = True
        self.final_state = state
        error = self._error
        try:
            self._commands.send(("close", state, message, wall_time))
            while True:
                kind, text = self._reply()
                if kind == "closed":
                    error = error or text
                    break
                if kind == "error":
                    error = error or text
                    if text and "ended unexpectedly" in text:
                        break
        except OSError as exc:
            error = error or f"the log writer process is gone ({exc})"
        finally:
            self._commands.close()
            self._process.join(CLOSE_TIMEOUT)
            if self._process.is_alive():
                self._process.kill()
                self._process.join()
                error = error or f"the log writer process did not finish within {CLOSE_TIMEOUT:g} s"
            self._replies.close()
        if error is not None:
            raise LogWriteError(f"{self.path}: writing the log failed: {error}")

    # ------------------------------------------------------ the block stream
    def block_logger(self, total_time: float, status_every: float, plan: Any = None,
                     first_column: int = 0, piece_steps: int | None = None) -> _BlockStream:
        """The observer of :func:`cosim.core.simulation.simulate` that streams the blocks into this log.

        The child writes them with a :class:`cosim.log.writer.BlockLogger` (and draws ``plan``'s scene,
        :class:`cosim.log.scene.SceneWriter`, from the sensor columns from ``first_column`` on).
        """
        self._send("logger", total_time, status_every, plan, first_column, piece_steps)
        return _BlockStream(self)


class _BlockStream:
    """:class:`cosim.log.writer.BlockLogger`'s interface on the run's side of a :class:`LogProcess`."""

    def __init__(self, log: LogProcess) -> None:
        self.log = log
        self._frames: list[Any] = []
        self._new_models: dict[str, Any] = {}

    def on_block(self, times, keep, report) -> None:  # noqa: ANN001 - the simulate() observer protocol
        self._hand_over(times, keep, report)

    def _hand_over(self, times, keep, report) -> None:  # noqa: ANN001
        frames, self._frames = self._frames, []
        models, self._new_models = self._new_models, {}
        self.log._send("block", times, keep, report, pack_frames(frames), models)

    def traffic_sink(self) -> _FrameSink:
        """A frame sink for a live traffic source (SUMO): its frames go to the child with the next block."""
        return _FrameSink(self)

    def paced(self, traffic: Any) -> Any:
        return traffic  # the child does not share the run's GIL: nothing to pace

    def close(self) -> None:
        """Hand over the frames still waiting; raise the child's first error."""
        if self._frames and not self.log._closed:
            self._hand_over(None, None, None)
        self.log.check()

    def __enter__(self) -> _BlockStream:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:  # noqa: ANN001
        try:
            self.close()
        except LogError:
            if exc_type is None:
                raise


class _FrameSink:
    """Collects SUMO frames (and each vehicle type's model, once) for the child."""

    def __init__(self, stream: _BlockStream) -> None:
        self.stream = stream

    def __call__(self, frame, new_models: dict) -> None:  # noqa: ANN001 - the frame sink protocol
        stream = self.stream
        stream._frames.append(frame)
        stream._new_models.update(new_models)  # handed to the child with the next block, before its frames

    def attach(self, name: str, data: bytes | str, media_type: str = "text/plain") -> None:
        """A document of the traffic source (its vehicle types, SUMO's messages) as an attachment of the log."""
        self.stream.log.attach(name, data, media_type)
