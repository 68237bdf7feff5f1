"""Reading cosim logs: the one MCAP reader behind info, export, plot, replay, studies and tests.

- :func:`open_log`: what a log holds without its messages (metadata,
  attachments, message counts, the final status, sensor names); by default
  every chunk is read and every checksum verified, or, for a finished log,
  only its summary (``check="file"`` or ``"summary"``: seconds for a day-long log);
- :func:`iter_messages`: the decoded messages of some topics, in file order,
  chunk by chunk (constant memory), optionally within a window of simulated
  time (only the chunks that overlap it are read); :func:`sensor_series` the
  sensor channels as arrays;
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
- verifies every checksum of what it reads: each chunk's (of its decompressed
  records), each attachment's, the summary's and the data section's (the
  file's bytes as written; older cosim logs have none); a mismatch is damage,
  named by record;
- checks that the messages of every chunk it reads lie in the time range its
  header (and the summary's index) claims, so that a window can skip chunks;
- checks every message it hands out against cosim's own schema for its topic
  (:mod:`cosim.log.checks`), and the "cosim" metadata record's values.

A finished log ends with a *summary*: the channels, the message counts and an
index of its chunks (offset and time range of each). Readers that need only
part of the log (a window of time, the overview) follow that index instead of
reading every chunk; what they skipped is said (:attr:`LogOverview.check`) and
``check="full"`` (``cosim info --verify``) reads everything and checks that the
summary agrees with the chunks.

One truncation rule for all of them: a log is *complete* when it ends with the
MCAP magic (it was finished: summary, index, footer). A complete log must be
intact: any damage (a checksum that does not match, a malformed record) is a
:class:`cosim.errors.LogError`. A log cut short (the process was killed) has
no summary: it is read record by record up to its last complete record, and
says it is truncated; a checksum that does not match is damage there too.

Logs are parsed, never evaluated or unpickled.
"""
from __future__ import annotations

import io
import json
import math
import os
import struct
import zlib
from collections.abc import Callable, Generator, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Literal

import numpy as np
import orjson
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import (
    AttachmentIndex,
    Channel,
    Chunk,
    DataEnd,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
)

from cosim.core.limits import MAX_ATTACHMENT_BYTES, MAX_CHUNK_BYTES, MAX_RECORD_BYTES
from cosim.core.traffic import Frame, FrameTraffic, TrafficBlock
from cosim.core.vehicles import VehicleModel, model_from_dict
from cosim.errors import ConfigError, CosimError, LogError

from .checks import message_check
from .schemas import (
    MAGIC,
    METADATA_NAME,
    PROFILE,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_TYPES,
    to_ns,
)

# --------------------------------------------------------------------------- files and records

_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length of the record's body
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_CHUNK_TIMES = struct.Struct("<QQ")  # a chunk record's first fields: message start and end time
_FOOTER = struct.Struct("<BQQQI")  # opcode, length (20), summary start, summary offset start, summary crc
_DATA_END = struct.Struct("<BQI")  # opcode, length (4), data section crc
_ATTACHMENT_OVERHEAD = 1 << 16  # name, media type, times and checksum around an attachment's data
_MAX_NS = (1 << 64) - 1  # log times are unsigned 64-bit nanoseconds
_CRC_BLOCK = 1 << 22  # bytes per read when the data section's checksum is computed


@dataclass
class ReadStats:
    """What a read cost, counted as it goes (as scipy's ``OdeSolver`` counts ``nfev``): pass one to
    :func:`open_log`, :func:`iter_messages` and the functions built on them, then look.

    Attributes:
        chunks: chunks decompressed (each one's checksum verified).
        messages: messages decoded (JSON parsed and checked against their topic's schema).
    """

    chunks: int = 0
    messages: int = 0


@dataclass(frozen=True, slots=True)  # slots: a day-long log's index holds 17 000 of them
class _ChunkEntry:
    """Where a chunk is and what it holds: from the summary's chunk index, or from the chunk itself."""

    number: int  # 1-based, in file order (the number errors name)
    offset: int  # of the chunk record
    length: int  # of its body
    start: int  # log time of its first and last message, ns
    end: int
    channels: frozenset[int] = frozenset()  # channels with messages in it (empty: not known)
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



