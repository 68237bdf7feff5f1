"""Reading cosim logs: the one log API behind info, export, plot, replay, studies and tests.

- :func:`open_log`: what a log holds without its messages (metadata,
  attachments, message counts, the final status, sensor names); by default
  every chunk is read and every checksum verified, or, for a finished log,
  only its summary (``check="file"`` or ``"summary"``: seconds for a day-long log);
- :func:`iter_messages`: the decoded messages of some topics, in file order,
  chunk by chunk (constant memory), optionally within a window of simulated
  time (only the chunks that overlap it are read); :func:`sensor_series` the
  sensor channels as arrays;
- :func:`read_log`: everything at once (:class:`LogContents`), for small logs
  and tests.

The logged SUMO frames as a traffic source again (a replay's) are
:mod:`cosim.log.replay_source`'s.

A log is untrusted input: people send logs to each other. Its records are read
within bounds, every checksum verified and every chunk's time range checked by
:mod:`cosim.log.records` (the MCAP record parser, and its one truncation rule:
a log cut short is read up to its last complete record and says it is
truncated; damage is a :class:`cosim.errors.LogError`, named by record). This
module checks every message it hands out against cosim's own schema for its
topic (:mod:`cosim.log.checks`), and the "cosim" metadata record's values.

Readers that need only part of a finished log (a window of time, the overview)
follow its summary's chunk index instead of reading every chunk; what they
skipped is said (:attr:`LogOverview.check`) and ``check="full"`` (``cosim info
--verify``) reads everything and checks that the summary agrees with the chunks.

Logs are parsed, never evaluated or unpickled.
"""
from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Literal

import numpy as np
import orjson
from mcap.records import Channel, Schema

from cosim.errors import CosimError, LogError

from .checks import message_check
from .records import (
    MAX_NS,
    LogRecords,
    ReadStats,
    Summary,
    Tally,
    check_data_section,
    compare_summary,
    ends_with_magic,
    indexed_attachments,
    indexed_metadata,
    last_message,
    open_file,
    read_header,
    read_summary,
    walk,
)
from .schemas import METADATA_NAME, TOPIC_SENSORS, TOPIC_STATUS, to_ns

# --------------------------------------------------------------------------- files, messages and metadata


def file_is_complete(path: str | os.PathLike[str]) -> bool:
    """True when the log was finished (it ends with the MCAP footer and magic); False if not, or unreadable."""
    try:
        with open(path, "rb") as fh:
            return ends_with_magic(fh)
    except OSError:
        return False


def _checked(path: Path, channel: Channel, value: object) -> dict:
    """A decoded message, checked against cosim's schema for its topic (the JSON log's, whatever the encoding)."""
    if not isinstance(value, dict):
        raise LogError(f"{path}: a message on {channel.topic} is not a JSON object")
    check = message_check(channel.topic)
    if check is not None:
        problem = check(value)
        if problem is not None:
            t = value.get("t")
            when = f" (t = {t:g} s)" if type(t) in (int, float) else ""
            raise LogError(f"{path}: a message on {channel.topic}{when} does not match its schema: {problem}")
    return value


def _decode_json(path: Path, channel: Channel, data: bytes) -> dict:
    try:
        value = orjson.loads(data)  # strict JSON (no NaN): what cosim writes; 5x faster than json
    except (orjson.JSONDecodeError, RecursionError):
        raise LogError(f"{path}: a message on {channel.topic} is not valid JSON") from None
    return _checked(path, channel, value)


