"""``cosim validate``: the verification and validation cases with their report (the work is :mod:`cosim.validation`)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from cosim.errors import CosimError

from .text import EXIT_RUN_FAILED, print_lines


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
