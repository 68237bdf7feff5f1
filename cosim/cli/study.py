"""``cosim study``: traffic-volume studies (the work is :mod:`cosim.study`)."""
from __future__ import annotations

import argparse
import sys
import textwrap
from typing import Any

from cosim.errors import interruption

from .options import FORMATTER, Subcommands

NAME = "study"


def add_parser(commands: Subcommands) -> None:
    """``cosim study``: its arguments and help."""
    study = commands.add_parser(
        "study",
        help="traffic-volume studies: a base scenario swept over demand, trucks, speed, road and seeds, on Dask",
        description=textwrap.dedent(
            """\
            Run every combination of the sweep axes of STUDY.toml (vehicles per hour, truck
            share, speed limit, SUMO demand, road class, seeds) on a Dask cluster, each run
            logged to MCAP, and write one table of results (results.csv, results.parquet)
            and plots into the output folder (default studies/<name>/). Running the same
            command again resumes: runs whose logs are complete are not run again. A
            failing run is recorded in the table; the others go on. docs/studies.md
            documents the study file and the output folder.

            Exit status: 0 every run ok, 1 some run failed (see the table), 2 bad input
            (also: --out is another study's folder), 128 + N stopped by signal N (130
            Ctrl-C, 143 SIGTERM, 129 SIGHUP): the runs in progress stop with finished logs,
            the table of the completed runs is written, the same command resumes."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim study examples/studies/volumes.toml
              cosim study examples/studies/volumes.toml --workers 2 --out /data/volumes
              cosim study examples/studies/volumes.toml --scheduler tcp://10.0.0.5:8786
            """
        ),
        formatter_class=FORMATTER,
    )
    study.add_argument("study", metavar="STUDY.toml", help="the study file")
    study.add_argument("--workers", "-w", type=int, metavar="N",
                       help="worker processes of the local Dask cluster (default: one per CPU; 0: run one "
                            "after another in this process, without Dask)")
    study.add_argument("--scheduler", metavar="ADDRESS",
                       help="submit to an existing Dask scheduler (tcp://HOST:PORT) instead of a local cluster; "
                            "its workers need cosim and the output folder at the same path")
    study.add_argument("--out", metavar="FOLDER",
                       help="the output folder (default: [study].output, else studies/<name>)")
    study.add_argument("--redo", action="store_true", help="run every run again, even those already done")
    study.add_argument("--no-plots", action="store_true", help="write the table only")
    study.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    study.set_defaults(func=cmd_study)


def cmd_study(args: argparse.Namespace) -> int:
    from cosim.study import load_study, run_study, summary_text

    from .summary import CompileNotice

    study = load_study(args.study, output=args.out)
    bar: Any = None
    failures: list[str] = []

    def progress(done: int, total: int, row: dict | None) -> None:
        nonlocal bar
        if row is not None and row.get("status") != "ok":
            failures.append(row["run_id"])
        if args.quiet:
            return
        if not sys.stderr.isatty():  # a log file: one line per finished run
            if row is not None:
                state = "ok" if row.get("status") == "ok" else f"FAILED: {(row.get('error') or '').splitlines()[0]}"
                print(f"run {done}/{total} {row['run_id']}: {state}", file=sys.stderr, flush=True)
            elif done:
                print(f"{done} of {total} runs done earlier", file=sys.stderr, flush=True)
            return
        if bar is None:
            from tqdm import tqdm

            bar = tqdm(total=total, initial=done, file=sys.stderr, desc=f"Study {study.name}", unit="run",
                       dynamic_ncols=True,
                       bar_format="{desc}: {n}/{total} runs |{bar}| [{elapsed}<{remaining}]{postfix}")
        if failures:
            bar.set_postfix_str(f"{len(failures)} failed", refresh=False)
        bar.update(done - bar.n)

    def compiling() -> None:  # from the Dask client's thread: tqdm.write keeps the bar whole
        if bar is not None:
            bar.write(CompileNotice.STUDY_LINE, file=sys.stderr)
        else:
            print(CompileNotice.STUDY_LINE, file=sys.stderr, flush=True)

    try:
        outcome = run_study(study, workers=args.workers, scheduler=args.scheduler, progress=progress,
                            redo=args.redo, plots=False if args.no_plots else None,
                            compiling=None if args.quiet else compiling)
    except KeyboardInterrupt as exc:
        if bar is not None:
            bar.close()
        signum, name = interruption(exc)
        try:
            print(f"cosim: interrupted by {name}; the runs completed so far are in {study.output / 'results.csv'}; "
                  "run the same command again to resume", file=sys.stderr)
        except (OSError, ValueError):  # SIGHUP: the terminal may be gone
            pass
        return 128 + signum
    if bar is not None:
        bar.close()
    print(summary_text(outcome))
    return 1 if outcome.failed else 0
