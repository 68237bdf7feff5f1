"""``cosim layout``: the Foxglove layout made for a log's run, as a file to import into Foxglove."""
from __future__ import annotations

import argparse
import textwrap
from pathlib import Path

from .options import FORMATTER, Subcommands

NAME = "layout"


def add_parser(commands: Subcommands) -> None:
    """``cosim layout``: its arguments and help."""
    layout = commands.add_parser(
        "layout",
        help="write the Foxglove layout made for a log's run",
        description=textwrap.dedent(
            """\
            Write the Foxglove layout of a log's run, the one the run attached to its log
            (foxglove_layout.json), made from what the log records: a plot per sensor
            quantity with its sensors, the vehicles' contact forces (per vehicle for
            scripted vehicles, all together for SUMO traffic), the positions of the traffic
            near the deck, a table of the vehicles on the deck, the events and status, and
            the 3D scene of the deck and its vehicles when the log has one. Logs written
            before layouts existed get one too. Open the log in Foxglove (desktop app or
            app.foxglove.dev: Open local file) and import the layout with Layouts ->
            Import from file. An existing file is replaced only with --force, never the log."""
        ),
        epilog="examples:\n  cosim layout runs/run1.mcap -o run1-layout.json\n",
        formatter_class=FORMATTER,
    )
    layout.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    layout.add_argument("-o", "--output", required=True, metavar="LAYOUT.json", help="the layout file to write")
    layout.add_argument("--force", "-f", action="store_true", help="overwrite LAYOUT.json if it exists")
    layout.set_defaults(func=cmd_layout)


def cmd_layout(args: argparse.Namespace) -> int:
    """Write the layout of a log's run (made from what the log records, as the run attached it)."""
    from cosim.run.export import write_layout

    log, out = Path(args.log), Path(args.output)
    inputs = write_layout(log, out, force=args.force)
    panels = ["a plot per sensor quantity" if inputs.sensors else "", "contact forces",
              "SUMO traffic" if inputs.sumo else "vehicle positions", "the vehicles on the deck", "events, status",
              "the 3D scene" if inputs.scene else ""]
    print(f"Wrote the Foxglove layout of {log} to {out} ({', '.join(p for p in panels if p)}); "
          "import it in Foxglove with Layouts -> Import from file")
    return 0
