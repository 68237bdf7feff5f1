"""The ``cosim`` command line: the only package that prints.

:func:`main` makes SIGINT, SIGTERM and SIGHUP stop cosim cleanly *before*
anything heavy is imported (numpy, numba, SUMO, ...), so that a signal at any
moment, start-up included, ends with one line and exit status 128 + the
signal's number, never a traceback.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
from typing import Any

from cosim.errors import interruption
from cosim.run.signals import STOP_SIGNALS, install_stop_handlers

__all__ = ["build_parser", "main", "report_interruption"]

# BLAS in one thread unless the user sets these: cosim's solver thread, SUMO and the log writer already keep
# both cores of a small machine busy, and OpenBLAS threads that wait for a busy core spin (the section's
# and the modes' dense eigen-solutions took 1.1-1.6 s at every start instead of 0.02 s; they must be set
# before numpy loads: nothing above imports it). Child processes (the log writer, SUMO's, a study's
# workers) inherit them.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


def main(argv: list[str] | None = None) -> int:
    """Run the ``cosim`` command line; returns the exit status.

    Args:
        argv: the arguments without the program name (default: ``sys.argv[1:]``).
    """
    previous = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}
    try:
        install_stop_handlers()
        # ``python -m cosim`` blocks them until the handlers are in place; a pending one arrives now.
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(STOP_SIGNALS))
        from .app import main as app_main

        return app_main(argv)
    except KeyboardInterrupt as exc:  # during start-up, or anywhere the command did not handle it
        return report_interruption(exc)
    finally:
        if threading.current_thread() is threading.main_thread():  # handlers can only be set there
            for signum, handler in previous.items():
                if handler is not None:
                    signal.signal(signum, handler)


def report_interruption(exc: KeyboardInterrupt) -> int:
    """Say which signal stopped cosim (one line on stderr) and return its exit status, 128 + its number."""
    signum, name = interruption(exc)
    try:
        print(f"cosim: interrupted ({name})", file=sys.stderr)
    except (OSError, ValueError):  # SIGHUP: the terminal may be gone
        pass
    return 128 + signum


def __getattr__(name: str) -> Any:
    if name == "build_parser":
        from .app import build_parser

        return build_parser
    raise AttributeError(f"module 'cosim.cli' has no attribute {name!r}")
