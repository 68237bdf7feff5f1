"""The logged SUMO frames of a log as a traffic source again: what ``cosim replay`` re-drives a bridge with.

- :class:`LoggedTraffic`: read from the file as the run needs them (constant
  memory, chunk by chunk, frames the run has passed dropped);
- :func:`traffic_from_log`: the same from a log read whole (:func:`cosim.log.reader.read_log`),
  and :func:`read_traffic` from a log's path.

Frames the log does not hold were empty (no vehicle near the deck); both fill
them in at their step times with the live source's time expression, so that
replays are bit-identical. Every frame and vehicle type is checked as it is
read (:mod:`cosim.log.reader`), and malformed traffic is a
:class:`cosim.errors.LogError`.
"""
from __future__ import annotations

import collections
import os
from pathlib import Path

import numpy as np

from cosim.core.traffic import Frame, FramedSource, FrameTraffic, LoadRecord, TrafficBlock
from cosim.core.vehicles import model_from_dict
from cosim.errors import ConfigError, LogError

from .reader import LogContents, iter_messages, read_log
from .schemas import TOPIC_TRAFFIC, TOPIC_VEHICLE_LOADS, TOPIC_VEHICLE_TYPES

#: How far (s of logged time) the replay reads frames beyond the block it builds: a logged run writes the load
#: records of a block after the frames of the piece that follows it (cosim.log.writer.BlockLogger).
READ_AHEAD = 5.0


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
        self.traffic = FrameTraffic(step, length)
        self.frames = 0

    def vehicle_type(self, message: dict) -> None:
        try:
            self.traffic.add_models({message["type"]: model_from_dict(message["model"])})
        except (ConfigError, KeyError, TypeError, ValueError) as exc:
            raise LogError(f"{self.path}: a vehicle type on {TOPIC_VEHICLE_TYPES} (t = {message['t']:g} s) is not "
                           f"a valid vehicle model: {exc}") from None

    def vehicle_load(self, message: dict) -> None:
        """A logged ``/cosim/vehicle_loads`` message: the vehicle's load record goes with the replay's blocks
        again (so the replay's log records it too)."""
        record = LoadRecord(id=message["id"], vehicle_class=message["class"], lane=message["lane"],
                            speed=float(message["speed"]), gvw=float(message["gvw"]),
                            axle_loads=tuple(float(v) for v in message["axle_loads"]),
                            axle_spacings=tuple(float(v) for v in message["axle_spacings"]),
                            y=float(message["y"]), wander=float(message["wander"]), source=message["source"])
        self.traffic.add_load_record(record, float(message["t"]))

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
                    + [(ns, 1, m) for ns, m in frames]
                    + [(ns, 2, m) for ns, m in contents.messages.get(TOPIC_VEHICLE_LOADS, [])],
                    key=lambda e: (e[0], e[1]))
    for _, kind, message in merged:
        if kind == 0:
            feed.vehicle_type(message)
        elif kind == 1:
            feed.frame(message)
        else:
            feed.vehicle_load(message)
    if until is not None:
        feed.pad(until)
    return feed.traffic


def read_traffic(path: str | os.PathLike[str], length: float, step: float, until: float | None = None
                 ) -> tuple[FrameTraffic, int]:
    """The logged SUMO frames of the log at ``path`` as a traffic source (see :func:`traffic_from_log`),
    and how many frames the log holds."""
    contents = read_log(path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES, TOPIC_VEHICLE_LOADS])
    return traffic_from_log(contents, length, step, until), len(contents.messages.get(TOPIC_TRAFFIC, []))


class LoggedTraffic(FramedSource):
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
        self._messages = iter_messages(self.path, [TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES, TOPIC_VEHICLE_LOADS])
        self._waiting: collections.deque[dict] = collections.deque()  # logged frames read, not yet needed
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

    def _read_ahead(self, until: float) -> None:
        """Read the log on until a frame after ``until`` (s) is waiting, or its end: vehicle types and load
        records on the way are taken in, frames wait in order."""
        while not self._exhausted and (not self._waiting or float(self._waiting[-1]["t"]) <= until):
            for topic, message in self._messages:
                if topic == TOPIC_VEHICLE_TYPES:
                    self._feed.vehicle_type(message)
                elif topic == TOPIC_VEHICLE_LOADS:
                    self._feed.vehicle_load(message)
                else:
                    self._waiting.append(message)
                    break
            else:
                self._exhausted = True

    def block(self, times: np.ndarray) -> TrafficBlock:
        """The vehicles at ``times`` (s), interpolated between the logged frames (the TrafficSource protocol).

        Frames are read, and the empty ones between them made, only as far as ``times`` need (and
        :data:`READ_AHEAD` beyond: a run logs a block's load records after the frames of the block that
        follows it): a long stretch without vehicles costs no memory either.
        """
        traffic = self._feed.traffic
        step = self._feed.step
        need = float(times[-1])
        self._read_ahead(need + READ_AHEAD)
        while traffic.last_time < need - 1e-9:
            if self._waiting and float(self._waiting[0]["t"]) < need + 0.5 * step:
                self._feed.frame(self._waiting.popleft())  # the empty frames before it, then it
            else:  # the next logged frame lies beyond: empty frames up to ``need``
                self._feed.pad(min(need, self.until) + 0.5 * step - 1e-9)
                if not self._waiting and self._exhausted and traffic.last_time < need - 1e-9:
                    break  # past the replay's end: FrameTraffic says so
        traffic.follows_paths = self.follows_paths
        out = traffic.block(times)
        traffic.forget_before(need)
        return out

    def close(self) -> None:
        """Close the log file (also done when the source is garbage-collected)."""
        self._messages.close()  # type: ignore[attr-defined]
