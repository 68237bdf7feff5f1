"""Reading cosim logs: the one MCAP reader behind info, export, plot, replay, studies and tests.

- :func:`open_log`: what a log holds without its messages (metadata,
  attachments, message counts, the final status, sensor names), every
  chunk's checksum verified;
- :func:`iter_messages`: the decoded messages of some topics, in file order,
  chunk by chunk (constant memory); :func:`sensor_series` the sensor channels
  as arrays;
- :func:`read_log`: everything at once (:class:`LogContents`), for small logs
  and tests;
- :func:`traffic_from_log`: the logged SUMO frames as a traffic source again.

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
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Iterable, Iterator, Sequence

import numpy as np
from mcap.data_stream import ReadDataStream
from mcap.reader import make_reader
from mcap.records import Attachment, Channel, Chunk, Header, Message, Metadata, Schema
from mcap.stream_reader import (
    CRCValidationError,
    StreamReader,
    breakup_chunk,
    get_chunk_data_stream,
)

from cosim.core.traffic import Frame, FrameTraffic
from cosim.core.vehicles import model_from_dict
from cosim.errors import ConfigError, LogError

from .schemas import (
    MAGIC,
    METADATA_NAME,
    PROFILE,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_TYPES,
)

_CHUNK_OPCODE = 0x06

# --------------------------------------------------------------------------- files and records


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


def _corrupt(path: Path, exc: BaseException) -> LogError:
    return LogError(f"{path}: corrupt MCAP file ({type(exc).__name__}: {exc})")


def _records(path: Path, fh: IO[bytes], complete: bool) -> Iterator[Any]:
    """Every record of the file in order (the one record walker).

    A file cut short ends quietly after its last complete record; damage
    (a checksum that does not match, or anything malformed in a complete file) raises.
    """
    try:
        yield from StreamReader(fh, validate_crcs=True).records
    except CRCValidationError as exc:
        raise _corrupt(path, exc) from None
    except LogError:
        raise
    except Exception as exc:  # noqa: BLE001 - a cut-off file ends in a partial record
        if complete:
            raise _corrupt(path, exc) from None


def _decode(path: Path, channel: Channel, data: bytes) -> dict:
    """One message as a JSON object (the one decoder)."""
    if channel.message_encoding != "json":
        raise LogError(f"{path}: channel {channel.topic} is {channel.message_encoding!r}, not a cosim JSON channel")
    try:
        value = json.loads(data)
    except (ValueError, UnicodeDecodeError):
        raise LogError(f"{path}: a message on {channel.topic} is not valid JSON") from None
    if not isinstance(value, dict):
        raise LogError(f"{path}: a message on {channel.topic} is not a JSON object")
    return value


def _check_profile(path: Path, profile: str | None) -> None:
    if profile is None:
        raise LogError(f"{path}: an MCAP file whose header cannot be read")
    if profile != PROFILE:
        raise LogError(f"{path}: an MCAP file, but not a cosim log (profile {profile!r})")


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


def open_log(path: str | os.PathLike[str]) -> LogOverview:
    """Read a log's metadata, attachments, message counts and final status (not the messages).

    A finished log is read through its summary, and the CRC of every chunk is
    checked; a log cut short is read record by record up to its last complete
    record. Either way in constant memory (besides the attachments).

    Raises:
        LogError: missing, not MCAP, not a cosim log, or damaged (e.g. a CRC that does not match).
    """
    path = Path(path)
    with _open(path) as fh:
        complete = _ends_with_magic(fh)
        fh.seek(0, os.SEEK_END)
        out = LogOverview(path=path, complete=complete, size=fh.tell())
        fh.seek(0)
        if complete:
            profile, sensor_schema = _overview_from_summary(path, fh, out)
        else:
            profile, sensor_schema = _overview_from_records(path, fh, out)
    _check_profile(path, profile)
    info = out.info
    try:
        out.sensor_names = json.loads(info["sensors"]) if "sensors" in info else []
        out.quantities = json.loads(info["quantities"]) if "quantities" in info else []
    except ValueError:
        raise LogError(f"{path}: malformed cosim metadata (sensors)") from None
    if not out.sensor_names and sensor_schema is not None:
        try:
            props = json.loads(sensor_schema).get("properties", {})
        except ValueError:
            props = {}
        out.sensor_names = [name for name in props if name != "t"]
    if len(out.quantities) != len(out.sensor_names):
        out.quantities = ["" for _ in out.sensor_names]
    return out


def _overview_from_records(path: Path, fh: IO[bytes], out: LogOverview) -> tuple[str | None, bytes | None]:
    """The overview of a log cut short: one pass over its records."""
    channels: dict[int, Channel] = {}
    schemas: dict[int, bytes] = {}
    sensor_schema: bytes | None = None
    profile = None
    for record in _records(path, fh, False):
        if isinstance(record, Message):
            channel = channels.get(record.channel_id)
            if channel is None:
                continue
            out.counts[channel.topic] = out.counts.get(channel.topic, 0) + 1
            out.end_time = max(out.end_time, record.log_time / 1e9)
            if channel.topic == TOPIC_STATUS:
                out.final_status = _decode(path, channel, record.data)
        elif isinstance(record, Channel):
            channels[record.id] = record
            if record.topic == TOPIC_SENSORS:
                sensor_schema = schemas.get(record.schema_id)
        elif isinstance(record, Schema):
            schemas[record.id] = record.data
        elif isinstance(record, Attachment):
            out.attachments[record.name] = record.data
        elif isinstance(record, Metadata):
            out.metadata[record.name] = dict(record.metadata)
        elif isinstance(record, Header):
            profile = record.profile
            out.library = record.library
    return profile, sensor_schema


def _overview_from_summary(path: Path, fh: IO[bytes], out: LogOverview) -> tuple[str | None, bytes | None]:
    """The overview of a finished log: counts from its statistics, every chunk's CRC, the last status."""
    try:
        reader = make_reader(fh, validate_crcs=True)
        header = reader.get_header()
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            raise ValueError("no summary section")
        channels = summary.channels
        stats = summary.statistics
        for cid, count in stats.channel_message_counts.items():
            if cid in channels and count:
                out.counts[channels[cid].topic] = count
        end_time = stats.message_end_time
        status_ids = {cid for cid, channel in channels.items() if channel.topic == TOPIC_STATUS}
        last_status: tuple[int, int, int, bytes] | None = None
        for index in summary.chunk_indexes:  # every chunk's CRC, without parsing its messages
            fh.seek(index.chunk_start_offset)
            head = fh.read(9)
            if len(head) != 9 or head[0] != _CHUNK_OPCODE:
                raise ValueError(f"no chunk record at offset {index.chunk_start_offset}")
            (length,) = struct.unpack("<Q", head[1:])
            chunk = Chunk.read(ReadDataStream(io.BytesIO(fh.read(length))))
            if index.message_end_time < end_time:
                get_chunk_data_stream(chunk, validate_crc=True)
                continue
            for record in breakup_chunk(chunk, validate_crc=True):  # the last chunk(s): the final status
                if isinstance(record, Message) and record.channel_id in status_ids:
                    key = (record.log_time, record.sequence, record.channel_id, record.data)
                    if last_status is None or key[:2] >= last_status[:2]:
                        last_status = key
        if last_status is not None:
            out.final_status = _decode(path, channels[last_status[2]], last_status[3])
        for att in reader.iter_attachments():
            out.attachments[att.name] = att.data
        for meta in reader.iter_metadata():
            out.metadata[meta.name] = dict(meta.metadata)
    except LogError:
        raise
    except Exception as exc:  # noqa: BLE001 - anything wrong in a finished file is damage
        raise _corrupt(path, exc) from None
    out.end_time = end_time / 1e9
    out.library = header.library
    sensor_schema = None
    for channel in channels.values():
        if channel.topic == TOPIC_SENSORS and channel.schema_id in summary.schemas:
            sensor_schema = summary.schemas[channel.schema_id].data
    return header.profile, sensor_schema


