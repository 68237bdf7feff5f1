"""cosim.run.signals.stop_signals with real signals sent to this process (pytest's main thread)."""
from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
from typing import Any

import pytest

from cosim.errors import Interrupted
from cosim.log.process import signals_held
from cosim.run.signals import stop_signals


def deliver(signum: signal.Signals) -> None:
    """Send ``signum`` to this process; Python runs the handler at the next bytecode boundary."""
    os.kill(os.getpid(), signum)
    time.sleep(0.01)


@pytest.fixture(autouse=True)
def stop_signals_not_ignored() -> Any:
    """These tests are about the guard, not about what the shell passed on: under ``nohup`` the process inherits
    SIGHUP ignored, which the guard respects (the last test); here it is the default for each test."""
    old = {signum: signal.getsignal(signum) for signum in (signal.SIGTERM, signal.SIGHUP)}
    for signum, handler in old.items():
        if handler == signal.SIG_IGN:
            signal.signal(signum, signal.SIG_DFL)
    yield
    for signum, handler in old.items():
        signal.signal(signum, handler)


def test_the_first_signal_is_raised_and_later_ones_wait_for_the_block_to_end() -> None:
    with pytest.raises(Interrupted) as first, stop_signals() as guard:
        deliver(signal.SIGTERM)
    assert first.value.name == "SIGTERM" and guard.received == 1
    with pytest.raises(Interrupted) as held, stop_signals() as guard:
        guard.closing = True  # the log's ending is being written: must not be cut short
        deliver(signal.SIGHUP)
        deliver(signal.SIGINT)
        assert guard.held is not None and guard.held.name == "SIGHUP"  # still running: nothing was raised
    assert held.value.name == "SIGHUP" and guard.received == 2


def test_held_signals_are_recorded_not_raised_and_the_first_is_raised_when_the_block_ends() -> None:
    """``hold``: the study's Dask loop polls ``guard.held`` (a KeyboardInterrupt inside a Dask call makes
    distributed log a traceback); none is raised inside the block, none is lost."""
    with pytest.raises(Interrupted) as held, stop_signals(hold=True) as guard:
        assert guard.held is None
        deliver(signal.SIGINT)
        deliver(signal.SIGTERM)
        assert guard.held is not None and guard.held.name == "SIGINT" and guard.received == 2
    assert held.value is guard.held and held.value.signum == signal.SIGINT
    before = signal.getsignal(signal.SIGTERM)
    with stop_signals(hold=True) as guard:
        assert signal.getsignal(signal.SIGTERM) != before
    assert guard.received == 0 and signal.getsignal(signal.SIGTERM) == before  # the handlers are restored


def test_a_signal_delivered_to_another_thread_waits_until_the_message_is_through_the_pipe() -> None:
    """The kernel may hand the process's SIGTERM to any thread that does not block it; Python then runs the
    handler in the main thread at its next instruction, inside a held block unless :func:`signals_held` defers
    it. Raised between a message's header and its body (``Connection.send_bytes`` writes them separately), it
    left a replay and its log writer each waiting on the other for hours (seen in this suite)."""
    receiver, sender = multiprocessing.Pipe(duplex=False)
    payload = b"x" * 40_000  # above 16 KiB: header and body are two writes (and within the pipe's 64 KiB)
    bystander = threading.Event()
    other = threading.Thread(target=bystander.wait)  # a thread with the stop signals unblocked
    other.start()
    through = []
    try:
        with pytest.raises(Interrupted) as stopped, stop_signals():
            with signals_held():
                signal.pthread_kill(other.ident, signal.SIGTERM)
                time.sleep(0.05)  # the handler would run here, in the main thread, were it not held
                sender.send_bytes(payload)
                through.append(True)
            through.append(False)  # the held signal is raised on leaving the block, before this
    finally:
        bystander.set()
        other.join()
    assert stopped.value.name == "SIGTERM" and through == [True]
    assert receiver.poll(1) and receiver.recv_bytes() == payload  # the message arrived whole


def test_a_signal_the_process_ignores_stays_ignored() -> None:
    """A run started under ``nohup`` (SIGHUP ignored) is not stopped by a hangup: the guard leaves an ignored
    signal as it found it, and it is never counted."""
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    with stop_signals() as guard:
        os.kill(os.getpid(), signal.SIGHUP)
        time.sleep(0.05)
        assert guard.received == 0 and guard.held is None
    assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
