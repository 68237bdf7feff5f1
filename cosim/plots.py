"""Every figure cosim draws (matplotlib, Agg): the only module that imports matplotlib.

Functions take plain values (arrays, results) and a path, draw one figure
and write it; they neither read logs nor run anything. Callers check the
output path before the work (``cosim.run.outputs``).
"""
from __future__ import annotations

import itertools
import os
import re
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

# --------------------------------------------------------------------------- common
import numpy.typing as npt

from cosim.errors import CosimError


def figure_formats() -> list[str]:
    """The file suffixes a figure can be written as (``png``, ``pdf``, ``svg``, ...), sorted."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    return sorted(FigureCanvasAgg.get_supported_filetypes())


def _figure(width: float, height: float) -> Any:
    """A matplotlib figure on the Agg canvas (no display needed), laid out by matplotlib."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Any, path: str | Path, dpi: int) -> None:
    """Write ``fig`` to ``path`` (its suffix picks the format)."""
    try:
        fig.savefig(path, dpi=dpi)
    except (OSError, ValueError) as exc:
        raise CosimError(f"{path}: cannot write the plot ({exc})") from None


# --------------------------------------------------------------------------- mode shapes

#: Most mode shapes drawn in one figure.
MAX_MODE_SHAPES = 6
#: A field of a mode below this share of the mode's largest is drawn as zero (round-off).
NEGLIGIBLE_SHARE = 1e-3
_MODE_FIELDS = (("v", "v (lateral)", "-"), ("w", "w (vertical)", "--"), ("theta_x", "θ_x (twist)", ":"))


def mode_shapes(x: npt.ArrayLike, shapes: Sequence[Mapping[str, npt.ArrayLike]], titles: Sequence[str],
                supports_x: npt.ArrayLike, half_width: float, path: str | Path) -> int:
    """Draw mode shapes along the bridge, one panel per mode (at most :data:`MAX_MODE_SHAPES`).

    Args:
        x: positions along the bridge, m.
        shapes: per mode, the fields ``v``, ``w`` (m) and ``theta_x`` (rad) at ``x``.
        titles: per mode, the panel's title.
        supports_x: positions of the support lines, m (drawn as vertical lines).
        half_width: half the deck width, m: the twist counts as its deck-edge displacement.
        path: the figure file (its suffix picks the format).

    Each field is normalised to a peak of 1; its legend gives its size relative
    to the largest of the mode's three. A field below :data:`NEGLIGIBLE_SHARE`
    is round-off (e.g. twist in a vertical mode of a symmetric section) and is
    drawn as zero.

    Returns:
        The number of modes drawn.
    """
    x = np.asarray(x, dtype=float)
    n = min(len(shapes), MAX_MODE_SHAPES)
    fig = _figure(8.0, 2.0 * n + 0.8)
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    for i, ax in enumerate(axes):
        values = {name: np.asarray(shapes[i][name], dtype=float) for name, _, _ in _MODE_FIELDS}
        peaks = {name: float(np.max(np.abs(v))) for name, v in values.items()}
        scaled = {name: peak * (half_width if name == "theta_x" else 1.0) for name, peak in peaks.items()}
        reference = max(scaled.values())
        for name, label, style in _MODE_FIELDS:
            share = scaled[name] / reference if reference > 0 else 0.0
            if share <= NEGLIGIBLE_SHARE or peaks[name] == 0.0:
                ax.plot(x, np.zeros_like(x), style, label=f"{label} ≈ 0")
            else:
                ax.plot(x, values[name] / peaks[name], style, label=f"{label} {100 * share:.3g} %")
        ax.legend(loc="upper right", fontsize=7, ncols=3, framealpha=0.8)
        for xs in np.asarray(supports_x, dtype=float):
            ax.axvline(xs, color="0.6", linewidth=0.8)
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.set_ylim(-1.2, 1.6)
        ax.set_title(titles[i], fontsize=10)
    axes[-1].set_xlabel("x [m]")
    _save(fig, path, dpi=120)
    return n


# --------------------------------------------------------------------------- logs (sensor time histories)


