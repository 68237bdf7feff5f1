"""SUMO adapter: the only module that imports libsumo.

SUMO runs at its own step; every step the adapter reads, through
subscriptions (no per-vehicle getter calls in the loop), the vehicles near
the bridge: position (front bumper), heading, speed,
acceleration and type. Each vehicle becomes one quarter-car per axle (a vType
without axles: one at its centre, half its length behind the bumper along the
heading), projected onto the bridge axis (x along the axis from its start
point, y to the left of it).
The frames feed :class:`cosim.core.traffic.FrameTraffic`, which the beam sub-steps
through with SUMO's ballistic motion between frames.

``libsumo`` is a per-process singleton: one SUMO simulation per process; it is
imported inside :meth:`SumoTraffic.start`, so importing this module does not load it.
What a vType is for the beam lives in :mod:`cosim.sumo.vtypes`, the reading of
SUMO's files in :mod:`cosim.sumo.files`.
"""
from __future__ import annotations

import contextlib
import difflib
import functools
import math
import os
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.traffic import Frame, FrameTraffic, TrafficBlock
from cosim.core.vehicles import VehicleModel
from cosim.errors import ConfigError, SumoError
from cosim.sumo.files import DEMAND_OPTIONS, distribution_ids, parse_xml, read_config, read_input
from cosim.sumo.vtypes import PARAM_KEYS, PARAM_PREFIX, axles_from_parameters, model_from_parameters, scaled_model

__all__ = ["WATCH_MARGIN", "BridgeAxis", "SumoTraffic", "bundled_networks", "sumo_binary"]

WATCH_MARGIN = 12.0  # m: watch edges reaching this far past the deck ends (half the longest vehicle + slack)


def bundled_networks() -> Path:
    """Folder of the SUMO networks shipped with cosim (sumo_networks/)."""
    return Path(str(resources.files("sumo_networks")))


def sumo_binary() -> str:
    """The ``sumo`` executable of the eclipse-sumo wheel (for SUMO_HOME and data files)."""
    try:
        import sumo  # eclipse-sumo

        return str(Path(sumo.SUMO_HOME) / "bin" / "sumo")
    except (ImportError, AttributeError):
        return "sumo"