class Decoder:
    """Messages as the dictionaries cosim's JSON logs held, checked against cosim's schema for their topic: the
    one decoder. It picks the decoding by the channel's message encoding: JSON (logs of earlier versions) or
    protobuf (:mod:`cosim.log.proto`, with cosim's own schema for the topic: a channel whose schema is not the
    one cosim writes is refused before any of its messages is used).

    ``schemas``: the log's schema records by id, filled as the walk meets them (:func:`cosim.log.records.walk`).
    """

    def __init__(self, path: Path, schemas: dict[int, Schema]) -> None:
        self.path = path
        self.schemas = schemas
        self._by_channel: dict[int, Callable[[bytes], dict]] = {}

    def __call__(self, channel: Channel, data: bytes) -> dict:
        decode = self._by_channel.get(channel.id)
        if decode is None:
            decode = self._by_channel[channel.id] = self._for(channel)
        return decode(data)

    def _for(self, channel: Channel) -> Callable[[bytes], dict]:
        path = self.path
        if channel.message_encoding == "json":
            return lambda data: _decode_json(path, channel, data)
        if channel.message_encoding != "protobuf":
            raise LogError(f"{path}: channel {channel.topic} is {channel.message_encoding!r}, not a cosim JSON or "
                           "protobuf channel")
        from google.protobuf.message import DecodeError

        from . import proto

        topic = channel.topic
        expected = proto.TOPIC_MESSAGES.get(topic)
        if expected is None:
            raise LogError(f"{path}: channel {topic} is not a cosim topic")
        schema = self.schemas.get(channel.schema_id)
        if schema is None or schema.encoding != "protobuf" or schema.name != expected:
            found = "none" if schema is None else f"{schema.name!r} ({schema.encoding})"
            raise LogError(f"{path}: channel {topic}: expected the protobuf schema {expected!r}, found {found}")
        try:
            decode = proto.decoder(expected, schema.data)
        except proto.SchemaProblem as exc:
            raise LogError(f"{path}: channel {topic}: {exc}") from None

        def checked(data: bytes) -> dict:
            try:
                value = decode(data)
            except (DecodeError, RecursionError, ValueError, UnicodeDecodeError):
                raise LogError(f"{path}: a message on {topic} is not a valid {expected} message") from None
            return _checked(path, channel, value)

        return checked


def _json_list(text: str, key: str, path: Path) -> list[str]:
    try:
        value = json.loads(text)
    except (ValueError, RecursionError):
        value = None
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise LogError(f"{path}: malformed cosim metadata: {key}: expected a JSON array of strings")
    return value


#: The "cosim" metadata keys that are read as numbers, and what they must be.
_METADATA_NUMBERS: dict[str, Callable[[float], bool]] = {
    "dt": lambda v: v > 0, "duration": lambda v: v > 0, "rate_hz": lambda v: v > 0,
    "every": lambda v: v >= 1 and float(v).is_integer(),
}


def _check_info(path: Path, info: dict[str, str]) -> None:
    """The values of the "cosim" metadata record that readers use must be what cosim writes."""
    for key, ok in _METADATA_NUMBERS.items():
        if key not in info:
            continue
        try:
            value = float(info[key])
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and ok(value)):
            raise LogError(f"{path}: malformed cosim metadata: {key} = {info[key][:40]!r}")
    for key in ("sensors", "quantities", "vehicles"):
        if key in info:
            _json_list(info[key], key, path)
    if "inputs" in info:
        try:
            inputs = json.loads(info["inputs"])
        except (ValueError, RecursionError):
            inputs = None
        if not isinstance(inputs, dict) or not all(isinstance(k, str) and isinstance(v, str)
                                                   for k, v in inputs.items()):
            raise LogError(f"{path}: malformed cosim metadata: inputs: expected a JSON object of file names")


# --------------------------------------------------------------------------- overview

#: How much of a log :func:`open_log` reads: see there.
Check = Literal["full", "file", "summary"]


@dataclass
class LogOverview:
    """What a log holds, without its messages.

    Attributes:
        path: the file.
        complete: finished with its summary and footer (False: cut short, read up to its last complete record).
        library: who wrote it.
        metadata: name -> {key: value}.
        attachments: name -> bytes.
        counts: topic -> messages.
        start_time: log time of the first message, s.
        end_time: log time of the last message, s (simulated time reached).
        final_status: the last /cosim/status message, or None.
        sensor_names: the sensor channels (from the metadata or the sensor schema).
        quantities: the quantity of each sensor channel ("" when the log does not say).
        size: bytes.
        check: how it was read: "full" (every chunk decompressed and checked; counts from the messages),
            or "file"/"summary" (a finished log's summary; counts and times from it; see :func:`open_log`).
        chunks: chunks in the log (up to the cut, for a log cut short).
        chunks_read: chunks decompressed, each one's checksum verified.
        data_checksum: the data section's checksum (every byte of the file before the summary): True
            verified, False the log has none (older cosim logs), None not checked (a log cut short has
            none; ``check="summary"`` does not read it).
        summary_checked: the summary's checksum verified (and, with ``check="full"``, the summary found to
            agree with the chunks); False for a log without one (cut short).
    """

    path: Path
    complete: bool
    library: str = ""
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    start_time: float = 0.0
    end_time: float = 0.0
    final_status: dict | None = None
    sensor_names: list[str] = field(default_factory=list)
    quantities: list[str] = field(default_factory=list)
    size: int = 0
    check: str = "full"
    chunks: int = 0
    chunks_read: int = 0
    data_checksum: bool | None = None
    summary_checked: bool = False

    @property
    def truncated(self) -> bool:
        return not self.complete

    @property
    def info(self) -> dict[str, str]:
        """The "cosim" metadata record."""
        return self.metadata.get(METADATA_NAME, {})

    @property
    def status_word(self) -> str:
        """The log's final state, e.g. "finished", or "running (truncated)" for a log cut short."""
        status = self.final_status or {}
        return str(status.get("state", "unknown")) + ("" if self.complete else " (truncated)")


