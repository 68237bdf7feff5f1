"""``cosim info``: what a log holds, and whether it is whole."""
from __future__ import annotations

import argparse
import json
import textwrap
from typing import TYPE_CHECKING

from cosim.log.schemas import REPLAY_METADATA_NAME

from .options import FORMATTER, Subcommands
from .text import fmt_g, print_lines, size_text

if TYPE_CHECKING:
    from cosim.log.reader import LogOverview
    from cosim.run.loginfo import DeckVehicles, LogInfo

NAME = "info"


def add_parser(commands: Subcommands) -> None:
    """``cosim info``: its arguments and help."""
    info = commands.add_parser(
        "info",
        help="summarise a log: scenario, duration, topics, status, truncated or not",
        description=textwrap.dedent(
            """\
            Summarise a log: its scenario, cosim version, simulated time, sensors, topics
            with message counts, final status and message, whether the file is truncated
            (cut short by a killed process: exit status 0, the readable part is shown) and
            its attachments. A finished log is read through its summary (counts, times,
            chunk index) in seconds however long it is; every byte is checked against the
            file's checksums, and the chunk holding the final status is decompressed.
            --verify also decompresses every chunk, verifies its checksum and counts the
            messages (the summary must agree). A damaged file or one that is not a cosim
            MCAP log exits with status 2."""
        ),
        epilog="examples:\n  cosim info runs/run1.mcap\n  cosim info --verify runs/run1.mcap\n",
        formatter_class=FORMATTER,
    )
    info.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    info.add_argument("--verify", action="store_true",
                      help="decompress every chunk and verify every checksum (seconds per 100 MB of log)")
    info.set_defaults(func=cmd_info)


def cmd_info(args: argparse.Namespace) -> int:
    """Summarise a log: from its summary, or (``--verify``) from every chunk."""
    from cosim.run.loginfo import log_info

    print_lines(info_lines(log_info(args.log, verify=args.verify)))
    return 0


def checked_line(o: LogOverview, extra_chunks: int = 0) -> str:
    """What ``cosim info`` verified, and what it did not (``extra_chunks``: read after ``o``, e.g. for events)."""
    if not o.complete:
        return (f"Checked: the {o.chunks} complete chunk(s) decompressed and their checksums verified "
                "(a file cut short has no summary or file checksum)")
    older = " (this log has no file checksum: older cosim versions wrote none)" if o.data_checksum is False else ""
    if o.check == "full":
        file = "the file's (every byte as written), " if o.data_checksum else ""
        agree = " (the summary agrees)" if o.summary_checked else ""
        return (f"Checked: all {o.chunks} chunks decompressed and their checksums verified, and {file}the "
                f"summary's and the attachments'{older}; counts from the messages{agree}")
    file = "the file (every byte as written), " if o.data_checksum else ""
    unread = "" if o.data_checksum else ", the others not read"
    read = min(o.chunks_read + extra_chunks, o.chunks)
    return (f"Checked: checksums of {file}the summary and the attachments; {read} of {o.chunks} chunks "
            f"decompressed{unread}{older}; counts from the summary (--verify: every chunk)")


