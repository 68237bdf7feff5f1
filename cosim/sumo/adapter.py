"""SUMO adapter: the only module that imports libsumo.

SUMO runs at its own step. The adapter watches the lanes on which a vehicle
can have an axle on the deck (:func:`cosim.sumo.network.watched_lanes`: the
deck's lanes, the junction lanes at its ends and the lanes before and after,
as far as the longest vehicle reaches) and reads each vehicle on them at every
step: position (front bumper), heading, speed and acceleration; its type and
length once, when first seen (libsumo's getters: its subscriptions cost more). A vehicle is followed by
position, not by the edge it is on: it stays in the frames while it crosses
the junction at a deck end, so each of its axles is on the deck from the
moment it passes one end until it passes the other. Each vehicle becomes one
contact point per axle (a quarter-car per axle, or one half-car body on all
of them: :mod:`cosim.sumo.vtypes`), each at its distance behind the
bumper on the path the bumper drove (:mod:`cosim.core.axle_paths`: a turning
vehicle's rear axles stay on their lane), projected onto the bridge axis (x
along the axis from its start point, y to the left of it); it loads the deck
while that projection lies on it (:func:`cosim.core.traffic.on_deck`) within
the deck's width (for a bridge placed by its axis alone, also a wheel up to
:data:`BESIDE_DECK` beside its width over its length, which the run then
reports as off the deck). The frames feed :class:`cosim.core.traffic.FrameTraffic`, which the
beam sub-steps through with SUMO's ballistic motion between frames.

The user's SUMO config stays theirs: SUMO runs on a copy of it and the files
it names in a scratch folder, with its messages (log, warnings, errors) going
to a file there that cosim reads (:attr:`SumoTraffic.messages`), nothing on
the terminal, and every output the config asks for (trip info, detectors,
...) written into that folder and discarded with it.

``libsumo`` is a per-process singleton: one SUMO simulation per process; it is
imported inside :meth:`SumoTraffic.start`, so importing this module does not load it.
"""
from __future__ import annotations

import contextlib
import itertools
import math
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from cosim.core.axle_paths import (
    AxisFrame,
    AxleTrails,
    LaneLine,
    contact_settings,
    contact_step,
    lane_line,
    path_behind,
)
from cosim.core.traffic import Frame, FramedSource, FrameSink, FrameTraffic, LoadRecord, TrafficBlock
from cosim.core.vehicles import VehicleModel
from cosim.errors import ConfigError, SumoError, first_line
from cosim.sumo.attachments import MESSAGES_FILE, VEHICLE_TYPES_ATTACHMENT
from cosim.sumo.files import Demand, read_demand, read_sumo_set, write_sumo_set
from cosim.sumo.install import bundled_networks, captured_output, sumo_binary
from cosim.sumo.loads import LoadSettings, VehicleLoads
from cosim.sumo.network import (
    REACH_SLACK,
    BridgeAxis,
    deck_directions,
    lanes_across,
    locate_bridge,
    net_path,
    watched_lanes,
)
from cosim.sumo.reads import SumoReads
from cosim.sumo.records import RecordFeed, RecordsPlan
from cosim.sumo.vtypes import LOADS_G, VehicleType, vehicle_type

__all__ = ["MESSAGES_FILE", "VEHICLE_TYPES_ATTACHMENT", "WATCH_MARGIN", "BridgeAxis", "LiveSumo", "SumoSettings",
           "SumoTraffic", "bundled_networks", "sumo_binary"]

#: The least reach of the watched lanes beyond the deck ends, m (the longest vehicle plus slack if longer).
WATCH_MARGIN = 12.0
_EMPTY = np.zeros(0)
#: SUMO steps between two looks for vehicles driving away beyond the watched reach (no longer read then).
DROP_DEPARTED_EVERY = 20
#: For a bridge placed by its axis alone, wheels this far beside the deck's width (m, a lane's width) over its
#: length stay in the frames (and the lanes there are watched): a vehicle on a lane the deck does not cover is
#: seen, and logged as off the deck, not silently left out. A bridge located by its edges needs none: the
#: deck covers their lanes (checked before the run), and another carriageway beside it is another structure.
BESIDE_DECK = 3.75
#: SUMO's built-in vTypes that carry no road vehicles (persons, containers, rail).
_BUILT_IN_OTHER = ("DEFAULT_PEDTYPE", "DEFAULT_CONTAINERTYPE", "DEFAULT_RAILTYPE")


