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