def info_lines(log: LogInfo) -> list[str]:
    """The lines of ``cosim info``."""
    o = log.overview
    info = o.info
    lines = [f"Log: {o.path} ({size_text(o.size)}, {'finished file' if o.complete else 'TRUNCATED'})"]
    if info:
        lines.append(f"Scenario: {info.get('scenario', '?')} (source: {info.get('source', '?')})")
        lines.append(f"Written by: cosim {info.get('version', '?')} ({info.get('kind', 'run')}), "
                     f"started {info.get('started', '?')}")
        replay = o.metadata.get(REPLAY_METADATA_NAME)
        if replay:
            lines.append(f"Replay of: {replay.get('log', '?')} (traffic of {replay.get('log_scenario', '?')}; "
                         f"bridge of {replay.get('scenario', '?')})")
        every = info.get("every", "?")
        steps = "every step" if every == "1" else f"every {every} steps"
        rate = fmt_g(float(info["rate_hz"]), 4) if "rate_hz" in info else "?"
        lines.append(f"Solver: {info.get('scheme', '?')}, {info.get('basis', '?')} basis, "
                     f"dt = {info.get('dt', '?')} s; logged at {rate} Hz ({steps})")
        planned = info.get("duration")
        planned_text = f" of {fmt_g(float(planned), 6)} s" if planned else ""
        lines.append(f"Simulated: {fmt_g(o.end_time, 6)} s{planned_text}")
    else:
        lines.append("Scenario: (no cosim metadata in this log)")
        lines.append(f"Simulated: {fmt_g(o.end_time, 6)} s")
    sensors = ", ".join(f"{n} ({q})" if q else n for n, q in zip(o.sensor_names, o.quantities)) or "none"
    lines.append(f"Sensors ({len(o.sensor_names)}): {sensors}")
    extra_chunks = 0
    if log.deck is not None:
        lines.extend(_sumo_vehicle_lines(o, log.deck))
        extra_chunks = log.deck.chunks
    elif "vehicles" in info:
        try:
            vehicles = json.loads(info["vehicles"])
            lines.append(f"Vehicles ({len(vehicles)}): {', '.join(vehicles) or 'none'}")
        except ValueError:
            pass
    lines.append("Topics:")
    width = max([len(t) for t in o.counts] + [10])
    for topic, count in sorted(o.counts.items()):
        lines.append(f"  {topic:<{width}}  {count:>9} messages")
    status = o.final_status
    if status is None:
        lines.append("Status: none logged")
    else:
        message = f": {status['message']}" if status.get("message") else ""
        lines.append(f"Status: {status.get('state', '?')} at t = {fmt_g(float(status.get('t', 0.0)), 6)} s{message}")
    if o.complete:
        lines.append("Truncated: no")
    else:
        lines.append("Truncated: yes - the file was cut short (the process was killed?); "
                     "it is read up to its last complete chunk")
    atts = ", ".join(f"{name} ({size_text(len(data))})" for name, data in o.attachments.items()) or "none"
    lines.append(f"Attachments: {atts}")
    lines.append(checked_line(o, extra_chunks))
    return lines


#: SUMO vehicles listed by name in ``cosim info`` (the rest are counted).
SHOWN_VEHICLES = 20


def _sumo_vehicle_lines(o: LogOverview, deck: DeckVehicles) -> list[str]:
    """The SUMO vehicles that were on the deck (without ``--verify``: those of the log's start, and the line
    says so) and the vehicle types of the run."""
    from cosim.sumo.attachments import VEHICLE_TYPES_ATTACHMENT

    vehicles = deck.vehicles
    shown = ", ".join(vehicles[:SHOWN_VEHICLES]) + (f", ... ({len(vehicles) - SHOWN_VEHICLES} more)"
                                                    if len(vehicles) > SHOWN_VEHICLES else "")
    axle_text = f", {deck.axles} axles" if deck.axles != len(vehicles) else ""
    when = f", in its first {fmt_g(deck.until, 6)} s (--verify: the whole log)" if deck.until is not None else ""
    lines = [f"Vehicles (SUMO, {len(vehicles)} on the deck{axle_text}{when}): {shown or 'none'}"]
    raw = o.attachments.get(VEHICLE_TYPES_ATTACHMENT)
    if raw is not None:
        try:
            types = json.loads(raw)
            rows = [f"  {t['type']} ({t['vclass']}): {t['model']}, {float(t['mass']):.0f} kg ({t['sources']['mass']}), "
                    f"{len(t['axles'])} axle(s) ({t['sources']['axles']})" for t in types]
            lines += [f"Vehicle types ({len(types)}), from {VEHICLE_TYPES_ATTACHMENT}:", *rows] if rows else \
                [f"Vehicle types: none in the SUMO config's files ({VEHICLE_TYPES_ATTACHMENT})"]
        except (ValueError, KeyError, TypeError):
            lines.append(f"Vehicle types: {VEHICLE_TYPES_ATTACHMENT} is malformed")
    return lines
