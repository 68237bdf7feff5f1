"""Stopping a run from outside: SIGINT (Ctrl-C), SIGTERM and SIGHUP all stop it the same way.

Schedulers (Dask, batch queues, containers) stop processes with SIGTERM, a
closed terminal sends SIGHUP, a user presses Ctrl-C: each raises
:class:`cosim.errors.Interrupted` (a ``KeyboardInterrupt``) in the main thread,
so that the code that finishes a log or a study's table runs for every one of
them. :func:`stop_signals` arranges that around a run, and holds further
signals back while the run's ending is written (the first one stops the run;
a second one must not cut the log's summary short).

Handlers are installed only in the main thread and only over the default
handlers (or cosim's own, :func:`cosim.errors.raise_interrupted`): a program
that handles these signals itself keeps its handlers.
"""
from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from typing import Any

from cosim.errors import Interrupted, raise_interrupted

__all__ = ["STOP_SIGNALS", "StopGuard", "install_stop_handlers", "stop_signals"]

#: The signals that stop a run, with a finished log.
STOP_SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


def _ours_or_default(handler: Any) -> bool:
    return handler in (signal.SIG_DFL, signal.default_int_handler, raise_interrupted)


def install_stop_handlers() -> None:
    """Make SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` in this process (main thread only).

    For the command line, first thing: a signal at any moment then ends in its
    one-line message and exit status instead of a traceback or a silent death.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for signum in STOP_SIGNALS:
        if _ours_or_default(signal.getsignal(signum)):
            signal.signal(signum, raise_interrupted)


class StopGuard:
    """The state of :func:`stop_signals`: set :attr:`closing` once the run's ending is being written.

    Attributes:
        closing: from now on signals are held back (recorded, not raised).
        held: the first signal held back while closing, raised when the block ends normally.
        received: how many signals arrived within the block (raised or held).
    """

    def __init__(self, closing: bool = False) -> None:
        self.closing = closing
        self.held: Interrupted | None = None
        self.received = 0
        self._old: dict[int, Any] = {}

    def _handle(self, signum: int, frame: object) -> None:
        self.received += 1
        if self.closing:
            if self.held is None:
                self.held = Interrupted(signum, signal.Signals(signum).name)
            return
        self.closing = True  # the first signal stops the run; the ones after it wait for its ending
        raise_interrupted(signum, frame)


@contextlib.contextmanager
def stop_signals(hold: bool = False) -> Iterator[StopGuard]:
    """Within the block, SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` once; then they are held back.

    A signal held back while the block was closing (``guard.closing``) is
    raised when the block ends without an exception of its own, so it is
    never lost: the caller sees the interruption after the log is finished.

    With ``hold``, every signal is held back from the start: the block polls
    ``guard.held`` and raises it where it is safe to (a ``KeyboardInterrupt``
    inside a Dask client call leaves its event loop printing a traceback).
    """
    guard = StopGuard(closing=hold)
    if threading.current_thread() is threading.main_thread():
        for signum in STOP_SIGNALS:
            old = signal.getsignal(signum)
            if _ours_or_default(old):
                guard._old[signum] = old
                signal.signal(signum, guard._handle)
    try:
        yield guard
    finally:
        for number, handler in guard._old.items():
            signal.signal(number, handler)
        guard._old.clear()
    if guard.held is not None:
        raise guard.held
