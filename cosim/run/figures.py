"""Figures of runs and bridges: the values to draw, taken from a log or a model, handed to :mod:`cosim.plots`.

- :func:`plot_log_sensors`: a log's sensor time histories, whole or in a window of time (``cosim plot``);
- :func:`plot_modes`: a bridge's mode shapes (``cosim modes --plot``);
- :func:`plot_bridge_location`: the SUMO network around a bridge (``cosim bridge --plot``).

The output file is checked before the work; :mod:`cosim.plots` draws.
"""
from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cosim import plots
from cosim.errors import CosimError, LogError
from cosim.log.reader import check_window, iter_messages, open_log
from cosim.log.records import ReadStats
from cosim.log.schemas import TOPIC_SENSORS

from .outputs import atomic_write, check_new_file, check_not_input
from .units import display_unit

if TYPE_CHECKING:
    from cosim.core.bridge import BridgeModel, ModalResult
    from cosim.sumo.network import BridgeLocation

#: Points along the bridge at which mode shapes are drawn.
MODE_SHAPE_POINTS = 401
#: Samples per sensor a plot draws as they are; a longer log is drawn as its min/max envelope of as many points.
MAX_PLOT_POINTS = 20_000
#: The figure of a bridge in its network shows the network this far beyond the deck's ends, m.
BRIDGE_MARGIN = 60.0
#: Samples read before they are added to an envelope at once (numpy's ufunc.at per batch, not per sample).
_BATCH = 8192


def plot_log_sensors(log: str | os.PathLike[str], out: str | os.PathLike[str], names: Sequence[str] | None = None,
                     force: bool = False, start: float | None = None, end: float | None = None,
                     stats: ReadStats | None = None) -> list[str]:
    """Draw the time histories of sensors of a log into ``out`` (one panel each, display units); returns their names.

    With ``start`` and/or ``end`` (s of simulated time), only that window: a
    finished log is read through its chunk index, so only the chunks that
    overlap the window are decompressed (:func:`cosim.log.reader.iter_messages`).
    Up to :data:`MAX_PLOT_POINTS` samples are drawn as they are; more, as their
    min/max envelope: memory does not grow with the log or the window.

    Raises:
        LogError: the log cannot be read. CosimError: no such sensor, a window that is empty or outside the
            log, no sample in it, an unsupported file type, or ``out`` exists (without ``force``) or cannot be
            written.
    """
    check_window(start, end)  # before the log is read
    overview = open_log(log, check="summary", stats=stats)
    available = overview.sensor_names
    if not available:
        raise CosimError(f"{log}: the log has no sensor channels to plot")
    chosen = list(names) if names else list(available)
    unknown = [n for n in chosen if n not in available]
    if unknown:
        raise CosimError(f"{log}: no sensor {', '.join(unknown)} in this log (sensors: {', '.join(available)})")
    windowed = start is not None or end is not None
    if windowed:
        check_window(start, end, overview)
    out = Path(out)
    if out.suffix.lower().lstrip(".") not in plots.figure_formats():
        raise CosimError(f"{out}: unsupported file type for the plot (expected .png, .pdf, .svg, ...)")
    check_not_input(out, "plot", [("the log", Path(log))])
    check_new_file(out, "plot", force)
    # Envelope bins span what the log covers within the window (from 0, as always, for a whole log).
    t_lo = 0.0 if start is None else max(start, overview.start_time)
    t_hi = overview.end_time if end is None else min(end, overview.end_time)
    t, series = sensor_history(log, chosen, t_lo, t_hi, start=start, end=end, stats=stats)
    if windowed and not len(t):
        raise CosimError(f"{log}: no sensor sample between t = {t_lo:g} and {t_hi:g} s (--from/--to)")
    quantity = dict(zip(available, overview.quantities))
    units = {name: display_unit(quantity.get(name, "")) for name in chosen}
    scaled = {name: series[name] * units[name][1] for name in chosen}
    span = f"; t = {t_lo:g} to {t_hi:g} s" if windowed else ""
    title = f"{overview.info.get('scenario', Path(log).stem)} — {Path(log).name} ({overview.status_word}{span})"
    with atomic_write(out, "plot") as partial:
        return plots.sensor_histories(t, scaled, {name: unit for name, (unit, _) in units.items()}, title, partial)


