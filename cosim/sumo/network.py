"""The road network around a bridge, read with sumolib: where the deck is, which lanes to watch, candidates.

A SUMO network is read once per file (and file version) with sumolib's own
reader, internal junction lanes included; cosim never parses a network by
hand. On it:

- :func:`locate_bridge`: the bridge from the edges it carries (``[traffic]
  edges``). The rule, stated once: the axis runs along the **carriageway's
  centre line**, midway between the outer edges of the outermost vehicle
  lanes of the named edges (for a two-way road with the same lanes each way,
  the line between the two directions; for a one-way bridge, the middle of
  its lanes). Its direction is the first named edge's direction of travel
  (chord of its lanes, first to last point); x = 0 is where the named lanes
  begin along it, and the deck length is their extent along the axis (first
  point to last, every lane, so a short curve at an end counts by its
  projection). A lane's lateral position is the median of its centre line's
  distance from the axis (curved ends do not move it). Sidewalks (lanes only
  pedestrians may use) are not part of the carriageway.
- :func:`watched_lanes`: the lanes on which a vehicle can have an axle on the
  deck: the deck's lanes, the opposite direction between the same junctions,
  and every lane (internal junction lanes included) that leads to them or
  leaves them within a reach (the longest vehicle plus slack), following the
  network's connections. A road passing under the bridge is not connected to
  it, so its vehicles are never taken for vehicles on the deck.
- :func:`lanes_across`: for an axis given without edges, the lanes whose
  centre line runs through the deck's box.
- :func:`bridge_candidates`: two-way edge pairs and one-way edges that could
  be a bridge (``cosim bridge``).

No libsumo here: this runs before SUMO starts, so a wrong edge is reported
before any file is written.
"""
from __future__ import annotations

import difflib
import functools
import heapq
import io
import math
import re
import shlex
import xml.sax
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cosim.errors import ConfigError, first_line
from cosim.sumo.files import read_config, read_input

__all__ = [
    "REACH_SLACK",
    "BridgeAxis",
    "BridgeCandidate",
    "BridgeLocation",
    "DeckLane",
    "bridge_candidates",
    "edge_options",
    "is_vehicle_lane",
    "lane_graph",
    "lanes_across",
    "polyline_samples",
    "wheel_paths_beyond",
    "locate_bridge",
    "net_path",
    "read_network",
    "watched_lanes",
]

#: Watched lanes reach this far beyond the longest vehicle, m (a step of travel and a junction's width).
REACH_SLACK = 10.0
#: Centre lines are sampled this finely to measure lateral positions and boxes, m.
SAMPLE_STEP = 0.5
#: A deck length may differ this much (m, or the share of the bridge's length if larger) from the lanes' extent;
#: the deck is then centred on the lanes.
LENGTH_TOLERANCE = (0.5, 0.02)


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
        """The unit vector along the axis and the left normal."""
        e = (np.asarray(self.end, dtype=float) - np.asarray(self.start, dtype=float)) / self.length
        return e, np.array([-e[1], e[0]])

    def project(self, px: Any, py: Any) -> tuple[np.ndarray, np.ndarray]:
        """Bridge coordinates (x along the axis from start, y to the left) of network points."""
        e, n = self._frame
        dx, dy = np.asarray(px, dtype=float) - self.start[0], np.asarray(py, dtype=float) - self.start[1]
        return dx * e[0] + dy * e[1], dx * n[0] + dy * n[1]


# --------------------------------------------------------------------------- reading


def net_path(path: str | Path) -> Path:
    """The network of ``path``: the file itself, or the ``net-file`` of a SUMO config (``.sumocfg``).

    Raises:
        ConfigError: a config that names no network, or several.
    """
    path = Path(path)
    if not path.name.endswith(".sumocfg"):
        return path
    config = read_config(path)
    nets = config.files(("net-file",))
    if len(nets) != 1:
        raise ConfigError(f"{path}: expected one net-file, got {len(nets)}")
    return nets[0]


