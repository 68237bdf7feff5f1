"""What ``cosim info`` shows of a log, as one call: :func:`log_info`.

The log's overview (:func:`cosim.log.reader.open_log`: through its summary,
or with ``verify`` from every chunk) and, for a log of SUMO traffic, the
vehicles that were on the deck, from its "entered" events. Without ``verify``
those are read from at most :data:`EVENT_CHUNKS` chunks (a day's log has
thousands): the vehicles of a long log are then those of its start.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from cosim.core.fields import vehicle_of
from cosim.log.reader import LogOverview, iter_messages, open_log
from cosim.log.records import ReadStats
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_TRAFFIC

#: Chunks read for the SUMO vehicles' events without ``verify``: about 20 min of the default run.
EVENT_CHUNKS = 256


@dataclass(frozen=True)
class DeckVehicles:
    """The SUMO vehicles a log saw on the deck, from its "entered" events.

    Attributes:
        vehicles: their ids, in the order they first entered.
        axles: the contact points (axles) that entered.
        until: None if every event was read; else the time of the last one read before the chunk budget
            ran out (the vehicles are those of the log's start up to there).
        chunks: the chunks decompressed for them.
    """

    vehicles: tuple[str, ...]
    axles: int
    until: float | None
    chunks: int


@dataclass(frozen=True)
class LogInfo:
    """A log's overview and, for SUMO traffic, the vehicles it saw on the deck (None otherwise)."""

    overview: LogOverview
    deck: DeckVehicles | None = None


def log_info(log: str | os.PathLike[str], verify: bool = False, event_chunks: int | None = None) -> LogInfo:
    """What a log holds: its overview, checked as ``verify`` says, and its SUMO vehicles on the deck.

    Args:
        log: the log.
        verify: decompress every chunk and verify every checksum (else the summary and the file's checksum).
        event_chunks: without ``verify``, read the events from at most this many chunks (default
            :data:`EVENT_CHUNKS`).

    Raises:
        LogError: the file is damaged or not a cosim MCAP log.
    """
    overview = open_log(log, check="full" if verify else "file")
    if not (overview.counts.get(TOPIC_TRAFFIC) or overview.info.get("traffic") == "sumo"):
        return LogInfo(overview)
    budget = None if overview.check == "full" else (EVENT_CHUNKS if event_chunks is None else event_chunks)
    return LogInfo(overview, deck_vehicles(overview, budget))


def deck_vehicles(overview: LogOverview, budget: int | None = None) -> DeckVehicles:
    """The vehicles that entered the deck, from the "entered" events of at most ``budget`` chunks (None: all)."""
    axles: dict[str, int] = {}
    stats = ReadStats()
    last_t, cut = 0.0, False
    if overview.counts.get(TOPIC_EVENTS):
        # A window over the whole log: a finished log's chunks are then read through its index, one at a time.
        messages = iter_messages(overview.path, [TOPIC_EVENTS], start=overview.start_time, stats=stats)
        for _, message in messages:
            if budget is not None and stats.chunks > budget:
                cut = True
                break
            last_t = float(message["t"])
            if message.get("event") == "entered":
                contact = str(message.get("vehicle", ""))
                axles.setdefault(contact, 0)
        messages.close()  # type: ignore[attr-defined]
    vehicles = tuple(dict.fromkeys(vehicle_of(c) for c in axles))
    return DeckVehicles(vehicles, len(axles), last_t if cut else None, stats.chunks)
