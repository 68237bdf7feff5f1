"""``cosim study``: traffic-volume studies (the work is :mod:`cosim.study`)."""
from __future__ import annotations

import argparse
import sys
from typing import Any

from cosim.errors import interruption


def cmd_study(args: argparse.Namespace) -> int:
    from cosim.study import load_study, run_study, summary_text

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

    try:
        outcome = run_study(study, workers=args.workers, scheduler=args.scheduler, progress=progress,
                            redo=args.redo, plots=False if args.no_plots else None)
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
