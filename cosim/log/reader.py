"""Reading cosim logs: the one MCAP reader behind info, export, plot, replay, studies and tests.

- :func:`open_log`: what a log holds without its messages (metadata,
  attachments, message counts, the final status, sensor names), every
  checksum verified;
- :func:`iter_messages`: the decoded messages of some topics, in file order,
  chunk by chunk (constant memory); :func:`sensor_series` the sensor channels
  as arrays;
- :func:`read_log`: everything at once (:class:`LogContents`), for small logs
  and tests;
- :class:`LoggedTraffic`: the logged SUMO frames as a traffic source again,
  read as a replay needs them (constant memory); :func:`traffic_from_log` the
  same from a log read whole.

A log is untrusted input: people send logs to each other. So the reader

- walks the file record by record itself (the MCAP record layout is a one-byte
  opcode and an eight-byte length) rather than through the ``mcap`` package's
  readers, which skip attachment checksums and decompress a chunk to whatever
  size it claims (a 33 kB file claiming a 1 GB chunk made ``cosim info`` use
  2 GB): every record's length is checked against the file and against
  :mod:`cosim.core.limits` before it is read or decompressed;
- verifies every checksum the file has: each chunk's (of its decompressed
  records), each attachment's, and the data section's (written by cosim since
  this version); a mismatch is damage, named by record;
- checks every message it hands out against cosim's own schema for its topic
  (:mod:`cosim.log.checks`), and the "cosim" metadata record's values.

One truncation rule for all of them: a log is *complete* when it ends with the
MCAP magic (it was finished: summary, index, footer). A complete log must be
intact: any damage (a checksum that does not match, a malformed record) is a
:class:`cosim.errors.LogError`. A log cut short (the process was killed) is
read record by record up to its last complete record, and says it is
truncated; a checksum that does not match is damage there too.

Logs are parsed, never evaluated or unpickled.
"""
from __future__ import annotations

import io
import json
import math
import os
import struct
import zlib
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
import orjson
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, DataEnd, Header, Metadata, Schema

from cosim.core.limits import MAX_ATTACHMENT_BYTES, MAX_CHUNK_BYTES, MAX_RECORD_BYTES
from cosim.core.traffic import Frame, FrameTraffic, TrafficBlock
from cosim.core.vehicles import VehicleModel, model_from_dict
from cosim.errors import ConfigError, LogError

from .checks import message_check
from .schemas import (
    MAGIC,
    METADATA_NAME,
    PROFILE,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_TYPES,
)

# --------------------------------------------------------------------------- files and records

_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length of the record's body
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_ATTACHMENT_OVERHEAD = 1 << 16  # name, media type, times and checksum around an attachment's data


def _open(path: Path) -> IO[bytes]:
    """The log file, opened for reading at its start; an error unless it starts like an MCAP file."""
    try:
        fh = open(path, "rb")
    except OSError as exc:
        raise LogError(f"{path}: cannot read ({exc.strerror})") from None
    if fh.read(8) != MAGIC:
        fh.close()
        raise LogError(f"{path}: not an MCAP file")
    fh.seek(0)
    return fh


def _ends_with_magic(fh: IO[bytes]) -> bool:
    """The truncation rule: a finished MCAP file ends with its magic (leaves ``fh`` at the start)."""
    fh.seek(0, os.SEEK_END)
    complete = fh.tell() >= 16
    if complete:
        fh.seek(-8, os.SEEK_END)
        complete = fh.read(8) == MAGIC
    fh.seek(0)
    return complete


def file_is_complete(path: str | os.PathLike[str]) -> bool:
    """True when the log was finished (it ends with the MCAP footer and magic); False if not, or unreadable."""
    try:
        with open(path, "rb") as fh:
            return _ends_with_magic(fh)
    except OSError:
        return False


def _corrupt(path: Path, what: str) -> LogError:
    return LogError(f"{path}: corrupt MCAP file: {what}")


