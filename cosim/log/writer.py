"""MCAP logs: topics and schemas (one place), a crash-safe recorder, and a reader.

Every message is JSON with a JSON Schema, so Foxglove and the ``mcap`` CLI can
read the logs. Log times are integer nanoseconds of *simulated* time. The
scenario, the resolved parameters, section constants, frequencies and every
input file are stored as attachments and metadata, so a log alone is enough
to re-run.

The writer (:class:`LogRecorder`) is a context manager: whatever ends the run
(normal end, Ctrl-C, an exception) a final status message is written and the
file is finished with its summary and index. A process killed outright
leaves the chunks already flushed; :func:`read_log` reads those and says the
file is truncated. Logs are parsed, never evaluated or unpickled.
"""
from __future__ import annotations

import bisect
import io
import itertools
import json
import os
import queue
import struct
import threading
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Iterable, Iterator

import numpy as np
import orjson
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.reader import make_reader
from mcap.records import (
    Attachment,
    Channel,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
)
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from cosim import __version__
from cosim.core.traffic import Frame, FrameTraffic
from cosim.core.vehicles import model_from_dict, model_to_dict
from cosim.errors import ConfigError, LogError

PROFILE = "cosim"
TOPIC_SENSORS = "/cosim/sensors"
TOPIC_VEHICLES = "/cosim/vehicles"
TOPIC_EVENTS = "/cosim/events"
TOPIC_STATUS = "/cosim/status"
TOPIC_TRAFFIC = "/cosim/traffic"
TOPIC_VEHICLE_TYPES = "/cosim/vehicle_types"

STATUS_STATES = ("started", "running", "finished", "interrupted", "error")
EVENT_KINDS = ("entered", "left", "liftoff", "touchdown")

_NUMBER = {"type": "number"}


def sensors_schema(names: Iterable[str]) -> dict[str, Any]:
    """Schema of one sensor sample: ``t`` (s) plus one number per sensor (SI unit of its quantity)."""
    props: dict[str, Any] = {"t": {"type": "number", "description": "simulated time, s"}}
    for name in names:
        props[name] = _NUMBER
    return {"title": "cosim.SensorSample", "type": "object", "properties": props,
            "required": ["t", *names], "additionalProperties": False}


VEHICLE_ITEM = {
    "type": "object",
    "properties": {
        "id": {"type": "string"},
        "model": {"type": "string"},
        "x": {"type": "number", "description": "contact point along the axis, m"},
        "y": {"type": "number", "description": "lateral offset, m"},
        "speed": {"type": "number", "description": "along +x, m/s"},
        "acceleration": {"type": "number", "description": "along +x, m/s^2"},
        "body_displacement": {"type": "number", "description": "from static equilibrium, m"},
        "body_acceleration": {"type": "number", "description": "m/s^2"},
        "contact_force": {"type": "number", "description": "wheel on deck, compression positive, N"},
    },
    "required": ["id", "model", "x", "y", "speed", "acceleration", "body_displacement",
                 "body_acceleration", "contact_force"],
    "additionalProperties": False,
}
VEHICLES_SCHEMA = {
    "title": "cosim.VehiclesOnDeck", "type": "object",
    "properties": {"t": _NUMBER, "vehicles": {"type": "array", "items": VEHICLE_ITEM}},
    "required": ["t", "vehicles"], "additionalProperties": False,
}
EVENTS_SCHEMA = {
    "title": "cosim.TrafficEvent", "type": "object",
    "properties": {"t": _NUMBER, "vehicle": {"type": "string"}, "event": {"enum": list(EVENT_KINDS)},
                   "x": _NUMBER},
    "required": ["t", "vehicle", "event"], "additionalProperties": False,
}
STATUS_SCHEMA = {
    "title": "cosim.RunStatus", "type": "object",
    "properties": {"t": _NUMBER, "state": {"enum": list(STATUS_STATES)}, "message": {"type": "string"},
                   "progress": _NUMBER, "wall_time": _NUMBER},
    "required": ["t", "state"], "additionalProperties": False,
}
TRAFFIC_SCHEMA = {
    "title": "cosim.TrafficFrame", "type": "object",
    "description": "Vehicles near the deck at one SUMO step (bridge coordinates): what replay re-drives.",
    "properties": {
        "t": _NUMBER,
        "ids": {"type": "array", "items": {"type": "string"}},
        "x": {"type": "array", "items": _NUMBER},
        "y": {"type": "array", "items": _NUMBER},
        "speed": {"type": "array", "items": _NUMBER},
        "acceleration": {"type": "array", "items": _NUMBER},
        "types": {"type": "array", "items": {"type": "string"}},
    },
    "required": ["t", "ids", "x", "y", "speed", "acceleration", "types"], "additionalProperties": False,
}
VEHICLE_TYPE_SCHEMA = {
    "title": "cosim.VehicleType", "type": "object",
    "description": "The vehicle model of a SUMO vType, logged when the type first appears.",
    "properties": {"t": _NUMBER, "type": {"type": "string"},
                   "model": {"type": "object", "properties": {"model": {"type": "string"}},
                             "required": ["model"], "additionalProperties": {"type": "number"}}},
    "required": ["t", "type", "model"], "additionalProperties": False,
}