def read_network(path: str | Path) -> Any:
    """The sumolib network of a ``.net.xml`` (or ``.net.xml.gz``), internal lanes included.

    The file is read through :func:`cosim.sumo.files.read_input` (bounded
    decompression) and parsed by sumolib's reader; a file is parsed once per
    version (its size and modification time).

    Raises:
        ConfigError: missing, unreadable or not a SUMO network.
    """
    path = Path(path)
    try:
        stat = path.stat()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read the network ({exc.strerror})") from None
    return _read_network(str(path), stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=4)
def _read_network(path: str, size: int, mtime_ns: int) -> Any:
    import sumolib.net  # the sumolib of the eclipse-sumo release (PyPI "sumolib")

    data = read_input(Path(path))
    reader = sumolib.net.NetReader(withInternal=True)
    try:
        parser = xml.sax.make_parser()  # external entities are not resolved (the default since Python 3.7.1)
        parser.setContentHandler(reader)
        parser.parse(io.BytesIO(data))
    except (xml.sax.SAXException, ValueError, KeyError, IndexError) as exc:
        raise ConfigError(f"{path}: not a readable SUMO network ({first_line(exc)})") from None
    net = reader.getNet()
    if not net.getEdges():
        raise ConfigError(f"{path}: the network has no edges")
    return net


# --------------------------------------------------------------------------- lanes


def polyline_samples(shape: Any, step: float = SAMPLE_STEP) -> np.ndarray:
    """Points along a polyline at most ``step`` apart (its vertices included), (n, 2)."""
    pts = np.asarray(shape, dtype=float)[:, :2]
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(int(math.ceil(math.dist(a, b) / step)), 1)
        t = np.arange(1, n + 1)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out)


def is_vehicle_lane(lane: Any) -> bool:
    """True unless only pedestrians may use the lane (a sidewalk is not part of the carriageway)."""
    allowed = set(lane.getPermissions())
    return bool(allowed - {"pedestrian"})


@functools.lru_cache(maxsize=4)
def lane_graph(net: Any) -> tuple[dict[str, list[str]], dict[str, list[str]], dict[str, float]]:
    """Successors and predecessors of every lane (internal junction lanes included), and lane lengths."""
    succ: dict[str, list[str]] = {}
    pred: dict[str, list[str]] = {}
    length: dict[str, float] = {}
    for edge in net.getEdges(withInternal=True):
        for lane in edge.getLanes():
            lid = lane.getID()
            length[lid] = float(lane.getLength())
            for conn in lane.getOutgoing():
                nxt = conn.getViaLaneID() or conn.getToLane().getID()
                succ.setdefault(lid, []).append(nxt)
                pred.setdefault(nxt, []).append(lid)
    return succ, pred, length


@dataclass(frozen=True)
class DeckLane:
    """A lane on the deck, in bridge coordinates.

    Attributes:
        id: the lane id; edge: its edge.
        y: lateral position of its centre line from the axis (median along the lane), m.
        width: m.
        direction: +1 drives along +x, -1 against it.
        x_range: its extent along the axis, m.
    """

    id: str
    edge: str
    y: float
    width: float
    direction: int
    x_range: tuple[float, float]