@dataclass(frozen=True)
class _Message:
    """A message record: its channel, log time (ns) and undecoded data."""

    channel_id: int
    log_time: int
    data: bytes


@dataclass(frozen=True)
class _Attachment:
    name: str
    media_type: str
    data: bytes


def _parse(path: Path, opcode: int, body: bytes, offset: int) -> Any:
    """The record of ``opcode`` in ``body`` (None for records the reader does not need)."""
    if opcode == Opcode.MESSAGE:
        if len(body) < _MESSAGE_HEAD.size:
            raise _corrupt(path, f"a message record at offset {offset} is too short")
        channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(body)
        return _Message(channel_id, log_time, body[_MESSAGE_HEAD.size:])
    readers: dict[int, Any] = {Opcode.HEADER: Header, Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel,
                               Opcode.METADATA: Metadata, Opcode.DATA_END: DataEnd}
    reader = readers.get(opcode)
    if reader is None:
        return None
    try:
        return reader.read(ReadDataStream(io.BytesIO(body)))
    except Exception:  # noqa: BLE001 - any parse failure of a whole record is damage
        raise _corrupt(path, f"a malformed {reader.__name__} record at offset {offset}") from None


def _attachment(path: Path, body: bytes, offset: int) -> _Attachment:
    """An attachment record, its checksum verified (the mcap package reads past it)."""
    try:
        stream = ReadDataStream(io.BytesIO(body))
        stream.read8()  # log time
        stream.read8()  # create time
        name = stream.read_prefixed_string()
        media_type = stream.read_prefixed_string()
        length = stream.read8()
        start = stream.count
        if start + length + 4 != len(body):
            raise ValueError("lengths do not add up")
    except Exception:  # noqa: BLE001 - any parse failure of a whole record is damage
        raise _corrupt(path, f"a malformed attachment record at offset {offset}") from None
    (stored,) = struct.unpack_from("<I", body, len(body) - 4)
    if stored != 0 and zlib.crc32(memoryview(body)[:-4]) != stored:
        raise _corrupt(path, f"the checksum of attachment {name!r} (offset {offset}) does not match: "
                             "it was changed after it was written")
    return _Attachment(name, media_type, body[start:start + length])


def _chunk_records(path: Path, body: bytes, offset: int, number: int) -> bytes:
    """The records inside a chunk: decompressed within the limit, their checksum verified."""
    try:
        chunk = Chunk.read(ReadDataStream(io.BytesIO(body)))
    except Exception:  # noqa: BLE001
        raise _corrupt(path, f"a malformed chunk record at offset {offset}") from None
    where = (f"chunk {number} (offset {offset}, messages at t = {chunk.message_start_time / 1e9:g} to "
             f"{chunk.message_end_time / 1e9:g} s)")
    size = chunk.uncompressed_size
    MAX_CHUNK_BYTES.check(size, f"{path}: {where}", "its decompressed size")
    try:
        if chunk.compression == "zstd":
            import zstandard

            data = zstandard.ZstdDecompressor().decompress(chunk.data, max_output_size=size)
        elif chunk.compression == "":
            data = chunk.data
        elif chunk.compression == "lz4":
            import lz4.frame  # only if installed: cosim writes zstd

            decompressor = lz4.frame.LZ4FrameDecompressor()
            data = decompressor.decompress(chunk.data, max_length=size)
        else:
            raise _corrupt(path, f"{where} uses an unknown compression {chunk.compression!r}")
    except LogError:
        raise
    except ImportError:
        raise LogError(f"{path}: {where} is compressed with {chunk.compression}, which this installation "
                       "cannot read") from None
    except Exception as exc:  # noqa: BLE001 - the decompressors raise their own error types
        raise _corrupt(path, f"{where} cannot be decompressed ({type(exc).__name__})") from None
    if len(data) != size:
        raise _corrupt(path, f"{where} decompresses to {len(data)} bytes, not the {size} it claims")
    if chunk.uncompressed_crc != 0 and zlib.crc32(data) != chunk.uncompressed_crc:
        raise _corrupt(path, f"the checksum of {where} does not match: it was changed after it was written")
    return data


