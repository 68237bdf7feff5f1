"""Exceptions raised by cosim.

Every error meant for a user derives from :class:`CosimError`; the command line
prints its message on one line and exits with status 2, without a traceback.
"""


class CosimError(Exception):
    """Base class of every error cosim reports to a user."""


class ConfigError(CosimError):
    """A scenario or input file is malformed or non-physical (names file and key)."""


class ModelError(CosimError):
    """The structural model cannot be built or solved as specified."""


class SumoError(CosimError):
    """SUMO failed or its inputs are broken."""


class LogError(CosimError):
    """An MCAP log is missing, corrupt or not a cosim log."""


class LogWriteError(LogError):
    """Writing a log failed part way (a full disk, a file-size limit, an I/O error): the file is cut short."""


class Interrupted(KeyboardInterrupt):
    """A run was stopped by a signal: SIGINT (Ctrl-C), SIGTERM or SIGHUP (a scheduler, a closed terminal).

    A :class:`KeyboardInterrupt`, so everything that finishes a log or a
    study's table on Ctrl-C does the same for the other signals; the command
    line exits with ``128 + signum``.

    Attributes:
        signum: the signal's number; name: its name ("SIGTERM").
    """

    def __init__(self, signum: int, name: str) -> None:
        super().__init__(name)
        self.signum = signum
        self.name = name


def first_line(exc: BaseException) -> str:
    """An exception's message as one line (its first), or its type's name if it says nothing: for reporting
    a third-party error (SUMO's, a parser's) inside a message of cosim's own."""
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def interruption(exc: BaseException) -> tuple[int, str]:
    """(signal number, name) of an interruption: an :class:`Interrupted`, or a bare KeyboardInterrupt (SIGINT)."""
    if isinstance(exc, Interrupted):
        return exc.signum, exc.name
    return 2, "SIGINT"


def interruption_message(exc: BaseException) -> str:
    """What a log's last status says about an interruption."""
    signum, name = interruption(exc)
    return "interrupted by the user (SIGINT)" if name == "SIGINT" else f"interrupted by {name}"


def raise_interrupted(signum: int, frame: object) -> None:
    """A signal handler: raise :class:`Interrupted` for ``signum`` (installed by the command line and by runs)."""
    import signal

    raise Interrupted(signum, signal.Signals(signum).name)
