"""The records of an MCAP file, read within bounds: the parser under :mod:`cosim.log.reader`.

A log is untrusted input: people send logs to each other. So this module

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
  header (and the summary's index) claims, so that a window can skip chunks.

A finished log ends with a *summary*: the channels, the message counts and an
index of its chunks (offset and time range of each). Readers that need only
part of the log (a window of time, the overview) follow that index instead of
reading every chunk (:func:`read_summary`, :func:`indexed_metadata`,
:func:`indexed_attachments`, :func:`last_message`); :func:`compare_summary`
checks that the summary agrees with the chunks a full read found.

One truncation rule for all of them: a log is *complete* when it ends with the
MCAP magic (it was finished: summary, index, footer). A complete log must be
intact: any damage (a checksum that does not match, a malformed record) is a
:class:`cosim.errors.LogError`. A log cut short (the process was killed) has
no summary: it is read record by record up to its last complete record; a
checksum that does not match is damage there too.

:func:`walk` is the one walker behind every reader, and the one place that
says what becomes of each kind of record. Records are parsed, never evaluated
or unpickled; the messages' contents are left to :mod:`cosim.log.reader`.
"""
from __future__ import annotations

import io
import os
import struct
import zlib
from collections.abc import Generator, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

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
from cosim.errors import LogError

from .schemas import MAGIC, PROFILE

# --------------------------------------------------------------------------- files and records

_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length of the record's body
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_CHUNK_TIMES = struct.Struct("<QQ")  # a chunk record's first fields: message start and end time
_FOOTER = struct.Struct("<BQQQI")  # opcode, length (20), summary start, summary offset start, summary crc
_DATA_END = struct.Struct("<BQI")  # opcode, length (4), data section crc
_ATTACHMENT_OVERHEAD = 1 << 16  # name, media type, times and checksum around an attachment's data
MAX_NS = (1 << 64) - 1  # log times are unsigned 64-bit nanoseconds
_CRC_BLOCK = 1 << 22  # bytes per read when the data section's checksum is computed


@dataclass
class ReadStats:
    """What a read cost, counted as it goes (as scipy's ``OdeSolver`` counts ``nfev``): pass one to
    :func:`cosim.log.reader.open_log`, :func:`cosim.log.reader.iter_messages` and the functions built on
    them, then look.

    Attributes:
        chunks: chunks decompressed (each one's checksum verified).
        messages: messages decoded (JSON parsed and checked against their topic's schema).
    """

    chunks: int = 0
    messages: int = 0


@dataclass(frozen=True, slots=True)  # slots: a day-long log's index holds 17 000 of them
class ChunkEntry:
    """Where a chunk is and what it holds: from the summary's chunk index, or from the chunk itself."""

    number: int  # 1-based, in file order (the number errors name)
    offset: int  # of the chunk record
    length: int  # of its body
    start: int  # log time of its first and last message, ns
    end: int
    channels: frozenset[int] = frozenset()  # channels with messages in it (empty: not known)


def open_file(path: Path) -> IO[bytes]:
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


def ends_with_magic(fh: IO[bytes]) -> bool:
    """The truncation rule: a finished MCAP file ends with its magic (leaves ``fh`` at the start)."""
    fh.seek(0, os.SEEK_END)
    complete = fh.tell() >= 16
    if complete:
        fh.seek(-8, os.SEEK_END)
        complete = fh.read(8) == MAGIC
    fh.seek(0)
    return complete


def _corrupt(path: Path, what: str) -> LogError:
    return LogError(f"{path}: corrupt MCAP file: {what}")


@dataclass(frozen=True)
class Message:
    """A message record: its channel, log time (ns) and undecoded data."""

    channel_id: int
    log_time: int
    data: bytes


@dataclass(frozen=True)
class Attachment:
    name: str
    media_type: str
    data: bytes


def _parse(path: Path, opcode: int, body: bytes, offset: int) -> Any:
    """The record of ``opcode`` in ``body`` (None for records the reader does not need)."""
    if opcode == Opcode.MESSAGE:
        if len(body) < _MESSAGE_HEAD.size:
            raise _corrupt(path, f"a message record at offset {offset} is too short")
        channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(body)
        return Message(channel_id, log_time, body[_MESSAGE_HEAD.size:])
    readers: dict[int, Any] = {Opcode.HEADER: Header, Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel,
                               Opcode.METADATA: Metadata, Opcode.DATA_END: DataEnd}
    reader = readers.get(opcode)
    if reader is None:
        return None
    try:
        return reader.read(ReadDataStream(io.BytesIO(body)))
    except Exception:  # noqa: BLE001 - any parse failure of a whole record is damage
        raise _corrupt(path, f"a malformed {reader.__name__} record at offset {offset}") from None