def _records(path: Path, fh: IO[bytes], complete: bool, wanted_ids: set[int] | None = None,
             others: bool = False) -> Iterator[tuple[int, Any]]:
    """(opcode, record) of every record the reader needs, in file order, chunks opened (the one record walker).

    Records: Header, Schema, Channel, :class:`_Message`, :class:`_Attachment`,
    Metadata. A file cut short ends quietly after its last complete record;
    damage (a checksum that does not match, a malformed record, or anything
    cut short in a complete file) raises. The data section's checksum is
    verified at its end (DataEnd); the summary after it is not needed.
    Messages inside chunks on channels not in ``wanted_ids`` (a set the caller
    may fill as channels appear; None: all) are skipped without a copy, or,
    with ``others``, yielded without their data (for counting).
    """
    fh.seek(0, os.SEEK_END)
    size = fh.tell()
    fh.seek(0)
    crc = zlib.crc32(fh.read(len(MAGIC)))
    offset = len(MAGIC)
    chunks = 0
    attachment_bytes = 0
    while True:
        head = fh.read(_RECORD_HEAD.size)
        if len(head) < _RECORD_HEAD.size:
            if complete:
                raise _corrupt(path, "the file ends before its data section does")
            return
        opcode, length = _RECORD_HEAD.unpack(head)
        if length > size - offset - _RECORD_HEAD.size:
            if complete:
                raise _corrupt(path, f"a record at offset {offset} claims {length} bytes, past the end of the file")
            return  # the record the process was writing when it was killed
        if opcode == Opcode.ATTACHMENT:
            attachment_bytes += length
            MAX_ATTACHMENT_BYTES.check(attachment_bytes - _ATTACHMENT_OVERHEAD, f"{path}: the attachments",
                                       f"up to the record at offset {offset}")
        elif opcode == Opcode.CHUNK:
            MAX_CHUNK_BYTES.check(length, f"{path}: the chunk at offset {offset}", "its compressed size")
        elif opcode not in (Opcode.MESSAGE_INDEX, Opcode.CHUNK_INDEX):
            MAX_RECORD_BYTES.check(length, f"{path}: the record at offset {offset} (opcode {opcode:#04x})")
        body = fh.read(length)
        if opcode == Opcode.DATA_END:
            end = _parse(path, opcode, body, offset)
            if end.data_section_crc != 0 and end.data_section_crc != crc:
                raise _corrupt(path, "the checksum of the data section does not match: the file was changed "
                                     "after it was written")
            return
        crc = zlib.crc32(body, zlib.crc32(head, crc))
        if opcode == Opcode.CHUNK:
            chunks += 1
            yield from _inner_records(path, _chunk_records(path, body, offset, chunks), offset, wanted_ids, others)
        elif opcode == Opcode.ATTACHMENT:
            yield opcode, _attachment(path, body, offset)
        elif opcode == Opcode.FOOTER:
            return
        else:
            record = _parse(path, opcode, body, offset)
            if record is not None:
                yield opcode, record
        offset += _RECORD_HEAD.size + length


def _inner_records(path: Path, data: bytes, chunk_offset: int, wanted_ids: set[int] | None = None,
                   others: bool = False) -> Iterator[tuple[int, Any]]:
    """The records of a decompressed chunk (schemas, channels, messages)."""
    view = memoryview(data)
    position, end = 0, len(data)
    head = _RECORD_HEAD
    message = Opcode.MESSAGE
    while position < end:
        if position + head.size > end:
            raise _corrupt(path, f"the chunk at offset {chunk_offset} ends inside a record")
        opcode, length = head.unpack_from(data, position)
        body_start = position + head.size
        if length > end - body_start:
            raise _corrupt(path, f"a record in the chunk at offset {chunk_offset} runs past the chunk's end")
        if opcode == message:  # the hot path: no record object, no copy of the header
            if length < _MESSAGE_HEAD.size:
                raise _corrupt(path, f"a message record in the chunk at offset {chunk_offset} is too short")
            channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(data, body_start)
            if wanted_ids is None or channel_id in wanted_ids:
                yield opcode, _Message(channel_id, log_time, bytes(view[body_start + _MESSAGE_HEAD.size:
                                                                          body_start + length]))
            elif others:
                yield opcode, _Message(channel_id, log_time, b"")
        else:
            record = _parse(path, opcode, bytes(view[body_start:body_start + length]), chunk_offset)
            if record is not None:
                yield opcode, record
        position = body_start + length