def sensor_histories(t: npt.ArrayLike, series: Mapping[str, npt.ArrayLike], units: Mapping[str, str], title: str,
                     path: str | Path) -> list[str]:
    """Draw sensor time histories, one panel each, over time in s.

    Args:
        t: sample times, s.
        series: sensor name -> values at ``t``, already in the unit of ``units[name]``.
        units: sensor name -> the unit of its values (the panel's label).
        title: the figure's title.
        path: the figure file (its suffix picks the format).

    Returns:
        The sensors drawn, in order.
    """
    names = list(series)
    fig = _figure(9.0, 1.9 * len(names) + 0.9)
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    for ax, name in zip(axes, names):
        ax.plot(t, series[name], linewidth=0.8)
        ax.set_ylabel(f"{name}\n[{units[name]}]", fontsize=9)
        ax.grid(True, linewidth=0.4, alpha=0.6)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(title, fontsize=10)
    _save(fig, path, dpi=110)
    return names


# --------------------------------------------------------------------------- network around a bridge


def network_figure(lanes: Sequence[npt.ArrayLike], junction_lanes: Sequence[npt.ArrayLike],
                   deck_lanes: Sequence[npt.ArrayLike], outline: npt.ArrayLike, axis: npt.ArrayLike, title: str,
                   path: str | Path, extent: tuple[float, float, float, float] | None = None) -> None:
    """Draw the road network around a bridge, in network coordinates (m), equal scales.

    Args:
        lanes: centre lines (n, 2) of the other lanes (grey); junction_lanes: of the junctions' internal
            lanes (light grey, dotted); deck_lanes: of the deck's lanes (blue).
        outline: the deck's carriageway outline, a closed polygon (k, 2).
        axis: the axis, start and end (2, 2): drawn as an arrow from x = 0 to x = L.
        title: the figure's title; path: the figure file (its suffix picks the format).
        extent: (x_min, x_max, y_min, y_max) shown, m (default: everything drawn).
    """
    fig = _figure(7.5, 6.5)
    ax = fig.add_subplot()
    for i, pts in enumerate(lanes):
        p = np.asarray(pts, dtype=float)
        ax.plot(p[:, 0], p[:, 1], color="0.55", linewidth=0.8, label="lanes" if i == 0 else None)
    for i, pts in enumerate(junction_lanes):
        p = np.asarray(pts, dtype=float)
        ax.plot(p[:, 0], p[:, 1], color="0.75", linewidth=0.7, linestyle=":",
                label="junction lanes" if i == 0 else None)
    box = np.asarray(outline, dtype=float)
    ax.fill(box[:, 0], box[:, 1], color="tab:orange", alpha=0.25, linewidth=0, label="deck (carriageway)")
    ax.plot(box[:, 0], box[:, 1], color="tab:orange", linewidth=1.0)
    for i, pts in enumerate(deck_lanes):
        p = np.asarray(pts, dtype=float)
        ax.plot(p[:, 0], p[:, 1], color="tab:blue", linewidth=1.4, label="deck lanes" if i == 0 else None)
    a = np.asarray(axis, dtype=float)
    ax.annotate("", xy=a[1], xytext=a[0], arrowprops={"arrowstyle": "->", "color": "tab:red", "linewidth": 1.5})
    ax.plot(a[:, 0], a[:, 1], color="tab:red", linewidth=1.5, label="axis, x = 0 -> L")
    ax.annotate("x = 0", a[0], fontsize=8, color="tab:red", xytext=(4, 4), textcoords="offset points")
    if extent is not None:
        ax.set_xlim(extent[0], extent[1])
        ax.set_ylim(extent[2], extent[3])
        ax.set_aspect("equal", adjustable="box")
    else:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("network x [m]")
    ax.set_ylabel("network y [m]")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(title, fontsize=10)
    _save(fig, path, dpi=110)


# --------------------------------------------------------------------------- studies


#: Most lines (combinations of the other axes) a study panel draws; more become one line over all runs.
STUDY_MAX_GROUPS = 6


