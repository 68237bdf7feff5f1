"""``cosim export``: a topic of a log (or a window of it) as CSV."""
from __future__ import annotations

import argparse
import sys
import textwrap

from cosim.log.schemas import TOPIC_EVENTS, TOPIC_SENSORS, TOPIC_STATUS, TOPIC_VEHICLES
from cosim.run.export import EXPORT_TOPICS

from .options import FORMATTER, WINDOW_VALUES, Subcommands, window_arguments
from .text import window_text

NAME = "export"
#: ``--from -5``: a negative time is a value (:func:`cosim.cli.options.dash_values_kept`).
DASH_VALUES = WINDOW_VALUES


def add_parser(commands: Subcommands) -> None:
    """``cosim export``: its arguments and help."""
    topics = ", ".join(EXPORT_TOPICS)
    export = commands.add_parser(
        "export",
        help="write a topic of a log as CSV (default: the sensor channels)",
        description=textwrap.dedent(
            f"""\
            Write a topic of a log as CSV with a header row, SI units, numbers in their
            shortest exact form. {TOPIC_SENSORS} (default): columns t,<sensor names>, one row
            per sample. {TOPIC_VEHICLES}: one row per vehicle on the deck per sample (t, id,
            model, x, y, speed, acceleration, body_displacement, body_acceleration,
            contact_force). {TOPIC_EVENTS} and {TOPIC_STATUS}: one row per message.
            --from/--to: only the messages from T0 to T1 s of simulated time (both
            included; either bound alone is fine): a finished log's chunk index is used
            to read only the chunks in the window (10 minutes of a day-long log take about
            as long as a 10-minute log). A log cut short is exported up to its last
            complete chunk (it has no index: it is read whole)."""
        ),
        epilog="examples:\n  cosim export runs/run1.mcap --csv run1.csv\n"
               f"  cosim export runs/run1.mcap --topic {TOPIC_VEHICLES} --csv vehicles.csv\n"
               "  cosim export runs/day.mcap --from 43200 --to 43800 --csv noon.csv\n",
        formatter_class=FORMATTER,
    )
    export.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    export.add_argument("--csv", metavar="OUT.csv", required=True, help="the CSV file to write")
    export.add_argument("--topic", default=TOPIC_SENSORS, metavar="TOPIC",
                        help=f"the topic to export (one of: {topics}; default: {TOPIC_SENSORS})")
    # float, not finite_float: a time that is not finite is then the window check's one-line error.
    window_arguments(export, "export")
    export.add_argument("--force", "-f", action="store_true", help="overwrite OUT.csv if it exists")
    export.set_defaults(func=cmd_export)


def cmd_export(args: argparse.Namespace) -> int:
    """Write a topic of a log (or of a window of it) as CSV."""
    from cosim.log.reader import file_is_complete
    from cosim.run.export import export_csv

    rows, columns = export_csv(args.log, args.csv, topic=args.topic, force=args.force, start=args.start,
                               end=args.end)
    if not file_is_complete(args.log):
        print(f"note: {args.log} was cut short (truncated); exported what it holds up to its last complete chunk",
              file=sys.stderr)
    units = "SI units: m, m/s, m/s^2, N m" if args.topic == TOPIC_SENSORS else "SI units"
    print(f"Wrote {rows} rows of {args.topic}{window_text(args.start, args.end)} to {args.csv} "
          f"(columns {','.join(columns)}; {units})")
    return 0