def _decode(path: Path, channel: Channel, data: bytes) -> dict:
    """One message as a JSON object checked against cosim's schema for its topic (the one decoder)."""
    if channel.message_encoding != "json":
        raise LogError(f"{path}: channel {channel.topic} is {channel.message_encoding!r}, not a cosim JSON channel")
    try:
        value = orjson.loads(data)  # strict JSON (no NaN): what cosim writes; 5x faster than json
    except (orjson.JSONDecodeError, RecursionError):
        raise LogError(f"{path}: a message on {channel.topic} is not valid JSON") from None
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


def _check_profile(path: Path, profile: str | None) -> None:
    if profile is None:
        raise LogError(f"{path}: an MCAP file whose header cannot be read")
    if profile != PROFILE:
        raise LogError(f"{path}: an MCAP file, but not a cosim log (profile {profile!r})")


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
        end_time: log time of the last message, s (simulated time reached).
        final_status: the last /cosim/status message, or None.
        sensor_names: the sensor channels (from the metadata or the sensor schema).
        quantities: the quantity of each sensor channel ("" when the log does not say).
        size: bytes.
    """

    path: Path
    complete: bool
    library: str = ""
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    end_time: float = 0.0
    final_status: dict | None = None
    sensor_names: list[str] = field(default_factory=list)
    quantities: list[str] = field(default_factory=list)
    size: int = 0

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


def _walk(path: Path, fh: IO[bytes], complete: bool, wanted: set[str] | None, others: bool = False
          ) -> Iterator[tuple[str, Any]]:
    """The events of a log in file order (the one walker behind every reader):

    ``("header", Header)`` first (the profile checked), ``("schema", Schema)``,
    ``("channel", Channel)``, ``("attachment", _Attachment)``, ``("metadata",
    Metadata)``, ``("message", (channel, _Message))`` for messages on ``wanted``
    topics (all if None; undecoded), with ``others`` the other messages too
    (their data empty), and ``("end", complete)`` last.
    """
    channels: dict[int, Channel] = {}
    wanted_ids: set[int] = set()
    first = True
    for opcode, record in _records(path, fh, complete, None if wanted is None else wanted_ids, others):
        if first:
            _check_profile(path, record.profile if opcode == Opcode.HEADER else None)
            first = False
        if opcode == Opcode.MESSAGE:
            if record.channel_id in wanted_ids or (others and record.channel_id in channels):
                yield "message", (channels[record.channel_id], record)
        elif opcode == Opcode.CHANNEL:
            channels[record.id] = record
            if wanted is None or record.topic in wanted:
                wanted_ids.add(record.id)
            else:
                wanted_ids.discard(record.id)
            yield "channel", record
        elif opcode == Opcode.HEADER:
            yield "header", record
        elif opcode == Opcode.SCHEMA:
            yield "schema", record
        elif opcode == Opcode.ATTACHMENT:
            yield "attachment", record
        elif opcode == Opcode.METADATA:
            yield "metadata", record
    if first:
        _check_profile(path, None)
    yield "end", complete


def open_log(path: str | os.PathLike[str]) -> LogOverview:
    """Read a log's metadata, attachments, message counts and final status (not the messages' contents).

    One pass over the file: every chunk is decompressed (within
    :data:`cosim.core.limits.MAX_CHUNK_BYTES`) and its checksum verified, as are
    the attachments' and the data section's; only the status messages are
    decoded. A log cut short is read up to its last complete record. Memory:
    one chunk at a time, plus the attachments (at most
    :data:`cosim.core.limits.MAX_ATTACHMENT_BYTES`).

    Raises:
        LogError: missing, not MCAP, not a cosim log, damaged (which record), over a limit, or its
            metadata or status messages are not what cosim writes.
    """
    path = Path(path)
    with _open(path) as fh:
        complete = _ends_with_magic(fh)
        fh.seek(0, os.SEEK_END)
        out = LogOverview(path=path, complete=complete, size=fh.tell())
        fh.seek(0)
        schemas: dict[int, bytes] = {}
        sensor_schema: bytes | None = None
        counts: dict[int, int] = {}
        end_ns = 0
        last_status: tuple[int, Channel, bytes] | None = None
        status_ids: set[int] = set()
        topics: dict[int, str] = {}
        for kind, item in _walk(path, fh, complete, {TOPIC_STATUS}, others=True):  # data of the statuses only
            if kind == "message":
                channel, message = item
                counts[message.channel_id] = counts.get(message.channel_id, 0) + 1
                end_ns = max(end_ns, message.log_time)
                if message.channel_id in status_ids and (last_status is None or message.log_time >= last_status[0]):
                    last_status = (message.log_time, channel, message.data)
            elif kind == "channel":
                topics[item.id] = item.topic
                if item.topic == TOPIC_STATUS:
                    status_ids.add(item.id)
                if item.topic == TOPIC_SENSORS:
                    sensor_schema = schemas.get(item.schema_id)
            elif kind == "schema":
                schemas[item.id] = item.data
            elif kind == "attachment":
                out.attachments[item.name] = item.data
            elif kind == "metadata":
                out.metadata[item.name] = dict(item.metadata)
            elif kind == "header":
                out.library = item.library
    for cid, count in counts.items():
        out.counts[topics[cid]] = out.counts.get(topics[cid], 0) + count
    out.end_time = end_ns / 1e9
    if last_status is not None:
        out.final_status = _decode(path, last_status[1], last_status[2])
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


# --------------------------------------------------------------------------- messages


def iter_messages(path: str | os.PathLike[str], topics: Iterable[str]) -> Iterator[tuple[str, dict]]:
    """The decoded messages on ``topics`` as (topic, message), in file order, chunk by chunk (constant memory).

    Every message is checked against cosim's schema for its topic. A log cut
    short yields what it holds up to its last complete record.

    Raises:
        LogError: missing, not MCAP, not a cosim log, damaged, or a message that does not match its schema.
    """
    path = Path(path)
    wanted = set(topics)
    with _open(path) as fh:
        for kind, item in _walk(path, fh, _ends_with_magic(fh), wanted):
            if kind == "message":
                channel, message = item
                yield channel.topic, _decode(path, channel, message.data)


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


def sensor_series(path: str | os.PathLike[str], names: Sequence[str] | None = None
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log as arrays (t, {name: values}), sorted by time (all channels by default).

    Memory grows with the log (8 bytes per sample and channel); :func:`iter_messages` streams.
    """
    path = Path(path)
    names = list(names) if names is not None else open_log(path).sensor_names
    t: list[float] = []
    rows: list[list[float]] = []
    for _, msg in iter_messages(path, [TOPIC_SENSORS]):
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
    with _open(path) as fh:
        for kind, item in _walk(path, fh, _ends_with_magic(fh), set(topics) if topics is not None else None):
            if kind == "message":
                channel, message = item
                messages.setdefault(channel.topic, []).append((message.log_time, _decode(path, channel, message.data)))
            elif kind == "attachment":
                out.attachments[item.name] = item.data
            elif kind == "metadata":
                out.metadata[item.name] = dict(item.metadata)
            elif kind == "header":
                out.profile = item.profile
            elif kind == "end":
                out.truncated = not item
    for msgs in messages.values():
        msgs.sort(key=lambda entry: entry[0])  # stable: file order among equal times
    return out