def to_ns(t: float) -> int:
    """Simulated time in seconds -> integer nanoseconds."""
    return int(round(t * 1e9))


_MESSAGE_HEAD = struct.Struct("<BQHIQQ")  # opcode, record length, channel id, sequence, log time, publish time
_MESSAGE_OPCODE = 0x05
_MESSAGE_FIXED = 22  # channel id (2) + sequence (4) + log time (8) + publish time (8)
_NUMPY = orjson.OPT_SERIALIZE_NUMPY


class _MessageIndex(MessageIndex):
    """A message index record written in one ``struct.pack`` (the same bytes as mcap's per-entry writes)."""

    def write(self, stream) -> None:  # noqa: ANN001 - mcap's RecordBuilder
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(len(self.records) * 16)
        stream.write(np.array(self.records, dtype="<u8").tobytes())
        stream.finish_record()


class _BulkWriter(Writer):
    """mcap's :class:`Writer` with a bulk path for many pre-encoded messages of one channel.

    The records, chunks, indexes and statistics are exactly those that
    ``add_message`` would write; only the Python work per message is less (one
    ``struct.pack`` and a list append instead of a record object, seven
    stream writes and their bookkeeping), which is most of the logging cost
    at 100 Hz. If the installed mcap's internals differ, it falls back to
    ``add_message`` per message.
    """

    def add_encoded(self, channel_id: int, log_times: list[int], datas: list[bytes], sequence: int) -> int:
        """Add ``datas[i]`` at ``log_times[i]`` (ns, also the publish time); returns the last sequence number."""
        try:
            builder = self._Writer__chunk_builder  # type: ignore[attr-defined]
            stats = self._Writer__statistics  # type: ignore[attr-defined]
            limit = self._Writer__chunk_size  # type: ignore[attr-defined]
            builder.record_writer._buffer.tell()
            finalize = self._Writer__maybe_finalize_chunk  # type: ignore[attr-defined]
        except AttributeError:
            builder = None
        if builder is None:
            for ns, data in zip(log_times, datas):
                sequence += 1
                self.add_message(channel_id, ns, data, ns, sequence)
            return sequence
        pack = _MESSAGE_HEAD.pack
        sizes = [9 + _MESSAGE_FIXED + len(d) for d in datas]
        ends = list(itertools.accumulate(sizes))  # record ends relative to the batch start
        start, n = 0, len(datas)
        while start < n:
            buffer = builder.record_writer._buffer  # a new one after every finished chunk
            base = buffer.tell()
            skipped = ends[start - 1] if start else 0
            # Records up to and including the first one that takes the chunk past its size, as add_message does.
            stop = min(bisect.bisect_right(ends, limit - base + skipped, lo=start) + 1, n)
            count = stop - start
            seqs = range(sequence + 1, sequence + count + 1)
            times = log_times[start:stop]
            parts: list[bytes] = [b""] * (2 * count)
            parts[0::2] = [pack(_MESSAGE_OPCODE, size - 9, channel_id, seq, ns, ns)
                           for size, seq, ns in zip(sizes[start:stop], seqs, times)]
            parts[1::2] = datas[start:stop]
            buffer.write(b"".join(parts))
            offsets = [base + e - skipped - size for e, size in zip(ends[start:stop], sizes[start:stop])]
            sequence += count
            first, last = min(times), max(times)
            records = builder.message_indices.get(channel_id)
            if records is None:
                records = builder.message_indices[channel_id] = _MessageIndex(channel_id=channel_id, records=[])
            records.records.extend(zip(times, offsets))
            if builder.num_messages == 0:
                builder.message_start_time = first
            else:
                builder.message_start_time = min(builder.message_start_time, first)
            builder.message_end_time = max(builder.message_end_time, last)
            builder.num_messages += count
            if stats.message_count == 0:
                stats.message_start_time = first
            else:
                stats.message_start_time = min(stats.message_start_time, first)
            stats.message_end_time = max(stats.message_end_time, last)
            stats.channel_message_counts[channel_id] += count
            stats.message_count += count
            finalize()
            start = stop
        return sequence


