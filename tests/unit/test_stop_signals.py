"""cosim.run.signals.stop_signals with real signals sent to this process (pytest's main thread)."""
from __future__ import annotations

import os
import signal
import time

import pytest

from cosim.errors import Interrupted
from cosim.run.signals import stop_signals


def deliver(signum: signal.Signals) -> None:
    """Send ``signum`` to this process; Python runs the handler at the next bytecode boundary."""
    os.kill(os.getpid(), signum)
    time.sleep(0.01)


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
