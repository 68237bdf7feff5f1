"""What the subcommands' parsers share: argument types, the note on bundled scenarios, the time window
options, and the options whose values may begin with "-".

Like every module the parser is built from, this one imports nothing heavy: ``cosim --help`` and
``cosim <command> --help`` load only the standard library and a few light cosim modules.
"""
from __future__ import annotations

import argparse
import re
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from cosim.run.bundled import list_bundled_scenarios

#: How every subcommand's help is formatted (descriptions and epilogs as written).
FORMATTER = argparse.RawDescriptionHelpFormatter


class Subcommands(Protocol):
    """What a command module's ``add_parser`` adds its parser to (``ArgumentParser.add_subparsers()``)."""

    def add_parser(self, name: str, *, help: str | None = ..., description: str | None = ...,  # noqa: A002
                   epilog: str | None = ..., formatter_class: type[argparse.HelpFormatter] = ...
                   ) -> argparse.ArgumentParser: ...


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {value}")
    return value


def finite_float(text: str) -> float:
    """argparse type: a finite number (``nan`` and ``inf`` are refused)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        # strip(): a negative number reaches here as " -1e999" (see dash_values_kept)
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text.strip()!r}")
    return value


def bundled_text() -> str:
    """The help's note on SCENARIO, with the bundled scenarios' names."""
    names = ", ".join(list_bundled_scenarios()) or "none"
    return textwrap.fill(f"SCENARIO is a path to a .toml file or the name of a bundled scenario ({names}).", 79)


def window_arguments(parser: argparse.ArgumentParser, verb: str) -> None:
    """``--from T0`` and ``--to T1``: a window of simulated time (export and plot); "--from -5" is a value
    (:data:`WINDOW_VALUES`)."""
    parser.add_argument("--from", dest="start", type=float, metavar="T0",
                        help=f"{verb} from t = T0 s of simulated time (default: the log's start)")
    parser.add_argument("--to", dest="end", type=float, metavar="T1",
                        help=f"{verb} up to t = T1 s, included (default: the log's end)")


# --------------------------------------------------------------------------- values that begin with "-"

#: A negative number written as a command line does: "-5", "-5.", "-.5", "-1e5", "-100e3".
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


@dataclass(frozen=True)
class DashValue:
    """An option whose values may begin with "-", which argparse would read as an option.

    Attributes:
        nargs: how many values the option takes.
        numbers: True: its values are numbers, and a negative one ("-1e5", which argparse before Python 3.13
            reads as an option) is a value; False: any word beginning with one "-" is its value (SUMO edge
            ids: OSM imports name a street's reverse direction "-<id>").
    """

    nargs: int = 1
    numbers: bool = True


#: ``--from`` and ``--to`` of :func:`window_arguments`.
WINDOW_VALUES = {"--from": DashValue(), "--to": DashValue()}


def _takes(word: str, option: str, value: DashValue) -> bool:
    """Whether ``word`` names ``option``: exactly, or (numbers) abbreviated as argparse allows ("--fro")."""
    return word == option or (value.numbers and len(word) > 2 and word.startswith("--") and option.startswith(word))


def dash_values_kept(argv: Sequence[str], options: Mapping[str, DashValue]) -> list[str]:
    """``argv`` with the values of ``options`` that begin with "-" made unmistakable to argparse.

    A text value is joined to its option (``--edge -148050455#0`` -> ``--edge=-148050455#0``); a negative
    number gets a leading space (``--load 20 0 -1e5`` -> ``--load 20 0 " -1e5"``): a word that does not begin
    with "-" is a value to argparse, and ``float()`` ignores the space. Everything after ``--`` is left as it is.
    """
    out: list[str] = []
    i = 0
    while i < len(argv):
        word = argv[i]
        out.append(word)
        i += 1
        if word == "--":
            return out + list(argv[i:])
        value = next((v for option, v in options.items() if _takes(word, option, v)), None)
        if value is None:
            continue
        for _ in range(value.nargs):
            following = argv[i] if i < len(argv) else ""
            if value.numbers and NEGATIVE_NUMBER.match(following):
                out.append(f" {following}")
            elif following[:1] != "-":  # a value as it is (or the end)
                if i < len(argv):
                    out.append(following)
            elif not value.numbers and following[:2] != "--":
                out[-1] = f"{word}={following}"
            else:  # an option: the values end here
                break
            i += 1
    return out