@dataclass(frozen=True)
class BridgeAxis:
    """The bridge in network coordinates: its axis from ``start`` to ``end`` (m)."""

    start: tuple[float, float]
    end: tuple[float, float]

    @property
    def length(self) -> float:
        return math.dist(self.start, self.end)

    @functools.cached_property
    def _frame(self) -> tuple[np.ndarray, np.ndarray]:
        return self.unit()

    def unit(self) -> tuple[np.ndarray, np.ndarray]:
        e = (np.asarray(self.end, dtype=float) - np.asarray(self.start, dtype=float)) / self.length
        return e, np.array([-e[1], e[0]])  # along, left normal

    def project(self, px: np.ndarray, py: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bridge coordinates (x along the axis from start, y to the left) of network points."""
        e, n = self._frame
        dx, dy = px - self.start[0], py - self.start[1]
        return dx * e[0] + dy * e[1], dx * n[0] + dy * n[1]


class SumoTraffic:
    """Vehicles from a SUMO simulation (through libsumo), as a traffic source for the beam.

    Args:
        config: the ``.sumocfg`` to run.
        axis: where the bridge is in the network.
        step: SUMO's step length, s (the beam's dt must divide it).
        begin, end: SUMO times to run, s (the co-simulation's t = 0 is ``begin``).
        edges: edges to watch; default: every edge with a lane within
            ``WATCH_MARGIN`` of the deck.
        seed: SUMO's random seed (recorded in the log), or None for the config's.
        half_width: lateral half-width of the deck, m; vehicles farther from the
            axis are not on the bridge.
        extra_args: further SUMO command-line options.
        frame_sink: called with every frame and the model table (e.g. a log's TrafficLogger).
    """

    def __init__(
        self,
        config: str | os.PathLike,
        axis: BridgeAxis,
        step: float = 0.05,
        begin: float = 0.0,
        end: float = 600.0,
        edges: Sequence[str] | None = None,
        seed: int | None = None,
        half_width: float = 50.0,
        extra_args: Sequence[str] = (),
        frame_sink: Callable[[Frame, dict[str, VehicleModel]], None] | None = None,
    ) -> None:
        self.config = Path(config)
        if not self.config.is_file():
            raise SumoError(f"{self.config}: SUMO config not found")
        if not step > 0:
            raise ConfigError(f"traffic `step` must be > 0 s (got {step})")
        if not end > begin:
            raise ConfigError(f"traffic `end` ({end} s) must be after `begin` ({begin} s)")
        self.axis, self.step, self.begin, self.end = axis, float(step), float(begin), float(end)
        self.seed, self.half_width = seed, float(half_width)
        self._edges_wanted = tuple(edges) if edges else None
        self.extra_args = tuple(extra_args)
        self.frame_sink = frame_sink
        self.edges: tuple[str, ...] = ()
        self.models: dict[str, VehicleModel] = {}
        self.frames: FrameTraffic | None = None
        self._axles: dict[str, tuple[tuple[float, float], ...]] = {}
        self.libsumo: Any = None  # the libsumo module once started (imported there, not here)
        self.sumo_steps = 0
        self.teleports = 0

    # ------------------------------------------------------------- lifecycle
    def start(self) -> "SumoTraffic":
        import libsumo  # the one place cosim imports libsumo

        self.libsumo = libsumo
        cmd = [
            sumo_binary(), "-c", str(self.config),
            "--step-length", repr(self.step),
            "--begin", repr(self.begin), "--end", repr(self.end),
            "--step-method.ballistic", "true",
            "--no-step-log", "true", "--no-warnings", "true",
            *(["--seed", str(self.seed)] if self.seed is not None else []),
            *self.extra_args,
        ]
        check_vtype_params(self.config)
        with _stderr_captured() as captured:
            try:
                libsumo.start(cmd)
            except Exception as exc:  # libsumo raises its own error types; SUMO printed the reason
                raise SumoError(f"{self.config}: SUMO could not load it: {_sumo_reason(captured(), exc)}") from None
        try:
            self._watch()
            # Every vType known at the start is turned into its vehicle model now, so that an
            # impossible parameter stops the run before it starts, naming the vType.
            distributions = distribution_ids(self.config)
            for type_id in libsumo.vehicletype.getIDList():
                if type_id not in distributions:  # a distribution's id is not a vehicle's type
                    self._model(type_id)
        except Exception:
            self.close()
            raise
        self.frames = FrameTraffic(self.step, self.axis.length, self.models)
        return self

    def close(self) -> None:
        if self.libsumo is not None:
            try:
                self.libsumo.close()
            except Exception:  # noqa: BLE001 - closing a failed simulation must not mask the first error
                pass
            self.libsumo = None

    def __enter__(self) -> "SumoTraffic":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()

    def _watch(self) -> None:
        ls = self.libsumo
        all_edges = [e for e in ls.edge.getIDList() if not e.startswith(":")]
        if self._edges_wanted is not None:
            missing = [e for e in self._edges_wanted if e not in all_edges]
            if missing:
                raise SumoError(f"{self.config}: the network has no edge(s) {', '.join(missing)} (bridge edges)")
            edges = list(self._edges_wanted)
        else:
            edges = []
            L = self.axis.length
            for edge in all_edges:
                for i in range(ls.edge.getLaneNumber(edge)):
                    shape = np.array(ls.lane.getShape(f"{edge}_{i}"))
                    x, y = self.axis.project(shape[:, 0], shape[:, 1])
                    # Sample the polyline densely enough to see it cross the watched box.
                    t = np.linspace(0, 1, 50)
                    xs = np.concatenate([np.interp(t, [0, 1], x[j:j + 2]) for j in range(len(x) - 1)])
                    ys = np.concatenate([np.interp(t, [0, 1], y[j:j + 2]) for j in range(len(y) - 1)])
                    inside = (xs > -WATCH_MARGIN) & (xs < L + WATCH_MARGIN) & (np.abs(ys) <= self.half_width)
                    if inside.any():
                        edges.append(edge)
                        break
            if not edges:
                raise SumoError(
                    f"{self.config}: no edge of the network lies on the bridge axis "
                    f"{self.axis.start} -> {self.axis.end}; check [traffic] axis or edges"
                )
        tc = ls.constants
        # Edge context subscriptions miss vehicles at some steps (their spatial query works
        # on edge shapes, cf. eclipse-sumo/sumo#16422), so: each watched edge reports its vehicle
        # list, and each vehicle seen there is subscribed to its own variables until it leaves.
        for edge in edges:
            ls.edge.subscribe(edge, [tc.LAST_STEP_VEHICLE_ID_LIST])
        self.edges = tuple(edges)
        self._vars = [tc.VAR_POSITION, tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_ACCELERATION, tc.VAR_TYPE,
                      tc.VAR_LENGTH]
        self._watched: set[str] = set()

    # --------------------------------------------------------------- stepping
    def _model(self, type_id: str) -> None:
        if type_id in self.models:
            return
        ls = self.libsumo
        vt = ls.vehicletype
        params = {}
        for key in PARAM_KEYS:
            value = vt.getParameter(type_id, PARAM_PREFIX + key)
            if value != "":
                params[PARAM_PREFIX + key] = value
        whole = model_from_parameters(type_id, vt.getMass(type_id), vt.getVehicleClass(type_id), params)
        axles = axles_from_parameters(type_id, vt.getLength(type_id), params)
        self._axles[type_id] = axles
        if len(axles) == 1:
            self.models[type_id] = whole
        else:  # one vehicle model per axle: "type#k" carries axle k's share
            for k, (_, share) in enumerate(axles):
                self.models[f"{type_id}#{k}"] = scaled_model(whole, share)
            self.models[type_id] = whole

    def advance(self) -> Frame:
        """One SUMO step; returns the frame of vehicles near the bridge."""
        ls = self.libsumo
        try:
            ls.simulationStep()
            self.teleports += ls.simulation.getStartingTeleportNumber()
        except Exception as exc:  # noqa: BLE001 - SUMO errors come as several libsumo exception types
            raise SumoError(f"SUMO failed at t = {ls.simulation.getTime() if ls else '?'} s: {_first_line(exc)}") \
                from None
        self.sumo_steps += 1
        tc = ls.constants
        present: set[str] = set()
        for edge in self.edges:
            present.update(ls.edge.getSubscriptionResults(edge)[tc.LAST_STEP_VEHICLE_ID_LIST])
        for vid in present - self._watched:
            ls.vehicle.subscribe(vid, self._vars)
        for vid in self._watched - present:
            try:
                ls.vehicle.unsubscribe(vid)
            except Exception:  # noqa: BLE001 - it arrived or was teleported away: nothing to undo
                pass
        self._watched = present
        results = ls.vehicle.getAllSubscriptionResults()
        ids = [vid for vid in sorted(present) if vid in results]
        n = len(ids)
        rows = [results[vid] for vid in ids]
        pos = np.array([r[tc.VAR_POSITION] for r in rows], dtype=float).reshape(n, 2)
        ang = np.fromiter((r[tc.VAR_ANGLE] for r in rows), dtype=float, count=n)
        spd = np.fromiter((r[tc.VAR_SPEED] for r in rows), dtype=float, count=n)
        acc = np.fromiter((r[tc.VAR_ACCELERATION] for r in rows), dtype=float, count=n)
        length = np.fromiter((r[tc.VAR_LENGTH] for r in rows), dtype=float, count=n)
        types = [r[tc.VAR_TYPE] for r in rows]
        for typ in types:
            if typ not in self.models:
                self._model(typ)
        # One contact point per axle (a vType without axles: one at mid-length), behind the bumper.
        back = np.array([d if len(self._axles[t]) > 1 else 0.5 * L
                         for t, L in zip(types, length) for d, _ in self._axles[t]], dtype=float)
        owner = np.array([i for i, t in enumerate(types) for _ in self._axles[t]], dtype=np.int64)
        if len(owner) != n:
            ids = [vid if len(self._axles[t]) == 1 else f"{vid}#{k}"
                   for vid, t in zip(ids, types) for k in range(len(self._axles[t]))]
            types = [t if len(self._axles[t]) == 1 else f"{t}#{k}"
                     for t in types for k in range(len(self._axles[t]))]
            pos, ang, spd, acc = pos[owner], ang[owner], spd[owner], acc[owner]
        heading = np.radians(ang)
        hx, hy = np.sin(heading), np.cos(heading)  # SUMO angle: 0 = north, clockwise
        x, y = self.axis.project(pos[:, 0] - back * hx, pos[:, 1] - back * hy)
        e, _ = self.axis._frame
        along = hx * e[0] + hy * e[1]
        keep = np.abs(y) <= self.half_width
        t = self.sumo_steps * self.step
        if not keep.all():
            ids = [i for i, k in zip(ids, keep) if k]
            types = [ty for ty, k in zip(types, keep) if k]
            x, y, spd, acc, along = x[keep], y[keep], spd[keep], acc[keep], along[keep]
        return Frame(t=t, ids=tuple(ids), x=x, y=y, v=spd * along, a=acc * along, types=tuple(types))

    def block(self, times: np.ndarray) -> TrafficBlock:
        """Run SUMO as far as ``times`` (s from ``begin``) need and interpolate the vehicles there."""
        if self.frames is None:
            raise SumoError("SumoTraffic.start() was not called")
        while self.frames.last_time < times[-1] - 1e-9:
            if self.begin + self.frames.last_time + self.step > self.end + 1e-9:
                raise SumoError(f"SUMO's run ends at {self.end} s; the co-simulation asked for {times[-1]} s")
            frame = self.advance()
            self.frames.add_frame(frame)
            if self.frame_sink is not None:
                self.frame_sink(frame, self.models)
        out = self.frames.block(times)
        self.frames.forget_before(float(times[-1]))
        return out


@contextlib.contextmanager
def _stderr_captured() -> Iterator[Callable[[], str]]:
    """Within the block, what is written to file descriptor 2 (SUMO's C++ error output) goes to a
    temporary file; yields a function that returns it. Written back to stderr when the block ends
    normally, so nothing is lost; on an error the caller words it into its one line instead."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        text: list[str] = []

        def captured() -> str:
            if not text:
                sink.seek(0)
                text.append(sink.read(1 << 16).decode("utf-8", "replace"))
            return text[0]

        failed = True
        try:
            yield captured
            failed = False
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            if not failed and captured().strip():
                print(captured().rstrip(), file=sys.stderr)


def _sumo_reason(output: str, exc: BaseException) -> str:
    """SUMO's own reason, from what it printed ("Error: ..." and the lines below it), on one line."""
    lines = [line.strip() for line in output.splitlines()]
    starts = [i for i, line in enumerate(lines) if line.startswith("Error:")]
    if not starts:
        return _first_line(exc)
    first = starts[0]
    detail = [lines[first][len("Error:"):].strip()]
    for line in lines[first + 1:]:
        if not line or line.startswith(("Error:", "Quitting", "Warning:")):
            break
        detail.append(line[0].lower() + line[1:])
    return " ".join(part.rstrip(".") for part in detail if part)


def check_vtype_params(config: str | os.PathLike) -> None:
    """Every ``cosim.*`` param of every vType in a config's demand files is one cosim reads, for its model.

    A misspelled key (``cosim.kv``) would otherwise leave the vClass default in
    place, and ``cosim.k_t`` on a quarter-car would be ignored. Lenient about
    files it cannot read (SUMO, which loads them next, judges those).

    Raises:
        SumoError: one line naming the file, the vType and the key, with the keys it may be.
    """
    try:
        parsed = read_config(Path(config))
    except ConfigError:
        return
    for path in parsed.files(DEMAND_OPTIONS):
        try:
            root = parse_xml(read_input(path), str(path))
        except ConfigError:
            continue
        for vtype in root.iter("vType"):
            params = {p.get("key", ""): p.get("value", "") for p in vtype.iter("param")}
            model = params.get(PARAM_PREFIX + "model", "quarter-car")
            allowed = _MODEL_PARAMS.get(model)
            if allowed is None:
                continue  # an unknown model: model_from_parameters names it
            for key in params:
                if not key.startswith(PARAM_PREFIX):
                    continue
                name = key[len(PARAM_PREFIX):]
                if name in allowed:
                    continue
                where = f"{path}: vType {vtype.get('id', '?')}: param `{key}`"
                if name in PARAM_KEYS:
                    raise SumoError(f"{where} is not used by model {model} (its params: "
                                    + ", ".join(PARAM_PREFIX + k for k in allowed) + ")")
                near = difflib.get_close_matches(name, PARAM_KEYS, n=1)
                hint = f"; did you mean `{PARAM_PREFIX}{near[0]}`?" if near else ""
                raise SumoError(f"{where} is not a cosim param{hint} (cosim reads: "
                                + ", ".join(PARAM_PREFIX + k for k in PARAM_KEYS) + ")")


#: The ``cosim.*`` params each vehicle model uses (the others would be ignored: an error).
_MODEL_PARAMS: dict[str, tuple[str, ...]] = {
    "quarter-car": ("model", "m_w", "k_v", "c_v", "axles", "axle_loads"),
    "tyre-quarter-car": ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads"),
    "moving-force": ("model", "axles", "axle_loads"),
}


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]
