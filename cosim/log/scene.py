"""The 3D scene of a run, in Foxglove's own schemas: the deck deflected and twisted, its vehicles, their forces.

Three topics (:mod:`cosim.log.schemas`), drawn by Foxglove's 3D panel:

- ``/cosim/scene`` (``foxglove.SceneUpdate``) at :data:`SCENE_RATE_HZ`: the
  deck as a surface with its edges and cross-lines, its vertical displacement
  ``w(x, y)`` (bending and twist) multiplied by an exaggeration; the wheel
  paths on it; the sensors at their deck points; every vehicle on or near the
  deck as a box over its axles, with its contact forces as arrows (down for
  compression, red and up for a wheel that pulls);
- ``/cosim/scene/static`` (once, at t = 0): the deck at rest, the approaches
  and the supports, the sensors' names and a note with the scales;
- ``/cosim/scene/transform`` (``foxglove.FrameTransform``, once): the
  ``bridge`` frame (cosim's axes) in a ``world`` frame centred on the bridge.

The deck shape comes from hidden displacement sensors at both deck edges at
a few stations per span (:func:`scene_sensors`): ``w`` is linear in ``y``
(``w = w_S + (y - y_S) theta_x``, docs/theory.md §1.4), so the two edges give
the whole cross-section exactly; along ``x`` it is drawn as a natural cubic
spline through the stations (the supports included), and the stations are
marked by cross-lines. Those channels are not logged on ``/cosim/sensors``.

Vehicles are schematic: boxes from their axles' positions (a single contact
point: a 4.5 m car or a 10 m truck), wider and taller over 3.5 t. The
exaggeration and the force scale are chosen once per run (:func:`plan_scene`)
and written into the scene's note and the log's metadata.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from cosim.core.bridge import BridgeModel, PointLoad
from cosim.core.fields import vehicle_of
from cosim.core.sensors import Sensor, sensor_row

from . import proto
from .schemas import SCENE_FRAME, TOPIC_SCENE, TOPIC_SCENE_STATIC, TOPIC_SCENE_TRANSFORM, WORLD_FRAME

__all__ = ["SCENE_MAX_DURATION", "SCENE_RATE_HZ", "ScenePlan", "SceneWriter", "plan_scene", "scene_sensors",
           "scene_wanted"]

#: Scenes per second of simulated time (at most one per step).
SCENE_RATE_HZ = 10.0
#: The scene is on by default for runs of at most this long, s.
SCENE_MAX_DURATION = 3600.0
#: Deck segments per span (fewer when the span has fewer elements). Each station between supports costs two
#: sensor rows, read only at the scenes' steps (``Sensor.every``): the deck is drawn as a spline through a few
#: stations.
SEGMENTS_PER_SPAN = 4
#: Points drawn per segment between stations.
DRAW_SUBDIVISIONS = 4
#: Reference loads for the automatic scales when the vehicles are not known before the run (SUMO, replayed
#: frames): a 40 t vehicle and a 10 t axle, the heaviest of EU road traffic (Directive 96/53/EC: 40 t for a
#: five-axle articulated vehicle, 11.5 t on a drive axle).
REFERENCE_VEHICLE_N = 40e3 * 9.81
REFERENCE_AXLE_N = 10e3 * 9.81
#: The reference vehicle's static mid-span deflection is drawn as this fraction of the longest span.
SAG_OF_SPAN = 1.0 / 20.0
#: The reference contact force is drawn as an arrow this long at most, m.
ARROW_LENGTH = 2.5
#: The approaches drawn at each end, m (the region the SUMO adapter watches around the deck).
APPROACH = 12.0
#: Above this gross mass a vehicle is drawn as a truck, kg.
HEAVY_KG = 3500.0
#: Wheel paths closer than about this are drawn as one, m; at most MAX_PATHS are drawn.
PATH_ROUNDING = 0.1
MAX_PATHS = 24
#: Coordinates are written to the centimetre of the drawing (a tenth of a millimetre of the deck's displacement
#: at an exaggeration of 100): the scene is a picture, and its numbers are most of the log's extra bytes.
_DECIMALS = 2
_HIDDEN_PREFIX = "~scene"

_GREY = {"r": 0.62, "g": 0.64, "b": 0.68, "a": 0.85}
_DARK = {"r": 0.2, "g": 0.22, "b": 0.26, "a": 1.0}
_REST = {"r": 0.45, "g": 0.47, "b": 0.5, "a": 0.6}
_PATH = {"r": 1.0, "g": 0.85, "b": 0.2, "a": 1.0}
_CAR = {"r": 0.25, "g": 0.5, "b": 0.95, "a": 0.4}
_TRUCK = {"r": 0.95, "g": 0.55, "b": 0.15, "a": 0.4}
_WHEEL = {"r": 0.1, "g": 0.1, "b": 0.1, "a": 1.0}
_PUSH = {"r": 0.1, "g": 0.75, "b": 0.3, "a": 1.0}
_PULL = {"r": 0.95, "g": 0.1, "b": 0.1, "a": 1.0}
_TEXT = {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0}
_QUANTITY_COLORS = {
    "displacement": {"r": 0.2, "g": 0.8, "b": 1.0, "a": 1.0},
    "velocity": {"r": 0.6, "g": 0.4, "b": 1.0, "a": 1.0},
    "acceleration": {"r": 1.0, "g": 0.3, "b": 0.8, "a": 1.0},
    "bending_moment": {"r": 1.0, "g": 1.0, "b": 0.3, "a": 1.0},
    "stress": {"r": 1.0, "g": 0.55, "b": 0.1, "a": 1.0},
    "strain": {"r": 0.3, "g": 1.0, "b": 0.5, "a": 1.0},
    "shear_stress_xy": {"r": 1.0, "g": 0.75, "b": 0.55, "a": 1.0},
    "shear_stress_xz": {"r": 0.85, "g": 0.55, "b": 0.35, "a": 1.0},
}
_IDENTITY = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
_S45 = math.sqrt(0.5)
_AXLE_ALONG_Y = {"x": _S45, "y": 0.0, "z": 0.0, "w": _S45}  # a cylinder's axis (z) turned onto y
_ARROW_DOWN = {"x": 0.0, "y": _S45, "z": 0.0, "w": _S45}  # an arrow's +x turned onto -z
_ARROW_UP = {"x": 0.0, "y": -_S45, "z": 0.0, "w": _S45}  # ... onto +z


def _nice(value: float, up: bool) -> float:
    """``value`` rounded down (or up) to 1, 2 or 5 times a power of ten."""
    exponent = math.floor(math.log10(value))
    candidates = [m * 10.0 ** e for e in (exponent - 1, exponent, exponent + 1) for m in (1.0, 2.0, 5.0)]
    return min(c for c in candidates if c >= value * (1 - 1e-12)) if up else \
        max(c for c in candidates if c <= value * (1 + 1e-12))


@dataclass(frozen=True)
class SceneSensor:
    """A sensor marked in the scene (its quantity gives its colour)."""

    name: str
    x: float
    y: float
    quantity: str


@dataclass(frozen=True)
class ScenePlan:
    """What the scene draws and how, fixed before the run.

    Attributes:
        length: the deck's length, m; supports: the support lines' x, m; deck_y: (right, left) edge, m.
        stations: x of the deck stations, m (the supports included).
        rows: for each station, the hidden sensor columns of its (right, left) edge, -1 where the
            displacement is zero whatever the load (a restrained support).
        exaggeration: deck displacements are drawn this many times larger.
        newton_per_m: contact forces are drawn as arrows of 1 m per this many N.
        every: steps per scene; dt: the time step, s.
        sensors: the named sensors to mark.
        paths: wheel paths known before the run (scripted vehicles), m.
        hidden: the sensors that read the deck's shape (:func:`scene_sensors`), to add after the named ones.
    """

    length: float
    supports: tuple[float, ...]
    deck_y: tuple[float, float]
    stations: tuple[float, ...]
    rows: tuple[tuple[int, int], ...]
    exaggeration: float
    newton_per_m: float
    every: int
    dt: float
    sensors: tuple[SceneSensor, ...] = ()
    paths: tuple[float, ...] = ()
    hidden: tuple[Sensor, ...] = field(default=(), repr=False)

    @property
    def rate_hz(self) -> float:
        """Scenes per second of simulated time."""
        return 1.0 / (self.every * self.dt)

    def metadata(self) -> dict[str, str]:
        """The scene's settings for the log's "cosim" metadata record."""
        return {"scene_hz": repr(self.rate_hz), "scene_exaggeration": repr(self.exaggeration),
                "scene_newton_per_m": repr(self.newton_per_m), "scene_length": repr(self.length)}


def scene_wanted(setting: bool | float | None, duration: float) -> bool:
    """Whether a run draws its scene: ``[output].scene`` (true, false or an exaggeration), unset: on for
    runs of at most :data:`SCENE_MAX_DURATION`."""
    if setting is None:
        return duration <= SCENE_MAX_DURATION
    return setting is not False


def _stations(bridge: BridgeModel) -> list[float]:
    """A few stations per span, equally spaced between its supports (at most one per element)."""
    xs: list[float] = []
    supports = bridge.support_x
    nodes = bridge.nodes_x
    for a, b in zip(supports[:-1], supports[1:]):
        elements = int(np.count_nonzero((nodes > a + 1e-9) & (nodes <= b + 1e-9)))
        segments = max(1, min(SEGMENTS_PER_SPAN, elements))
        for k in range(segments + 1):
            x = float(a + (b - a) * k / segments)
            if not xs or x > xs[-1] + 1e-9:
                xs.append(x)
    return xs


def _reference_sag(bridge: BridgeModel, weight: float) -> float:
    """The static deflection under ``weight`` (N) at the middle of the longest span, on the axis, m (> 0)."""
    spans = np.diff(bridge.support_x)
    i = int(np.argmax(spans))
    x = float(bridge.support_x[i] + spans[i] / 2)
    y = float(min(max(0.0, bridge.section.deck_y[0]), bridge.section.deck_y[1]))
    w = bridge.static([PointLoad(x, y, -weight)]).field("w_deck", [x], y)[0]
    return abs(float(w))


def plan_scene(bridge: BridgeModel, sensors: Sequence[Sensor], dt: float, *, exaggeration: float | None = None,
               reference_weight: float | None = None, reference_contact: float | None = None,
               paths: Iterable[float] = (), taken: Iterable[str] = ()) -> ScenePlan:
    """The scene of a run on ``bridge``: stations, scales and the hidden sensors that read the deck's shape.

    Args:
        bridge: the structural model; sensors: the named sensors to mark; dt: the time step, s.
        exaggeration: the deck displacement's scale in the drawing; default: the static mid-span
            deflection under ``reference_weight`` drawn as 1/20 of the longest span (1, 2 or 5 times a power of 10).
        reference_weight: the heaviest vehicle's weight, N (default :data:`REFERENCE_VEHICLE_N`).
        reference_contact: the heaviest contact point's static force, N (default :data:`REFERENCE_AXLE_N`):
            drawn as an arrow of at most :data:`ARROW_LENGTH`.
        paths: wheel paths known before the run, m.
        taken: sensor names in use (the hidden ones get other names).
    """
    stations = _stations(bridge)
    y_min, y_max = (float(v) for v in bridge.section.deck_y)
    every = max(1, int(round(1.0 / (SCENE_RATE_HZ * dt))))
    names = set(taken)
    prefix = _HIDDEN_PREFIX
    while any(n.startswith(prefix) for n in names):
        prefix += "~"
    hidden: list[Sensor] = []
    rows: list[tuple[int, int]] = []
    restrained = set(bridge.restrained.tolist())
    for i, x in enumerate(stations):
        pair = []
        for side, y in (("right", y_min), ("left", y_max)):
            sensor = Sensor(f"{prefix}/{side}/{i}", x, y, "displacement", every=every)  # read at scenes only
            row = sensor_row(bridge, sensor)
            values = np.abs(row.values[0])
            read = row.dofs[values > 1e-12 * max(float(values.max()), 1e-300)]  # shape-function round-off aside
            if all(int(d) in restrained for d in read):
                pair.append(-1)  # held by a support: zero under any load
            else:
                pair.append(len(hidden))
                hidden.append(sensor)
        rows.append((pair[0], pair[1]))
    if exaggeration is None:
        sag = _reference_sag(bridge, reference_weight or REFERENCE_VEHICLE_N)
        target = SAG_OF_SPAN * float(np.max(np.diff(bridge.support_x)))
        exaggeration = _nice(min(max(target / sag, 1.0), 1e6), up=False) if sag > 0 and math.isfinite(sag) else 1.0
    newton_per_m = _nice((reference_contact or REFERENCE_AXLE_N) / ARROW_LENGTH, up=True)
    axis = min(max(0.0, y_min), y_max)  # where a bending moment (of the whole section) is marked
    marks = tuple(SceneSensor(s.name, float(s.x), float(s.y) if s.quantity != "bending_moment" else axis,
                              s.quantity) for s in sensors)
    known: dict[int, float] = {}
    for p in paths:
        known.setdefault(round(float(p) / PATH_ROUNDING), float(p))
    return ScenePlan(length=float(bridge.length), supports=tuple(float(x) for x in bridge.support_x),
                     deck_y=(y_min, y_max), stations=tuple(stations), rows=tuple(rows),
                     exaggeration=float(exaggeration), newton_per_m=float(newton_per_m), every=every, dt=float(dt),
                     sensors=marks, paths=tuple(sorted(known.values()))[:MAX_PATHS], hidden=tuple(hidden))


def scene_sensors(plan: ScenePlan) -> list[Sensor]:
    """The hidden sensors that read the deck's shape, in the order of ``plan.rows``' columns."""
    return list(plan.hidden)


# --------------------------------------------------------------------------- encoding


def _vec(x: float, y: float, z: float) -> dict[str, float]:
    return {"x": round(float(x), _DECIMALS) + 0.0, "y": round(float(y), _DECIMALS) + 0.0,
            "z": round(float(z), _DECIMALS) + 0.0}


def _time(t: float) -> dict[str, int]:
    ns = int(round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def _entity(entity_id: str, t: float, **primitives: Any) -> dict[str, Any]:
    return {"timestamp": _time(t), "frame_id": SCENE_FRAME, "id": entity_id, "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": False, **primitives}


_Z = "%s"  # a number filled in at every scene (a hole of the scene's template, :mod:`cosim.log.proto`)
_OPEN = {"sec": _Z, "nsec": _Z}  # a timestamp filled in at every scene
_HEAD = ("timestamp", "frame_id", "id", "lifetime", "frame_locked")  # an entity's fields before its primitives


def _body(big: bool) -> tuple[float, float, float]:
    """A drawn vehicle's width, height and wheel diameter, m: a truck's (``big``) or a car's."""
    return (2.5, 3.0, 0.9) if big else (1.8, 1.4, 0.65)