# --------------------------------------------------------------------------- messages


def _walk(path: Path, wanted: set[str] | None) -> Iterator[tuple[str, Any]]:
    """("header" | "attachment" | "metadata", record) and ("message", (topic, log_time, decoded)) of a log,
    in file order; messages only on ``wanted`` topics (all if None). Checks the profile first."""
    with _open(path) as fh:
        complete = _ends_with_magic(fh)
        channels: dict[int, Channel] = {}
        profile_checked = False
        for record in _records(path, fh, complete):
            if isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is not None and (wanted is None or channel.topic in wanted):
                    yield "message", (channel.topic, record.log_time, _decode(path, channel, record.data))
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Header):
                _check_profile(path, record.profile)
                profile_checked = True
                yield "header", record
            elif isinstance(record, (Attachment, Metadata)):
                yield ("attachment" if isinstance(record, Attachment) else "metadata"), record
        if not profile_checked:
            _check_profile(path, None)
        yield "end", complete


def iter_messages(path: str | os.PathLike[str], topics: Iterable[str]) -> Iterator[tuple[str, dict]]:
    """The decoded messages on ``topics`` as (topic, message), in file order, chunk by chunk (constant memory).

    A log cut short yields what it holds up to its last complete record.

    Raises:
        LogError: missing, not MCAP, not a cosim log, or damaged.
    """
    for kind, item in _walk(Path(path), set(topics)):
        if kind == "message":
            yield item[0], item[2]