def _chunk_records(path: Path, body: bytes, offset: int, number: int) -> tuple[bytes, Chunk]:
    """The records inside a chunk, decompressed within the limit and their checksum verified, and the
    chunk record (its time range)."""
    try:
        chunk = Chunk.read(ReadDataStream(io.BytesIO(body)))
    except Exception:  # noqa: BLE001
        raise _corrupt(path, f"a malformed chunk record at offset {offset}") from None
    where = _chunk_where(number, offset, chunk.message_start_time, chunk.message_end_time)
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
    return data, chunk


def _chunk_where(number: int, offset: int, start: int, end: int) -> str:
    return f"chunk {number} (offset {offset}, messages at t = {start / 1e9:g} to {end / 1e9:g} s)"


def _check_span(path: Path, entry: _ChunkEntry, found: tuple[int, int, int]) -> None:
    """The messages of a chunk span exactly the time range its header claims (what windows rely on)."""
    count, first, last = found
    if count and (first, last) != (entry.start, entry.end):
        raise _corrupt(path, f"{_chunk_where(entry.number, entry.offset, entry.start, entry.end)} holds messages "
                             f"at t = {first / 1e9:g} to {last / 1e9:g} s")


def _records(path: Path, fh: IO[bytes], complete: bool, wanted_ids: set[int] | None = None,
             tally: _Tally | None = None, window: tuple[int, int] | None = None,
             stats: ReadStats | None = None) -> Iterator[tuple[int, Any]]:
    """(opcode, record) of every record the reader needs, in file order, chunks opened (the one record walker).

    Records: Header, Schema, Channel, :class:`_Message`, :class:`_Attachment`,
    Metadata, a :class:`_ChunkEntry` after each chunk's records, and DataEnd
    (its checksum verified) last. A file cut short ends quietly after its last
    complete record; damage (a checksum that does not match, a malformed
    record, or anything cut short in a complete file) raises. The summary
    after the data section is not read here (:func:`_read_summary`).
    Messages inside chunks on channels not in ``wanted_ids`` (a set the caller
    may fill as channels appear; None: all), or outside ``window`` (log times,
    ns, both ends included), are skipped without a copy; ``tally``, if given,
    counts every message record and its time.
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
            yield opcode, end
            return
        crc = zlib.crc32(body, zlib.crc32(head, crc))
        if opcode == Opcode.CHUNK:
            chunks += 1
            data, chunk = _chunk_records(path, body, offset, chunks)
            if stats is not None:
                stats.chunks += 1
            entry = _ChunkEntry(chunks, offset, length, chunk.message_start_time, chunk.message_end_time)
            found = yield from _inner_records(path, data, offset, wanted_ids,
                                              tally.counts if tally is not None else None, window)
            if tally is not None:
                tally.span(*found)
            _check_span(path, entry, found)
            yield opcode, entry
        elif opcode == Opcode.ATTACHMENT:
            yield opcode, _attachment(path, body, offset)
        elif opcode == Opcode.FOOTER:
            return
        else:
            record = _parse(path, opcode, body, offset)
            if opcode == Opcode.MESSAGE and tally is not None:
                tally.counts[record.channel_id] = tally.counts.get(record.channel_id, 0) + 1
                tally.span(1, record.log_time, record.log_time)
            if record is not None and not (opcode == Opcode.MESSAGE and window is not None
                                           and not window[0] <= record.log_time <= window[1]):
                yield opcode, record
        offset += _RECORD_HEAD.size + length


def _inner_records(path: Path, data: bytes, chunk_offset: int, wanted_ids: set[int] | None = None,
                   counts: dict[int, int] | None = None, window: tuple[int, int] | None = None
                   ) -> Generator[tuple[int, Any], None, tuple[int, int, int]]:
    """The records of a decompressed chunk (schemas, channels, messages; see :func:`_records`).

    Returns (as a generator's value) the number of messages and their first and last log time.
    """
    view = memoryview(data)
    position, end = 0, len(data)
    head = _RECORD_HEAD
    unpack_message = _MESSAGE_HEAD.unpack_from
    message = Opcode.MESSAGE
    lo, hi = window if window is not None else (0, _MAX_NS)
    count, first, last = 0, _MAX_NS, 0
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
            channel_id, _, log_time, _ = unpack_message(data, body_start)
            count += 1
            if log_time < first:
                first = log_time
            if log_time > last:
                last = log_time
            if counts is not None:
                counts[channel_id] = counts.get(channel_id, 0) + 1
            if lo <= log_time <= hi and (wanted_ids is None or channel_id in wanted_ids):
                yield opcode, _Message(channel_id, log_time, bytes(view[body_start + _MESSAGE_HEAD.size:
                                                                      body_start + length]))
        else:
            record = _parse(path, opcode, bytes(view[body_start:body_start + length]), chunk_offset)
            if record is not None:
                yield opcode, record
        position = body_start + length
    return count, first, last


# --------------------------------------------------------------------------- the summary of a finished log


@dataclass
class _Summary:
    """The summary section of a finished log (its checksum verified), and where its data section ends."""

    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    statistics: Statistics
    chunks: list[_ChunkEntry]  # in file order
    attachments: list[AttachmentIndex]
    metadata: list[MetadataIndex]
    data_end: int  # offset of the DataEnd record: the data section is the file's bytes before it
    data_crc: int  # the data section's checksum (0: none written)


_SUMMARY_RECORDS: dict[int, Any] = {Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.STATISTICS: Statistics,
                                    Opcode.ATTACHMENT_INDEX: AttachmentIndex, Opcode.METADATA_INDEX: MetadataIndex}
_CHUNK_INDEX_HEAD = struct.Struct("<QQQQI")  # message start and end time, chunk offset and length, map length
_CHUNK_INDEX_ENTRY = struct.Struct("<HQ")  # channel id, offset of its message index
_U32, _U64 = struct.Struct("<I"), struct.Struct("<Q")


def _chunk_index(data: bytes, position: int, length: int, shared: dict[frozenset[int], frozenset[int]]
                 ) -> tuple[int, int, int, int, frozenset[int]]:
    """A chunk index record's (start, end, chunk offset, chunk length, channel ids); equal sets of channel
    ids are one object, kept in ``shared``.

    Parsed with ``struct`` rather than mcap's record reader, which costs 50 us a record: a day-long log's
    summary has 17 000 of them, read by every window and overview.

    Raises:
        ValueError: the record is malformed (its fields do not fill it exactly).
    """
    end = position + length
    start_time, end_time, offset, chunk_length, map_length = _CHUNK_INDEX_HEAD.unpack_from(data, position)
    position += _CHUNK_INDEX_HEAD.size
    if map_length % _CHUNK_INDEX_ENTRY.size or position + map_length > end:
        raise ValueError("a message index map that does not fit")
    ids = frozenset(cid for cid, _ in _CHUNK_INDEX_ENTRY.iter_unpack(data[position:position + map_length]))
    ids = shared.setdefault(ids, ids)
    position += map_length + _U64.size  # the message indexes' length
    (compression_length,) = _U32.unpack_from(data, position)
    position += _U32.size + compression_length + 2 * _U64.size  # compression, compressed and uncompressed size
    if position != end:
        raise ValueError("fields that do not fill the record")
    return start_time, end_time, offset, chunk_length, ids


def _read_summary(path: Path, fh: IO[bytes]) -> _Summary | None:
    """The summary of a complete log, or None when it has none the fast readers can use (they then walk the
    file): no summary, no statistics or chunk index, or not the usual layout.

    Raises:
        LogError: the footer or the summary is damaged (its checksum, a malformed record, an index that
            points outside the data section), or larger than :data:`cosim.core.limits.MAX_RECORD_BYTES`.
    """
    fh.seek(0, os.SEEK_END)
    size = fh.tell()
    footer_at = size - len(MAGIC) - _FOOTER.size
    if footer_at < len(MAGIC):
        return None
    fh.seek(footer_at)
    footer = fh.read(_FOOTER.size)
    opcode, length, start, offsets_start, crc = _FOOTER.unpack(footer)
    if opcode != Opcode.FOOTER or length != _FOOTER.size - _RECORD_HEAD.size:
        raise _corrupt(path, f"the footer (offset {footer_at}) is malformed")
    if start == 0:
        return None
    if not (len(MAGIC) + _DATA_END.size <= start <= footer_at) or not (offsets_start == 0
                                                                       or start <= offsets_start <= footer_at):
        raise _corrupt(path, f"the footer (offset {footer_at}) points outside the file")
    MAX_RECORD_BYTES.check(footer_at - start, f"{path}: the summary section (offset {start})")
    fh.seek(start)
    data = fh.read(footer_at - start)
    if crc != 0 and zlib.crc32(footer[:-4], zlib.crc32(data)) != crc:
        raise _corrupt(path, "the checksum of the summary does not match: it was changed after it was written")
    fh.seek(start - _DATA_END.size)
    end_opcode, end_length, data_crc = _DATA_END.unpack(fh.read(_DATA_END.size))
    if end_opcode != Opcode.DATA_END or end_length != 4:
        return None  # a data section that does not end where the summary starts: walk it
    data_end = start - _DATA_END.size
    found: dict[int, list[Any]] = {}
    channel_sets: dict[frozenset[int], frozenset[int]] = {}
    position = 0
    while position < len(data):
        if position + _RECORD_HEAD.size > len(data):
            raise _corrupt(path, f"the summary (offset {start}) ends inside a record")
        opcode, length = _RECORD_HEAD.unpack_from(data, position)
        body = position + _RECORD_HEAD.size
        if length > len(data) - body:
            raise _corrupt(path, f"a record of the summary at offset {start + position} runs past its end")
        reader = _SUMMARY_RECORDS.get(opcode)
        if opcode == Opcode.CHUNK_INDEX:
            try:
                found.setdefault(opcode, []).append(_chunk_index(data, body, length, channel_sets))
            except (ValueError, struct.error):
                raise _corrupt(path, f"a malformed ChunkIndex record in the summary (offset {start + position})"
                               ) from None
        elif reader is not None:
            stream = ReadDataStream(io.BytesIO(data[body:body + length]))
            try:
                record = reader.read(stream)
                if stream.count != length:
                    raise ValueError("the record's fields do not fill it")
            except Exception:  # noqa: BLE001 - any parse failure of a whole record is damage
                raise _corrupt(path, f"a malformed {reader.__name__} record in the summary "
                                     f"(offset {start + position})") from None
            found.setdefault(opcode, []).append(record)
        position = body + length
    statistics = found.get(Opcode.STATISTICS, [])
    indexes = sorted(found.get(Opcode.CHUNK_INDEX, []), key=lambda c: c[2])
    channels = {c.id: c for c in found.get(Opcode.CHANNEL, [])}
    if len(statistics) != 1 or statistics[0].chunk_count != len(indexes) \
            or any(n and cid not in channels for cid, n in statistics[0].channel_message_counts.items()):
        return None  # written without statistics, a chunk index or the channels
    chunks = []
    for number, (start_time, end_time, offset, chunk_length, ids) in enumerate(indexes, start=1):
        if not (len(MAGIC) <= offset and offset + chunk_length <= data_end
                and chunk_length >= _RECORD_HEAD.size + _CHUNK_TIMES.size and start_time <= end_time):
            raise _corrupt(path, f"the summary's index of chunk {number} points outside the data section "
                                 f"(offset {offset}, {chunk_length} bytes)")
        chunks.append(_ChunkEntry(number, offset, chunk_length - _RECORD_HEAD.size, start_time, end_time, ids))
    for index in [*found.get(Opcode.ATTACHMENT_INDEX, []), *found.get(Opcode.METADATA_INDEX, [])]:
        if not (len(MAGIC) <= index.offset and index.offset + index.length <= data_end):
            raise _corrupt(path, f"the summary's index of {index.name!r} points outside the data section")
    return _Summary(schemas={s.id: s for s in found.get(Opcode.SCHEMA, [])}, channels=channels,
                    statistics=statistics[0],
                    chunks=chunks, attachments=found.get(Opcode.ATTACHMENT_INDEX, []),
                    metadata=found.get(Opcode.METADATA_INDEX, []), data_end=data_end, data_crc=data_crc)


def _record_at(path: Path, fh: IO[bytes], offset: int, opcode: int, length: int, what: str) -> bytes:
    """The body of the record at ``offset`` that an index points to: it must be an ``opcode`` record of
    ``length`` bytes with its head (the caller checked ``length`` against its limit)."""
    fh.seek(0, os.SEEK_END)
    size = fh.tell()
    fh.seek(offset)
    head = fh.read(_RECORD_HEAD.size)
    found, body_length = _RECORD_HEAD.unpack(head) if len(head) == _RECORD_HEAD.size else (None, 0)
    if found != opcode or body_length + _RECORD_HEAD.size != length or body_length > size - offset - _RECORD_HEAD.size:
        raise _corrupt(path, f"the summary's index points to {what} at offset {offset}, where there is none")
    return fh.read(body_length)


def _read_chunk(path: Path, fh: IO[bytes], entry: _ChunkEntry, stats: ReadStats | None) -> bytes:
    """A chunk the summary's index points to: read, decompressed and checked (checksum, time range)."""
    MAX_CHUNK_BYTES.check(entry.length, f"{path}: the chunk at offset {entry.offset}", "its compressed size")
    body = _record_at(path, fh, entry.offset, Opcode.CHUNK, entry.length + _RECORD_HEAD.size,
                      f"chunk {entry.number}")
    data, chunk = _chunk_records(path, body, entry.offset, entry.number)
    if (chunk.message_start_time, chunk.message_end_time) != (entry.start, entry.end):
        where = _chunk_where(entry.number, entry.offset, chunk.message_start_time, chunk.message_end_time)
        raise _corrupt(path, f"{where} is not what the summary's index says (t = {entry.start / 1e9:g} to "
                             f"{entry.end / 1e9:g} s)")
    if stats is not None:
        stats.chunks += 1
    return data


def _header(path: Path, fh: IO[bytes]) -> Header:
    """The header record, which must open a cosim log (its profile checked)."""
    fh.seek(len(MAGIC))
    head = fh.read(_RECORD_HEAD.size)
    opcode, length = _RECORD_HEAD.unpack(head) if len(head) == _RECORD_HEAD.size else (None, 0)
    if opcode != Opcode.HEADER:
        _check_profile(path, None)
    MAX_RECORD_BYTES.check(length, f"{path}: the record at offset {len(MAGIC)} (opcode {Opcode.HEADER:#04x})")
    header = _parse(path, Opcode.HEADER, fh.read(length), len(MAGIC))
    _check_profile(path, header.profile)
    return header


def _indexed_records(path: Path, fh: IO[bytes], summary: _Summary, wanted_ids: set[int] | None,
                     window: tuple[int, int], stats: ReadStats | None) -> Iterator[tuple[int, Any]]:
    """The records a window needs, found through the summary: the header, the schemas and channels, and the
    records of the chunks whose time range overlaps ``window`` and that hold a wanted channel (see
    :func:`_records`; no attachments, metadata or DataEnd)."""
    yield Opcode.HEADER, _header(path, fh)
    for schema in summary.schemas.values():
        yield Opcode.SCHEMA, schema
    for channel in summary.channels.values():
        yield Opcode.CHANNEL, channel  # the caller fills ``wanted_ids`` from these
    lo, hi = window
    for entry in summary.chunks:
        if entry.end < lo or entry.start > hi:
            continue
        if wanted_ids is not None and entry.channels and entry.channels.isdisjoint(wanted_ids):
            continue
        data = _read_chunk(path, fh, entry, stats)
        found = yield from _inner_records(path, data, entry.offset, wanted_ids, None, window)
        _check_span(path, entry, found)
        yield Opcode.CHUNK, entry
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


class _Tally:
    """Messages counted per channel, and the first and last log time among them (ns)."""

    def __init__(self) -> None:
        self.counts: dict[int, int] = {}
        self.first = _MAX_NS
        self.last = -1

    def span(self, count: int, first: int, last: int) -> None:
        if count:
            self.first = min(self.first, first)
            self.last = max(self.last, last)


#: What the record walk yields for the other records it passes on, by opcode.
_RECORD_KINDS: dict[int, str] = {Opcode.CHUNK: "chunk", Opcode.HEADER: "header", Opcode.SCHEMA: "schema",
                                  Opcode.ATTACHMENT: "attachment", Opcode.METADATA: "metadata",
                                  Opcode.DATA_END: "data_end"}


def _walk(path: Path, fh: IO[bytes], complete: bool, wanted: set[str] | None, tally: _Tally | None = None,
          window: tuple[int, int] | None = None, summary: _Summary | None = None, stats: ReadStats | None = None
          ) -> Iterator[tuple[str, Any]]:
    """The events of a log in file order (the one walker behind every reader):

    ``("header", Header)`` first (the profile checked), ``("schema", Schema)``,
    ``("channel", Channel)``, ``("attachment", _Attachment)``, ``("metadata",
    Metadata)``, ``("message", (channel, _Message))`` for messages on ``wanted``
    topics (all if None; undecoded) within ``window`` (log times, ns, both
    ends included; None: all), ``("chunk", _ChunkEntry)`` after each chunk's
    messages, ``("data_end", DataEnd)``, and ``("end", complete)`` last.

    With a ``window`` and the log's ``summary``, only the chunks that overlap
    the window are read (no attachments, metadata or data-section checksum:
    :func:`_indexed_records`); otherwise every record is (:func:`_records`).
    """
    channels: dict[int, Channel] = {}
    wanted_ids: set[int] = set()
    ids = None if wanted is None else wanted_ids
    if summary is not None and window is not None:
        records = _indexed_records(path, fh, summary, ids, window, stats)
    else:
        records = _records(path, fh, complete, ids, tally, window, stats)
    first = True
    for opcode, record in records:
        if first:
            _check_profile(path, record.profile if opcode == Opcode.HEADER else None)
            first = False
        if opcode == Opcode.MESSAGE:
            if record.channel_id in wanted_ids:
                yield "message", (channels[record.channel_id], record)
        elif opcode == Opcode.CHANNEL:
            channels[record.id] = record
            if wanted is None or record.topic in wanted:
                wanted_ids.add(record.id)
            else:
                wanted_ids.discard(record.id)
            yield "channel", record
        elif opcode in _RECORD_KINDS:
            yield _RECORD_KINDS[opcode], record
    if first:
        _check_profile(path, None)
    yield "end", complete


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
    with _open(path) as fh:
        complete = _ends_with_magic(fh)
        fh.seek(0, os.SEEK_END)
        out = LogOverview(path=path, complete=complete, size=fh.tell())
        summary = _read_summary(path, fh) if complete else None
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


def _overview_from_walk(path: Path, fh: IO[bytes], summary: _Summary | None, out: LogOverview,
                        stats: ReadStats | None) -> bytes | None:
    """Fill ``out`` from every record of the file (and check the summary, if any, against the chunks);
    returns the sensor topic's schema."""
    schemas: dict[int, bytes] = {}
    sensor_schema: bytes | None = None
    topics: dict[int, str] = {}
    tally = _Tally()
    chunks: list[_ChunkEntry] = []
    last_status: tuple[int, Channel, bytes] | None = None
    for kind, item in _walk(path, fh, out.complete, {TOPIC_STATUS}, tally=tally, stats=stats):
        if kind == "message":  # a status message: the only ones decoded
            channel, message = item
            if last_status is None or message.log_time >= last_status[0]:
                last_status = (message.log_time, channel, message.data)
        elif kind == "chunk":
            chunks.append(item)
        elif kind == "channel":
            topics[item.id] = item.topic
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
        elif kind == "data_end":
            out.data_checksum = item.data_section_crc != 0
    for cid, count in tally.counts.items():
        if cid in topics:
            out.counts[topics[cid]] = out.counts.get(topics[cid], 0) + count
    if tally.last >= 0:
        out.start_time, out.end_time = tally.first / 1e9, tally.last / 1e9
    if last_status is not None:
        out.final_status = _decode(path, last_status[1], last_status[2])
    out.check, out.chunks, out.chunks_read = "full", len(chunks), len(chunks)
    if summary is not None:
        _compare_summary(path, summary, chunks, tally)
        out.summary_checked = True
    return sensor_schema


def _compare_summary(path: Path, summary: _Summary, chunks: list[_ChunkEntry], tally: _Tally) -> None:
    """The summary (what windows and the overview trust) must say what the chunks hold."""
    indexed = [(e.offset, e.length, e.start, e.end) for e in summary.chunks]
    walked = [(e.offset, e.length, e.start, e.end) for e in chunks]
    if indexed != walked:
        at = next((i for i, (a, b) in enumerate(zip(indexed, walked)) if a != b), min(len(indexed), len(walked)))
        raise _corrupt(path, f"the summary's chunk index does not match the chunks (it lists {len(indexed)}, the "
                             f"file holds {len(walked)}; they differ from chunk {at + 1} on)")
    stats = summary.statistics
    claimed = {cid: n for cid, n in stats.channel_message_counts.items() if n}
    if claimed != {cid: n for cid, n in tally.counts.items() if n}:
        topic = next((summary.channels[c].topic if c in summary.channels else f"channel {c}"
                      for c in sorted(set(claimed) | set(tally.counts))
                      if claimed.get(c, 0) != tally.counts.get(c, 0)), "?")
        raise _corrupt(path, f"the summary's message counts do not match the chunks (on {topic})")
    if stats.message_count and (stats.message_start_time, stats.message_end_time) != (tally.first, tally.last):
        raise _corrupt(path, "the summary's time range does not match the messages")


def _overview_from_summary(path: Path, fh: IO[bytes], summary: _Summary, out: LogOverview, check: str,
                           stats: ReadStats | None) -> bytes | None:
    """Fill ``out`` from a finished log's summary and what it points to; returns the sensor topic's schema."""
    out.library = _header(path, fh).library
    for index in summary.metadata:
        MAX_RECORD_BYTES.check(index.length, f"{path}: the record at offset {index.offset} "
                                             f"(opcode {Opcode.METADATA:#04x})")
        body = _record_at(path, fh, index.offset, Opcode.METADATA, index.length, f"metadata {index.name!r}")
        record = _parse(path, Opcode.METADATA, body, index.offset)
        out.metadata[record.name] = dict(record.metadata)
    attachment_bytes = 0
    for where in summary.attachments:
        attachment_bytes += where.length - _RECORD_HEAD.size
        MAX_ATTACHMENT_BYTES.check(attachment_bytes - _ATTACHMENT_OVERHEAD, f"{path}: the attachments",
                                   f"up to the record at offset {where.offset}")
        body = _record_at(path, fh, where.offset, Opcode.ATTACHMENT, where.length, f"attachment {where.name!r}")
        attachment = _attachment(path, body, where.offset)
        out.attachments[attachment.name] = attachment.data
    statistics = summary.statistics
    for cid, count in statistics.channel_message_counts.items():
        if count:  # every counted channel is defined (_read_summary)
            topic = summary.channels[cid].topic
            out.counts[topic] = out.counts.get(topic, 0) + count
    if statistics.message_count:
        out.start_time, out.end_time = statistics.message_start_time / 1e9, statistics.message_end_time / 1e9
    before = stats.chunks if stats is not None else 0
    counter = stats if stats is not None else ReadStats()
    out.final_status = _last_status(path, fh, summary, counter)
    out.check, out.chunks, out.chunks_read = check, len(summary.chunks), counter.chunks - before
    out.summary_checked = True
    if check == "file":
        if summary.data_crc != 0:
            _check_data_section(path, fh, summary.data_end, summary.data_crc)
        out.data_checksum = summary.data_crc != 0
    channel = next((c for c in summary.channels.values() if c.topic == TOPIC_SENSORS), None)
    schema = summary.schemas.get(channel.schema_id) if channel is not None else None
    return schema.data if schema is not None else None


def _last_status(path: Path, fh: IO[bytes], summary: _Summary, stats: ReadStats) -> dict | None:
    """The last status message (the latest log time, the last in file order among equals), read from the
    last chunk(s) that hold status messages, as the summary's chunk index says."""
    ids = {cid for cid, channel in summary.channels.items() if channel.topic == TOPIC_STATUS}
    if not ids:
        return None
    known = any(entry.channels for entry in summary.chunks)  # an index that says which channels a chunk holds
    candidates = sorted((e for e in summary.chunks if not known or not e.channels.isdisjoint(ids)),
                        key=lambda e: (e.end, e.offset), reverse=True)
    best: tuple[int, int, int] | None = None  # log time, chunk offset, position in the chunk
    found: _Message | None = None
    for entry in candidates:
        if best is not None and (entry.end, entry.offset) < best[:2]:
            break  # no status message in this chunk or the ones after it can come later
        data = _read_chunk(path, fh, entry, stats)
        records = _inner_records(path, data, entry.offset, ids)
        position = 0
        while True:
            try:
                _, message = next(records)
            except StopIteration as done:
                _check_span(path, entry, done.value)
                break
            if isinstance(message, _Message):
                position += 1
                key = (message.log_time, entry.offset, position)
                if best is None or key >= best:
                    best, found = key, message
    if found is None:
        return None
    return _decode(path, summary.channels[found.channel_id], found.data)


def _check_data_section(path: Path, fh: IO[bytes], data_end: int, expected: int) -> None:
    """Every byte before DataEnd against the data section's checksum, read in blocks (constant memory)."""
    fh.seek(0)
    crc = 0
    buffer = memoryview(bytearray(_CRC_BLOCK))
    remaining = data_end
    while remaining:
        n = fh.readinto(buffer[:min(_CRC_BLOCK, remaining)])  # type: ignore[attr-defined]
        if not n:
            raise _corrupt(path, "the file ends before its data section does")
        crc = zlib.crc32(buffer[:n], crc)
        remaining -= n
    if crc != expected:
        raise _corrupt(path, "the checksum of the data section does not match: the file was changed "
                             "after it was written")


# --------------------------------------------------------------------------- windows of time


def _window_ns(start: float | None, end: float | None) -> tuple[int, int] | None:
    """A window of simulated time (s; None: open on that side) as log times (ns, both ends included)."""
    if start is None and end is None:
        return None
    for name, value in (("start", start), ("end", end)):
        if value is not None and not math.isfinite(value):
            raise CosimError(f"`{name}` of the time window: expected a finite time in s, got {value!r}")
    lo = 0 if start is None else max(_log_time(start), 0)
    hi = _MAX_NS if end is None else _log_time(end)
    return lo, hi


def _log_time(t: float) -> int:
    """A finite time in s as a log time (ns, as :func:`cosim.log.schemas.to_ns`), clamped to what log times
    can be (and one below: nothing lies before a negative end)."""
    ns = t * 1e9
    if ns >= _MAX_NS:
        return _MAX_NS
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
    with _open(path) as fh:
        complete = _ends_with_magic(fh)
        summary = _read_summary(path, fh) if complete and window is not None else None
        for kind, item in _walk(path, fh, complete, wanted, window=window, summary=summary, stats=stats):
            if kind == "message":
                channel, message = item
                if stats is not None:
                    stats.messages += 1
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