@dataclass(frozen=True)
class SumoSettings:
    """What a SUMO run is: the config, where the bridge is in its network, the times, the seed.

    Attributes:
        config: the ``.sumocfg`` to run (it is copied with its files into a scratch folder and run there).
        axis: where the bridge is in the network.
        step: SUMO's step length, s (the beam's dt must divide it).
        begin, end: SUMO times to run, s (the co-simulation's t = 0 is ``begin``).
        edges: the deck's edges; their lanes (and the opposite direction's between the same junctions)
            are the deck's. None: every lane running through the deck's box.
        seed: SUMO's random seed (recorded in the log), or None for the config's.
        deck_y: the deck's lateral extent (y_min, y_max), m: an axle outside it is not on the bridge.
        extra_args: further SUMO command-line options.
        demand: the config's demand files as read (:func:`cosim.sumo.files.read_demand`), if already read.
        loads: each vehicle's own loads from a WIM-calibrated model (``[traffic.loads]``), or None: the vTypes'.
        records: WIM records inserted into the network (``[traffic.records] via = "sumo"``,
            :mod:`cosim.sumo.records`), or None.

    Raises:
        SumoError, ConfigError: a config that is not there, a step or times that are not physical.
    """

    config: Path
    axis: BridgeAxis
    step: float = 0.05
    begin: float = 0.0
    end: float = 600.0
    edges: tuple[str, ...] | None = None
    seed: int | None = None
    deck_y: tuple[float, float] = (-50.0, 50.0)
    extra_args: tuple[str, ...] = ()
    demand: Demand | None = None
    loads: LoadSettings | None = None
    records: RecordsPlan | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "config", Path(self.config))
        if not self.config.is_file():
            raise SumoError(f"{self.config}: SUMO config not found")
        if not self.step > 0:
            raise ConfigError(f"traffic `step` must be > 0 s (got {self.step})")
        if not self.end > self.begin:
            raise ConfigError(f"traffic `end` ({self.end} s) must be after `begin` ({self.begin} s)")
        object.__setattr__(self, "step", float(self.step))
        object.__setattr__(self, "deck_y", (float(self.deck_y[0]), float(self.deck_y[1])))
        object.__setattr__(self, "edges", tuple(self.edges) if self.edges else None)
        object.__setattr__(self, "extra_args", tuple(self.extra_args))


class LiveSumo(FramedSource):
    """SUMO's frames as a traffic source: what SUMO stepped in this process (:class:`SumoTraffic`) and in a
    child process (:class:`cosim.run.sumo_process.SumoProcess`) share.

    Its frames go, as they come, into the :class:`~cosim.core.traffic.FrameSink` it is built with (a log),
    each with the models of the vehicle types that became known since the frame before (every consumer keeps
    its own table: none is shared). The sink also gets the vehicle-type table when SUMO has started and
    SUMO's messages when it has closed. The frames feed a :class:`~cosim.core.traffic.FrameTraffic`, which the
    beam sub-steps through.
    """

    def __init__(self, settings: SumoSettings, frame_sink: FrameSink | None = None) -> None:
        self.settings = settings
        self.frame_sink = frame_sink
        self.edges: tuple[str, ...] = ()
        self.lanes: tuple[str, ...] = ()
        self.deck_lanes: tuple[str, ...] = ()
        self.reach = WATCH_MARGIN
        self._models: dict[str, VehicleModel] = {}  # every type known so far (this source's own table)
        self._fresh: dict[str, VehicleModel] = {}  # known since the last frame was handed on
        self.types: dict[str, VehicleType] = {}
        self.frames: FrameTraffic | None = None
        self.sumo_steps = 0
        self.teleports = 0
        self.messages = ""  # SUMO's own messages, once closed

    @property
    def config(self) -> Path:
        return self.settings.config

    @property
    def axis(self) -> BridgeAxis:
        return self.settings.axis

    @property
    def step(self) -> float:
        return self.settings.step

    @property
    def begin(self) -> float:
        return self.settings.begin

    @property
    def end(self) -> float:
        return self.settings.end

    @property
    def seed(self) -> int | None:
        return self.settings.seed

    @property
    def deck_y(self) -> tuple[float, float]:
        return self.settings.deck_y

    @property
    def models(self) -> Mapping[str, VehicleModel]:
        """Every vehicle type known so far -> its model (read-only)."""
        return MappingProxyType(self._models)

    def take_new_models(self) -> dict[str, VehicleModel]:
        """The vehicle types known since the last call (or the last frame handed on), no longer new after it:
        what a consumer of the frames has not seen yet, without going through every type so far (a day of
        vehicles with their own loads makes tens of thousands)."""
        fresh, self._fresh = self._fresh, {}
        return fresh

    def _known(self, models: Mapping[str, VehicleModel]) -> None:
        """More vehicle types (those already known are kept as they are)."""
        for key, model in models.items():
            if key not in self._models:
                self._models[key] = model
                self._fresh[key] = model

    def _attach(self, name: str, data: bytes | str, media_type: str) -> None:
        if self.frame_sink is not None:
            self.frame_sink.attach(name, data, media_type)

    # ------------------------------------------------------------- lifecycle
    def start(self) -> LiveSumo:
        """Start SUMO; the sink gets the vehicle-type table (model, mass, axles and their sources)."""
        table = self._start_sumo()
        try:
            self._attach(VEHICLE_TYPES_ATTACHMENT, table, "application/json")
        except BaseException:
            self.close()
            raise
        self.frames = FrameTraffic(self.step, self.axis.length)
        return self

    def close(self) -> None:
        """Close SUMO (idempotent); the sink gets SUMO's messages (the log may already be closed: then not)."""
        if self._close_sumo() and self.messages:
            with contextlib.suppress(Exception):  # the log may already be closed (its own failure)
                self._attach(MESSAGES_FILE, self.messages, "text/plain")

    def __enter__(self) -> LiveSumo:
        return self.start()

    def block(self, times: np.ndarray) -> TrafficBlock:
        """Take SUMO's frames as far as ``times`` (s from ``begin``) need, each handed to the frame sink as it
        comes, and interpolate the vehicles there."""
        frames = self.frames
        if frames is None:
            raise SumoError(f"{type(self).__name__}.start() was not called")
        while frames.last_time < times[-1] - 1e-9:
            if self.begin + frames.last_time + self.step > self.end + 1e-9:
                raise SumoError(f"SUMO's run ends at {self.end} s; the co-simulation asked for {times[-1]} s")
            frame = self._next_frame()
            fresh = self.take_new_models()
            frames.add_frame(frame, fresh)
            if self.frame_sink is not None:
                self.frame_sink(frame, fresh)
        frames.follows_paths = self.follows_paths
        out = frames.block(times)
        frames.forget_before(float(times[-1]))
        return out

    # ----------------------------------------------- what each way of running SUMO does
    def _start_sumo(self) -> str:
        """Start SUMO; the vehicle-type table as JSON."""
        raise NotImplementedError

    def _next_frame(self) -> Frame:
        """SUMO's next frame (one step)."""
        raise NotImplementedError

    def _close_sumo(self) -> bool:
        """Close SUMO and take its messages; False if it was not running."""
        raise NotImplementedError