def open_log(path: str | os.PathLike[str], check: Check = "full", stats: ReadStats | None = None) -> LogOverview:
    """Read a log's metadata, attachments, message counts and final status (not the messages' contents).

    ``check`` says how much of a finished log is read (a log cut short has no
    summary and is always read whole, as with "full"):

    - ``"full"`` (``cosim info --verify``): one pass over the file; every chunk
      is decompressed (within :data:`cosim.core.limits.MAX_CHUNK_BYTES`) and
      its checksum verified, as are the attachments', the data section's and
      the summary's; the counts come from the messages, and the summary must
      agree with them. Seconds per 100 MB of log.
    - ``"file"`` (``cosim info``): the summary (counts, times, chunk index),
      the metadata and attachments it points to, and the chunk(s) holding the
      final status; every byte of the file is checked against the data
      section's checksum, without decompressing the other chunks.
    - ``"summary"`` (export and plot, before they read what they need): the
      same without the data section's checksum: its cost does not grow with
      the log.

    Only the status messages are decoded. Memory: one chunk at a time, plus
    the attachments (at most :data:`cosim.core.limits.MAX_ATTACHMENT_BYTES`).

    Raises:
        LogError: missing, not MCAP, not a cosim log, damaged (which record), over a limit, or its
            metadata or status messages are not what cosim writes.
    """
    if check not in ("full", "file", "summary"):
        raise ValueError(f"check: expected 'full', 'file' or 'summary', got {check!r}")
    path = Path(path)
    with open_file(path) as fh:
        complete = ends_with_magic(fh)
        fh.seek(0, os.SEEK_END)
        out = LogOverview(path=path, complete=complete, size=fh.tell())
        summary = read_summary(path, fh) if complete else None
        if summary is not None and check != "full":
            sensor_schema = _overview_from_summary(path, fh, summary, out, check, stats)
        else:
            sensor_schema = _overview_from_walk(path, fh, summary, out, stats)
    info = out.info
    _check_info(path, info)
    out.sensor_names = _json_list(info["sensors"], "sensors", path) if "sensors" in info else []
    out.quantities = _json_list(info["quantities"], "quantities", path) if "quantities" in info else []
    if not out.sensor_names and sensor_schema is not None:
        try:
            props = json.loads(sensor_schema).get("properties", {})
        except (ValueError, AttributeError, RecursionError):
            props = {}
        out.sensor_names = [name for name in props if name != "t" and isinstance(name, str)]
    if len(out.quantities) != len(out.sensor_names):
        out.quantities = ["" for _ in out.sensor_names]
    return out


def _sensor_schema(schemas: dict[int, bytes], channels: Iterable[Channel]) -> bytes | None:
    """The schema of the sensor topic's channel (the first, if several), or None."""
    channel = next((c for c in channels if c.topic == TOPIC_SENSORS), None)
    return schemas.get(channel.schema_id) if channel is not None else None


def _overview_from_walk(path: Path, fh: IO[bytes], summary: Summary | None, out: LogOverview,
                        stats: ReadStats | None) -> bytes | None:
    """Fill ``out`` from every record of the file (and check the summary, if any, against the chunks);
    returns the sensor topic's schema."""
    found = LogRecords()
    tally = Tally()
    last_status: tuple[int, Channel, bytes] | None = None
    decode = Decoder(path, found.schemas)
    for channel, message in walk(path, fh, out.complete, {TOPIC_STATUS}, found, tally=tally, stats=stats):
        if last_status is None or message.log_time >= last_status[0]:  # a status message: the only ones decoded
            last_status = (message.log_time, channel, message.data)
    out.library = found.header.library if found.header is not None else ""
    out.attachments, out.metadata = found.attachments, found.metadata
    for cid, count in tally.counts.items():
        if cid in found.channels:
            topic = found.channels[cid].topic
            out.counts[topic] = out.counts.get(topic, 0) + count
    if tally.last >= 0:
        out.start_time, out.end_time = tally.first / 1e9, tally.last / 1e9
    if last_status is not None:
        out.final_status = decode(last_status[1], last_status[2])
    if found.data_crc is not None:
        out.data_checksum = found.data_crc != 0
    out.check, out.chunks, out.chunks_read = "full", len(found.chunks), len(found.chunks)
    if summary is not None:
        compare_summary(path, summary, found.chunks, tally)
        out.summary_checked = True
    return _sensor_schema({i: s.data for i, s in found.schemas.items()}, found.channels.values())


