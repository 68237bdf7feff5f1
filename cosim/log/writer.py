"""Writing cosim logs: a crash-safe MCAP recorder and the observers that stream a run into it.

The writer (:class:`LogRecorder`) is a context manager: whatever ends the run
(normal end, Ctrl-C, an exception) a final status message is written and the
file is finished with its summary and index. A process killed outright
leaves the chunks already flushed; :mod:`cosim.log.reader` reads those and
says the file is truncated.

:class:`BlockLogger` streams the blocks of :func:`cosim.core.simulation.simulate`
(sensor samples, vehicles on the deck, events, status) and
:class:`TrafficLogger` the frames of a live traffic source (SUMO), so that a
log can be replayed. Topics and schemas: :mod:`cosim.log.schemas`.
"""
from __future__ import annotations

import bisect
import dataclasses
import itertools
import queue
import struct
import threading
import time
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO, Any

import numpy as np
from mcap.opcode import Opcode
from mcap.records import MessageIndex, Statistics
from mcap.writer import CompressionType, Writer

from cosim import __version__
from cosim.core.fields import VEHICLE_FIELDS, VEHICLE_NUMBERS, vehicle_of
from cosim.core.vehicles import model_to_dict
from cosim.errors import LogError, LogWriteError, interruption_message

from . import proto
from .schemas import (
    PROFILE,
    TOPIC_EVENTS,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLE_LOADS,
    TOPIC_VEHICLE_TYPES,
    TOPIC_VEHICLES,
    to_ns,
    topic_schemas,
)

_MESSAGE_HEAD = struct.Struct("<BQHIQQ")  # opcode, record length, channel id, sequence, log time, publish time
_MESSAGE_OPCODE = 0x05
_MESSAGE_FIXED = 22  # channel id (2) + sequence (4) + log time (8) + publish time (8)


class _MessageIndex(MessageIndex):
    """A message index record written in one ``struct.pack`` (the same bytes as mcap's per-entry writes)."""

    def write(self, stream) -> None:  # noqa: ANN001 - mcap's RecordBuilder
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(len(self.records) * 16)
        stream.write(np.array(self.records, dtype="<u8").tobytes())
        stream.finish_record()


@dataclasses.dataclass(frozen=True)
class _ChunkState:
    """What :class:`_BulkWriter`'s bulk path updates of mcap's :class:`Writer`, as ``add_message`` would."""

    builder: Any  # the chunk being built (mcap's ChunkBuilder: record_writer, message_indices, times, count)
    statistics: Statistics
    chunk_size: int
    finish_if_full: Callable[[], None]  # writes the chunk out once it is over ``chunk_size``


#: The chunk builder's fields the bulk path reads and updates.
_BUILDER_FIELDS = ("record_writer", "message_indices", "message_start_time", "message_end_time", "num_messages")


def _mcap_chunk_state(writer: Writer) -> _ChunkState | None:
    """The chunk state of an mcap :class:`Writer`, or None if the installed mcap keeps it otherwise."""
    # Why: mcap's Writer has no public bulk path for pre-encoded messages (tests/unit/test_log.py guards this).
    try:
        state = _ChunkState(builder=writer._Writer__chunk_builder,  # type: ignore[attr-defined]
                            statistics=writer._Writer__statistics,  # type: ignore[attr-defined]
                            chunk_size=writer._Writer__chunk_size,  # type: ignore[attr-defined]
                            finish_if_full=writer._Writer__maybe_finalize_chunk)  # type: ignore[attr-defined]
    except AttributeError:
        return None
    builder = state.builder
    usable = (isinstance(state.statistics, Statistics) and isinstance(state.chunk_size, int)
              and all(hasattr(builder, name) for name in _BUILDER_FIELDS)
              and all(hasattr(builder.record_writer, name) for name in ("count", "write")))
    return state if usable else None