@dataclass(frozen=True)
class BridgeLocation:
    """A bridge located in a network by the edges it carries (:func:`locate_bridge`).

    Attributes:
        net: the network file.
        edges: the named edges (the deck); opposite: other edges between the same junctions,
            in the other direction, watched too.
        axis: the deck's axis (its length is the bridge's when one was given).
        lanes_length: the named lanes' extent along the axis, m.
        lanes: the vehicle lanes of the named edges.
        carriageway: (y_min, y_max) of the outer lane edges, m from the axis.
        footways: the named edges' lanes only pedestrians may use (sidewalks), in bridge coordinates: not part
            of the carriageway, and not loaded (cosim models no pedestrians), so a deck need not cover them.
        wheel_paths: where the vehicle lanes' centre lines (the wheel paths) reach farthest to each side over
            the deck's length, 0 <= x <= L: ((y_min, lane, x), (y_max, lane, x)), m. On a straight bridge they lie
            within the carriageway; an edge that curves against the straight axis takes them beyond it.
        junctions: the junctions at the edges' ends (id, type).
        names: street names the network kept for the edges.
        osm_bridge: the edges' OSM ``bridge`` attributes, where the network kept them.
    """

    net: Path
    edges: tuple[str, ...]
    opposite: tuple[str, ...]
    axis: BridgeAxis
    lanes_length: float
    lanes: tuple[DeckLane, ...]
    carriageway: tuple[float, float]
    junctions: tuple[tuple[str, str], ...]
    names: tuple[str, ...]
    osm_bridge: tuple[str, ...]
    footways: tuple[DeckLane, ...] = ()
    wheel_paths: tuple[tuple[float, str, float], tuple[float, str, float]] = ((0.0, "", 0.0), (0.0, "", 0.0))

    @functools.cached_property
    def deck_lanes(self) -> tuple[str, ...]:
        """Every lane of the named and the opposite edges (the lanes a vehicle on the deck can be on)."""
        net = read_network(self.net)
        return tuple(lane.getID() for e in (*self.edges, *self.opposite) for lane in net.getEdge(e).getLanes())

    @property
    def two_way(self) -> bool:
        return len({lane.direction for lane in self.lanes}) == 2


def _edge_or_error(net: Any, net_file: Path, edge_id: str, known: list[str]) -> Any:
    if not net.hasEdge(edge_id):
        near = difflib.get_close_matches(edge_id, known, n=3, cutoff=0.5)
        hint = f" (did you mean {', '.join(near)}?)" if near else " (`cosim bridge NET` lists candidate bridges)"
        raise ConfigError(f"the network {net_file.name} has no edge {edge_id!r}{hint}")
    edge = net.getEdge(edge_id)
    if edge.getFunction() == "internal":
        raise ConfigError(f"{edge_id!r} is an internal (junction) edge of {net_file.name}: name only the bridge's "
                          "own edges; vehicles in the junctions at its ends are followed anyway")
    if edge.getFunction() not in ("", "normal"):
        raise ConfigError(f"{edge_id!r} is a {edge.getFunction()} edge of {net_file.name}, not a road")
    return edge


def _opposite(net: Any, edge: Any) -> list[Any]:
    """Normal edges from ``edge``'s end junction back to its start junction."""
    return [o for o in edge.getToNode().getOutgoing()
            if o.getToNode() is edge.getFromNode() and o.getFunction() in ("", "normal")]


