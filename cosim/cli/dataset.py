"""``cosim dataset``: labelled monitoring datasets (the work is :mod:`cosim.dataset`)."""
from __future__ import annotations

import argparse
import sys

from .options import Subcommands

NAME = "dataset"


def add_parser(commands: Subcommands) -> None:
    """``cosim dataset``: its arguments and help."""
    dataset = commands.add_parser(
        "dataset",
        help="write a labelled monitoring dataset (healthy and damaged, temperature, instruments)",
        description="Run a base scenario window by window for every damage case of the dataset file, measure the "
                    "responses with its instruments (anti-aliasing, sampling, noise, quantisation) and write one "
                    "row per window with its labels to dataset.parquet, plus the MCAP logs. docs/analysis.md "
                    "documents the dataset file.",
    )
    dataset.add_argument("dataset", metavar="SPEC.toml", help="the dataset file")
    dataset.add_argument("--out", metavar="FOLDER",
                         help="the output folder (default: [dataset].output, else datasets/<name>)")
    dataset.add_argument("--force", action="store_true", help="overwrite an existing dataset and its logs")
    dataset.add_argument("--quiet", "-q", action="store_true", help="no progress on stderr")
    dataset.set_defaults(func=cmd_dataset)


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