class _BulkWriter(Writer):
    """mcap's :class:`Writer` with a bulk path for many pre-encoded messages of one channel.

    The records, chunks, indexes and statistics are exactly those that
    ``add_message`` would write; only the Python work per message is less (one
    ``struct.pack`` and a list append instead of a record object, seven
    stream writes and their bookkeeping), which is most of the logging cost
    at 100 Hz. If the installed mcap's internals differ (:func:`_mcap_chunk_state`),
    it falls back to ``add_message`` per message.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._chunk_state = _mcap_chunk_state(self)

    def add_encoded(self, channel_id: int, log_times: list[int], datas: list[bytes], sequence: int) -> int:
        """Add ``datas[i]`` at ``log_times[i]`` (ns, also the publish time); returns the last sequence number."""
        state = self._chunk_state
        if state is None:
            for ns, data in zip(log_times, datas):
                sequence += 1
                self.add_message(channel_id, ns, data, ns, sequence)
            return sequence
        builder, stats, limit, finalize = state.builder, state.statistics, state.chunk_size, state.finish_if_full
        pack = _MESSAGE_HEAD.pack
        sizes = [9 + _MESSAGE_FIXED + len(d) for d in datas]
        ends = list(itertools.accumulate(sizes))  # record ends relative to the batch start
        start, n = 0, len(datas)
        while start < n:
            records_out = builder.record_writer  # the chunk's records (emptied after every finished chunk)
            base = records_out.count
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
            records_out.write(b"".join(parts))
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


class LogRecorder:
    """Write one run's MCAP log; use as a context manager.

    Args:
        path: the ``.mcap`` file to create.
        sensor_names: the sensor channels, in order.
        force: overwrite an existing file (otherwise refuse).
        chunk_size: bytes per chunk; small chunks lose little when the process is killed.
        scene: also register the 3D scene's topics (:mod:`cosim.log.scene`).
    """

    def __init__(self, path: str | Path, sensor_names: Iterable[str], force: bool = False,
                 chunk_size: int = 256 * 1024, scene: bool = False) -> None:
        self.path = Path(path)
        if self.path.exists() and not force:
            raise LogError(f"{self.path}: exists; refusing to overwrite a log (use --force)")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._stream: IO[bytes] = open(self.path, "wb")
        except OSError as exc:
            raise LogError(f"{self.path}: cannot create the log ({exc.strerror})") from None
        # Data-section CRC on: a reader can then tell a file changed after it was written (cosim.log.reader).
        self._writer = _BulkWriter(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD,
                                   enable_data_crcs=True)
        self._writer.start(profile=PROFILE, library=f"cosim {__version__}")
        self.sensor_names = list(sensor_names)
        self._channels: dict[str, int] = {}
        self._sequence = 0
        self._closed = False
        self.final_state: str | None = None
        schema_ids: dict[str, int] = {}
        names = tuple(self.sensor_names)
        self._specs: dict[str, proto.MessageSpec] = {}
        for topic, _ in topic_schemas(self.sensor_names, scene=scene):
            message = proto.TOPIC_MESSAGES[topic]
            if message not in schema_ids:  # one schema record for the topics that share it
                data = proto.schema_data(message, names)
                schema_ids[message] = self._writer.register_schema(message, proto.SCHEMA_ENCODING, data)
            self._channels[topic] = self._writer.register_channel(topic, proto.ENCODING, schema_ids[message])
            self._specs[topic] = proto.spec_of(message, names if topic == TOPIC_SENSORS else ())
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

    def spec(self, topic: str) -> proto.MessageSpec:
        """What the messages of ``topic`` are made of (:mod:`cosim.log.proto`)."""
        return self._specs[topic]

    def write(self, topic: str, t: float, message: dict[str, Any]) -> None:
        """One message on ``topic`` at simulated time ``t`` (s), given as the JSON log held it."""
        ns = to_ns(t)
        if topic == TOPIC_VEHICLE_TYPES:
            message = proto.vehicle_type_wire(message)
        data = proto.encode(self._specs[topic], message)
        with self._lock:
            self._sequence += 1
            self._writer.add_message(self._channels[topic], ns, data, ns, self._sequence)
            self._last_t = max(self._last_t, t)

    def write_encoded(self, topic: str, times: list[float], datas: list[bytes]) -> None:
        """Many messages on ``topic``, already encoded, at simulated times ``times`` (s)."""
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

    def __enter__(self) -> LogRecorder:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close("finished")
        elif issubclass(exc_type, KeyboardInterrupt):
            self.close("interrupted", interruption_message(exc))
        else:
            self.close("error", f"{exc_type.__name__}: {exc}")


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


#: The per-step arrays of a :class:`cosim.core.coupling.BlockReport` (rows: steps).
_PER_STEP = ("x", "v", "a", "on_deck", "contact_force", "body_displacement", "body_acceleration", "sensors",
             "lifted", "off_surface")
#: The :class:`cosim.core.coupling.BlockReport` array of a numeric vehicle field, where the names differ.
_REPORT_ARRAYS = {"speed": "v", "acceleration": "a", "y": "lateral"}


def load_message(t: float, record: Any, speed: float | None = None) -> dict[str, Any]:
    """A :class:`cosim.core.traffic.LoadRecord` as its ``/cosim/vehicle_loads`` message at time ``t`` (s)."""
    return {"t": t, "id": record.id, "class": record.vehicle_class, "lane": record.lane,
            "speed": float(record.speed if speed is None else speed), "gvw": float(record.gvw),
            "n_axles": len(record.axle_loads), "axle_loads": [float(v) for v in record.axle_loads],
            "axle_spacings": [float(v) for v in record.axle_spacings], "y": float(record.y),
            "wander": float(record.wander), "source": record.source}


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

    ``piece_steps``: a block is written in pieces of at most this many steps, each topic's messages of a
    piece together (the solver may hand over long blocks: one piece per topic would make chunks of each
    topic span many seconds, and a window of the log would read more chunks).

    The first ``len(sensor_names)`` sensor columns of a block are logged; columns after them (the
    scene's, :mod:`cosim.log.scene`) go only to ``scene`` (an object with ``write_block(times, report)``),
    which draws the 3D scene in the same thread.
    """

    def __init__(self, recorder: LogRecorder, sensor_names: Iterable[str], total_time: float,
                 status_every: float = 10.0, threaded: bool = True, scene: Any = None,
                 piece_steps: int | None = None) -> None:
        self.rec = recorder
        self.piece_steps = piece_steps
        self.names = list(sensor_names)
        self.scene = scene
        self.total_time = total_time
        self.status_every = status_every
        self._next_status = status_every
        self._on: dict[str, bool] = {}
        self._lifted: dict[str, bool] = {}
        self._off: dict[str, bool] = {}  # wheels beside the deck's surface at the end of the last block
        self._last_x: dict[str, float] = {}  # vehicles on the deck at the end of the last block: their x
        self._model_names: dict[str, str] = {}  # the last block's vehicles' models' names
        self._names_of: tuple[str, ...] = ()
        holes = {"t": proto.Hole(0), **{n: proto.Hole(i + 1) for i, n in enumerate(self.names)}}
        self._sensor_template = proto.FixedTemplate(recorder.spec(TOPIC_SENSORS), holes)
        self._vehicle_templates: dict[tuple[str, ...], proto.FixedTemplate] = {}
        self._error: BaseException | None = None
        self._pace: threading.Event | None = None
        self._closing = False
        self._queue: queue.Queue | None = None
        self._thread: threading.Thread | None = None
        self._traffic: TrafficLogger | None = None
        self._frames: list[tuple[Any, dict]] = []  # SUMO frames for the writer, handed over with the next block
        self._ahead: list[tuple[Any, dict]] = []  # frames handed over, for the pieces of a later block
        if threaded:
            self._queue = queue.Queue(maxsize=4)
            self._thread = threading.Thread(target=self._drain, name="cosim-log-writer", daemon=True)
            self._thread.start()

    @classmethod
    def for_run(cls, recorder: LogRecorder, sensor_names: Iterable[str], total_time: float, *, status_every: float,
                plan: Any, first_column: int, piece_steps: int | None, threaded: bool) -> BlockLogger:
        """The logger of a run: with ``plan``'s 3D scene (a :class:`cosim.log.scene.ScenePlan`, or None), started
        here (its static part and the deck at rest), drawn from the sensor columns from ``first_column`` on."""
        from .scene import SceneWriter  # the scene's drawing needs scipy: only runs that draw one load it

        scene = SceneWriter(recorder, plan, first_column) if plan is not None else None
        if scene is not None:
            scene.start()
        return cls(recorder, sensor_names, total_time, status_every=status_every, threaded=threaded, scene=scene,
                   piece_steps=piece_steps)

    def on_block(self, times, keep, report) -> None:
        if self._error is not None:
            raise LogWriteError(f"{self.rec.path}: writing the log failed: {self._error}")
        frames = self._frames[:]
        self._frames.clear()  # the same list: the traffic sink appends to it
        if self._queue is None:
            self._write_block(times, keep, report, frames)
        else:
            self._queue.put((times, keep, report, frames))

    def traffic_sink(self) -> TrafficLogger:
        """A frame sink for a live traffic source (SUMO) whose frames this logger's thread encodes and writes.

        Encoding every SUMO frame in the thread that runs SUMO cost that thread (the run's slowest) about a
        tenth of its time; the frames wait in a list until the next block is handed over, and :meth:`close`
        writes those still waiting.
        """
        self._traffic = TrafficLogger(self.rec, defer=self._frames)
        return self._traffic

    def paced(self, traffic: Any) -> _PacedTraffic:
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
        """Wait until every queued block (and every SUMO frame handed over) is written."""
        frames = self._frames[:]
        self._frames.clear()  # the same list: the traffic sink appends to it
        if self._traffic is not None:  # with those handed over earlier for pieces that did not come
            if self._queue is not None and self._thread is not None:
                self._queue.put((None, None, None, frames))
            elif self._error is None:
                self._write_block(None, None, None, frames)
        if self._thread is not None and self._queue is not None:
            self._closing = True
            if self._pace is not None:
                self._pace.set()
            self._queue.put(None)
            self._thread.join()
            self._thread = None
        if self._error is not None:
            where = getattr(self, "_error_trace", "").strip().splitlines()
            raise LogWriteError(f"{self.rec.path}: writing the log failed: {self._error!r}"
                           + (f" ({where[-3].strip()})" if len(where) >= 3 else ""))

    def __enter__(self) -> BlockLogger:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            self.close()
        except LogError:
            if exc_type is None:
                raise

    def _write_block(self, times, keep, report, frames: list[tuple[Any, dict]]) -> None:
        frames = self._ahead + frames
        self._ahead = []
        if times is None:  # only frames (the last ones, at close)
            if frames and self._traffic is not None:
                self._traffic.write_frames(frames)
            return
        if report.loads:
            self._write_loads(times, report)
        piece = self.piece_steps or len(times)
        for lo in range(0, len(times), piece):
            hi = min(lo + piece, len(times))
            if frames and self._traffic is not None:
                # SUMO runs ahead of the bridge (by a block or more): each piece takes the frames up to the end
                # of a piece after it, those beyond wait for the pieces they belong with.
                limit = 2.0 * times[hi - 1] - times[lo] + (times[1] - times[0] if len(times) > 1 else 0.0)
                upto = next((i for i, (f, _) in enumerate(frames) if f.t > limit + 1e-9), len(frames))
                self._traffic.write_frames(frames[:upto])
                frames = frames[upto:]
            part = report if (lo, hi) == (0, len(times)) else dataclasses.replace(
                report, **{name: getattr(report, name)[lo:hi] for name in _PER_STEP
                           if getattr(report, name) is not None})
            self._write_piece(times[lo:hi], keep[lo:hi], part)
        self._ahead = frames

    def _write_piece(self, times, keep, report) -> None:
        rec = self.rec
        kept = np.flatnonzero(keep)
        if len(kept):
            t = times[kept]
            values = np.column_stack([t, report.sensors[kept, :len(self.names)]])
            rec.write_encoded(TOPIC_SENSORS, t.tolist(), self._sensor_template.render(values))
        self._gone(times, report)
        if report.ids:
            self._events(times, report)
            self._vehicles(times, kept, report)
        if self.scene is not None:
            self.scene.write_block(times, report)
        if times[-1] >= self._next_status:
            rec.status(float(times[-1]), "running", progress=float(times[-1] / self.total_time))
            rec.flush()
            self._next_status += self.status_every

    def _write_loads(self, times, report) -> None:  # noqa: ANN001
        """One ``/cosim/vehicle_loads`` message per vehicle that came onto the deck in the block, at the step its
        first contact point did (its speed then, when the record leaves it to the entry)."""
        owners = [vehicle_of(i) for i in report.ids]
        for record in report.loads:
            cols = [j for j, o in enumerate(owners) if o == record.id]
            on = report.on_deck[:, cols].any(axis=1) if cols else np.zeros(len(times), dtype=bool)
            k = int(np.argmax(on)) if on.any() else 0
            speed = record.speed
            if not np.isfinite(speed):
                speed = abs(float(report.v[k, cols[0]])) if cols else 0.0
            t = float(times[k])
            self.rec.write(TOPIC_VEHICLE_LOADS, t, load_message(t, record, speed))

    def _gone(self, times, report) -> None:
        """Vehicles on the deck at the end of the last block that the traffic no longer has: they left
        (arrived or removed on the deck); the event carries where they were last."""
        present = set(report.ids)
        for vid in [v for v, on in self._on.items() if on and v not in present]:
            t = float(times[0])
            self.rec.write(TOPIC_EVENTS, t, {"t": t, "vehicle": vid, "event": "left",
                                             "x": self._last_x.pop(vid, 0.0)})
            self._on.pop(vid, None)
            self._lifted.pop(vid, None)

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
                if state[k, j] or names[0] != "left":
                    x = float(report.x[k, j])
                else:  # left: where it was last on the deck (a vehicle that vanished has no position after)
                    x = float(report.x[k - 1, j]) if k > 0 else self._last_x.get(ids[j], float(report.x[k, j]))
                self.rec.write(TOPIC_EVENTS, t, {"t": t, "vehicle": ids[j], "event": names[int(state[k, j])],
                                                 "x": x})
        off = report.off_surface
        if off is not None and off.any():
            prev_off = np.array([self._off.get(v, False) for v in ids])
            went = np.diff(np.vstack([prev_off[None, :], off]).astype(np.int8), axis=0) > 0
            for k, j in zip(*np.nonzero(went)):
                t = float(times[k])
                self.rec.write(TOPIC_EVENTS, t, {"t": t, "vehicle": ids[j], "event": "offdeck",
                                                 "x": float(report.x[k, j]), "y": float(report.lateral[k, j])})
        self._off = {v: bool(off[-1, j]) for j, v in enumerate(ids) if off[-1, j]} if off is not None else {}
        # Only the vehicles on the deck are remembered (a vehicle not in them is off it): the writer holds the
        # few on the deck, not every vehicle of a long run (a year of records is a million).
        for j, vid in enumerate(ids):
            if on[-1, j]:
                self._on[vid], self._lifted[vid] = True, bool(lifted[-1, j])
                self._last_x[vid] = float(report.x[-1, j])
            else:
                self._on.pop(vid, None)
                self._lifted.pop(vid, None)
                self._last_x.pop(vid, None)

    def _vehicle_template(self, ids: tuple[str, ...]) -> proto.FixedTemplate:
        """The message of these vehicles on the deck, in this order, with holes for ``t`` and their numbers
        (:data:`VEHICLE_FIELDS` order), made once per fleet."""
        template = self._vehicle_templates.get(ids)
        if template is None:
            holes = iter(range(1 + len(VEHICLE_NUMBERS) * len(ids)))
            text = {}
            vehicles = []
            for vid in ids:
                text = {"id": vid, "model": self._model_names[vid]}
                vehicles.append({f.name: text[f.name] if f.json_type == "string" else proto.Hole(next(holes) + 1)
                                 for f in VEHICLE_FIELDS})
            template = proto.FixedTemplate(self.rec.spec(TOPIC_VEHICLES), {"t": proto.Hole(0), "vehicles": vehicles})
            if len(self._vehicle_templates) > 256:
                self._vehicle_templates.clear()
            self._vehicle_templates[ids] = template
        return template

    def _vehicles(self, times, kept, report) -> None:
        """One message per kept step with a vehicle on the deck; encoded per group of steps with the same fleet."""
        ids = report.ids
        if ids != self._names_of:  # the block's vehicles' model names (the fleet's, not every vehicle's so far)
            self._model_names = {vid: getattr(model, "kind", type(model).__name__)
                                 for vid, model in zip(ids, report.models)}
            self._names_of = ids
        on = report.on_deck[kept]
        rows = np.flatnonzero(on.any(axis=1))
        if not len(rows):
            return
        steps = kept[rows]
        on = on[rows]
        shape = (len(steps), len(ids))
        columns = []
        for name in VEHICLE_NUMBERS:  # per step and vehicle, or per vehicle (the lateral offset)
            array = getattr(report, _REPORT_ARRAYS.get(name, name))
            columns.append(array[steps] if array.ndim == 2 else np.broadcast_to(array, shape))
        fields = np.stack(columns, axis=2)  # (samples, vehicles, numeric fields)
        width_per_vehicle = len(VEHICLE_NUMBERS)
        t = times[steps]
        out: list[bytes] = [b""] * len(steps)
        # Consecutive samples with the same vehicles on the deck share one template.
        change = np.flatnonzero(np.any(on[1:] != on[:-1], axis=1)) + 1
        bounds = np.concatenate([[0], change, [len(steps)]])
        for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
            cols = np.flatnonzero(on[lo])
            template = self._vehicle_template(tuple(ids[j] for j in cols))
            width = 1 + width_per_vehicle * len(cols)
            values = np.column_stack([t[lo:hi], fields[lo:hi][:, cols, :].reshape(hi - lo, width - 1)])
            out[lo:hi] = template.render(values)
        self.rec.write_encoded(TOPIC_VEHICLES, t.tolist(), out)