def locate_bridge(net_file: str | Path, edges: Sequence[str], length: float | None = None) -> BridgeLocation:
    """The bridge carried by ``edges``: its axis, deck length and lanes (the rule: this module's docstring).

    Args:
        net_file: the network (``.net.xml`` or gzipped).
        edges: the deck's edges (one or both directions, any number of lanes).
        length: the bridge's length, m; the axis then has this length, centred on the lanes.
            Without it, the axis spans the lanes.

    Raises:
        ConfigError: an edge that the network lacks (with close matches), an internal edge, no vehicle
            lane, or a length that differs from the lanes' by more than :data:`LENGTH_TOLERANCE`.
    """
    net_file = Path(net_file)
    if not edges:
        raise ConfigError("give at least one edge")
    repeated = sorted({e for e in edges if list(edges).count(e) > 1})
    if repeated:
        raise ConfigError(f"edge(s) named more than once: {', '.join(repeated)}")
    net = read_network(net_file)
    known = [e.getID() for e in net.getEdges()]
    found = [_edge_or_error(net, net_file, e, known) for e in edges]
    lanes = [(edge, lane) for edge in found for lane in edge.getLanes() if is_vehicle_lane(lane)]
    footways = [(edge, lane) for edge in found for lane in edge.getLanes() if not is_vehicle_lane(lane)]
    if not lanes:
        raise ConfigError(f"edge(s) {', '.join(edges)} of {net_file.name} have no lane for vehicles")
    # Direction: the first named edge's lanes, first point to last.
    chords = [np.subtract(lane.getShape()[-1][:2], lane.getShape()[0][:2]) for e, lane in lanes if e is found[0]]
    chord = np.sum(chords, axis=0)
    if not np.linalg.norm(chord) > 0:
        raise ConfigError(f"edge {edges[0]!r} of {net_file.name} has no length")
    e_dir = chord / np.linalg.norm(chord)
    n_dir = np.array([-e_dir[1], e_dir[0]])
    origin = np.asarray(lanes[0][1].getShape()[0][:2], dtype=float)
    centre_lines = {}

    def row(edge: Any, lane: Any) -> tuple[Any, Any, float, float, int, float, float]:
        pts = polyline_samples(lane.getShape()) - origin
        along, across = pts @ e_dir, pts @ n_dir
        centre_lines[lane.getID()] = (along, across)
        return (lane, edge, float(np.median(across)), float(lane.getWidth()), lane_sense(lane, e_dir),
                float(along.min()), float(along.max()))

    rows = [row(edge, lane) for edge, lane in lanes]
    lo = min(r[2] - r[3] / 2 for r in rows)
    hi = max(r[2] + r[3] / 2 for r in rows)
    centre = 0.5 * (lo + hi)
    x0, x1 = min(r[5] for r in rows), max(r[6] for r in rows)
    extent = x1 - x0
    if length is None:
        a, b = x0, x1
    else:
        tol = max(LENGTH_TOLERANCE[0], LENGTH_TOLERANCE[1] * length)
        if abs(extent - length) > tol:
            raise ConfigError(
                f"the lanes of edge(s) {', '.join(edges)} are {extent:.3f} m long along the derived axis, the "
                f"bridge {length:g} m: set [bridge] spans to add up to {extent:.3f} m, or give [traffic] axis to "
                f"place a deck of another length (cosim bridge {shlex.quote(net_file.name)} {edge_options(edges)} "
                "prints the lines)")
        mid = 0.5 * (x0 + x1)
        a, b = mid - 0.5 * length, mid + 0.5 * length
    reach: list[tuple[float, str, float]] = []
    for lane, *_ in rows:
        along, across = centre_lines[lane.getID()]
        over = (along >= a) & (along <= b)
        if over.any():
            k_lo, k_hi = np.argmin(np.where(over, across, np.inf)), np.argmax(np.where(over, across, -np.inf))
            reach += [(float(across[k_lo] - centre), lane.getID(), float(along[k_lo] - a)),
                      (float(across[k_hi] - centre), lane.getID(), float(along[k_hi] - a))]
    wheel_paths = (min(reach), max(reach)) if reach else ((0.0, "", 0.0), (0.0, "", 0.0))
    start = origin + centre * n_dir + a * e_dir
    end = origin + centre * n_dir + b * e_dir
    axis = BridgeAxis((float(start[0]), float(start[1])), (float(end[0]), float(end[1])))
    deck = tuple(DeckLane(lane.getID(), edge.getID(), y - centre, width, d, (xa - a, xb - a))
                 for lane, edge, y, width, d, xa, xb in rows)
    opposite = []
    for edge in found:
        for o in _opposite(net, edge):
            if o.getID() not in edges and o.getID() not in opposite:
                opposite.append(o.getID())
    junctions = []
    for edge in found:
        for node in (edge.getFromNode(), edge.getToNode()):
            item = (node.getID(), node.getType())
            if item not in junctions:
                junctions.append(item)
    return BridgeLocation(
        net=net_file, edges=tuple(edges), opposite=tuple(opposite), axis=axis, lanes_length=extent, lanes=deck,
        carriageway=(lo - centre, hi - centre), junctions=tuple(junctions),
        names=tuple(dict.fromkeys(n for n in (e.getName() for e in found) if n)),
        osm_bridge=tuple(dict.fromkeys(v for v in (_osm_bridge(e) for e in found) if v)),
        wheel_paths=wheel_paths,
        footways=tuple(DeckLane(lane.getID(), edge.getID(), y - centre, width, d, (xa - a, xb - a))
                       for lane, edge, y, width, d, xa, xb in (row(edge, lane) for edge, lane in footways)),
    )


def _osm_bridge(edge: Any) -> str:
    """The edge's OSM ``bridge`` attribute (kept by netconvert --osm.all-attributes), or ""."""
    params: dict[str, str] = getattr(edge, "getParams", dict)() or {}
    return str(params.get("bridge", ""))


