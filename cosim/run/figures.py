"""Figures of runs and bridges: the values to draw, taken from a log or a model, handed to :mod:`cosim.plots`.

- :func:`plot_log_sensors`: a log's sensor time histories (``cosim plot``);
- :func:`plot_modes`: a bridge's mode shapes (``cosim modes --plot``).

The output file is checked before the work; :mod:`cosim.plots` draws.
"""
from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from cosim import plots
from cosim.core.bridge import BridgeModel, ModalResult
from cosim.errors import CosimError, LogError
from cosim.log.reader import iter_messages, open_log, sensor_series
from cosim.log.schemas import TOPIC_SENSORS

from .outputs import atomic_write, check_new_file, check_not_input
from .units import display_unit

#: Points along the bridge at which mode shapes are drawn.
MODE_SHAPE_POINTS = 401
#: Samples per sensor a plot draws as they are; a longer log is drawn as its min/max envelope of as many points.
MAX_PLOT_POINTS = 20_000


def plot_log_sensors(log: str | os.PathLike[str], out: str | os.PathLike[str], names: Sequence[str] | None = None,
                     force: bool = False) -> list[str]:
    """Draw the time histories of sensors of a log into ``out`` (one panel each, display units); returns their names.

    Raises:
        LogError: the log cannot be read. CosimError: no such sensor, an unsupported file type, or ``out``
            exists (without ``force``) or cannot be written.
    """
    overview = open_log(log)
    available = overview.sensor_names
    if not available:
        raise CosimError(f"{log}: the log has no sensor channels to plot")
    chosen = list(names) if names else list(available)
    unknown = [n for n in chosen if n not in available]
    if unknown:
        raise CosimError(f"{log}: no sensor {', '.join(unknown)} in this log (sensors: {', '.join(available)})")
    out = Path(out)
    if out.suffix.lower().lstrip(".") not in plots.figure_formats():
        raise CosimError(f"{out}: unsupported file type for the plot (expected .png, .pdf, .svg, ...)")
    check_not_input(out, "plot", [("the log", Path(log))])
    check_new_file(out, "plot", force)
    if overview.counts.get(TOPIC_SENSORS, 0) <= MAX_PLOT_POINTS:
        t, series = sensor_series(log, chosen)
    else:  # a long log: each panel's min/max envelope, streamed (memory does not grow with the log)
        t, series = sensor_envelope(log, chosen, overview.end_time, MAX_PLOT_POINTS // 2)
    quantity = dict(zip(available, overview.quantities))
    units = {name: display_unit(quantity.get(name, "")) for name in chosen}
    scaled = {name: series[name] * units[name][1] for name in chosen}
    title = f"{overview.info.get('scenario', Path(log).stem)} — {Path(log).name} ({overview.status_word})"
    with atomic_write(out, "plot") as partial:
        return plots.sensor_histories(t, scaled, {name: unit for name, (unit, _) in units.items()}, title, partial)


def sensor_envelope(log: str | os.PathLike[str], names: Sequence[str], end_time: float, bins: int
                    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensor channels of a log reduced to their min and max in each of ``bins`` equal time bins.

    Returns times and values of two points per bin (its minimum, then its
    maximum, both at the bin's centre): drawn as a line, the envelope looks
    like the full history at any figure width below ``bins`` pixels, in
    memory that does not depend on the log's length. Bins without samples
    are left out.
    """
    width = end_time / bins if end_time > 0 else 1.0
    lo = np.full((bins, len(names)), np.inf)
    hi = np.full((bins, len(names)), -np.inf)
    seen = np.zeros(bins, dtype=bool)
    times: list[float] = []
    rows: list[list[float]] = []

    def flush() -> None:
        if not times:
            return
        index = np.clip((np.asarray(times) / width).astype(np.int64), 0, bins - 1)
        values = np.asarray(rows, dtype=float).reshape(len(rows), len(names))
        np.minimum.at(lo, index, values)
        np.maximum.at(hi, index, values)
        seen[index] = True
        times.clear()
        rows.clear()

    for _, message in iter_messages(log, [TOPIC_SENSORS]):
        times.append(float(message["t"]))
        try:
            rows.append([float(message[n]) for n in names])
        except KeyError as exc:
            raise LogError(f"{log}: a sensor sample at t = {message['t']:g} s has no channel {exc.args[0]!r}") from None
        if len(times) >= 8192:
            flush()
    flush()
    keep = np.flatnonzero(seen)
    centre = (keep + 0.5) * width
    t = np.repeat(centre, 2)
    series = {name: np.column_stack([lo[keep, i], hi[keep, i]]).ravel() for i, name in enumerate(names)}
    return t, series


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
