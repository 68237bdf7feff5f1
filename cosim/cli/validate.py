"""``cosim validate``: the verification and validation cases with their report (the work is :mod:`cosim.validation`)."""
from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from cosim.errors import CosimError

from .options import FORMATTER, Subcommands
from .text import EXIT_RUN_FAILED, print_lines

NAME = "validate"


def add_parser(commands: Subcommands) -> None:
    """``cosim validate``: its arguments and help."""
    validate = commands.add_parser(
        "validate",
        help="run the verification and validation cases; write a report with plots",
        description=textwrap.dedent(
            """\
            Run every verification case against its closed form or independent solution
            (Timoshenko statics and frequencies, non-uniform torsion, torsional and coupled
            lateral-torsional frequencies, Fryba's moving force, a sprung mass against an
            independent modal ODE, energy conservation, time-step and mesh convergence,
            ISO 8608 spectra, a parked vehicle, Benscoter torsion against its closed forms
            and frequency equation, VBI-2D's sprung vehicle on an Euler-Bernoulli beam) and
            the paper's 40 m double-tee case (Nodes 1-3 like its Figs. 4-6, quarter-cars
            and moving forces, direct and modal bases, Vlasov and Benscoter torsion).
            Writes DIR/report.md with each case's reference, error and tolerance, and PNG
            plots next to it.

            Exit status: 0 every case within its tolerance, 1 a case failed, 2 bad input."""
        ),
        epilog="examples:\n  cosim validate\n  cosim validate --out validation --quick\n",
        formatter_class=FORMATTER,
    )
    validate.add_argument("--out", default="validation", metavar="DIR",
                          help="folder for report.md and the plots (default: validation)")
    validate.add_argument("--quick", action="store_true", help="coarser settings (seconds instead of a minute)")
    validate.add_argument("--force", "-f", action="store_true",
                          help="replace the report (and plots) in DIR if it has one (default: refuse)")
    validate.set_defaults(func=cmd_validate)


def cmd_validate(args: argparse.Namespace) -> int:
    from cosim.validation import run_validation

    def progress(done: int, total: int, label: str) -> None:
        print(f"[{done}/{total}] {label}", file=sys.stderr, flush=True)

    out = Path(args.out)
    if (out / "report.md").exists() and not args.force:
        raise CosimError(f"{out}: already holds a validation report; refusing to replace it (use --force, "
                         "or another --out)")
    report = run_validation(out, quick=args.quick, progress=progress)
    print_lines(report.summary_lines())
    return 0 if report.all_passed else EXIT_RUN_FAILED