class _Envelope:
    """The min and max of each channel in each of ``bins`` equal time bins over ``[t_lo, t_hi]``, fed in batches."""

    def __init__(self, channels: int, t_lo: float, t_hi: float, bins: int) -> None:
        self.t_lo = t_lo
        self.width = (t_hi - t_lo) / bins if t_hi > t_lo else 1.0
        self.bins = bins
        self.lo = np.full((bins, channels), np.inf)
        self.hi = np.full((bins, channels), -np.inf)
        self.seen = np.zeros(bins, dtype=bool)

    def add(self, times: list[float], rows: list[list[float]]) -> None:
        if not times:
            return
        index = np.clip(((np.asarray(times) - self.t_lo) / self.width).astype(np.int64), 0, self.bins - 1)
        values = np.asarray(rows, dtype=float).reshape(len(rows), self.lo.shape[1])
        np.minimum.at(self.lo, index, values)
        np.maximum.at(self.hi, index, values)
        self.seen[index] = True

    def result(self, names: Sequence[str]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        keep = np.flatnonzero(self.seen)
        t = np.repeat(self.t_lo + (keep + 0.5) * self.width, 2)
        return t, {name: np.column_stack([self.lo[keep, i], self.hi[keep, i]]).ravel() for i, name in enumerate(names)}


def _sensor_batches(log: str | os.PathLike[str], names: Sequence[str], start: float | None, end: float | None,
                    stats: ReadStats | None) -> Iterator[tuple[list[float], list[list[float]]]]:
    """The sensor samples of a log (in a window), as batches of (times, rows of values)."""
    times: list[float] = []
    rows: list[list[float]] = []
    for _, message in iter_messages(log, [TOPIC_SENSORS], start, end, stats):
        times.append(float(message["t"]))
        try:
            rows.append([float(message[n]) for n in names])
        except KeyError as exc:
            raise LogError(f"{log}: a sensor sample at t = {message['t']:g} s has no channel {exc.args[0]!r}") from None
        if len(times) >= _BATCH:
            yield times, rows
            times, rows = [], []
    yield times, rows


def sensor_history(log: str | os.PathLike[str], names: Sequence[str], t_lo: float, t_hi: float,
                   start: float | None = None, end: float | None = None, stats: ReadStats | None = None,
                   max_points: int = MAX_PLOT_POINTS) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """What a plot draws of the sensor channels of a log (in the window ``[start, end]``), in one pass and
    bounded memory: every sample sorted by time if there are at most ``max_points``, else the min/max
    envelope of ``max_points // 2`` bins over ``[t_lo, t_hi]`` (see :func:`sensor_envelope`)."""
    envelope = _Envelope(len(names), t_lo, t_hi, max_points // 2)
    kept_t: list[float] = []
    kept: list[list[float]] = []
    exact = True
    for times, rows in _sensor_batches(log, names, start, end, stats):
        envelope.add(times, rows)
        if exact:
            kept_t.extend(times)
            kept.extend(rows)
            if len(kept_t) > max_points:
                exact = False
                kept_t, kept = [], []
    if not exact:
        return envelope.result(names)
    t = np.asarray(kept_t, dtype=float)
    values = np.asarray(kept, dtype=float).reshape(len(kept), len(names))
    order = np.argsort(t, kind="stable")
    return t[order], {name: values[order, i] for i, name in enumerate(names)}


def sensor_envelope(log: str | os.PathLike[str], names: Sequence[str], end_time: float, bins: int,
                    start_time: float = 0.0, start: float | None = None, end: float | None = None,
                    stats: ReadStats | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log (in the window ``[start, end]``) reduced to their min and max in each of
    ``bins`` equal time bins from ``start_time`` to ``end_time``.

    Returns times and values of two points per bin (its minimum, then its
    maximum, both at the bin's centre): drawn as a line, the envelope looks
    like the full history at any figure width below ``bins`` pixels, in
    memory that does not depend on the log's length. Bins without samples
    are left out.
    """
    envelope = _Envelope(len(names), start_time, end_time, bins)
    for times, rows in _sensor_batches(log, names, start, end, stats):
        envelope.add(times, rows)
    return envelope.result(names)


def plot_modes(bridge: BridgeModel, modal: ModalResult, path: str | os.PathLike[str], count: int) -> int:
    """Draw v, w and theta_x of the first ``count`` modes (at most :data:`cosim.plots.MAX_MODE_SHAPES`)
    along the bridge into ``path``; returns how many were drawn."""
    n = min(count, len(modal.f_hz), plots.MAX_MODE_SHAPES)
    x = np.linspace(0.0, bridge.length, MODE_SHAPE_POINTS)
    shapes = [{name: modal.field(i, name, x) for name in ("v", "w", "theta_x")} for i in range(n)]
    titles = [f"mode {i + 1}: {modal.f_hz[i]:.3f} Hz, {modal.kinds[i]}" for i in range(n)]
    supports_x = np.concatenate([[0.0], np.cumsum(bridge.spans)])
    half_width = max(abs(bridge.section.deck_y[0]), abs(bridge.section.deck_y[1]), 1.0)
    with atomic_write(path, "plot") as partial:
        return plots.mode_shapes(x, shapes, titles, supports_x, half_width, partial)


def plot_bridge_location(loc: BridgeLocation, path: str | Path, margin: float = BRIDGE_MARGIN) -> None:
    """Draw the SUMO network around a located bridge into ``path`` (``cosim bridge --plot``): the lanes, the
    junctions, the deck's lanes, the carriageway's outline and the axis, ``margin`` m beyond the deck's ends."""
    from cosim.sumo.network import lane_shapes

    axis = loc.axis
    middle = tuple(0.5 * (np.asarray(axis.start) + np.asarray(axis.end)))
    half = 0.5 * axis.length + margin
    shapes = lane_shapes(loc.net, (float(middle[0]), float(middle[1])), half)
    deck_ids = set(loc.deck_lanes)
    e, n = axis.unit()
    lo, hi = loc.carriageway
    s = np.asarray(axis.start, dtype=float)
    corners = [s + lo * n, s + axis.length * e + lo * n, s + axis.length * e + hi * n, s + hi * n, s + lo * n]
    plots.network_figure(
        lanes=[pts for lid, pts in shapes if lid not in deck_ids and not lid.startswith(":")],
        junction_lanes=[pts for lid, pts in shapes if lid.startswith(":")],
        deck_lanes=[pts for lid, pts in shapes if lid in deck_ids],
        outline=np.array(corners), axis=np.array([axis.start, axis.end]),
        title=f"edges {', '.join(loc.edges)} of {loc.net.name}: {axis.length:.2f} m", path=path,
        extent=(middle[0] - half, middle[0] + half, middle[1] - half, middle[1] + half),
    )
