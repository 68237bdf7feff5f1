"""The ``cosim`` command line: the top-level parser, the list of subcommands, and how errors become exit
statuses.

Each subcommand is one module of this package (:data:`COMMANDS`) that adds its own parser
(``add_parser``: its arguments and help) and runs the command (``cmd_<name>``)::

    cosim modes SCENARIO [--count N] [--json] [--plot FILE.png]              modes.py
    cosim static SCENARIO --load X Y FZ [--load X Y FZ ...] [--json]         static.py
    cosim run [SCENARIO] [--out LOG.mcap] [--csv OUT.csv] [--force] [--quiet] run.py
    cosim replay LOG.mcap [--scenario OTHER] [--out NEW.mcap] [--force]      replay.py
    cosim export LOG.mcap --csv OUT.csv [--topic TOPIC] [--from T0] [--to T1] export.py
    cosim info LOG.mcap [--verify]                                           info.py
    cosim plot LOG.mcap [--sensor NAME ...] [--from T0] [--to T1] -o FIG.png plot.py
    cosim layout LOG.mcap -o LAYOUT.json [--force]                           layout.py
    cosim validate [--out DIR] [--quick]                                     validate.py
    cosim study STUDY.toml [--workers N] ...                                 study.py
    cosim dataset SPEC.toml [--out FOLDER] [--force]                         dataset.py
    cosim bridge NET_OR_SUMOCFG [--edge ID ...] [--near X Y] [--plot FIG.png] bridge.py

Building the parser loads nothing heavy: a command module imports what its
command needs (numpy, the scenario machinery, mcap, SUMO, Dask, ...) inside
its command function, so that ``cosim --help`` and ``cosim <command> --help``
answer at once (tests/integration/test_cli.py checks what they load).

The work is done by :mod:`cosim.run` (and :mod:`cosim.study`,
:mod:`cosim.dataset`, :mod:`cosim.validation`): the command line parses, calls
one library function per command and prints what it returns; it is the only
package that prints.

Every :class:`cosim.errors.CosimError` becomes ``cosim: error: <message>`` on
stderr and exit status 2 (as for usage errors); a :class:`cosim.errors.ModelError`
after the time stepping started (the solution diverged) exits with 1 (the log then
ends with status "error"); SIGINT (Ctrl-C), SIGTERM and SIGHUP exit with 128 +
the signal's number, 130, 143 and 129 (a started log ends with status "interrupted").
"""
from __future__ import annotations

import argparse
import os
import sys
import textwrap

from cosim import __version__
from cosim.errors import CosimError

from . import (
    bridge,
    dataset,
    export,
    info,
    layout,
    modes,
    plot,
    replay,
    report_interruption,
    run,
    static,
    study,
    validate,
)
from .options import FORMATTER, bundled_text, dash_values_kept
from .run import DEFAULT_SCENARIO
from .text import EXIT_USAGE, report_error

#: The subcommands, in the order ``cosim --help`` lists them: each module has ``NAME``, ``add_parser`` and
#: ``cmd_<name>``, and ``DASH_VALUES`` if some of its options take values that may begin with "-".
COMMANDS = (modes, static, run, replay, export, info, plot, layout, validate, study, dataset, bridge)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``cosim`` program: the top-level options and one subparser per command."""
    parser = argparse.ArgumentParser(
        prog="cosim",
        description=textwrap.dedent(
            """\
            Co-simulation of road traffic and bridge vibration: a 7-DOF
            Timoshenko-Vlasov beam model of the bridge (shear deformation,
            rotary inertia, uniform and non-uniform torsion) driven by scripted
            vehicles or by SUMO traffic, every run logged to MCAP.
            Scenarios are TOML files (see docs/scenario.md); SI units throughout."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the bundled default bridge ({DEFAULT_SCENARIO}) -> runs/*.mcap
              cosim run my-bridge.toml --out run1.mcap
              cosim info run1.mcap
              cosim export run1.mcap --csv run1.csv
              cosim plot run1.mcap -o run1.png
              cosim layout run1.mcap -o run1-layout.json   # for Foxglove
              cosim replay run1.mcap --scenario other-bridge.toml
              cosim modes paper-double-tee --count 12 --plot modes.png
              cosim static paper-double-tee --load 20 3.325 -100e3
            """
        )
        + "\n"
        + bundled_text()
        + "\nErrors print 'cosim: error: ...' on stderr and exit with status 2; SIGINT, SIGTERM and SIGHUP\n"
        "exit with 128 + the signal's number. Limits on input sizes: docs/limits.md.",
        formatter_class=FORMATTER,
    )
    parser.add_argument("--version", action="version", version=f"cosim {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")
    commands.required = True

    for command in COMMANDS:
        command.add_parser(commands)
    return parser


def values_kept(argv: list[str]) -> list[str]:
    """``argv`` with the values that begin with "-" of the command's options marked as values for argparse
    (the command's ``DASH_VALUES``; :func:`.options.dash_values_kept`)."""
    name = next((word for word in argv if not word.startswith("-")), None)
    command = next((c for c in COMMANDS if c.NAME == name), None)
    options = getattr(command, "DASH_VALUES", None)
    if name is None or not options:
        return argv
    at = argv.index(name) + 1
    return [*argv[:at], *dash_values_kept(argv[at:], options)]


def main(argv: list[str] | None = None) -> int:
    """Run the ``cosim`` command line; returns the exit status.

    Args:
        argv: the arguments without the program name (default: ``sys.argv[1:]``).
    """
    parser = build_parser()
    try:
        args = parser.parse_args(values_kept(sys.argv[1:] if argv is None else list(argv)))
    except SystemExit as exc:  # --help, --version (0) and usage errors (2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    try:
        return int(args.func(args))
    except CosimError as exc:
        report_error(str(exc))
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # SIGINT, SIGTERM or SIGHUP where the command did not report it itself
        return report_interruption(exc)
    except BrokenPipeError:  # e.g. `cosim modes ... | head`
        try:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        except OSError:
            pass
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