def _overview_from_summary(path: Path, fh: IO[bytes], summary: Summary, out: LogOverview, check: str,
                           stats: ReadStats | None) -> bytes | None:
    """Fill ``out`` from a finished log's summary and what it points to; returns the sensor topic's schema."""
    out.library = read_header(path, fh).library
    for record in indexed_metadata(path, fh, summary):
        out.metadata[record.name] = dict(record.metadata)
    for attachment in indexed_attachments(path, fh, summary):
        out.attachments[attachment.name] = attachment.data
    statistics = summary.statistics
    for cid, count in statistics.channel_message_counts.items():
        if count:  # every counted channel is defined (read_summary)
            topic = summary.channels[cid].topic
            out.counts[topic] = out.counts.get(topic, 0) + count
    if statistics.message_count:
        out.start_time, out.end_time = statistics.message_start_time / 1e9, statistics.message_end_time / 1e9
    before = stats.chunks if stats is not None else 0
    counter = stats if stats is not None else ReadStats()
    ids = {cid for cid, channel in summary.channels.items() if channel.topic == TOPIC_STATUS}
    status = last_message(path, fh, summary, ids, counter) if ids else None
    if status is not None:
        out.final_status = Decoder(path, summary.schemas)(summary.channels[status.channel_id], status.data)
    out.check, out.chunks, out.chunks_read = check, len(summary.chunks), counter.chunks - before
    out.summary_checked = True
    if check == "file":
        if summary.data_crc != 0:
            check_data_section(path, fh, summary.data_end, summary.data_crc)
        out.data_checksum = summary.data_crc != 0
    return _sensor_schema({i: s.data for i, s in summary.schemas.items()}, summary.channels.values())


# --------------------------------------------------------------------------- windows of time


def _window_ns(start: float | None, end: float | None) -> tuple[int, int] | None:
    """A window of simulated time (s; None: open on that side) as log times (ns, both ends included)."""
    if start is None and end is None:
        return None
    for name, value in (("start", start), ("end", end)):
        if value is not None and not math.isfinite(value):
            raise CosimError(f"`{name}` of the time window: expected a finite time in s, got {value!r}")
    lo = 0 if start is None else max(_log_time(start), 0)
    hi = MAX_NS if end is None else _log_time(end)
    return lo, hi


def _log_time(t: float) -> int:
    """A finite time in s as a log time (ns, as :func:`cosim.log.schemas.to_ns`), clamped to what log times
    can be (and one below: nothing lies before a negative end)."""
    ns = t * 1e9
    if ns >= MAX_NS:
        return MAX_NS
    return to_ns(t) if ns > -1.0 else -1


def check_window(start: float | None, end: float | None, overview: LogOverview | None = None) -> None:
    """Check a window of simulated time ``[start, end]`` (s; None: the log's start or end): finite, not
    empty, and, given the log's ``overview``, overlapping the time the log covers.

    Raises:
        CosimError: one line naming ``--from``/``--to`` (and what the log covers).
    """
    for option, value in (("--from", start), ("--to", end)):
        if value is not None and not math.isfinite(value):
            raise CosimError(f"{option} {value!r}: expected a finite time in s")
    if start is not None and end is not None and not end > start:
        raise CosimError(f"--from {start:g} --to {end:g}: an empty window; --to must be later than --from")
    if overview is None:
        return
    path = overview.path
    if not overview.counts:
        raise CosimError(f"{path}: the log holds no messages, so no window of it can be read")
    covers = f"the log covers t = {overview.start_time:g} to {overview.end_time:g} s"
    if start is not None and _log_time(start) > _log_time(overview.end_time):
        raise CosimError(f"{path}: --from {start:g} s: after the end of the log ({covers})")
    if end is not None and _log_time(end) < _log_time(overview.start_time):
        raise CosimError(f"{path}: --to {end:g} s: before the start of the log ({covers})")


# --------------------------------------------------------------------------- messages