def lanes_across(net_file: str | Path, axis: BridgeAxis, y_range: tuple[float, float]) -> tuple[str, ...]:
    """Lanes (internal ones included) whose centre line runs through the deck's box, 0 < x < L within y_range."""
    net = read_network(net_file)
    found = []
    lo, hi = y_range
    for edge in net.getEdges(withInternal=True):
        for lane in edge.getLanes():
            if not is_vehicle_lane(lane):
                continue
            pts = polyline_samples(lane.getShape())
            x, y = axis.project(pts[:, 0], pts[:, 1])
            if np.any((x > 0.0) & (x < axis.length) & (y >= lo) & (y <= hi)):
                found.append(lane.getID())
    return tuple(found)


def watched_lanes(net_file: str | Path, deck_lanes: Iterable[str], reach: float,
                  upstream: float = REACH_SLACK) -> tuple[str, ...]:
    """The deck lanes and the lanes that leave them within ``reach`` m or lead to them within ``upstream`` m.

    Distances are path lengths along the network's connections (internal
    junction lanes are lanes like any other here). Downstream, a lane is
    watched when it begins less than ``reach`` after the end of a deck lane: a
    vehicle whose front is on it can still have an axle on the deck, so
    ``reach`` is the longest vehicle plus slack. Upstream, where a vehicle's
    axles are all behind its front bumper and so off the deck, a short
    ``upstream`` reach lets the frames see a vehicle a step before it enters.
    """
    net = read_network(net_file)
    succ, pred, length = lane_graph(net)
    deck = list(dict.fromkeys(deck_lanes))
    found = dict.fromkeys(deck)
    for graph, limit in ((succ, reach), (pred, upstream)):
        # Dijkstra on path length from the deck's lane ends: a lane's distance is where it starts
        # (downstream) or ends (upstream), measured from the deck.
        dist: dict[str, float] = {}
        heap = [(0.0, nxt) for lane in deck for nxt in graph.get(lane, ()) if nxt not in found]
        heapq.heapify(heap)
        while heap:
            d, lane = heapq.heappop(heap)
            if lane in dist or d >= limit:
                continue
            dist[lane] = d
            found.setdefault(lane)
            for nxt in graph.get(lane, ()):
                if nxt not in dist and nxt not in deck:
                    heapq.heappush(heap, (d + length.get(lane, 0.0), nxt))
    return tuple(found)


def lane_sense(lane: Any, along: Any) -> int:
    """+1 if a sumolib lane drives along the unit vector ``along`` (its chord, first point to last), else -1."""
    return 1 if float(np.dot(np.subtract(lane.getShape()[-1][:2], lane.getShape()[0][:2]), along)) >= 0.0 else -1


def deck_directions(net_file: str | Path, deck_lanes: Iterable[str], axis: BridgeAxis) -> dict[str, int]:
    """Each deck lane's edge -> the way it drives, as Grave's direction (:mod:`cosim.core.loads`): 1 along the
    bridge axis, 2 against it (:func:`lane_sense`)."""
    net = read_network(net_file)
    along = axis.unit()[0]
    out: dict[str, int] = {}
    for lane_id in deck_lanes:
        lane = net.getLane(lane_id)
        out.setdefault(lane.getEdge().getID(), 1 if lane_sense(lane, along) > 0 else 2)
    return out


def wheel_paths_beyond(location: BridgeLocation, deck_y: tuple[float, float], what: str = "the deck") -> str:
    """A line saying where the lanes' centre lines (the wheel paths) leave ``what`` (its lateral extent
    ``deck_y``, m) over the deck's length, or "" if they do not: an edge that curves against the straight axis."""
    (lo, lane_lo, x_lo), (hi, lane_hi, x_hi) = location.wheel_paths
    parts = []
    if lo < deck_y[0]:
        parts.append(f"y = {lo:.2f} m (lane {lane_lo} at x = {x_lo:.1f} m)")
    if hi > deck_y[1]:
        parts.append(f"y = {hi:.2f} m (lane {lane_hi} at x = {x_hi:.1f} m)")
    if not parts:
        return ""
    return (f"wheel paths beyond {what} (y = {deck_y[0]:.3f} to {deck_y[1]:.3f} m): the lanes' centre lines reach "
            f"{' and '.join(parts)}; the edge curves against the straight axis there, and a wheel beyond the deck "
            "loads nothing (each time, an \"offdeck\" event in the log)")