def _c(value: float) -> float:
    """A coordinate rounded to the drawing's centimetre (no "-0.0"), as :func:`_vec` writes it."""
    return round(float(value), _DECIMALS) + 0.0


class SceneWriter:
    """Writes a run's scene into a :class:`cosim.log.writer.LogRecorder`, from the blocks of the simulation.

    Args:
        recorder: the log; plan: the scene (:func:`plan_scene`).
        first_column: where the hidden sensors start among the block report's sensor columns.
    """

    def __init__(self, recorder: Any, plan: ScenePlan, first_column: int) -> None:
        self.rec = recorder
        self.plan = plan
        self.first = first_column
        self.paths: list[float] = list(plan.paths)
        stations = np.array(plan.stations)
        from scipy.interpolate import CubicSpline  # here: in the log writer's process, not at every start

        # The spline through the stations is linear in their values: a matrix per set of points drawn.
        self._basis = CubicSpline(stations, np.eye(len(stations)), bc_type="natural")
        self.draw_x = np.unique(np.concatenate([np.linspace(a, b, DRAW_SUBDIVISIONS + 1)
                                                for a, b in zip(stations[:-1], stations[1:])]))
        self._deck_matrix = self.spline_matrix(self.draw_x)
        rows = np.array(plan.rows, dtype=np.int64).reshape(len(stations), 2)
        self._have = rows >= 0
        self._columns = first_column + rows[self._have]
        self._marks = np.array([[s.x, s.y] for s in plan.sensors], dtype=float).reshape(-1, 2)
        self._mark_matrix = self.spline_matrix(self._marks[:, 0])
        self._scene_fill = self._scene_template()
        self._vehicle_templates: dict[tuple[bool, int, tuple[int, ...]], proto.FixedTemplate] = {}

    # ------------------------------------------------------------- geometry
    def spline_matrix(self, x: np.ndarray) -> np.ndarray:
        """(len(x), stations): the deck's w along an edge at ``x`` from its values at the stations (zero off
        the deck)."""
        x = np.asarray(x, dtype=float)
        matrix = np.asarray(self._basis(np.clip(x, 0.0, self.plan.length))).reshape(len(x), len(self.plan.stations))
        matrix[(x < 0.0) | (x > self.plan.length)] = 0.0
        return matrix

    def edges(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The deck's displacement at the stations' (right, left) edges, m, from one step's sensor values."""
        out = np.zeros(self._have.shape)
        out[self._have] = values[self._columns]
        return out[:, 0], out[:, 1]

    def deck_w(self, right: np.ndarray, left: np.ndarray, x: np.ndarray, y: np.ndarray,
               matrix: np.ndarray | None = None) -> np.ndarray:
        """w at deck points (x, y), m: a cubic spline along x through the stations, exactly linear across."""
        m = self.spline_matrix(x) if matrix is None else matrix
        y_min, y_max = self.plan.deck_y
        share = (np.asarray(y, dtype=float) - y_min) / (y_max - y_min)
        w_r, w_l = m @ right, m @ left
        return w_r + share * (w_l - w_r)

    def _deck_entity(self) -> dict[str, Any]:
        """The deck entity: a surface, its two edges and a cross-line at each station (heights left open)."""
        y_min, y_max = self.plan.deck_y
        xs = [round(float(x), _DECIMALS) for x in self.draw_x]
        surface = [{"x": x, "y": y, "z": _Z} for x in xs for y in (y_min, y_max)]
        n = len(xs)
        triangles = [i for k in range(n - 1) for i in (2 * k, 2 * k + 2, 2 * k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3)]
        lines = [{"type": 0, "thickness": 2.0, "scale_invariant": True, "color": _DARK,
                  "points": [{"x": x, "y": y, "z": _Z} for x in xs]} for y in (y_min, y_max)]
        cross = [{"x": round(x, _DECIMALS), "y": y, "z": _Z} for x in self.plan.stations for y in (y_min, y_max)]
        lines.append({"type": 2, "thickness": 1.5, "scale_invariant": True, "color": _DARK, "points": cross})
        return {**_entity("deck", 0.0, triangles=[{"points": surface, "color": _GREY, "indices": triangles}],
                          lines=lines), "timestamp": _OPEN}

    def _path_entity(self) -> dict[str, Any]:
        """The wheel paths on the deck: a line per path, following the deck."""
        lines = [{"type": 0, "thickness": 3.0, "scale_invariant": True, "color": _PATH,
                  "points": [{"x": round(float(x), _DECIMALS), "y": y, "z": _Z} for x in self.draw_x]}
                 for y in self.paths]
        return {**_entity("wheel paths", 0.0, lines=lines), "timestamp": _OPEN}

    def _sensor_entity(self) -> dict[str, Any]:
        spheres = [{"pose": {"position": {"x": s.x, "y": s.y, "z": _Z}, "orientation": _IDENTITY},
                    "size": {"x": 0.6, "y": 0.6, "z": 0.6}, "color": _QUANTITY_COLORS[s.quantity]}
                   for s in self.plan.sensors]
        return {**_entity("sensors", 0.0, spheres=spheres), "timestamp": _OPEN}

    def _scene_template(self) -> proto.FixedTemplate:
        """A scene up to its vehicles: the deck, the wheel paths and the sensors, with their timestamps and
        drawn heights left open (filled in :meth:`_write`, the heights to the centimetre)."""
        entities = [self._deck_entity(), *([self._path_entity()] if self.paths else []),
                    *([self._sensor_entity()] if self.plan.sensors else [])]
        scene = {"deletions": [{"timestamp": _OPEN, "type": 1, "id": ""}], "entities": entities}
        value, _ = proto.number_holes(scene, _Z)
        return proto.FixedTemplate(self.rec.spec(TOPIC_SCENE), value, decimals=_DECIMALS)

    # ------------------------------------------------------------- messages
    def start(self) -> None:
        """The transform and the static scene (at t = 0), and the deck at rest."""
        plan = self.plan
        self.rec.write(TOPIC_SCENE_TRANSFORM, 0.0, {
            "timestamp": _time(0.0), "parent_frame_id": WORLD_FRAME, "child_frame_id": SCENE_FRAME,
            "translation": {"x": -plan.length / 2, "y": 0.0, "z": 0.0}, "rotation": _IDENTITY})
        self.rec.write(TOPIC_SCENE_STATIC, 0.0, self._static())
        self._write([0.0], np.zeros((1, self.first + len(plan.hidden))), None, [0])

    def _static(self) -> dict[str, Any]:
        plan = self.plan
        y_min, y_max = plan.deck_y
        a, b = -APPROACH, plan.length + APPROACH
        outline = [_vec(0.0, y_min, 0.0), _vec(plan.length, y_min, 0.0), _vec(plan.length, y_max, 0.0),
                   _vec(0.0, y_max, 0.0)]
        road = [_vec(a, y_min, 0.0), _vec(0.0, y_min, 0.0), _vec(a, y_max, 0.0), _vec(0.0, y_max, 0.0),
                _vec(plan.length, y_min, 0.0), _vec(b, y_min, 0.0), _vec(plan.length, y_max, 0.0),
                _vec(b, y_max, 0.0)]
        supports = [{"pose": {"position": _vec(x, 0.0, -0.6), "orientation": _IDENTITY},
                     "size": {"x": 0.6, "y": round(y_max - y_min, _DECIMALS), "z": 1.0}, "color": _DARK}
                    for x in plan.supports]
        labels = [{"pose": {"position": _vec(s.x, s.y, 2.0), "orientation": _IDENTITY}, "billboard": True,
                   "font_size": 12.0, "scale_invariant": True, "color": _TEXT, "text": s.name} for s in plan.sensors]
        note = (f"deck displacement x{plan.exaggeration:g}; arrows: contact forces, 1 m = "
                f"{plan.newton_per_m / 1e3:g} kN")
        labels.append({"pose": {"position": _vec(plan.length / 2, y_max + 4.0, 5.0), "orientation": _IDENTITY},
                       "billboard": True, "font_size": 14.0, "scale_invariant": True, "color": _TEXT, "text": note})
        return {"deletions": [], "entities": [
            _entity("deck at rest", 0.0, lines=[{"type": 1, "thickness": 1.0, "scale_invariant": True,
                                                 "points": outline, "color": _REST}]),
            _entity("approaches", 0.0, lines=[{"type": 2, "thickness": 1.5, "scale_invariant": True, "points": road,
                                               "color": _REST}]),
            _entity("supports", 0.0, cubes=supports),
            _entity("labels", 0.0, texts=labels),
        ]}

    def write_block(self, times: np.ndarray, report: Any) -> None:
        """The scenes at this block's steps that fall on the scene's rate."""
        steps = np.rint(np.asarray(times) / self.plan.dt).astype(np.int64)
        picked = np.flatnonzero(steps % self.plan.every == 0)
        if len(picked):
            self._write(times[picked].tolist(), report.sensors[picked], report, picked.tolist())

    def _learn_paths(self, report: Any) -> None:
        """Wheel paths seen in the traffic (SUMO puts vehicles where it likes): a line for each, once seen
        (paths closer than :data:`PATH_ROUNDING` are one)."""
        if report is None or not report.ids or len(self.paths) >= MAX_PATHS:
            return
        y_min, y_max = self.plan.deck_y
        known = {round(p / PATH_ROUNDING) for p in self.paths}
        new = False
        for y in np.asarray(report.y, dtype=float).tolist():
            key = round(y / PATH_ROUNDING)
            if key not in known and y_min <= y <= y_max and len(self.paths) < MAX_PATHS:
                known.add(key)
                self.paths.append(y)
                new = True
        if new:
            self.paths.sort()
            self._scene_fill = self._scene_template()

    def _write(self, times: list[float], sensors: np.ndarray, report: Any, rows: list[int]) -> None:
        """The scenes at ``times`` (their sensor rows ``sensors``, rows ``rows`` of the block), encoded together."""
        plan = self.plan
        e = plan.exaggeration
        self._learn_paths(report)
        count = len(times)
        stations = np.zeros((count,) + self._have.shape)
        stations[:, self._have] = sensors[:, self._columns]
        right, left = stations[:, :, 0], stations[:, :, 1]
        w_r, w_l = right @ self._deck_matrix.T, left @ self._deck_matrix.T  # (scenes, points drawn)
        deck = np.concatenate([np.stack([w_r, w_l], axis=2).reshape(count, -1), w_r, w_l,
                               stations.reshape(count, -1)], axis=1) * e
        y_min, y_max = plan.deck_y
        share = (np.array(self.paths, dtype=float) - y_min) / (y_max - y_min)
        paths = ((w_r[:, None, :] + share[None, :, None] * (w_l - w_r)[:, None, :]) * e + 0.03).reshape(count, -1)
        m_r, m_l = right @ self._mark_matrix.T, left @ self._mark_matrix.T
        marks = (m_r + (self._marks[:, 1] - y_min) / (y_max - y_min) * (m_l - m_r)) * e + 0.3
        ns = np.rint(np.asarray(times, dtype=np.float64) * 1e9).astype(np.int64)  # as _time
        seconds, nanoseconds = np.divmod(ns, 1_000_000_000)
        stamps = np.column_stack([seconds, nanoseconds]).astype(np.float64)
        columns = [stamps, stamps, deck]
        if self.paths:
            columns += [stamps, paths]
        if plan.sensors:
            columns += [stamps, marks]
        scenes = self._scene_fill.render(np.concatenate(columns, axis=1))
        vehicles = report is not None and bool(report.ids)
        if vehicles:  # the deck under every contact point at every scene, in one go
            x = np.asarray(report.x, dtype=float)[rows]
            near = np.isfinite(x) & (x >= -APPROACH) & (x <= plan.length + APPROACH)
            y = np.broadcast_to(np.asarray(report.y, dtype=float), x.shape)
            z = np.zeros(x.shape)
            matrix = self.spline_matrix(x[near])
            wr = np.einsum("ij,ij->i", matrix, right[np.nonzero(near)[0]])
            wl = np.einsum("ij,ij->i", matrix, left[np.nonzero(near)[0]])
            z[near] = (wr + (y[near] - y_min) / (y_max - y_min) * (wl - wr)) * e
            groups: dict[str, list[int]] = {}
            for j, contact in enumerate(report.ids):
                groups.setdefault(vehicle_of(contact), []).append(j)
            heavy = {owner: len(cols) > 1 or max(report.models[j].total_mass for j in cols) > HEAVY_KG
                     for owner, cols in groups.items()}
            stamp_of = list(zip(seconds.tolist(), nanoseconds.tolist()))
            names = {owner: proto.length_delimited(3, f"vehicle {owner}".encode()) for owner in groups}  # entity ids
            y_list: list[float] = np.asarray(report.y, dtype=float).tolist()
            forces: list[list[float]] = report.contact_force[rows].tolist()
            on_deck: list[list[bool]] = report.on_deck[rows].tolist()
            x_rows: list[list[float]] = x.tolist()
            z_rows = cast(list[list[float]], z.tolist())  # numpy's stubs say a float
            near_rows: list[list[bool]] = near.tolist()
            scenes = [b"".join([scene, *self._vehicles(stamp_of[i], y_list, forces[i], on_deck[i], groups, heavy,
                                                       names, x_rows[i], near_rows[i], z_rows[i])])
                      for i, scene in enumerate(scenes)]
        self.rec.write_encoded(TOPIC_SCENE, times, scenes)

    def _vehicle_template(self, big: bool, axles: int, arrows: tuple[int, ...]) -> proto.FixedTemplate:
        """A vehicle's entity but its id, its numbers left open (``arrows``: per axle 0 none, 1 push, -1 pull),
        made once per shape: building and encoding the nested messages at every scene was most of its cost."""
        key = (big, axles, arrows)
        template = self._vehicle_templates.get(key)
        if template is None:
            width, height, wheel = _body(big)
            point = {"x": _Z, "y": _Z, "z": _Z}
            box = {"pose": {"position": point, "orientation": _IDENTITY},
                   "size": {"x": _Z, "y": _c(width), "z": _c(height)}, "color": _TRUCK if big else _CAR}
            # A wheel: the cylinder's scales written out (protobuf's default, 0, would draw a cone to a point).
            cylinders = [{"pose": {"position": point, "orientation": _AXLE_ALONG_Y},
                          "size": _vec(wheel, wheel, width + 0.2), "bottom_scale": 1.0, "top_scale": 1.0,
                          "color": _WHEEL} for _ in range(axles)]
            drawn = [{"pose": {"position": point, "orientation": _ARROW_DOWN if sign > 0 else _ARROW_UP},
                      "shaft_length": _Z, "shaft_diameter": 0.2, "head_length": _Z, "head_diameter": 0.5,
                      "color": _PUSH if sign > 0 else _PULL} for sign in arrows if sign]
            entity = {"timestamp": _OPEN, "frame_id": SCENE_FRAME, "lifetime": {"sec": 0, "nsec": 0},
                      "frame_locked": False, "cubes": [box], "cylinders": cylinders, "arrows": drawn}
            value, _ = proto.number_holes(entity, _Z)
            template = self._vehicle_templates[key] = proto.FixedTemplate(self.rec.spec(TOPIC_SCENE).fields[1].message,
                                                                          value)
        return template

    def _vehicles(self, stamp: tuple[int, int], y_all: list[float], forces: list[float], on_deck: list[bool],
                  groups: dict[str, list[int]], heavy: dict[str, bool], names: dict[str, bytes], x_all: list[float],
                  near: list[bool], z_all: list[float]) -> list[bytes]:
        """A box over each vehicle's axles, its wheels (axles) and its contact forces as arrows, at one scene
        (time ``stamp``: s, ns), as encoded entities. ``groups``: each vehicle's contact columns; per contact
        point: ``y_all``, ``x_all`` and ``z_all`` its lateral offset, x and drawn deck level, m, ``forces`` its
        contact force (N), ``on_deck`` and ``near`` whether on or near the deck; ``names``: each vehicle's
        entity id, encoded. Python lists, not arrays: at 10 scenes a second, numpy's per-element access was a
        good part of the scene's cost (and arrays over the few vehicles of a scene cost more than they save)."""
        newton_per_m = self.plan.newton_per_m
        longest = 4.0 * ARROW_LENGTH
        sec, nsec = stamp
        out = []
        for owner, cols in groups.items():
            cols = [j for j in cols if near[j]]
            if not cols:
                continue
            xs = [x_all[j] for j in cols]
            zs = [z_all[j] for j in cols]
            big = heavy[owner]
            width, height, wheel = _body(big)
            overhang = 1.5 if len(cols) > 1 else (5.0 if big else 2.25)
            front, back = max(xs) + overhang, min(xs) - overhang
            y = sum(y_all[j] for j in cols) / len(cols)
            z0 = sum(zs) / len(cols)
            cy = _c(y)
            numbers: list[Any] = [sec, nsec, _c((front + back) / 2), cy, _c(z0 + wheel * 0.6 + height / 2),
                                  _c(front - back)]
            half = wheel / 2
            for x, z in zip(xs, zs):
                numbers += (_c(x), cy, _c(z + half))
            arrows = []
            for j, x, z in zip(cols, xs, zs):
                force = forces[j]
                length = min(abs(force) / newton_per_m, longest)
                if not on_deck[j] or length < 0.05:
                    arrows.append(0)
                    continue
                arrows.append(1 if force > 0 else -1)
                head = min(0.5, 0.5 * length)
                # Beside the body (on its right), where the box does not hide it, down to the deck.
                numbers += (_c(x), _c(y - width / 2 - 0.4), _c(z + (length if force > 0 else 0.0)),
                            round(length - head, _DECIMALS), round(head, _DECIMALS))
            body = self._vehicle_template(big, len(cols), tuple(arrows)).row(numbers) + names[owner]
            out.append(proto.length_delimited(2, body))
        return out