def iter_messages(path: str | os.PathLike[str], topics: Iterable[str], start: float | None = None,
                  end: float | None = None, stats: ReadStats | None = None) -> Iterator[tuple[str, dict]]:
    """The decoded messages on ``topics`` as (topic, message), in file order, chunk by chunk (constant memory).

    With ``start`` and/or ``end`` (s of simulated time, both included; None:
    open on that side), only the messages whose log time lies in the window:
    a finished log is read through its summary's chunk index, so only the
    chunks that overlap the window are read and decompressed (their
    checksums verified, and the summary's; the rest of the file is not read);
    a log cut short has no index and is walked whole, skipping the messages
    outside the window before they are decoded. Without a window every record
    is read and every checksum verified.

    Every message is checked against cosim's schema for its topic. A log cut
    short yields what it holds up to its last complete record.

    Raises:
        LogError: missing, not MCAP, not a cosim log, damaged, or a message that does not match its schema.
        CosimError: a bound of the window that is not finite.
    """
    path = Path(path)
    wanted = set(topics)
    window = _window_ns(start, end)
    with open_file(path) as fh:
        complete = ends_with_magic(fh)
        summary = read_summary(path, fh) if complete and window is not None else None
        schemas: dict[int, Schema] = {}
        decode = Decoder(path, schemas)
        for channel, message in walk(path, fh, complete, wanted, window=window, summary=summary, stats=stats,
                                     schemas=schemas):
            if stats is not None:
                stats.messages += 1
            yield channel.topic, decode(channel, message.data)


def check_messages(path: str | os.PathLike[str], topics: Iterable[str]) -> dict[str, int]:
    """Read every message on ``topics`` once, checking each against its schema; returns the count per topic.

    For a caller that must know a log is sound before it starts writing (a replay).

    Raises:
        LogError: as :func:`iter_messages`.
    """
    counts: dict[str, int] = {}
    for topic, _ in iter_messages(path, topics):
        counts[topic] = counts.get(topic, 0) + 1
    return counts


def _sensor_values(path: Path, message: dict, names: Sequence[str]) -> list[float]:
    try:
        return [float(message[n]) for n in names]
    except KeyError as exc:
        raise LogError(f"{path}: a message on {TOPIC_SENSORS} (t = {message['t']:g} s) has no sensor "
                       f"{exc.args[0]!r}") from None


def sensor_series(path: str | os.PathLike[str], names: Sequence[str] | None = None, start: float | None = None,
                  end: float | None = None, stats: ReadStats | None = None
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log as arrays (t, {name: values}), sorted by time (all channels by default),
    within the window ``[start, end]`` if given (see :func:`iter_messages`).

    Memory grows with the samples read (8 bytes per sample and channel); :func:`iter_messages` streams.
    """
    path = Path(path)
    names = list(names) if names is not None else open_log(path, check="summary", stats=stats).sensor_names
    t: list[float] = []
    rows: list[list[float]] = []
    for _, msg in iter_messages(path, [TOPIC_SENSORS], start, end, stats):
        t.append(float(msg["t"]))
        rows.append(_sensor_values(path, msg, names))
    t_arr = np.asarray(t, dtype=float)
    values = np.asarray(rows, dtype=float).reshape(len(rows), len(names))
    order = np.argsort(t_arr, kind="stable")
    return t_arr[order], {n: values[order, i] for i, n in enumerate(names)}


@dataclass
class LogContents:
    """Everything a log holds. ``messages`` maps topic -> list of (log_time ns, decoded JSON), by log time."""

    path: Path
    profile: str = ""
    messages: dict[str, list[tuple[int, dict]]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    truncated: bool = False

    @property
    def final_status(self) -> dict | None:
        status = self.messages.get(TOPIC_STATUS, [])
        return status[-1][1] if status else None

    def topic(self, name: str) -> list[dict]:
        """The messages on topic ``name``, by log time."""
        return [m for _, m in self.messages.get(name, [])]


def read_log(path: str | os.PathLike[str], topics: Iterable[str] | None = None) -> LogContents:
    """Read a whole cosim log (the messages on ``topics``, all by default) into memory.

    A log cut short (process killed) is read up to its last complete record and
    marked ``truncated``. Memory grows with the log: for long logs stream with
    :func:`iter_messages`.

    Raises:
        LogError: missing, not MCAP, not a cosim log, damaged, or a message that does not match its schema.
    """
    path = Path(path)
    out = LogContents(path=path)
    messages = out.messages
    found = LogRecords()
    with open_file(path) as fh:
        complete = ends_with_magic(fh)
        decode = Decoder(path, found.schemas)
        for channel, message in walk(path, fh, complete, set(topics) if topics is not None else None, found):
            messages.setdefault(channel.topic, []).append((message.log_time, decode(channel, message.data)))
    out.attachments, out.metadata, out.truncated = found.attachments, found.metadata, not complete
    out.profile = found.header.profile if found.header is not None else ""
    for msgs in messages.values():
        msgs.sort(key=lambda entry: entry[0])  # stable: file order among equal times
    return out