# --------------------------------------------------------------------------- candidates


def edge_options(edges: Sequence[str]) -> str:
    """``--edge=ID`` for each edge, quoted for a POSIX shell where needed: a command that works when pasted,
    whatever SUMO allows in an id (``-148050455#0``, ``43[1]``, ``:J1_0``)."""
    # "#" only starts a shell comment at a word's start, never after "--edge=": no quotes for OSM's "123#0".
    return " ".join("--edge=" + (e if re.fullmatch(r"[\w@%+=:,./#-]+", e) else shlex.quote(e)) for e in edges)



@dataclass(frozen=True)
class BridgeCandidate:
    """Edges that could be a bridge: a two-way pair between two junctions, or a one-way edge.

    Attributes:
        edges: one or two edge ids; length: m (the longer); lanes: vehicle lanes per edge;
        names: street names; osm_bridge: OSM bridge attributes kept by the network;
        middle: the midpoint of the first edge, network coordinates.
    """

    edges: tuple[str, ...]
    length: float
    lanes: tuple[int, ...]
    names: tuple[str, ...]
    osm_bridge: tuple[str, ...]
    middle: tuple[float, float]

    @property
    def kind(self) -> str:
        return "two-way" if len(self.edges) == 2 else "one-way"


def bridge_candidates(net_file: str | Path, near: tuple[float, float] | None = None,
                      min_length: float = 10.0) -> list[BridgeCandidate]:
    """Two-way edge pairs and one-way edges of at least ``min_length`` m with vehicle lanes.

    Sorted: edges the network marks as OSM bridges first, then by distance from
    ``near`` (network coordinates) if given, else longest first.
    """
    net = read_network(net_file)
    seen: set[str] = set()
    out = []
    for edge in sorted(net.getEdges(), key=lambda e: e.getID()):
        if edge.getID() in seen or edge.getFunction() not in ("", "normal"):
            continue
        lanes = [lane for lane in edge.getLanes() if is_vehicle_lane(lane)]
        if not lanes:
            continue
        pair = [edge] + [o for o in _opposite(net, edge) if o.getID() not in seen][:1]
        seen.update(e.getID() for e in pair)
        length = max(float(e.getLength()) for e in pair)
        if length < min_length:
            continue
        pts = polyline_samples(edge.getShape())
        mid = pts[len(pts) // 2]
        out.append(BridgeCandidate(
            edges=tuple(e.getID() for e in pair), length=length,
            lanes=tuple(sum(1 for lane in e.getLanes() if is_vehicle_lane(lane)) for e in pair),
            names=tuple(dict.fromkeys(n for n in (e.getName() for e in pair) if n)),
            osm_bridge=tuple(dict.fromkeys(v for v in (_osm_bridge(e) for e in pair) if v)),
            middle=(float(mid[0]), float(mid[1])),
        ))

    def key(c: BridgeCandidate) -> tuple[int, float]:
        rank = 0 if c.osm_bridge and c.osm_bridge != ("no",) else 1
        if near is not None:
            return rank, math.dist(c.middle, near)
        return rank, -c.length

    return sorted(out, key=key)


def lane_shapes(net_file: str | Path, around: tuple[float, float], radius: float) -> list[tuple[str, np.ndarray]]:
    """(lane id, (n, 2) centre line) of every normal and internal lane with a point within ``radius`` of ``around``."""
    net = read_network(net_file)
    out = []
    for edge in net.getEdges(withInternal=True):
        for lane in edge.getLanes():
            pts = np.asarray(lane.getShape(), dtype=float)[:, :2]
            if np.min(np.hypot(*(polyline_samples(pts) - np.asarray(around)).T)) <= radius:
                out.append((lane.getID(), pts))
    return out
