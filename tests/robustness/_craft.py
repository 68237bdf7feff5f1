"""Crafting hostile logs from real ones: the records of a real log written again with some changed.

Uses the ``mcap`` package's own reader and writer (an independent
implementation of the format), so the crafted files are valid MCAP whose
contents lie, which is what a hostile log looks like.
"""
from __future__ import annotations

import json
import struct
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

MAGIC = b"\x89MCAP0\r\n"


def rewrite(source: Path, target: Path, *, attachments: dict[str, bytes | None] | None = None,
            metadata: dict[str, dict[str, str]] | None = None,
            message: Callable[[str, dict[str, Any]], dict[str, Any] | None] | None = None,
            raw: Callable[[Any, str, bytes], bytes | None] | None = None,
            profile: str = "cosim") -> Path:
    """``source`` written again as ``target``: attachments replaced (None: dropped) or added, metadata
    records updated key by key, and each message passed through ``message(topic, decoded)`` (JSON logs: the
    message's JSON) or ``raw(schema, topic, data)`` (its bytes, any encoding; None: dropped)."""
    attachments = dict(attachments or {})
    metadata = metadata or {}
    with open(source, "rb") as fh:
        reader = make_reader(fh)
        summary = reader.get_summary()
        assert summary is not None
        out = open(target, "wb")
        writer = Writer(out, compression=CompressionType.ZSTD, chunk_size=64 * 1024)
        writer.start(profile=profile, library="crafted")
        schema_ids = {sid: writer.register_schema(s.name, s.encoding, s.data) for sid, s in summary.schemas.items()}
        channel_ids = {cid: writer.register_channel(c.topic, c.message_encoding, schema_ids[c.schema_id])
                       for cid, c in summary.channels.items()}
        for att in reader.iter_attachments():
            data = attachments.pop(att.name, att.data)
            if data is not None:
                writer.add_attachment(att.create_time, att.log_time, att.name, att.media_type, data)
        for name, data in attachments.items():
            if data is not None:
                writer.add_attachment(0, 0, name, "application/octet-stream", data)
        for meta in reader.iter_metadata():
            writer.add_metadata(meta.name, {**meta.metadata, **metadata.get(meta.name, {})})
        for _schema, channel, msg in reader.iter_messages():
            data = msg.data
            if raw is not None:
                changed = raw(_schema, channel.topic, data)
                if changed is None:
                    continue
                data = changed
            if message is not None:
                value = message(channel.topic, json.loads(data))
                if value is None:
                    continue
                data = json.dumps(value).encode()
            writer.add_message(channel_ids[channel.id], msg.log_time, data, msg.publish_time, msg.sequence)
        writer.finish()
        out.close()
    return target


def attachment_offset(path: Path, name: str) -> tuple[int, int]:
    """(offset of the data, its length) of the first attachment called ``name`` in the file."""
    raw = path.read_bytes()
    position = len(MAGIC)
    while position < len(raw):
        opcode, length = struct.unpack_from("<BQ", raw, position)
        body = position + 9
        if opcode == 0x09:  # attachment: log time, create time, name, media type, data length, data, crc
            cursor = body + 16
            (n,) = struct.unpack_from("<I", raw, cursor)
            record_name = raw[cursor + 4:cursor + 4 + n].decode()
            cursor += 4 + n
            (m,) = struct.unpack_from("<I", raw, cursor)
            cursor += 4 + m
            (size,) = struct.unpack_from("<Q", raw, cursor)
            if record_name == name:
                return cursor + 8, size
        position = body + length
    raise KeyError(name)


def bomb(target: Path, claimed: int = 1 << 30) -> Path:
    """A small, otherwise valid cosim log whose one chunk decompresses to ``claimed`` bytes of zeros."""
    import zstandard

    def record(opcode: int, body: bytes) -> bytes:
        return struct.pack("<BQ", opcode, len(body)) + body

    def string(text: str) -> bytes:
        data = text.encode()
        return struct.pack("<I", len(data)) + data

    header = record(0x01, string("cosim") + string("crafted"))
    compressor = zstandard.ZstdCompressor(level=1)
    zeros = b"\0" * (1 << 20)
    chunks = compressor.chunker(chunk_size=1 << 20)
    data = b"".join(chunk for _ in range(claimed >> 20) for chunk in chunks.compress(zeros))
    data += b"".join(chunks.finish())
    body = struct.pack("<QQQI", 0, 0, claimed, zlib.crc32(b"")) + string("zstd") + struct.pack("<Q", len(data)) + data
    chunk = record(0x06, body)
    return _finish(target, header + chunk)


def _finish(target: Path, records: bytes) -> Path:
    data_end = struct.pack("<BQI", 0x0F, 4, 0)
    footer = struct.pack("<BQQQI", 0x02, 20, 0, 0, 0)
    target.write_bytes(MAGIC + records + data_end + footer + MAGIC)
    return target


def records(path: Path) -> list[tuple[int, int, int]]:
    """(opcode, offset, body length) of every top-level record of an MCAP file, up to its footer."""
    raw = path.read_bytes()
    found = []
    position = len(MAGIC)
    while position + 9 <= len(raw) - len(MAGIC):
        opcode, length = struct.unpack_from("<BQ", raw, position)
        found.append((opcode, position, length))
        if opcode == 0x02:  # footer
            break
        position += 9 + length
    return found


def edit_protobuf(schema: Any, data: bytes, change: Callable[[Any], None]) -> bytes:
    """A protobuf message changed field by field: parsed with the protobuf runtime from the log's own schema
    record (its ``FileDescriptorSet``), ``change(message)`` applied, serialized again (a valid message whose
    values lie)."""
    from google.protobuf import descriptor_pb2, message_factory

    files = descriptor_pb2.FileDescriptorSet.FromString(schema.data).file
    message = message_factory.GetMessages(list(files))[schema.name].FromString(data)
    change(message)
    return message.SerializeToString()