def plot_sweep(
    table: Any,
    axes: Mapping[str, Sequence[Any]],
    statistics: Sequence[tuple[str, str, float]],
    folder: Path,
    *,
    title: str,
    axis_labels: Mapping[str, str],
    tick_labels: Mapping[str, Mapping[Any, str]] | None = None,
    repetitions: str = "seed",
) -> list[Path]:
    """One PNG per statistic of a swept study (``<folder>/<column>.png``), a panel per swept axis.

    Each panel shows the statistic against its axis: the mean over the
    repetitions (a line per combination of the other swept axes, or one line
    over all runs when there are more than :data:`STUDY_MAX_GROUPS`), their
    spread (min-max band) and every run as a dot. Axes with one value get no
    panel; with the repetitions as the only axis, the statistic is drawn
    against them.

    Args:
        table: a pandas DataFrame, one row per run to draw, with a column per axis and per statistic.
        axes: the swept axes and their values, in sweep order.
        statistics: (column, y-axis label, display factor) of each figure.
        folder: where the PNGs go (created).
        title: what the runs are (the study's name), at the top of each figure.
        axis_labels: axis -> x-axis label.
        tick_labels: axis -> value -> tick label, for axes of text values.
        repetitions: the axis of Monte Carlo repetitions (not a panel when others vary; no band).

    Returns:
        The files written (none without runs or without an axis).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    folder.mkdir(parents=True, exist_ok=True)
    varied = [a for a in axes if a != repetitions and len(axes[a]) > 1]
    panels = varied or ([repetitions] if repetitions in axes else [])
    written: list[Path] = []
    if not panels or table.empty:
        return written
    count = len(axes.get(repetitions, (None,)))
    for column, label, factor in statistics:
        fig = Figure(figsize=(4.2 * len(panels) + 0.6, 3.6), layout="constrained")
        FigureCanvasAgg(fig)
        subplots = fig.subplots(1, len(panels), squeeze=False)[0]
        for ax, axis in zip(subplots, panels):
            _sweep_panel(ax, table, axes, axis, [a for a in varied if a != axis], column, factor,
                         (tick_labels or {}).get(axis, {}), band=axis != repetitions)
            ax.set_xlabel(axis_labels.get(axis, axis))
            ax.grid(True, linewidth=0.4, alpha=0.6)
        subplots[0].set_ylabel(label, fontsize=9)
        fig.suptitle(f"{title}: {len(table)} runs, {count} {repetitions}{'s' if count > 1 else ''} each "
                     "(mean, min-max, every run)", fontsize=9)
        path = folder / f"{re.sub(r'[^A-Za-z0-9_.-]', '_', column)}.png"
        partial = path.with_name(path.stem + ".part.png")
        fig.savefig(partial, dpi=100)
        os.replace(partial, path)
        written.append(path)
    return written


def _sweep_panel(ax: Any, table: Any, axes: Mapping[str, Sequence[Any]], axis: str, others: list[str], column: str,
                 factor: float, ticks: Mapping[Any, str], band: bool) -> None:
    values = list(axes[axis])
    numeric = all(isinstance(v, (int, float)) for v in values)
    positions = {v: (float(v) if numeric else float(i)) for i, v in enumerate(values)}
    groups: list[tuple[str, Any]] = []
    if others:
        keys = list(itertools.product(*(axes[o] for o in others)))
        if len(keys) <= STUDY_MAX_GROUPS:
            for key in keys:
                mask = np.ones(len(table), dtype=bool)
                for o, v in zip(others, key):
                    mask &= (table[o] == v).to_numpy()
                groups.append((", ".join(f"{o} = {v}" for o, v in zip(others, key)), table[mask]))
        else:
            groups.append(("all runs", table))
    else:
        groups.append(("", table))
    for label, sub in groups:
        xs, mean, lo, hi = [], [], [], []
        for v in values:
            y = sub[sub[axis] == v][column].to_numpy(dtype=float) * factor
            y = y[np.isfinite(y)]
            if not len(y):
                continue
            xs.append(positions[v])
            mean.append(y.mean())
            lo.append(y.min())
            hi.append(y.max())
            ax.plot(np.full(len(y), positions[v]), y, ".", color="0.45", markersize=3)
        if not xs:
            continue
        line, = ax.plot(xs, mean, "o-", linewidth=1.2, markersize=4, label=label or None)
        if band:
            ax.fill_between(xs, lo, hi, color=line.get_color(), alpha=0.18, linewidth=0)
    if not numeric:
        ax.set_xticks([positions[v] for v in values], [ticks.get(v, str(v)) for v in values])
    if any(label for label, _ in groups):
        ax.legend(fontsize=7)


# --------------------------------------------------------------------------- validation