@dataclass
class _AxleLayout:
    """The contact points of one set of followed vehicles (:meth:`SumoTraffic._new_layout`)."""

    vehicles: tuple[str, ...]  # sorted
    vehicle_types: list[str]  # each vehicle's (its own, for a vehicle with its own loads)
    slots: np.ndarray  # each vehicle's trail
    owner: np.ndarray  # each contact point's vehicle (row)
    back: np.ndarray  # each contact point's distance behind the bumper, m
    left: np.ndarray  # each contact point's offset to the left of its path, m (empty: all on it)
    wander: np.ndarray  # each contact point's vehicle's wander in its lane, m (empty: no loads' table)
    ids: tuple[str, ...]  # each contact point's id (``vehicle#k`` for axle k of several)
    types: tuple[str, ...]  # each contact point's model key
    unrecorded: bool  # a vehicle whose load record has not gone out


class SumoTraffic(LiveSumo):
    """Vehicles from a SUMO simulation stepped in this process (through libsumo), as a traffic source.

    Args:
        config, axis, step, begin, end, edges, seed, extra_args, deck_y, demand: the run (:class:`SumoSettings`).
        half_width: lateral half-width of the deck, m, when ``deck_y`` is not given.
        frame_sink: where every frame goes (e.g. a log's TrafficLogger), with the vehicle-type table at the
            start and SUMO's messages at the end (:class:`~cosim.core.traffic.FrameSink`).
        settings: the run as one value instead (the other arguments but ``frame_sink`` are then not read).
    """

    def __init__(
        self,
        config: str | os.PathLike | None = None,
        axis: BridgeAxis | None = None,
        step: float = 0.05,
        begin: float = 0.0,
        end: float = 600.0,
        edges: Sequence[str] | None = None,
        seed: int | None = None,
        half_width: float = 50.0,
        extra_args: Sequence[str] = (),
        frame_sink: FrameSink | None = None,
        deck_y: tuple[float, float] | None = None,
        demand: Demand | None = None,
        *,
        settings: SumoSettings | None = None,
    ) -> None:
        if settings is None:
            if config is None or axis is None:
                raise ConfigError("SumoTraffic needs a config and an axis (or settings)")
            settings = SumoSettings(Path(config), axis, step, begin, end, tuple(edges) if edges else None, seed,
                                    deck_y if deck_y is not None else (-half_width, half_width), tuple(extra_args),
                                    demand)
        super().__init__(settings, frame_sink)
        self.demand = settings.demand
        self._axles: dict[str, tuple[tuple[float, float], ...]] = {}  # per contact: behind the bumper, left, m
        self._sideways: set[str] = set()  # the types with a contact point beside the path (left != 0)
        self._draws = VehicleLoads(settings.loads) if settings.loads is not None else None
        self._feed = RecordFeed(settings.records, settings.step, settings.begin) if settings.records else None
        self._own: dict[str, VehicleType] = {}  # a vehicle with its own loads -> its vehicle type
        self._label: dict[str, tuple[str, float, str]] = {}  # vehicle -> its class, wander (m), loads' source
        self._recorded: set[str] = set()  # vehicles whose load record went out (at their entry onto the deck)
        self._trails: AxleTrails | None = None  # each followed vehicle's bumper path (its axles stand on it)
        self._lane_geometry: dict[str, LaneLine | None] = {}  # None: a line of fewer than two points
        self.deck_directions: dict[str, int] = {}  # deck edge -> Grave's direction: 1 along the axis, 2 against
        self.libsumo: Any = None  # the libsumo module once started (imported there, not here)
        self._scratch: Path | None = None
        self._watched: set[str] = set()
        self._done: set[str] = set()  # on a watched lane, but past the deck for good: not followed
        self._fixed: dict[str, tuple[str, float]] = {}  # each followed vehicle's SUMO type and length, m
        self._layout: _AxleLayout | None = None  # the contact points of the vehicles followed at the last step
        self._read: SumoReads | None = None  # libsumo's getters read at every step (once started)

    @property
    def half_width(self) -> float:
        return max(abs(self.deck_y[0]), abs(self.deck_y[1]))

    def _start_sumo(self) -> str:
        import json

        import libsumo  # the one place cosim imports libsumo

        if self.demand is None:
            self.demand = read_demand(self.config)
        self._scratch = Path(tempfile.mkdtemp(prefix="cosim-sumo-"))
        try:
            config = write_sumo_set(read_sumo_set(self.config, self.config.stem), self._scratch)
        except Exception:
            self._remove_scratch()
            raise
        messages = self._scratch / MESSAGES_FILE
        cmd = [
            sumo_binary(), "-c", str(config),
            "--step-length", repr(self.step),
            "--begin", repr(self.begin), "--end", repr(self.end),
            "--step-method.ballistic", "true",
            # SUMO's messages into the scratch folder, none on the terminal (warnings included:
            # --no-warnings keeps them off the terminal, --error-log still writes them).
            "--verbose", "false", "--no-step-log", "true", "--no-warnings", "true",
            "--log", str(messages), "--error-log", str(messages),
            "--gui-settings-file", "",  # a GUI-only file (a user's config may name one that is not there)
            *(["--seed", str(self.seed)] if self.seed is not None else []),
            *self.settings.extra_args,
        ]
        self.libsumo = libsumo
        self._read = SumoReads.of(libsumo)
        try:
            with captured_output(self._scratch / "console.txt"):
                libsumo.start(cmd)
        except Exception as exc:  # libsumo raises its own error types; SUMO said why on its console
            self.libsumo = None
            reason = self._sumo_error() or first_line(exc)
            self._remove_scratch()
            raise SumoError(f"{self.config}: SUMO could not load it: {reason}") from None
        try:
            self._watch()
            if self._feed is not None:
                self._feed.define_types(libsumo)
            # Every vType known at the start is turned into its vehicle model now, so that an
            # impossible parameter stops the run before it starts, naming the vType.
            for type_id in libsumo.vehicletype.getIDList():
                if type_id not in self.demand.distributions and type_id not in _BUILT_IN_OTHER:
                    self._model(type_id)
            if self._feed is not None:
                self._feed.start(self.types)
            self._extend_reach()
            self._trails = AxleTrails(self.reach)
        except Exception:
            self.close()
            raise
        self._unit = self.axis.unit()
        self._axis_frame = AxisFrame(np.array(self.axis.start, dtype=float), *self._unit)
        return json.dumps([t.summary() for t in self.table()], indent=1)

    def _close_sumo(self) -> bool:
        was_running = self.libsumo is not None or self._scratch is not None
        if self._feed is not None:
            self._feed.close()
        if self.libsumo is not None:
            try:
                with captured_output(self._scratch / "console.txt") if self._scratch else contextlib.nullcontext():
                    self.libsumo.close()
            except Exception:  # noqa: BLE001 - closing a failed simulation must not mask the first error
                pass
            self.libsumo = None
        if self._scratch is not None:
            self.messages = self._read_messages()
            self._remove_scratch()
        return was_running

    def _read_messages(self) -> str:
        assert self._scratch is not None
        parts = []
        for name in ("console.txt", MESSAGES_FILE):
            path = self._scratch / name
            if path.is_file():
                with contextlib.suppress(OSError):
                    parts.append(path.read_text(encoding="utf-8", errors="replace"))
        return "".join(parts)

    def _sumo_error(self) -> str:
        """SUMO's first error line ("Error: ..."), from its console or its log."""
        if self._scratch is None:
            return ""
        for line in self._read_messages().splitlines():
            if line.startswith("Error:"):
                return line[len("Error:"):].strip()
        return ""

    def _remove_scratch(self) -> None:
        if self._scratch is not None:
            shutil.rmtree(self._scratch, ignore_errors=True)
            self._scratch = None

    def table(self) -> list[VehicleType]:
        """Every vType of the demand files (and SUMO's default one when a vehicle names no type) as the beam
        sees it: as SUMO resolved it, or, for one SUMO has not loaded yet (route files load as the run goes),
        as its file says."""
        demand = self.demand or Demand()
        wanted = [t for t in demand.vtypes if t not in demand.distributions]
        if demand.untyped:
            wanted.append("DEFAULT_VEHTYPE")
        out = []
        for type_id in wanted:
            if type_id in self.types:
                out.append(self.types[type_id])
                continue
            entry = demand.vtypes.get(type_id)
            if entry is not None:
                out.append(vehicle_type(type_id, entry.vclass or "passenger", entry.length, entry.mass, entry.params))
        return out

    def _watch(self) -> None:
        """The deck's lanes (the named edges', or those through the deck's box); the watched lanes around them."""
        net = net_path(self.config)
        try:
            if self.settings.edges is not None:
                location = locate_bridge(net, self.settings.edges)
                self.edges = (*location.edges, *location.opposite)
                deck = location.deck_lanes
            else:
                # Lanes beside the deck's width too: their wheels are seen (and logged as off the deck), not lost.
                lo, hi = self.deck_y
                deck = lanes_across(net, self.axis, (lo - BESIDE_DECK, hi + BESIDE_DECK))
                self.edges = tuple(dict.fromkeys(lane.rsplit("_", 1)[0] for lane in deck))
        except ConfigError as exc:
            raise SumoError(f"{self.config}: {exc}") from None
        if not deck:
            raise SumoError(
                f"{self.config}: no lane of the network lies on the bridge axis "
                f"{self.axis.start} -> {self.axis.end}; check [traffic] axis or edges"
            )
        self.deck_lanes = tuple(deck)
        self.deck_directions = deck_directions(net, self.deck_lanes, self.axis)
        self._watched_lanes: set[str] = set()
        self._watch_lanes(net)

    def _watch_lanes(self, net: Path) -> None:
        """Watch the lanes within :attr:`reach` of the deck: each is asked for its vehicles at every step (edge
        context subscriptions miss vehicles at some steps, cf. eclipse-sumo/sumo#16422; and libsumo's
        subscriptions cost more inside each step than the getters they replace: benchmarks/results/profile.md)."""
        self._watched_lanes.update(watched_lanes(net, self.deck_lanes, self.reach))
        self.lanes = tuple(self._watched_lanes)
        # The contact points kept (contact_step's region, bridge coordinates, m): on the deck's width within the
        # reach along it, or beside the width over the deck's length (a bridge placed by its axis alone).
        beside = 0.0 if self.settings.edges else BESIDE_DECK
        self._contact_settings = contact_settings(self.deck_y, self.reach, self.axis.length, beside, self.step)

    def _extend_reach(self) -> None:
        """Watch far enough for the longest vehicle type known so far (its last axle still on the deck)."""
        longest = max(max((t.length for t in self.types.values()), default=0.0),
                      self._feed.longest if self._feed is not None else 0.0)
        wanted = max(WATCH_MARGIN, longest + REACH_SLACK)
        if wanted > self.reach + 1e-9 or not self.lanes:
            self.reach = wanted
            self._watch_lanes(net_path(self.config))
            if self._trails is not None:
                self._trails.ensure_reach(self.reach)

    # --------------------------------------------------------------- stepping
    def _model(self, type_id: str) -> None:
        if type_id in self.types:
            return
        vt = self.libsumo.vehicletype
        demand = self.demand or Demand()
        entry = demand.vtypes.get(type_id)
        # The vType's own mass only when its file sets one: SUMO's default masses are never used.
        mass = entry.mass if entry is not None else None
        params = entry.params if entry is not None else {}
        typ = vehicle_type(type_id, vt.getVehicleClass(type_id), vt.getLength(type_id), mass, params)
        self.types[type_id] = typ
        columns = typ.contact_columns()
        self._axles[type_id] = tuple((back, left) for _, _, back, left in columns)
        if any(left for _, left in self._axles[type_id]):
            self._sideways.add(type_id)
        models = {key: model for key, model, _, _ in columns}
        if len(columns) > 1:
            models[type_id] = typ.model
        self._known(models)

    def _next_frame(self) -> Frame:
        return self.advance()

    def advance(self) -> Frame:
        """One SUMO step; returns the frame of vehicles near the bridge."""
        ls = self.libsumo
        feed = self._feed
        if feed is not None and feed.insert(ls, ls.simulation.getTime()) and \
                feed.longest + REACH_SLACK > self.reach + 1e-9:
            self._extend_reach()  # a record longer than any vehicle so far: watch farther
        try:
            ls.simulationStep()
            self.teleports += ls.simulation.getStartingTeleportNumber()
            if feed is not None and feed.live:
                feed.gone(ls.simulation.getArrivedIDList())
        except Exception as exc:  # noqa: BLE001 - SUMO errors come as several libsumo exception types
            raise SumoError(f"SUMO failed at t = {ls.simulation.getTime() if ls else '?'} s: {first_line(exc)}") \
                from None
        self.sumo_steps += 1
        t = self.sumo_steps * self.settings.step
        read = self._read
        assert read is not None
        present = set(itertools.chain.from_iterable(map(read.lane_vehicles, self.lanes)))
        done = self._done
        if done:
            done &= present  # a vehicle that left the watched lanes is forgotten
            present -= done
        same = present == self._watched  # most steps: the same vehicles as the step before
        if not same:
            fixed = self._fixed
            veh = ls.vehicle
            for vid in present - self._watched:  # what does not change while it drives: read once
                fixed[vid] = (veh.getTypeID(vid), veh.getLength(vid))
            for vid in self._watched - present:
                self._forget(vid)
            self._watched = present
        if not present:
            return Frame(t, (), _EMPTY, _EMPTY, _EMPTY, _EMPTY, ())
        layout = self._layout
        # The same vehicles: the layout made for them at the step before is theirs (a vehicle gone drops it).
        ids = layout.vehicles if same and layout is not None else tuple(sorted(present))
        trails = self._trails
        assert trails is not None
        position, angle, speed, acceleration = read.position, read.angle, read.speed, read.acceleration
        fixed = self._fixed
        flat: list[float] = []  # one flat list, reshaped: a third cheaper than numpy's reading a list of tuples
        for vid in ids:
            flat += position(vid)
            flat += (angle(vid), speed(vid), acceleration(vid), fixed[vid][1])
        num = np.array(flat, dtype=float).reshape(-1, 6)
        if layout is None or layout.vehicles != ids:
            layout = self._layout = self._new_layout(ids, num)
        # One contact point per axle (a vType without axles: one at mid-length), behind the bumper on the path
        # it drove, with its offsets (cosim.core.axle_paths). Axles in the region kept (a vehicle on a long lane
        # after the deck is dropped once far from it); a vehicle's axles stay together (one body, several axles).
        owner = layout.owner
        xyva, marks, kept, on_deck = contact_step(num, layout.slots, trails.arrays, layout.back, owner, layout.left,
                                                  layout.wander, self._axis_frame, self._contact_settings)
        loads: tuple[LoadRecord, ...] = ()
        if layout.unrecorded and on_deck:  # a vehicle whose load record has not gone out yet
            loads = self._entering(ids, layout.vehicle_types, num, owner, xyva[0], xyva[1])
            if loads:
                layout.unrecorded = any(vid not in self._recorded for vid in ids)
        # Vehicles gone for good are dropped every few steps, at the steps they were before contact_step found them
        # at every one (the same layouts and slots as then); a late drop only reads a far vehicle a while longer.
        axle_ids, axle_types = layout.ids, layout.types
        contacts = len(axle_ids)
        if self.sumo_steps % DROP_DEPARTED_EVERY == 0 and marks[contacts:].any():
            self._drop_departed(ids, marks[contacts:])
        if kept < contacts:  # one selection of the four rows, the names by a list of flags (not numpy's bools)
            keep = marks[:contacts]
            flags = keep.tolist()
            axle_ids = tuple(itertools.compress(axle_ids, flags))
            axle_types = tuple(itertools.compress(axle_types, flags))
            xyva = xyva[:, keep]
        x, y, v, a = xyva
        return Frame(t, axle_ids, x, y, v, a, axle_types, loads)  # by position: a third cheaper than by keywords

    def _new_layout(self, ids: tuple[str, ...], num: np.ndarray) -> _AxleLayout:
        """The contact points of a set of followed vehicles (sorted ids), which stay the same from step to step
        while the set does: each vehicle's type (a new one modelled), first sight (trail, loads), slot, its axles'
        owners, distances behind the bumper, sideways offsets and wander, their ids and types."""
        feed, fixed, trails = self._feed, self._fixed, self._trails
        assert trails is not None
        vtypes = [fixed[vid][0] for vid in ids]
        if feed is not None and feed.live:  # a record's SUMO type is its own (its length): modelled as its vType's
            live = feed.live
            vtypes = [live[vid].base if vid in live else typ for vid, typ in zip(ids, vtypes)]
        for typ in dict.fromkeys(vtypes):
            if typ not in self.types:
                self._model(typ)
                self._extend_reach()  # a longer vehicle than any known so far: watch farther
        for j, vid in enumerate(ids):
            if vid not in trails.slot_of:
                trails.add(vid)
                self._seed_trail(vid, num[j])
                self._first_sight(vid, vtypes[j], num[j])
        own = self._own
        types = [own[vid].id if vid in own else typ for vid, typ in zip(ids, vtypes)] if own else vtypes
        lengths = num[:, 5]
        axle_ids, axle_types = list(ids), types
        if all(len(self._axles[typ]) == 1 for typ in types):
            owner = np.arange(len(ids))
            back = 0.5 * lengths
        else:
            owner = np.array([i for i, typ in enumerate(types) for _ in self._axles[typ]], dtype=np.int64)
            back = np.array([d if len(self._axles[typ]) > 1 else 0.5 * length
                             for typ, length in zip(types, lengths) for d, _ in self._axles[typ]], dtype=float)
            axle_ids = [vid if len(self._axles[typ]) == 1 else f"{vid}#{k}"
                        for vid, typ in zip(ids, types) for k in range(len(self._axles[typ]))]
            axle_types = [typ if len(self._axles[typ]) == 1 else f"{typ}#{k}"
                          for typ in types for k in range(len(self._axles[typ]))]
        left = _EMPTY  # none beside its path
        if self._sideways and not self._sideways.isdisjoint(types):
            left = np.array([side for typ in types for _, side in self._axles[typ]])
        wander = _EMPTY  # none wanders
        if self._draws is not None or feed is not None:
            wander = np.array([self._label[vid][1] if vid in self._label else 0.0 for vid in ids])[owner]
        return _AxleLayout(vehicles=ids, vehicle_types=types, slots=trails.slots(ids), owner=owner, back=back,
                           left=left, wander=wander, ids=tuple(axle_ids), types=tuple(axle_types),
                           unrecorded=any(vid not in self._recorded for vid in ids))


    # ----------------------------------------------------------------- loads
    def _first_sight(self, vid: str, vtype: str, row: np.ndarray) -> None:
        """A vehicle seen for the first time: with ``[traffic.loads]``, what it carries (its own vehicle type,
        class, wander and the loads' source), drawn from the seed and its id, for the direction it will cross the
        deck in (:meth:`_crossing_direction`). A WIM record inserted into SUMO carries its recorded axles
        (:mod:`cosim.sumo.records`)."""
        record = self._feed.live.get(vid) if self._feed is not None else None
        if record is not None:
            self._own_type(vid, record.vehicle_type)
            self._label[vid] = (record.load.vehicle_class, record.wander, record.load.source)
            return
        if self._draws is None:
            return
        direction = self._crossing_direction(vid)
        if direction is None:  # no deck edge ahead on its route: the way it heads
            heading = np.radians(row[2])
            along = self._unit[0]
            direction = 1 if math.sin(heading) * along[0] + math.cos(heading) * along[1] >= 0.0 else 2
        draw = self._draws.draw(vid, self.types[vtype], direction)
        if draw.vehicle_type is not None:
            self._own_type(vid, draw.vehicle_type)
        self._label[vid] = (draw.vehicle_class, draw.wander, draw.source)

    def _crossing_direction(self, vid: str) -> int | None:
        """Grave's direction of the deck edge next on the vehicle's route from where it is (:attr:`deck_directions`),
        or None if it crosses none from there. Not its heading: first seen on a side road or in a junction, a
        vehicle heads across the axis, or away from the way it will cross."""
        try:
            route, index = self.libsumo.vehicle.getRoute(vid), self.libsumo.vehicle.getRouteIndex(vid)
        except Exception:  # noqa: BLE001 - no route to be had (SUMO's exception types vary): its heading decides
            return None
        return next((self.deck_directions[e] for e in route[max(index, 0):] if e in self.deck_directions), None)

    def _own_type(self, vid: str, own: VehicleType) -> None:
        """A vehicle with a vehicle type of its own (its own axles and loads).

        A vehicle seen again after it left the watched lanes (a bus crossing back the other way) draws again,
        for the direction it now drives; the models of its first crossing are still in the tables that the
        frames' consumers keep under its type's name, so a different draw takes a name of its own
        (``type@vehicle/2``), not the first one's models.
        """
        columns, drawn, again = own.contact_columns(), own, 1
        while any(key in self._models and self._models[key] != model for key, model, _, _ in columns):
            again += 1
            own = replace(drawn, id=f"{drawn.id}/{again}")
            columns = own.contact_columns()
        self._axles[own.id] = tuple((back, left) for _, _, back, left in columns)
        if any(left for _, left in self._axles[own.id]):
            self._sideways.add(own.id)
        self._known({key: model for key, model, _, _ in columns})
        self._own[vid] = own

    def _entering(self, vehicles: Sequence[str], types: list[str], num: np.ndarray, owner: np.ndarray, x: np.ndarray,
                  y: np.ndarray) -> tuple[LoadRecord, ...]:
        """The load records of the vehicles whose first contact point came onto the deck in this step: class,
        weights, axles, the lane it drives on (SUMO's), its speed, path and wander, and the loads' source."""
        # Python lists, not numpy: a few contact points, at every step while a vehicle nears the deck behind another
        # on it (numpy's masks and searches on them cost several times the loop).
        length, owners, recorded = self.axis.length, owner.tolist(), self._recorded
        out = []
        for xi, r in zip(x.tolist(), owners):
            if not 0.0 <= xi <= length or vehicles[r] in recorded:
                continue
            vid = vehicles[r]
            recorded.add(vid)
            vtype = self._own.get(vid) or self.types[types[r]]
            label, offset, source = self._label.get(vid, (vtype.vclass, 0.0, f"vType {vtype.id}: "
                                                                             f"{vtype.sources.get('mass', '')}"))
            try:
                lane = str(self.libsumo.vehicle.getLaneID(vid))
            except Exception:  # noqa: BLE001 - no lane to be had: the record says so
                lane = ""
            first = owners.index(r)
            record = self._feed.live.get(vid) if self._feed is not None else None
            if record is not None:  # a WIM record: its recorded loads, as recorded
                out.append(replace(record.load, lane=lane, speed=float(num[r, 3]), y=float(y[first])))
                continue
            weight = vtype.mass * LOADS_G
            distances = [d for d, _ in vtype.axles]
            out.append(LoadRecord(id=vid, vehicle_class=label, lane=lane, speed=float(num[r, 3]), gvw=weight,
                                  axle_loads=tuple(share * weight for _, share in vtype.axles),
                                  axle_spacings=tuple(b - a for a, b in zip(distances, distances[1:])),
                                  y=float(y[first]), wander=offset, source=source))
        return tuple(out)

    def _forget(self, vid: str) -> None:
        """A vehicle no longer followed: its trail, its own vehicle type and its record's bookkeeping go."""
        assert self._trails is not None
        self._trails.drop(vid)
        own = self._own.pop(vid, None)
        if own is not None:
            self._axles.pop(own.id, None)
            self._sideways.discard(own.id)
        self._label.pop(vid, None)
        self._recorded.discard(vid)
        self._fixed.pop(vid, None)
        self._layout = None  # its slot is free: a vehicle seen again with the same id is new

    def _seed_trail(self, vid: str, row: np.ndarray) -> None:
        """A vehicle seen for the first time: its trail starts with its lane behind its bumper (a vehicle
        inserted on the deck has its axles on its lane behind it), as far back as the watched reach."""
        ls = self.libsumo
        try:
            lane, position = ls.vehicle.getLaneID(vid), ls.vehicle.getLanePosition(vid)
            if lane not in self._lane_geometry:
                shape = ls.lane.getShape(lane)
                self._lane_geometry[lane] = lane_line(shape, float(ls.lane.getLength(lane))) if len(shape) >= 2 \
                    else None
            line = self._lane_geometry[lane]
        except Exception:  # noqa: BLE001 - no lane to be had (SUMO's exception types vary): the trail starts here
            return
        if line is None:
            return
        assert self._trails is not None
        points, behind = path_behind(line, position, row[:2], self.reach)
        self._trails.seed(vid, points, behind, float(row[3]))

    def _drop_departed(self, ids: Sequence[str], gone: np.ndarray) -> None:
        """Stop following the vehicles ``gone`` says are beyond the watched reach for good, driving away from the
        deck (:func:`cosim.core.axle_paths.contact_step`).

        They are still on a watched lane (a long lane after the deck) but can no longer reach it: they are
        no longer read, not at every step until they leave the lane.
        """
        for i in np.flatnonzero(gone).tolist():
            vid = ids[i]
            self._done.add(vid)
            self._watched.discard(vid)
            self._forget(vid)
