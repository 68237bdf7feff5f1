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


# --------------------------------------------------------------------------- mode shapes


# --------------------------------------------------------------------------- logs (sensor time histories)


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