# --------------------------------------------------------------------------- replaying traffic


def _frame(path: Path, message: dict) -> Frame:
    """A logged SUMO frame (checked against its schema) as a core :class:`Frame`; its arrays must agree."""
    n = len(message["ids"])
    lengths = {key: len(message[key]) for key in ("x", "y", "speed", "acceleration", "types")}
    if any(length != n for length in lengths.values()):
        raise LogError(f"{path}: a frame on {TOPIC_TRAFFIC} (t = {message['t']:g} s) has {n} ids but "
                       + ", ".join(f"{length} {key}" for key, length in lengths.items()))
    return Frame(t=float(message["t"]), ids=tuple(message["ids"]), x=np.array(message["x"], dtype=float),
                 y=np.array(message["y"], dtype=float), v=np.array(message["speed"], dtype=float),
                 a=np.array(message["acceleration"], dtype=float), types=tuple(message["types"]))


class _FrameFeed:
    """Logged frames and vehicle types, fed in order into a :class:`FrameTraffic` with the empty frames between.

    Frames the log does not hold were empty (no vehicle near the deck); they are
    filled in at their step times, with the same time expression as the live
    source (``k * step``), so that replays are bit-identical.
    """

    def __init__(self, path: Path, length: float, step: float) -> None:
        self.path = path
        self.step = float(step)
        self.models: dict[str, VehicleModel] = {}
        self.traffic = FrameTraffic(step, length, self.models)
        self.frames = 0

    def vehicle_type(self, message: dict) -> None:
        try:
            self.models[message["type"]] = model_from_dict(message["model"])
        except (ConfigError, KeyError, TypeError, ValueError) as exc:
            raise LogError(f"{self.path}: a vehicle type on {TOPIC_VEHICLE_TYPES} (t = {message['t']:g} s) is not "
                           f"a valid vehicle model: {exc}") from None

    def pad(self, t_end: float) -> None:
        """Empty frames while one more still ends before ``t_end`` (half a step of slack for round-off)."""
        traffic, step = self.traffic, self.step
        empty = np.zeros(0)
        while traffic.last_time + step < t_end + 0.5 * step:
            k = int(round(traffic.last_time / step)) + 1
            traffic.add_frame(Frame(k * step, (), empty, empty, empty, empty, ()))

    def frame(self, message: dict) -> None:
        frame = _frame(self.path, message)
        if not frame.t > self.traffic.last_time:
            raise LogError(f"{self.path}: the frames on {TOPIC_TRAFFIC} go back in time (t = {frame.t:g} s after "
                           f"{self.traffic.last_time:g} s)")
        try:
            self.pad(frame.t - self.step)
            self.traffic.add_frame(frame)
        except ConfigError as exc:
            raise LogError(f"{self.path}: malformed traffic frames ({exc})") from None
        self.frames += 1