class TrafficLogger:
    """Frame sink for a live traffic source (SUMO): logs every frame with vehicles, and each new vehicle type.

    These are what :func:`cosim.log.replay_source.traffic_from_log` needs to re-drive a bridge with
    exactly the same vehicle kinematics (``cosim replay``). A frame without
    vehicles near the deck is not written: a missing frame is an empty one.
    """

    def __init__(self, recorder: LogRecorder, defer: list[tuple[Any, dict]] | None = None) -> None:
        self.rec = recorder
        self._types: set[str] = set()  # the types whose message is written
        self._models: dict[str, Any] = {}  # every type announced by the source (its model)
        self._defer = defer  # frames are appended here for a writer thread (BlockLogger.traffic_sink)
        self._strings: dict[tuple[int, str], bytes] = {}  # (field, id or type) -> its encoded field

    def attach(self, name: str, data: bytes | str, media_type: str = "text/plain") -> None:
        """A document of the traffic source (its vehicle types, SUMO's messages) as an attachment of the log."""
        self.rec.attach(name, data, media_type)

    def __call__(self, frame, new_models: dict) -> None:
        if self._defer is not None:
            self._defer.append((frame, new_models))  # frames are immutable, and so are the new models handed on
        else:
            self.write_frame(frame, new_models)

    def write_frames(self, frames: list[tuple[Any, dict]]) -> None:
        """Write frames handed over by :meth:`__call__`, in order: encoded together and added in one bulk
        write (per-message writes were a sixth of the log writer's time), a new vehicle type's message
        still before the first frame that has it."""
        times: list[float] = []
        datas: list[bytes] = []
        for frame, new_models in frames:
            if new_models:
                self._models.update(new_models)
            if any(typ not in self._types for typ in frame.types):
                self.rec.write_encoded(TOPIC_TRAFFIC, times, datas)
                times, datas = [], []
                self._write_types(frame)
            if frame.ids:
                times.append(frame.t)
                datas.append(self._encode(frame))
        self.rec.write_encoded(TOPIC_TRAFFIC, times, datas)

    def write_frame(self, frame, new_models: dict) -> None:
        """Write one frame (and the vehicle types it brings first)."""
        self.write_frames([(frame, new_models)])

    def _write_types(self, frame) -> None:  # noqa: ANN001
        for typ in frame.types:
            if typ not in self._types:
                self._types.add(typ)
                self.rec.write(TOPIC_VEHICLE_TYPES, frame.t, {"t": frame.t, "type": typ,
                                                              "model": model_to_dict(self._models[typ])})

    def _encode(self, frame) -> bytes:  # noqa: ANN001
        """A frame as its ``cosim.TrafficFrame`` (the strings' fields encoded once per id and type)."""
        strings = self._strings
        parts = [_T_FIELD, _DOUBLE.pack(frame.t)]
        for number, values in ((2, frame.ids), (7, frame.types)):
            for value in values:
                field = strings.get((number, value))
                if field is None:
                    if len(strings) > 100_000:
                        strings.clear()
                    field = strings[(number, value)] = proto.length_delimited(number, value.encode())
                parts.append(field)
        count = len(frame.ids)
        if count:
            head = _PACKED_LENGTH.get(count) or proto.varint(8 * count)
            for tag, values in ((b"\x1a", frame.x), (b"\x22", frame.y), (b"\x2a", frame.v), (b"\x32", frame.a)):
                parts += (tag, head, np.ascontiguousarray(values, dtype="<f8").tobytes())
        return b"".join(parts)


_T_FIELD = b"\x09"  # field 1 (t), a double
_DOUBLE = struct.Struct("<d")
_PACKED_LENGTH = {n: proto.varint(8 * n) for n in range(1, 16)}  # the length of n packed doubles
