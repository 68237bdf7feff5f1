"""``python -m cosim``: the same as the ``cosim`` command.

SIGINT, SIGTERM and SIGHUP are blocked until :func:`cosim.cli.main` has
installed its handlers (then unblocked, a pending one delivered): a Ctrl-C
in the first milliseconds ends like one at any later moment, without a
traceback.
"""
import signal
import sys

signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM, signal.SIGHUP})

from cosim.cli import main  # noqa: E402 - after the signals are blocked

sys.exit(main())