def traffic_from_log(contents: LogContents, length: float, step: float, until: float | None = None) -> FrameTraffic:
    """Rebuild the logged traffic frames as a traffic source for a bridge of ``length`` m (all in memory).

    Frames the log does not hold were empty (no vehicle near the deck); they
    are filled in at their step times, up to ``until`` (s) if given.

    Args:
        contents: the log, read with (at least) the topics ``/cosim/traffic`` and ``/cosim/vehicle_types``.
        length: the bridge's length, m.
        step: the traffic source's step, s (``[traffic].step`` of the logged run).
        until: pad with empty frames up to this time, s.

    Raises:
        LogError: the log has no traffic frames (and no ``until``), or they are malformed.
    """
    frames = contents.messages.get(TOPIC_TRAFFIC, [])
    if not frames and until is None:
        raise LogError(f"{contents.path}: no traffic frames ({TOPIC_TRAFFIC}) in this log")
    feed = _FrameFeed(contents.path, length, step)
    merged = sorted([(ns, 0, m) for ns, m in contents.messages.get(TOPIC_VEHICLE_TYPES, [])]
                    + [(ns, 1, m) for ns, m in frames], key=lambda e: (e[0], e[1]))
    for _, kind, message in merged:
        if kind == 0:
            feed.vehicle_type(message)
        else:
            feed.frame(message)
    if until is not None:
        feed.pad(until)
    return feed.traffic


