"""The argument checks of cosim's Python API: a finite number, one of a few names.

Each raises :class:`~cosim.errors.ConfigError` naming the parameter in
backticks, after ``where``, the object it belongs to (``"sensor mid: "``,
``"plate 0: "``, ``"quarter-car: "``)::

    finite(-1, "dt", above=0)                  # `dt` must be a finite number > 0 (got -1)
    finite(nan, "x", "sensor mid: ", unit="m") # sensor mid: `x` must be a finite number, m (got nan)
    one_of("x", BASES, "basis")                # `basis` must be one of direct, modal (got 'x')

Files (scenarios, studies, datasets) are checked before they reach these, with
the file and key in every message, by :mod:`cosim.run.config_base`.
"""
from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

from cosim.errors import ConfigError

__all__ = ["finite", "one_of"]


def finite(value: object, name: str, where: str = "", *, above: float | None = None,
           at_least: float | None = None, unit: str = "") -> float:
    """``value`` as a float, if it is a finite real number (not a bool) ``> above`` and ``>= at_least``.

    Args:
        value: the argument.
        name: the parameter's name, shown in backticks.
        where: what it belongs to, written before it (ends with ": ").
        above, at_least: the bound, if any.
        unit: its unit, for the message.

    Raises:
        ConfigError: ``<where>`<name>` must be a finite number[ > above][, unit] (got <value>)``.
    """
    number = float(value) if isinstance(value, numbers.Real) and not isinstance(value, bool) else math.nan
    if not (math.isfinite(number) and (above is None or number > above) and (at_least is None or number >= at_least)):
        bound = f" > {above:g}" if above is not None else f" >= {at_least:g}" if at_least is not None else ""
        raise ConfigError(f"{where}`{name}` must be a finite number{bound}{f', {unit}' if unit else ''} "
                          f"(got {value!r})")
    return number


def one_of(value: object, choices: Sequence[str], name: str, where: str = "") -> str:
    """``value`` if it is one of ``choices``.

    Raises:
        ConfigError: ``<where>`<name>` must be one of <choices> (got <value>)``.
    """
    if not isinstance(value, str) or value not in choices:
        raise ConfigError(f"{where}`{name}` must be one of {', '.join(choices)} (got {value!r})")
    return value