def _attachment(path: Path, body: bytes, offset: int) -> Attachment:
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
    return Attachment(name, media_type, body[start:start + length])


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


def _check_span(path: Path, entry: ChunkEntry, found: tuple[int, int, int]) -> None:
    """The messages of a chunk span exactly the time range its header claims (what windows rely on)."""
    count, first, last = found
    if count and (first, last) != (entry.start, entry.end):
        raise _corrupt(path, f"{_chunk_where(entry.number, entry.offset, entry.start, entry.end)} holds messages "
                             f"at t = {first / 1e9:g} to {last / 1e9:g} s")


class Tally:
    """Messages counted per channel, and the first and last log time among them (ns)."""

    def __init__(self) -> None:
        self.counts: dict[int, int] = {}
        self.first = MAX_NS
        self.last = -1

    def span(self, count: int, first: int, last: int) -> None:
        if count:
            self.first = min(self.first, first)
            self.last = max(self.last, last)


def _records(path: Path, fh: IO[bytes], complete: bool, wanted_ids: set[int] | None = None,
             tally: Tally | None = None, window: tuple[int, int] | None = None,
             stats: ReadStats | None = None) -> Iterator[tuple[int, Any]]:
    """(opcode, record) of every record the reader needs, in file order, chunks opened (the file's records).

    Records: Header, Schema, Channel, :class:`Message`, :class:`Attachment`,
    Metadata, a :class:`ChunkEntry` after each chunk's records, and DataEnd
    (its checksum verified) last. A file cut short ends quietly after its last
    complete record; damage (a checksum that does not match, a malformed
    record, or anything cut short in a complete file) raises. The summary
    after the data section is not read here (:func:`read_summary`).
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
            entry = ChunkEntry(chunks, offset, length, chunk.message_start_time, chunk.message_end_time)
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
    lo, hi = window if window is not None else (0, MAX_NS)
    count, first, last = 0, MAX_NS, 0
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
                yield opcode, Message(channel_id, log_time, bytes(view[body_start + _MESSAGE_HEAD.size:
                                                                     body_start + length]))
        else:
            record = _parse(path, opcode, bytes(view[body_start:body_start + length]), chunk_offset)
            if record is not None:
                yield opcode, record
        position = body_start + length
    return count, first, last


# --------------------------------------------------------------------------- the summary of a finished log


@dataclass
class Summary:
    """The summary section of a finished log (its checksum verified), and where its data section ends."""

    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    statistics: Statistics
    chunks: list[ChunkEntry]  # in file order
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


def read_summary(path: Path, fh: IO[bytes]) -> Summary | None:
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
        chunks.append(ChunkEntry(number, offset, chunk_length - _RECORD_HEAD.size, start_time, end_time, ids))
    for index in [*found.get(Opcode.ATTACHMENT_INDEX, []), *found.get(Opcode.METADATA_INDEX, [])]:
        if not (len(MAGIC) <= index.offset and index.offset + index.length <= data_end):
            raise _corrupt(path, f"the summary's index of {index.name!r} points outside the data section")
    return Summary(schemas={s.id: s for s in found.get(Opcode.SCHEMA, [])}, channels=channels,
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


def _read_chunk(path: Path, fh: IO[bytes], entry: ChunkEntry, stats: ReadStats | None) -> bytes:
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


def _check_profile(path: Path, profile: str | None) -> None:
    if profile is None:
        raise LogError(f"{path}: an MCAP file whose header cannot be read")
    if profile != PROFILE:
        raise LogError(f"{path}: an MCAP file, but not a cosim log (profile {profile!r})")


def read_header(path: Path, fh: IO[bytes]) -> Header:
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


def _indexed_records(path: Path, fh: IO[bytes], summary: Summary, wanted_ids: set[int] | None,
                     window: tuple[int, int], stats: ReadStats | None) -> Iterator[tuple[int, Any]]:
    """The records a window needs, found through the summary: the header, the schemas and channels, and the
    records of the chunks whose time range overlaps ``window`` and that hold a wanted channel (see
    :func:`_records`; no attachments, metadata or DataEnd)."""
    yield Opcode.HEADER, read_header(path, fh)
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


def indexed_metadata(path: Path, fh: IO[bytes], summary: Summary) -> Iterator[Metadata]:
    """The metadata records the summary's index points to, in its order."""
    for index in summary.metadata:
        MAX_RECORD_BYTES.check(index.length, f"{path}: the record at offset {index.offset} "
                                             f"(opcode {Opcode.METADATA:#04x})")
        body = _record_at(path, fh, index.offset, Opcode.METADATA, index.length, f"metadata {index.name!r}")
        yield _parse(path, Opcode.METADATA, body, index.offset)