def read_traffic(path: str | os.PathLike[str], length: float, step: float, until: float | None = None
                 ) -> tuple[FrameTraffic, int]:
    """The logged SUMO frames of the log at ``path`` as a traffic source (see :func:`traffic_from_log`),
    and how many frames the log holds."""
    contents = read_log(path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
    return traffic_from_log(contents, length, step, until), len(contents.messages.get(TOPIC_TRAFFIC, []))


class LoggedTraffic:
    """The logged SUMO frames of a log as a traffic source, read from the file as the run needs them.

    Memory stays constant however long the log: frames are read chunk by
    chunk, and frames the run has passed are dropped (as with live SUMO).
    Replays are bit-identical to :func:`traffic_from_log`'s.

    Args:
        path: the log.
        length: the bridge's length, m (positions are along the logged run's axis).
        step: the logged run's ``[traffic].step``, s.
        until: the replay's end, s; empty frames are filled in up to it.

    Raises:
        LogError: from :meth:`block`, if the frames are malformed (check them first with :func:`check_messages`).
    """

    def __init__(self, path: str | os.PathLike[str], length: float, step: float, until: float) -> None:
        self.path = Path(path)
        self.length = float(length)
        self.until = float(until)
        self._feed = _FrameFeed(self.path, length, step)
        self._messages = iter_messages(self.path, [TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
        self._pending: dict | None = None  # the next logged frame, read but not yet needed
        self._exhausted = False

    def check(self) -> int:
        """Read every logged frame and vehicle type once, as :meth:`block` will (constant memory), so that a
        malformed one is found before a replay writes anything; returns how many frames the log holds.

        Raises:
            LogError: a frame or vehicle type that does not match its schema, frames whose arrays differ in
                length, go back in time, are off the step, or name a vehicle type the log does not define.
        """
        feed = _FrameFeed(self.path, self.length, self._feed.step)
        for topic, message in iter_messages(self.path, [TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES]):
            if topic == TOPIC_VEHICLE_TYPES:
                feed.vehicle_type(message)
            else:
                feed.frame(message)
                feed.traffic.forget_before(feed.traffic.last_time)
        return feed.frames

    @property
    def frames_read(self) -> int:
        """Logged (non-empty) frames read so far."""
        return self._feed.frames

    def _next_frame(self) -> dict | None:
        """The next logged frame (vehicle types on the way are taken in), or None at the end of the log."""
        for topic, message in self._messages:
            if topic == TOPIC_VEHICLE_TYPES:
                self._feed.vehicle_type(message)
            else:
                return message
        self._exhausted = True
        return None

    def block(self, times: np.ndarray) -> TrafficBlock:
        """The vehicles at ``times`` (s), interpolated between the logged frames (the TrafficSource protocol).

        Frames are read, and the empty ones between them made, only as far as ``times`` need: a long
        stretch without vehicles costs no memory either.
        """
        traffic = self._feed.traffic
        step = self._feed.step
        need = float(times[-1])
        while traffic.last_time < need - 1e-9:
            if self._pending is None and not self._exhausted:
                self._pending = self._next_frame()
            if self._pending is not None and float(self._pending["t"]) < need + 0.5 * step:
                self._feed.frame(self._pending)  # the empty frames before it, then it
                self._pending = None
            else:  # the next logged frame lies beyond: empty frames up to ``need``
                self._feed.pad(min(need, self.until) + 0.5 * step - 1e-9)
                if self._pending is None and self._exhausted and traffic.last_time < need - 1e-9:
                    break  # past the replay's end: FrameTraffic says so
        out = traffic.block(times)
        traffic.forget_before(need)
        return out

    def close(self) -> None:
        """Close the log file (also done when the source is garbage-collected)."""
        self._messages.close()  # type: ignore[attr-defined]
