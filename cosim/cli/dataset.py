"""``cosim dataset``: labelled monitoring datasets (the work is :mod:`cosim.dataset`)."""
from __future__ import annotations

import argparse
import sys


def cmd_dataset(args: argparse.Namespace) -> int:
    from cosim.dataset import load_dataset, write_dataset

    dataset = load_dataset(args.dataset, output=args.out)

    def progress(done: int, total: int) -> None:
        if not args.quiet:
            print(f"window {done}/{total}", file=sys.stderr, flush=True)

    outcome = write_dataset(dataset, force=args.force, progress=progress)
    cases = ", ".join(c.name for c in dataset.damage)
    print(f"Dataset: {dataset.name} ({dataset.source}), base {dataset.base.source}")
    print(f"Windows: {dataset.windows} of {dataset.window:g} s per damage case ({cases}): {len(outcome.rows)} rows")
    print(f"Table: {outcome.table} (labels also in labels.json); logs: {len(outcome.logs)} MCAP files in "
          f"{outcome.table.parent / 'logs'}")
    print(f"Wall time: {outcome.wall_time:.3g} s")
    return 0
