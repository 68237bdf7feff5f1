"""``cosim plot``: the sensor time histories of a log (or of a window of it) as a figure."""
from __future__ import annotations

import argparse
import textwrap

from .options import FORMATTER, WINDOW_VALUES, Subcommands, window_arguments
from .text import window_text

NAME = "plot"
#: ``--from -5``: a negative time is a value (:func:`cosim.cli.options.dash_values_kept`).
DASH_VALUES = WINDOW_VALUES


def add_parser(commands: Subcommands) -> None:
    """``cosim plot``: its arguments and help."""
    plot = commands.add_parser(
        "plot",
        help="draw the sensor time histories of a log",
        description=textwrap.dedent(
            """\
            Draw the time histories of a log's sensors, one panel each, over time in s
            (displacements in mm, velocities in mm/s, accelerations in m/s^2, bending
            moments in kN m). --from/--to: only T0 to T1 s of simulated time, read from
            the chunks in that window. More than 20000 samples are drawn as their min/max
            envelope."""
        ),
        epilog="examples:\n  cosim plot runs/run1.mcap -o run1.png\n"
               "  cosim plot runs/run1.mcap --sensor node1 --sensor node3_acc -o two.png\n"
               "  cosim plot runs/day.mcap --sensor node1 --from 43200 --to 43260 -o noon.png\n",
        formatter_class=FORMATTER,
    )
    plot.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    plot.add_argument("--sensor", action="append", metavar="NAME",
                      help="a sensor to draw (repeat for more; default: all)")
    plot.add_argument("-o", "--output", required=True, metavar="FIG.png", help="the figure (.png, .pdf, .svg, ...)")
    window_arguments(plot, "draw")
    plot.add_argument("--force", "-f", action="store_true", help="overwrite FIG if it exists")
    plot.set_defaults(func=cmd_plot)


def cmd_plot(args: argparse.Namespace) -> int:
    """Draw a log's sensor time histories (or a window of them)."""
    from cosim.run.figures import plot_log_sensors

    drawn = plot_log_sensors(args.log, args.output, args.sensor, force=args.force, start=args.start, end=args.end)
    print(f"Wrote {len(drawn)} sensor time histor{'y' if len(drawn) == 1 else 'ies'} ({', '.join(drawn)})"
          f"{window_text(args.start, args.end)} to {args.output}")
    return 0