def _template_part(value: str) -> bytes:
    """A JSON string for a bytes %-template (``%`` doubled)."""
    return orjson.dumps(value).replace(b"%", b"%%")


def _number_tokens(values: np.ndarray) -> list[bytes]:
    """The JSON numbers of a 2-D float array, row by row (one orjson call: shortest round-trip form)."""
    text = orjson.dumps(np.ascontiguousarray(values, dtype=np.float64), option=_NUMPY)
    return text.replace(b"[", b"").replace(b"]", b"").split(b",")


class LogRecorder:
    """Write one run's MCAP log; use as a context manager.

    Args:
        path: the ``.mcap`` file to create.
        sensor_names: the sensor channels, in order.
        force: overwrite an existing file (otherwise refuse).
        chunk_size: bytes per chunk; small chunks lose little when the process is killed.
    """

    def __init__(self, path: str | Path, sensor_names: Iterable[str], force: bool = False,
                 chunk_size: int = 256 * 1024) -> None:
        self.path = Path(path)
        if self.path.exists() and not force:
            raise LogError(f"{self.path}: exists; refusing to overwrite a log (use --force)")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._stream: IO[bytes] = open(self.path, "wb")
        except OSError as exc:
            raise LogError(f"{self.path}: cannot create the log ({exc.strerror})") from None
        self._writer = _BulkWriter(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(profile=PROFILE, library=f"cosim {__version__}")
        self.sensor_names = list(sensor_names)
        self._channels: dict[str, int] = {}
        self._sequence = 0
        self._closed = False
        self.final_state: str | None = None
        for topic, title, schema in (
            (TOPIC_SENSORS, "cosim.SensorSample", sensors_schema(self.sensor_names)),
            (TOPIC_VEHICLES, "cosim.VehiclesOnDeck", VEHICLES_SCHEMA),
            (TOPIC_EVENTS, "cosim.TrafficEvent", EVENTS_SCHEMA),
            (TOPIC_STATUS, "cosim.RunStatus", STATUS_SCHEMA),
            (TOPIC_TRAFFIC, "cosim.TrafficFrame", TRAFFIC_SCHEMA),
            (TOPIC_VEHICLE_TYPES, "cosim.VehicleType", VEHICLE_TYPE_SCHEMA),
        ):
            sid = self._writer.register_schema(title, "jsonschema", json.dumps(schema).encode())
            self._channels[topic] = self._writer.register_channel(topic, "json", sid)
        self._last_t = 0.0
        # The block logger's thread and the traffic source (main thread) both write.
        self._lock = threading.Lock()

    # --------------------------------------------------------------- content
    def attach(self, name: str, data: bytes | str, media_type: str = "text/plain") -> None:
        """Store an input file or a derived document (resolved parameters, modes) in the log."""
        if isinstance(data, str):
            data = data.encode()
        with self._lock:
            self._writer.add_attachment(0, 0, name, media_type, data)

    def metadata(self, name: str, values: dict[str, str]) -> None:
        with self._lock:
            self._writer.add_metadata(name, {k: str(v) for k, v in values.items()})

    def write(self, topic: str, t: float, message: dict[str, Any]) -> None:
        """One JSON message on ``topic`` at simulated time ``t`` (s)."""
        ns = to_ns(t)
        # orjson: the logging budget is a fraction of a ~20 us solver step per sample.
        data = orjson.dumps(message)
        with self._lock:
            self._sequence += 1
            self._writer.add_message(self._channels[topic], ns, data, ns, self._sequence)
            self._last_t = max(self._last_t, t)

    def write_encoded(self, topic: str, times: list[float], datas: list[bytes]) -> None:
        """Many messages on ``topic``, already JSON-encoded, at simulated times ``times`` (s)."""
        if not datas:
            return
        log_times = np.rint(np.asarray(times, dtype=np.float64) * 1e9).astype(np.int64).tolist()  # = to_ns
        with self._lock:
            self._sequence = self._writer.add_encoded(self._channels[topic], log_times, datas, self._sequence)
            self._last_t = max(self._last_t, max(times))

    def status(self, t: float, state: str, message: str = "", progress: float | None = None,
               wall_time: float | None = None) -> None:
        msg: dict[str, Any] = {"t": t, "state": state}
        if message:
            msg["message"] = message
        if progress is not None:
            msg["progress"] = progress
        if wall_time is not None:
            msg["wall_time"] = wall_time
        self.write(TOPIC_STATUS, t, msg)
        if state != "running":
            self.flush()

    def flush(self) -> None:
        """Push what the writer has finished to the operating system."""
        with self._lock:
            self._stream.flush()

    # ------------------------------------------------------------- lifecycle
    def close(self, state: str = "finished", message: str = "", wall_time: float | None = None) -> None:
        """Write the final status and finish the file (summary, index); idempotent."""
        if self._closed:
            return
        self._closed = True
        self.final_state = state
        try:
            self.status(self._last_t, state, message, wall_time=wall_time)
        finally:
            with self._lock:
                self._writer.finish()
                self._stream.close()

    def __enter__(self) -> "LogRecorder":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close("finished")
        elif issubclass(exc_type, KeyboardInterrupt):
            self.close("interrupted", "interrupted by the user (SIGINT)")
        else:
            self.close("error", f"{exc_type.__name__}: {exc}")


# ------------------------------------------------------------------ reading
@dataclass
class LogContents:
    """What a log holds. ``messages`` maps topic -> list of (log_time ns, decoded JSON)."""

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
        return [m for _, m in self.messages.get(name, [])]


def _decode(path: Path, channel: Channel, data: bytes) -> dict:
    if channel.message_encoding != "json":
        raise LogError(f"{path}: channel {channel.topic} is {channel.message_encoding!r}, not a cosim JSON channel")
    try:
        return json.loads(data)
    except (ValueError, UnicodeDecodeError):
        raise LogError(f"{path}: a message on {channel.topic} is not valid JSON") from None


def read_log(path: str | Path, topics: Iterable[str] | None = None) -> LogContents:
    """Read a cosim log; a log cut short (process killed) is read up to its last complete chunk.

    Raises:
        LogError: the file is missing, not MCAP, or not a cosim log.
    """
    path = Path(path)
    wanted = set(topics) if topics is not None else None
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise LogError(f"{path}: cannot read ({exc.strerror})") from None
    if not raw.startswith(b"\x89MCAP0\r\n"):
        raise LogError(f"{path}: not an MCAP file")
    out = LogContents(path=path)
    try:
        reader = make_reader(io.BytesIO(raw), validate_crcs=True)
        header = reader.get_header()
        out.profile = header.profile
        for _, channel, message in reader.iter_messages(topics=list(wanted) if wanted else None):
            out.messages.setdefault(channel.topic, []).append((message.log_time, _decode(path, channel, message.data)))
        for att in reader.iter_attachments():
            out.attachments[att.name] = att.data
        for meta in reader.iter_metadata():
            out.metadata[meta.name] = dict(meta.metadata)
    except (McapError, EOFError, ValueError, KeyError, OSError):
        out = _read_stream(path, raw, wanted)
    if out.profile != PROFILE:
        raise LogError(f"{path}: an MCAP file, but not a cosim log (profile {out.profile!r})")
    for msgs in out.messages.values():
        msgs.sort(key=lambda item: item[0])
    return out


def _read_stream(path: Path, raw: bytes, wanted: set[str] | None) -> LogContents:
    """Record-by-record read that stops at the first incomplete record (a truncated file)."""
    out = LogContents(path=path, truncated=True)
    channels: dict[int, Channel] = {}
    records: Iterator = StreamReader(io.BytesIO(raw), validate_crcs=True).records
    complete = False
    try:
        for record in records:
            if isinstance(record, Header):
                out.profile = record.profile
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is not None and (wanted is None or channel.topic in wanted):
                    out.messages.setdefault(channel.topic, []).append(
                        (record.log_time, _decode(path, channel, record.data)))
            elif isinstance(record, Attachment):
                out.attachments[record.name] = record.data
            elif isinstance(record, Metadata):
                out.metadata[record.name] = dict(record.metadata)
            elif isinstance(record, Footer):
                complete = True
    except LogError:
        raise
    except Exception:  # noqa: BLE001 - any malformed record ends the readable part of a cut-off file
        pass
    if not out.profile:
        raise LogError(f"{path}: an MCAP file whose header cannot be read")
    out.truncated = not complete
    return out


def file_is_complete(path: str | Path) -> bool:
    """True when the log was finished (it ends with the MCAP footer and magic)."""
    try:
        with open(path, "rb") as fh:
            fh.seek(0, os.SEEK_END)
            if fh.tell() < 16:
                return False
            fh.seek(-8, os.SEEK_END)
            return fh.read(8) == b"\x89MCAP0\r\n"
    except OSError:
        return False


#: The block logger's writer thread waits this long at most for the solver's next block, s.
PACE_TIMEOUT = 0.02
#: ... and then this long, for the solver thread to enter its compiled (GIL-free) loop, s.
PACE_DELAY = 0.0003


class _PacedTraffic:
    """A traffic source that signals an event whenever the solver asks for its next block."""

    def __init__(self, traffic: Any, pace: threading.Event | None) -> None:
        self.traffic = traffic
        self._pace = pace

    def block(self, times):  # noqa: ANN001, ANN201 - the TrafficSource protocol
        out = self.traffic.block(times)
        if self._pace is not None:
            self._pace.set()
        return out

    def __getattr__(self, name: str) -> Any:
        return getattr(self.traffic, name)


class BlockLogger:
    """Observer of :func:`cosim.core.simulation.simulate` that streams every block into a :class:`LogRecorder`.

    Sensor samples and vehicles on the deck at the logging rate (the
    simulation's ``output_every``); traffic events (entered/left the deck,
    lift-off/touch-down) at every step; a "running" status every
    ``status_every`` seconds of simulated time. Nothing is accumulated.

    Encoding and writing run in a background thread while the (GIL-free)
    compiled solver computes the next block, so logging costs little wall
    time on a machine with a spare core; the queue holds a few blocks at most.
    Use as a context manager (or call :meth:`close`) so the thread drains.
    """

    def __init__(self, recorder: LogRecorder, sensor_names: Iterable[str], total_time: float,
                 status_every: float = 10.0, threaded: bool = True) -> None:
        self.rec = recorder
        self.names = list(sensor_names)
        self.total_time = total_time
        self.status_every = status_every
        self._next_status = status_every
        self._on: dict[str, bool] = {}
        self._lifted: dict[str, bool] = {}
        self._model_names: dict[str, str] = {}
        self._sensor_template = (b'{"t":%s' + b"".join(b"," + _template_part(n) + b":%s" for n in self.names) + b"}")
        self._vehicle_templates: dict[tuple[str, ...], bytes] = {}
        self._error: BaseException | None = None
        self._pace: threading.Event | None = None
        self._closing = False
        self._queue: queue.Queue | None = None
        self._thread: threading.Thread | None = None
        if threaded:
            self._queue = queue.Queue(maxsize=4)
            self._thread = threading.Thread(target=self._drain, name="cosim-log-writer", daemon=True)
            self._thread.start()

    def on_block(self, times, keep, report) -> None:
        if self._error is not None:
            raise LogError(f"{self.rec.path}: writing the log failed: {self._error}")
        if self._queue is None:
            self._write_block(times, keep, report)
        else:
            self._queue.put((times, keep, report))

    def paced(self, traffic: Any) -> "_PacedTraffic":
        """``traffic``, wrapped so that the writer thread knows when the solver starts its next block.

        Pass the wrapper to :func:`cosim.core.simulation.simulate` instead of
        ``traffic``: the thread then encodes a block while the compiled solver
        (which releases the GIL) computes the next one, instead of holding the
        GIL while the solver thread needs it between two blocks. It costs
        nothing in correctness: without a signal the thread waits at most
        :data:`PACE_TIMEOUT`.
        """
        if self._queue is None:
            return _PacedTraffic(traffic, None)
        self._pace = threading.Event()
        return _PacedTraffic(traffic, self._pace)

    def _drain(self) -> None:
        assert self._queue is not None
        while True:
            item = self._queue.get()
            if item is None:
                return
            pace = self._pace
            if pace is not None and not self._closing:
                pace.wait(PACE_TIMEOUT)
                pace.clear()
                time.sleep(PACE_DELAY)  # let the solver thread reach its compiled loop
            if self._error is None:
                try:
                    self._write_block(*item)
                except BaseException as exc:  # noqa: BLE001 - reported to the solver thread
                    self._error = exc
                    self._error_trace = traceback.format_exc()

    def close(self) -> None:
        """Wait until every queued block is written."""
        if self._thread is not None and self._queue is not None:
            self._closing = True
            if self._pace is not None:
                self._pace.set()
            self._queue.put(None)
            self._thread.join()
            self._thread = None
        if self._error is not None:
            where = getattr(self, "_error_trace", "").strip().splitlines()
            raise LogError(f"{self.rec.path}: writing the log failed: {self._error!r}"
                           + (f" ({where[-3].strip()})" if len(where) >= 3 else ""))

    def __enter__(self) -> "BlockLogger":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            self.close()
        except LogError:
            if exc_type is None:
                raise

    def _write_block(self, times, keep, report) -> None:
        rec = self.rec
        kept = np.flatnonzero(keep)
        if len(kept):
            t = times[kept]
            tokens = _number_tokens(np.column_stack([t, report.sensors[kept]]))
            width = 1 + len(self.names)
            template = self._sensor_template
            rec.write_encoded(TOPIC_SENSORS, t.tolist(),
                              [template % tuple(tokens[i:i + width]) for i in range(0, len(tokens), width)])
        self._gone(times, report)
        if report.ids:
            self._events(times, report)
            self._vehicles(times, kept, report)
        if times[-1] >= self._next_status:
            rec.status(float(times[-1]), "running", progress=float(times[-1] / self.total_time))
            rec.flush()
            self._next_status += self.status_every

    def _gone(self, times, report) -> None:
        """Vehicles on the deck at the end of the last block that the traffic no longer has: they left."""
        present = set(report.ids)
        for vid in [v for v, on in self._on.items() if on and v not in present]:
            t = float(times[0])
            self.rec.write(TOPIC_EVENTS, t, {"t": t, "vehicle": vid, "event": "left"})
            self._on[vid] = self._lifted[vid] = False

    def _events(self, times, report) -> None:
        """Entered/left the deck and lift-off/touch-down: transitions at any step of the block."""
        ids = report.ids
        on = report.on_deck
        lifted = on & (report.contact_force < 0)
        prev_on = np.array([self._on.get(v, False) for v in ids])
        prev_lift = np.array([self._lifted.get(v, False) for v in ids])
        for state, prev, names in ((on, prev_on, ("left", "entered")), (lifted, prev_lift, ("touchdown", "liftoff"))):
            changed = np.diff(np.vstack([prev[None, :], state]).astype(np.int8), axis=0) != 0
            for k, j in zip(*np.nonzero(changed)):
                t = float(times[k])
                self.rec.write(TOPIC_EVENTS, t, {"t": t, "vehicle": ids[j], "event": names[int(state[k, j])],
                                                 "x": float(report.x[k, j])})
        for j, vid in enumerate(ids):
            self._on[vid], self._lifted[vid] = bool(on[-1, j]), bool(lifted[-1, j])

    _VEHICLE_FIELDS = (b'%s,"y":%s,"speed":%s,"acceleration":%s,"body_displacement":%s,'
                       b'"body_acceleration":%s,"contact_force":%s}')

    def _vehicle_template(self, ids: tuple[str, ...]) -> bytes:
        """``{"t":%s,"vehicles":[{"id":..,"model":..,"x":%s,...},...]}`` for these vehicles, in this order."""
        key = ids
        template = self._vehicle_templates.get(key)
        if template is None:
            items = [b'{"id":' + _template_part(vid) + b',"model":' + _template_part(self._model_names[vid])
                     + b',"x":' + self._VEHICLE_FIELDS for vid in ids]
            template = b'{"t":%s,"vehicles":[' + b",".join(items) + b"]}"
            if len(self._vehicle_templates) > 256:
                self._vehicle_templates.clear()
            self._vehicle_templates[key] = template
        return template

    def _vehicles(self, times, kept, report) -> None:
        """One message per kept step with a vehicle on the deck; encoded per group of steps with the same fleet."""
        ids = report.ids
        for vid, model in zip(ids, report.models):
            if vid not in self._model_names:
                self._model_names[vid] = getattr(model, "kind", type(model).__name__)
        on = report.on_deck[kept]
        rows = np.flatnonzero(on.any(axis=1))
        if not len(rows):
            return
        steps = kept[rows]
        on = on[rows]
        fields = np.stack([report.x[steps], np.broadcast_to(report.y, (len(steps), len(ids))), report.v[steps],
                           report.a[steps], report.body_displacement[steps], report.body_acceleration[steps],
                           report.contact_force[steps]], axis=2)  # (samples, vehicles, 7)
        t = times[steps]
        out: list[bytes] = [b""] * len(steps)
        # Consecutive samples with the same vehicles on the deck share one template.
        change = np.flatnonzero(np.any(on[1:] != on[:-1], axis=1)) + 1
        bounds = np.concatenate([[0], change, [len(steps)]])
        for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
            cols = np.flatnonzero(on[lo])
            template = self._vehicle_template(tuple(ids[j] for j in cols))
            values = np.column_stack([t[lo:hi], fields[lo:hi][:, cols, :].reshape(hi - lo, 7 * len(cols))])
            tokens = _number_tokens(values)
            width = 1 + 7 * len(cols)
            out[lo:hi] = [template % tuple(tokens[i:i + width]) for i in range(0, len(tokens), width)]
        self.rec.write_encoded(TOPIC_VEHICLES, t.tolist(), out)

class TrafficLogger:
    """Frame sink for a live traffic source (SUMO): logs every frame with vehicles, and each new vehicle type.

    These are what :func:`traffic_from_log` needs to re-drive a bridge with
    exactly the same vehicle kinematics (``cosim replay``). A frame without
    vehicles near the deck is not written: a missing frame is an empty one.
    """

    def __init__(self, recorder: LogRecorder) -> None:
        self.rec = recorder
        self._types: set[str] = set()

    def __call__(self, frame, models: dict) -> None:
        for typ in frame.types:
            if typ not in self._types:
                self._types.add(typ)
                self.rec.write(TOPIC_VEHICLE_TYPES, frame.t, {"t": frame.t, "type": typ,
                                                              "model": model_to_dict(models[typ])})
        if not frame.ids:
            return
        self.rec.write(TOPIC_TRAFFIC, frame.t, {
            "t": frame.t, "ids": list(frame.ids), "x": frame.x.tolist(), "y": frame.y.tolist(),
            "speed": frame.v.tolist(), "acceleration": frame.a.tolist(), "types": list(frame.types)})


def traffic_from_log(contents: LogContents, length: float, step: float, until: float | None = None) -> FrameTraffic:
    """Rebuild the logged traffic frames as a traffic source for a bridge of ``length`` m.

    Frames the log does not hold were empty (no vehicle near the deck); they
    are filled in at their step times, up to ``until`` (s) if given.

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