def indexed_attachments(path: Path, fh: IO[bytes], summary: Summary) -> Iterator[Attachment]:
    """The attachments the summary's index points to, in its order, their checksums verified (together
    within :data:`cosim.core.limits.MAX_ATTACHMENT_BYTES`)."""
    attachment_bytes = 0
    for where in summary.attachments:
        attachment_bytes += where.length - _RECORD_HEAD.size
        MAX_ATTACHMENT_BYTES.check(attachment_bytes - _ATTACHMENT_OVERHEAD, f"{path}: the attachments",
                                   f"up to the record at offset {where.offset}")
        body = _record_at(path, fh, where.offset, Opcode.ATTACHMENT, where.length, f"attachment {where.name!r}")
        yield _attachment(path, body, where.offset)


def last_message(path: Path, fh: IO[bytes], summary: Summary, ids: set[int], stats: ReadStats) -> Message | None:
    """The last message on the channels ``ids`` (the latest log time, the last in file order among equals),
    read from the last chunk(s) that hold such messages, as the summary's chunk index says."""
    known = any(entry.channels for entry in summary.chunks)  # an index that says which channels a chunk holds
    candidates = sorted((e for e in summary.chunks if not known or not e.channels.isdisjoint(ids)),
                        key=lambda e: (e.end, e.offset), reverse=True)
    best: tuple[int, int, int] | None = None  # log time, chunk offset, position in the chunk
    found: Message | None = None
    for entry in candidates:
        if best is not None and (entry.end, entry.offset) < best[:2]:
            break  # no such message in this chunk or the ones after it can come later
        data = _read_chunk(path, fh, entry, stats)
        records = _inner_records(path, data, entry.offset, ids)
        position = 0
        while True:
            try:
                _, message = next(records)
            except StopIteration as done:
                _check_span(path, entry, done.value)
                break
            if isinstance(message, Message):
                position += 1
                key = (message.log_time, entry.offset, position)
                if best is None or key >= best:
                    best, found = key, message
    return found


def compare_summary(path: Path, summary: Summary, chunks: list[ChunkEntry], tally: Tally) -> None:
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


def check_data_section(path: Path, fh: IO[bytes], data_end: int, expected: int) -> None:
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


# --------------------------------------------------------------------------- the walk


@dataclass
class LogRecords:
    """The records of a log other than its messages, as :func:`walk` meets them (filled as it goes)."""

    header: Header | None = None
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)  # name -> data
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)  # name -> {key: value}
    chunks: list[ChunkEntry] = field(default_factory=list)  # in file order
    data_crc: int | None = None  # the DataEnd record's data-section checksum (0: none written; None: not read)


def walk(path: Path, fh: IO[bytes], complete: bool, wanted: set[str] | None, found: LogRecords | None = None,
         tally: Tally | None = None, window: tuple[int, int] | None = None, summary: Summary | None = None,
         stats: ReadStats | None = None, schemas: dict[int, Schema] | None = None) -> Iterator[tuple[Channel, Message]]:
    """The messages of a log on ``wanted`` topics (all if None; undecoded) within ``window`` (log times, ns,
    both ends included; None: all), with their channels, in file order: the one walker behind every reader,
    and the one dispatch over the kinds of record.

    The header must open a cosim log (its profile is checked). Every other
    record the walk meets goes into ``found``, if given (:class:`LogRecords`:
    without it only the channels are kept, so that a stream of messages costs
    constant memory). With a ``window`` and the log's ``summary``, only the
    chunks that overlap the window are read (no attachments, metadata or
    data-section checksum: :func:`_indexed_records`); otherwise every record
    is (:func:`_records`), and ``tally``, if given, counts every message. ``schemas``, if given, gets every
    schema record (``found``'s, if given), as channels come with theirs: the messages' decoders need them.
    """
    channels: dict[int, Channel] = found.channels if found is not None else {}
    if schemas is None and found is not None:
        schemas = found.schemas
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
                yield channels[record.channel_id], record
        elif opcode == Opcode.CHANNEL:
            channels[record.id] = record
            if wanted is None or record.topic in wanted:
                wanted_ids.add(record.id)
            else:
                wanted_ids.discard(record.id)
        elif opcode == Opcode.SCHEMA and schemas is not None:
            schemas[record.id] = record
        elif found is None:
            continue
        elif opcode == Opcode.CHUNK:
            found.chunks.append(record)
        elif opcode == Opcode.ATTACHMENT:
            found.attachments[record.name] = record.data
        elif opcode == Opcode.METADATA:
            found.metadata[record.name] = dict(record.metadata)
        elif opcode == Opcode.HEADER:
            found.header = record
        elif opcode == Opcode.DATA_END:
            found.data_crc = record.data_section_crc
    if first:
        _check_profile(path, None)
