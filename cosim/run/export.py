"""What is exported from a log: its topics as CSV (``cosim export``, ``cosim run --csv``; SI units, every float
in its shortest exact form) and the Foxglove layout made for its run (``cosim layout``).

Importing this module loads neither mcap nor numpy (the command line's help lists :data:`EXPORT_TOPICS`).
"""
from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cosim.core.fields import VEHICLE_FIELDS
from cosim.errors import CosimError
from cosim.log.schemas import (
    EVENTS_SCHEMA,
    STATUS_SCHEMA,
    TOPIC_EVENTS,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_VEHICLE_LOADS,
    TOPIC_VEHICLES,
)

from .outputs import atomic_write, check_new_file, check_not_input

if TYPE_CHECKING:  # the reader loads mcap and numpy: only when a log is read
    from cosim.log.layout import LayoutInputs
    from cosim.log.records import ReadStats

#: The topics a log can be exported from.
EXPORT_TOPICS = (TOPIC_SENSORS, TOPIC_VEHICLES, TOPIC_EVENTS, TOPIC_STATUS, TOPIC_VEHICLE_LOADS)
#: Columns of each topic's CSV but the sensors' (``t,<sensor names>``).
VEHICLE_COLUMNS = ("t", *(f.name for f in VEHICLE_FIELDS))
EVENT_COLUMNS: tuple[str, ...] = tuple(EVENTS_SCHEMA["properties"])  # type: ignore[arg-type]
STATUS_COLUMNS: tuple[str, ...] = tuple(STATUS_SCHEMA["properties"])  # type: ignore[arg-type]
#: ``/cosim/vehicle_loads`` (SI: weights in N, spacings in m; lists ``;``-separated).
VEHICLE_LOAD_COLUMNS = ("t", "id", "class", "lane", "speed", "gvw", "n_axles", "axle_loads", "axle_spacings", "y",
                        "source")


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, list):
        return ";".join(_cell(v) for v in value)
    return str(value)


def export_csv(log: str | os.PathLike[str], out: str | os.PathLike[str], topic: str = TOPIC_SENSORS,
               force: bool = False, start: float | None = None, end: float | None = None,
               stats: ReadStats | None = None) -> tuple[int, list[str]]:
    """Write one topic of a log as CSV (SI units, a header row); returns (rows, columns).

    ``/cosim/sensors``: ``t,<sensor names>``; ``/cosim/vehicles``: one row per
    vehicle per sample (:data:`VEHICLE_COLUMNS`); events, status and vehicle loads
    (:data:`VEHICLE_LOAD_COLUMNS`, lists ``;``-separated): one row per message.
    With ``start`` and/or ``end`` (s of simulated time, both included),
    only the messages in that window: exactly the rows of the whole export whose
    message lies in it, read from the chunks that overlap it
    (:func:`cosim.log.reader.iter_messages`). A log cut short is exported up to
    its last complete record. Memory does not grow with the log. Written
    through a temporary file, so a failure leaves no half file.

    Raises:
        LogError: the log cannot be read. CosimError: not an exportable topic, a window that is empty or
            outside the log, or the CSV cannot be written.
    """
    from cosim.log.reader import check_window, iter_messages, open_log

    log, out = Path(log), Path(out)
    check_window(start, end)  # before the log is read
    overview = open_log(log, check="summary", stats=stats)
    if topic not in EXPORT_TOPICS:
        present = ", ".join(t for t in EXPORT_TOPICS if overview.counts.get(t))
        raise CosimError(f"--topic {topic}: not an exportable topic (this log has: {present})")
    if start is not None or end is not None:
        check_window(start, end, overview)
    if topic == TOPIC_SENSORS:
        columns = ["t", *overview.sensor_names]
    elif topic == TOPIC_VEHICLES:
        columns = list(VEHICLE_COLUMNS)
    elif topic == TOPIC_EVENTS:
        columns = list(EVENT_COLUMNS)
    elif topic == TOPIC_VEHICLE_LOADS:
        columns = list(VEHICLE_LOAD_COLUMNS)
    else:
        columns = list(STATUS_COLUMNS)
    check_not_input(out, "CSV", [("the log", log)])
    check_new_file(out, "CSV", force)
    rows = 0
    with atomic_write(out, "CSV") as partial, open(partial, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        for _, msg in iter_messages(log, [topic], start, end, stats):
            if topic == TOPIC_VEHICLES:
                for vehicle in msg["vehicles"]:
                    writer.writerow([_cell(msg["t"]), *(_cell(vehicle.get(c)) for c in columns[1:])])
                    rows += 1
            else:
                writer.writerow([_cell(msg.get(c)) for c in columns])
                rows += 1
    return rows, columns


def write_layout(log: str | os.PathLike[str], out: str | os.PathLike[str], force: bool = False) -> LayoutInputs:
    """Write the Foxglove layout of a log's run to ``out`` (a .json file); returns what the layout shows.

    The layout is made from what the log records, as the run attached it (a log written before layouts
    existed gets one too). ``out`` is never the log, and an existing file is replaced only with ``force``.

    Raises:
        LogError: the log cannot be read. CosimError: ``out`` is the log, not a .json name, or exists.
    """
    from cosim.log.layout import inputs_from_log, layout_bytes, make_layout
    from cosim.log.reader import open_log

    log, out = Path(log), Path(out)
    check_not_input(out, "layout", [("the log", log)])
    if out.suffix.lower() != ".json":
        raise CosimError(f"{out}: a Foxglove layout is a JSON file: expected a name ending in .json")
    inputs = inputs_from_log(open_log(log))
    check_new_file(out, "layout", force)
    with atomic_write(out, "layout") as partial:
        partial.write_bytes(layout_bytes(make_layout(inputs)))
    return inputs