def sensor_series(path: str | os.PathLike[str], names: Sequence[str] | None = None
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log as arrays (t, {name: values}), sorted by time (all channels by default)."""
    names = list(names) if names is not None else open_log(path).sensor_names
    t: list[float] = []
    columns: dict[str, list[float]] = {n: [] for n in names}
    for _, msg in iter_messages(path, [TOPIC_SENSORS]):
        t.append(msg["t"])
        for n in names:
            columns[n].append(msg[n])
    order = np.argsort(np.asarray(t), kind="stable")
    return np.asarray(t)[order], {n: np.asarray(v, dtype=float)[order] for n, v in columns.items()}


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
    marked ``truncated``.

    Raises:
        LogError: missing, not MCAP, not a cosim log, or damaged.
    """
    path = Path(path)
    out = LogContents(path=path)
    messages = out.messages
    for kind, item in _walk(path, set(topics) if topics is not None else None):
        if kind == "message":
            topic, log_time, msg = item
            messages.setdefault(topic, []).append((log_time, msg))
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


def traffic_from_log(contents: LogContents, length: float, step: float, until: float | None = None) -> FrameTraffic:
    """Rebuild the logged traffic frames as a traffic source for a bridge of ``length`` m.

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
    frames = contents.topic(TOPIC_TRAFFIC)
    if not frames and until is None:
        raise LogError(f"{contents.path}: no traffic frames ({TOPIC_TRAFFIC}) in this log")
    empty = np.zeros(0)

    def pad(traffic: FrameTraffic, t_end: float) -> None:
        """Empty frames while one more still ends before ``t_end`` (half a step of slack for round-off)."""
        # Same time expression as the live source (k * step), so replays are bit-identical.
        while traffic.last_time + step < t_end + 0.5 * step:
            k = int(round(traffic.last_time / step)) + 1
            traffic.add_frame(Frame(k * step, (), empty, empty, empty, empty, ()))

    try:
        models = {m["type"]: model_from_dict(m["model"]) for m in contents.topic(TOPIC_VEHICLE_TYPES)}
        traffic = FrameTraffic(step, length, models)
        for f in frames:
            t = float(f["t"])
            pad(traffic, t - step)
            traffic.add_frame(Frame(
                t=t, ids=tuple(f["ids"]), x=np.array(f["x"], dtype=float), y=np.array(f["y"], dtype=float),
                v=np.array(f["speed"], dtype=float), a=np.array(f["acceleration"], dtype=float),
                types=tuple(f["types"])))
        if until is not None:
            pad(traffic, until)
    except (KeyError, TypeError, ValueError, ConfigError) as exc:
        raise LogError(f"{contents.path}: malformed traffic frames ({exc})") from None
    return traffic


def read_traffic(path: str | os.PathLike[str], length: float, step: float, until: float | None = None
                 ) -> tuple[FrameTraffic, int]:
    """The logged SUMO frames of the log at ``path`` as a traffic source (see :func:`traffic_from_log`),
    and how many frames the log holds."""
    contents = read_log(path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
    return traffic_from_log(contents, length, step, until), len(contents.messages.get(TOPIC_TRAFFIC, []))
