"""Every figure cosim draws (matplotlib, Agg): the only module that imports matplotlib.

Functions take plain values (arrays, results) and a path, draw one figure
and write it; they neither read logs nor run anything. Callers check the
output path before the work (``cosim.run.outputs``).
"""
from __future__ import annotations

import itertools
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cosim.errors import CosimError

if TYPE_CHECKING:
    import numpy.typing as npt

# --------------------------------------------------------------------------- common


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
    import numpy as np

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
    import numpy as np

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
    import numpy as np

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


# --------------------------------------------------------------------------- extremes


def return_level_plot(samples_years: npt.ArrayLike, samples: npt.ArrayLike, curve_years: npt.ArrayLike,
                      curve: npt.ArrayLike, target: tuple[float, float, float, float], *, label: str, title: str,
                      path: str | Path) -> Path:
    """A return-level plot: the fitted law's level against the return period (years, log scale), the data at
    their plotting positions, and the target return level with its confidence interval.

    Args:
        samples_years, samples: the data's empirical return periods (years) and values, in display units.
        curve_years, curve: the fitted return-level curve.
        target: (return period, level, lower bound, upper bound) of the characteristic value.
        label: the y-axis label (quantity and unit); title: the figure's title; path: the file.
    """
    years, level, lower, upper = target
    fig = _figure(6.4, 4.2)
    ax = fig.subplots()
    ax.semilogx(curve_years, curve, "-", linewidth=1.4, label="fitted law")
    ax.semilogx(samples_years, samples, "o", color="0.35", markersize=3.5, label="data (Gringorten positions)")
    ax.errorbar([years], [level], yerr=[[level - lower], [upper - level]], fmt="s", color="C3", capsize=4,
                label=f"{years:g}-year value {level:.4g} [{lower:.4g}, {upper:.4g}]")
    ax.set_xlabel("return period [years]")
    ax.set_ylabel(label, fontsize=9)
    ax.grid(True, which="both", linewidth=0.4, alpha=0.5)
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    _save(fig, path, dpi=110)
    return Path(path)


# --------------------------------------------------------------------------- validation
#
# One function per figure of ``cosim validate`` (:mod:`cosim.validation`): each takes the path
# to write and the arrays its case computed (the fields of the case's figure data), draws
# one figure on an Agg canvas (no pyplot state) and returns the path.


def _validation_figure(rows: int = 1, cols: int = 1, size: tuple[float, float] = (8.0, 4.5), **subplots):  # noqa: ANN202
    """A Figure on an Agg canvas and its axes array (rows, cols)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.subplots(rows, cols, squeeze=False, **subplots)


def _validation_save(fig, path: str | Path) -> Path:  # noqa: ANN001 - a matplotlib Figure
    path = Path(path)
    try:
        fig.savefig(path, dpi=110)
    except (OSError, ValueError) as exc:
        raise CosimError(f"{path}: cannot write the plot ({exc})") from None
    return path


def _validation_log_ticks(ax, ticks: Sequence[int] | None = None) -> None:  # noqa: ANN001 - matplotlib Axes
    from matplotlib.ticker import NullFormatter

    if ticks is not None:
        ax.set_xticks(list(ticks), [str(n) for n in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())


def validation_paper_node(
    path: str | Path, *, title: str, t: npt.ArrayLike, w_qc: npt.ArrayLike, w_modal: npt.ArrayLike,
    w_mf: npt.ArrayLike, events: Sequence[tuple[float, str]], mf_masses: tuple[float, float], modal_modes: int,
    duration: float,
) -> Path:
    """The paper case at one node: displacement histories (m) on top, the differences too small to see below."""
    import numpy as np

    fig, axes = _validation_figure(2, 1, size=(8.0, 5.6), sharex=True, height_ratios=[3.0, 1.2])
    top, bottom = axes[0, 0], axes[1, 0]
    t, w_qc, w_modal, w_mf = (np.asarray(a, dtype=float) for a in (t, w_qc, w_modal, w_mf))
    top.plot(t, 1e3 * w_mf, "-", color="C3", lw=3.0, alpha=0.45,
             label=f"moving forces ({mf_masses[0]:g} kg, {mf_masses[1]:g} kg), direct basis")
    top.plot(t, 1e3 * w_qc, "-", color="C0", lw=1.3, label="quarter-cars, direct FE basis")
    top.plot(t, 1e3 * w_modal, "--", color="k", lw=0.9, label=f"quarter-cars, modal basis ({modal_modes} modes)")
    lo, hi = 1e3 * min(w_qc.min(), w_mf.min()), 1e3 * max(w_qc.max(), w_mf.max())
    top.set_ylim(lo - 0.05 * (hi - lo), hi + 0.15 * (hi - lo))
    for ax in (top, bottom):
        ax.axhline(0.0, color="0.85", lw=0.6)
        for t_event, _ in events:
            ax.axvline(t_event, color="0.75", lw=0.8, ls=":")
    for t_event, text in events:
        top.text(t_event, 0.985, text, transform=top.get_xaxis_transform(), fontsize=7, color="0.4",
                 ha="center", va="top")
    top.set_ylabel("vertical displacement w [mm]")
    top.set_title(title, fontsize=10)
    top.legend(loc="lower left", fontsize=8)
    bottom.plot(t, 1e6 * (w_qc - w_mf), "-", color="C3", lw=1.0, label="quarter-cars - moving forces")
    bottom.plot(t, 1e6 * (w_qc - w_modal), "-", color="k", lw=0.8, label="direct - modal (quarter-cars)")
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("difference [µm]")
    bottom.set_xlim(0.0, duration)
    bottom.legend(loc="lower left", fontsize=7, ncols=2)
    return _validation_save(fig, path)


def validation_paper_asymmetric(
    path: str | Path, *, title: str, labels: Sequence[str], t_asymmetric: npt.ArrayLike,
    w_asymmetric: Sequence[npt.ArrayLike], t_symmetric: npt.ArrayLike, w_symmetric: Sequence[npt.ArrayLike],
    duration: float,
) -> Path:
    """The paper case's asymmetric section (solid) against the symmetric one (dotted), one colour per node."""
    import numpy as np

    fig, axes = _validation_figure(size=(8.0, 4.8))
    ax = axes[0, 0]
    for i, (label, w) in enumerate(zip(labels, w_asymmetric)):
        ax.plot(t_asymmetric, 1e3 * np.asarray(w), "-", color=f"C{i}", lw=1.4, label=f"{label}, asymmetric")
    for i, (label, w) in enumerate(zip(labels, w_symmetric)):
        ax.plot(t_symmetric, 1e3 * np.asarray(w), ":", color=f"C{i}", lw=1.0,
                label=f"{label.split(' (')[0]}, symmetric")
    ax.axhline(0.0, color="0.85", lw=0.6)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("vertical displacement w [mm]")
    ax.set_xlim(0.0, duration)
    ax.set_title(title, fontsize=10)
    fig.legend(loc="outside lower center", fontsize=8, ncols=2)
    return _validation_save(fig, path)


def validation_timoshenko_static(
    path: str | Path, *, ss_title: str, ss_loads: Sequence[float], ss_x: npt.ArrayLike,
    ss_closed: Sequence[npt.ArrayLike], ss_nodes_x: npt.ArrayLike, ss_fe: Sequence[npt.ArrayLike],
    cantilever_title: str, cantilever_x: npt.ArrayLike, cantilever_closed: npt.ArrayLike,
    cantilever_bending_only: npt.ArrayLike, cantilever_nodes_x: npt.ArrayLike, cantilever_fe: npt.ArrayLike,
) -> Path:
    """Static deflection (m): closed forms as lines, FE nodal values as circles; simply supported and cantilever."""
    import numpy as np

    fig, axes = _validation_figure(1, 2, size=(10.0, 4.0))
    ax = axes[0, 0]
    for k, (a_over_l, closed, fe) in enumerate(zip(ss_loads, ss_closed, ss_fe)):
        ax.plot(ss_x, 1e3 * np.asarray(closed), "-", color=f"C{k}", label=f"closed form, load at a = {a_over_l:g} L")
        ax.plot(ss_nodes_x, 1e3 * np.asarray(fe), "o", ms=4, mfc="none", color=f"C{k}",
                label=f"FE nodes, a = {a_over_l:g} L")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title(ss_title, fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    ax.plot(cantilever_x, 1e3 * np.asarray(cantilever_closed), "-", color="C0", label="closed form (bending + shear)")
    ax.plot(cantilever_x, 1e3 * np.asarray(cantilever_bending_only), ":", color="0.5",
            label="bending only (Euler-Bernoulli)")
    ax.plot(cantilever_nodes_x, 1e3 * np.asarray(cantilever_fe), "o", ms=4, mfc="none", color="C0", label="FE nodes")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title(cantilever_title, fontsize=10)
    ax.legend(fontsize=7)
    return _validation_save(fig, path)


def validation_torsion_static(
    path: str | Path, *, title: str, x: npt.ArrayLike, uniform: npt.ArrayLike, warping: Sequence[str],
    closed: Sequence[npt.ArrayLike], nodes_x: npt.ArrayLike, fe: Sequence[npt.ArrayLike],
) -> Path:
    """Twist (rad) under a mid-span torque: uniform torsion, Vlasov closed forms and FE nodes."""
    import numpy as np

    fig, axes = _validation_figure(size=(8.0, 4.2))
    ax = axes[0, 0]
    ax.plot(x, 1e3 * np.asarray(uniform), ":", color="0.5", label="uniform (St Venant) torsion only")
    for k, (name, line, nodal) in enumerate(zip(warping, closed, fe)):
        ax.plot(x, 1e3 * np.asarray(line), "-", color=f"C{k}", label=f"closed form, warping {name}")
        ax.plot(nodes_x, 1e3 * np.asarray(nodal), "o", ms=3.5, mfc="none", color=f"C{k}",
                label=f"FE nodes, warping {name}")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("twist θx [mrad]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    return _validation_save(fig, path)


def validation_fryba(
    path: str | Path, *, basis: str, ref_modes: int, speed_parameters: Sequence[float], speeds: Sequence[float],
    position: Sequence[npt.ArrayLike], w_fe: Sequence[npt.ArrayLike], w_ref: Sequence[npt.ArrayLike],
    w_static: float,
) -> Path:
    """Mid-span deflection (m) under a moving force against Fryba's series, one panel per speed parameter."""
    import numpy as np

    fig, axes = _validation_figure(1, len(speed_parameters), size=(10.0, 4.0))
    for k, (alpha, v, pos, fe, ref) in enumerate(zip(speed_parameters, speeds, position, w_fe, w_ref)):
        ax = axes[0, k]
        ax.plot(pos, 1e3 * np.asarray(fe), "-", color="C0", lw=1.6, label=f"FE, {basis} basis")
        ax.plot(pos, 1e3 * np.asarray(ref), "--", color="k", lw=1.0, label=f"Fryba series ({ref_modes} modes)")
        ax.axhline(1e3 * w_static, color="0.6", ls=":", lw=0.8, label="static P L³ / 48 EI")
        ax.set_xlabel("load position v t / L [-]")
        ax.set_ylabel("mid-span deflection w [mm]")
        ax.set_title(f"speed parameter α = v / (2 f1 L) = {alpha:g} (v = {v:.1f} m/s)", fontsize=10)
        ax.legend(fontsize=8, loc="upper right")
    return _validation_save(fig, path)


def validation_sprung_mass(
    path: str | Path, *, title: str, ref_modes: int, t: npt.ArrayLike, w_fe: npt.ArrayLike, w_ref: npt.ArrayLike,
    t_body: npt.ArrayLike, a_fe: npt.ArrayLike, a_ref: npt.ArrayLike,
) -> Path:
    """The sprung mass: mid-span deflection (m, left) and body acceleration (m/s^2, right), FE and reference."""
    import numpy as np

    fig, axes = _validation_figure(1, 2, size=(10.0, 4.0))
    ax = axes[0, 0]
    ax.plot(t, 1e3 * np.asarray(w_fe), "-", color="C0", lw=1.6, label="FE, direct basis")
    ax.plot(t, 1e3 * np.asarray(w_ref), "--", color="k", lw=1.0, label=f"modal ODE ({ref_modes} modes, solve_ivp)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("mid-span deflection w [mm]")
    ax.set_title("Bridge", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(t_body, a_fe, "-", color="C1", lw=1.6, label="FE, direct basis")
    ax.plot(t_body, a_ref, "--", color="k", lw=1.0, label="modal ODE")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("body acceleration [m/s²]")
    ax.set_title("Sprung mass", fontsize=10)
    ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return _validation_save(fig, path)


def validation_energy(
    path: str | Path, *, title: str, tolerance: float, t: npt.ArrayLike, kinetic: npt.ArrayLike,
    strain: npt.ArrayLike, drift: npt.ArrayLike,
) -> Path:
    """Kinetic, strain and total energy (J, top) and the relative drift of the total (bottom)."""
    import numpy as np

    fig, axes = _validation_figure(2, 1, size=(8.0, 5.2), sharex=True)
    top, bottom = axes[0, 0], axes[1, 0]
    kinetic, strain = np.asarray(kinetic, dtype=float), np.asarray(strain, dtype=float)
    top.plot(t, kinetic, "-", color="C0", lw=1.0, label="kinetic")
    top.plot(t, strain, "-", color="C1", lw=1.0, label="strain")
    top.plot(t, kinetic + strain, "-", color="k", lw=1.2, label="total")
    top.set_ylabel("energy [J]")
    top.set_title(title, fontsize=10)
    top.legend(fontsize=8, loc="center right")
    bottom.plot(t, drift, "-", color="k", lw=0.8, label="(E(t) - E0) / E0")
    bottom.axhline(0.0, color="0.8", lw=0.6)
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("relative drift [-]")
    bottom.legend(fontsize=8, loc="upper right", title=f"tolerance ±{tolerance:g}", title_fontsize=8)
    return _validation_save(fig, path)


def validation_time_step(
    path: str | Path, *, title: str, dt: npt.ArrayLike, labels: Sequence[str], errors: Sequence[npt.ArrayLike],
) -> Path:
    """Error (m) against the time step (log-log) per model and scheme, with a slope-2 line."""
    import numpy as np

    fig, axes = _validation_figure(size=(7.0, 5.0))
    ax = axes[0, 0]
    dt = np.asarray(dt, dtype=float)
    for k, (label, err) in enumerate(zip(labels, errors)):
        ax.loglog(dt, err, "o-", color=f"C{k}", ms=4, label=label)
    anchor = np.asarray(errors[0], dtype=float)[-1]
    ax.loglog(dt, anchor * (dt / dt[-1]) ** 2, "k--", lw=1.0, label="slope 2")
    _validation_log_ticks(ax)
    ax.set_xlabel("time step dt [s]")
    ax.set_ylabel("error of the mid-span deflection at t = 0.4 s [m]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", color="0.92", lw=0.5)
    return _validation_save(fig, path)


def validation_roughness(
    path: str | Path, *, n0: float, n_range: tuple[float, float], road_classes: Sequence[str], seeds: Sequence[int],
    class_values: Sequence[float], bands: Sequence[tuple[float, float]], centres: Sequence[npt.ArrayLike],
    psd: Sequence[npt.ArrayLike],
) -> Path:
    """Third-octave PSDs of generated profiles (m^3) with their ISO 8608 class values and bands."""
    import numpy as np

    fig, axes = _validation_figure(size=(8.0, 5.0))
    ax = axes[0, 0]
    n_line = np.logspace(np.log10(n_range[0]), np.log10(n_range[1]), 200)
    for k, (road_class, seed, gd0, (lo, hi), n, g) in enumerate(zip(road_classes, seeds, class_values, bands,
                                                                     centres, psd)):
        color = f"C{k}"
        ax.fill_between(n_line, lo * (n_line / n0) ** -2, hi * (n_line / n0) ** -2, color=color, alpha=0.15,
                        label=f"class {road_class} band ({lo:.3g}-{hi:.3g} m³)")
        ax.loglog(n_line, gd0 * (n_line / n0) ** -2, "--", color=color, lw=1.0,
                  label=f"class {road_class} value {gd0:.3g} m³")
        ax.loglog(n, g, "o", color=color, ms=4, label=f"generated class {road_class} (seed {seed}), 1/3 octaves")
    ax.axvline(n0, color="0.6", ls=":", lw=0.8)
    ax.text(n0, 0.02, " n0", transform=ax.get_xaxis_transform(), fontsize=8, color="0.4")
    ax.set_xlim(0.008, 4.0)
    ax.set_xlabel("spatial frequency n [cycle/m]")
    ax.set_ylabel("displacement PSD G_d(n) [m³]")
    ax.set_title("Generated road profiles against their ISO 8608 classes", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, which="both", color="0.92", lw=0.5)
    return _validation_save(fig, path)


def validation_mesh(
    path: str | Path, *, title: str, labels: Sequence[str], counts: Sequence[npt.ArrayLike],
    errors: Sequence[npt.ArrayLike], expected_orders: Sequence[float],
) -> Path:
    """Relative frequency error against the element count (log-log), with the expected slopes dashed."""
    import numpy as np

    fig, axes = _validation_figure(size=(7.0, 5.0))
    ax = axes[0, 0]
    for k, (label, n, err, order) in enumerate(zip(labels, counts, errors, expected_orders)):
        n, err = np.asarray(n), np.asarray(err, dtype=float)
        ax.loglog(n, err, "o-", color=f"C{k}", ms=4, label=label)
        ax.loglog(n, err[0] * (n / n[0]) ** -order, "--", color=f"C{k}", lw=0.8, label=f"slope {order:g}")
    _validation_log_ticks(ax, sorted({int(n) for group in counts for n in np.asarray(group)}))
    ax.set_xlabel("elements in the span [-]")
    ax.set_ylabel("relative error of the first vertical frequency [-]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", color="0.92", lw=0.5)
    return _validation_save(fig, path)


def validation_parked(
    path: str | Path, *, title: str, t: npt.ArrayLike, w: npt.ArrayLike, w_static: float, stop_time: float,
) -> Path:
    """Deflection under the wheel (m) of a vehicle braking to a stop, against the static deflection."""
    import numpy as np

    fig, axes = _validation_figure(size=(8.0, 3.8))
    ax = axes[0, 0]
    ax.plot(t, 1e3 * np.asarray(w), "-", color="C0", lw=1.2, label="FE, under the wheel (x = 10 m, y = 0.3 m)")
    ax.axhline(1e3 * w_static, color="k", ls="--", lw=1.0, label="static deflection under (m_v + m_w) g")
    ax.axvline(stop_time, color="0.7", ls=":", lw=0.8)
    ax.text(stop_time, 0.95, " stops at mid-span", transform=ax.get_xaxis_transform(), fontsize=8, color="0.4")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    return _validation_save(fig, path)


def validation_benscoter(
    path: str | Path, *, static_title: str, x: npt.ArrayLike, warping: Sequence[str], closed: Sequence[npt.ArrayLike],
    vlasov: Sequence[npt.ArrayLike], nodes_x: npt.ArrayLike, fe: Sequence[npt.ArrayLike], frequency_title: str,
    modes: npt.ArrayLike, f_vlasov: npt.ArrayLike, f_ref: npt.ArrayLike, f_fe: npt.ArrayLike, n_elements: int,
    mesh_label: str, counts: npt.ArrayLike, errors: npt.ArrayLike, expected_order: float,
) -> Path:
    """Benscoter torsion: twist (rad) under a mid-span torque, torsional frequencies (Hz), mesh convergence."""
    import numpy as np

    fig, axes = _validation_figure(1, 3, size=(14.0, 4.2))
    ax = axes[0, 0]
    for k, (name, line, line_vlasov, nodal) in enumerate(zip(warping, closed, vlasov, fe)):
        ax.plot(x, 1e3 * np.asarray(line), "-", color=f"C{k}", label=f"closed form, warping {name}")
        ax.plot(x, 1e3 * np.asarray(line_vlasov), ":", color=f"C{k}", label=f"Vlasov (ψ = θx'), warping {name}")
        ax.plot(nodes_x, 1e3 * np.asarray(nodal), "o", ms=3.0, mfc="none", color=f"C{k}", label=f"FE nodes, {name}")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("twist θx [mrad]")
    ax.set_title(static_title, fontsize=10)
    ax.legend(fontsize=6)
    ax = axes[0, 1]
    ax.plot(modes, f_vlasov, "s:", color="0.5", label="Vlasov frequency equation")
    ax.plot(modes, f_ref, "-", color="C0", label="Benscoter frequency equation")
    ax.plot(modes, f_fe, "o", mfc="none", color="C0", label=f"FE, {n_elements} elements")
    ax.set_xticks(list(np.asarray(modes)))
    ax.set_xlabel("torsional mode n [-]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(frequency_title, fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[0, 2]
    counts, errors = np.asarray(counts), np.asarray(errors, dtype=float)
    ax.loglog(counts, errors, "o-", color="C0", ms=4, label=mesh_label)
    ax.loglog(counts, errors[0] * (counts / counts[0]) ** -expected_order, "--", color="0.5", lw=0.8,
              label=f"slope {expected_order:g}")
    _validation_log_ticks(ax, [int(n) for n in counts])
    ax.set_xlabel("elements [-]")
    ax.set_ylabel("relative error [-]")
    ax.set_title("Mesh convergence", fontsize=10)
    ax.legend(fontsize=7)
    return _validation_save(fig, path)


def validation_paper_theories(
    path: str | Path, *, title: str, node_titles: Sequence[str], theories: Sequence[str], torsion_1: Sequence[float],
    t: Sequence[npt.ArrayLike], w: Sequence[npt.ArrayLike], duration: float,
) -> Path:
    """The paper case under moving forces with each torsion theory: mid-span histories (m), one panel per node."""
    import numpy as np

    fig, axes = _validation_figure(1, len(node_titles), size=(14.0, 4.0), sharey=True)
    styles = ("-", "--", ":", "-.")
    for i, node_title in enumerate(node_titles):
        ax = axes[0, i]
        for name, style, f1, t_theory, w_theory in zip(theories, itertools.cycle(styles), torsion_1, t, w):
            ax.plot(t_theory, 1e3 * np.asarray(w_theory)[i], style, lw=1.2, label=f"{name} (torsion-1 {f1:.3f} Hz)")
        ax.set_xlabel("time t [s]")
        ax.set_title(node_title, fontsize=10)
        ax.set_xlim(0.0, duration)
        ax.legend(fontsize=7, loc="lower left")
    axes[0, 0].set_ylabel("vertical displacement w [mm]")
    fig.suptitle(title, fontsize=10)
    return _validation_save(fig, path)


def validation_vbi2d(
    path: str | Path, *, title: str, n_elements: int, ref_modes: int, t: npt.ArrayLike, w_fe: npt.ArrayLike,
    w_ref: npt.ArrayLike, peak_t: float, peak_w: float, t_body: npt.ArrayLike, a_fe: npt.ArrayLike,
    a_ref: npt.ArrayLike,
) -> Path:
    """VBI-2D's sprung vehicle: mid-span deflection (m) with the published peak (left), body acceleration (right)."""
    import numpy as np

    fig, axes = _validation_figure(1, 2, size=(10.0, 4.0))
    ax = axes[0, 0]
    ax.plot(t, 1e3 * np.asarray(w_fe), "-", color="C0", lw=1.6, label=f"cosim, Euler-Bernoulli, {n_elements} elements")
    ax.plot(t, 1e3 * np.asarray(w_ref), "--", color="k", lw=1.0, label=f"modal ODE ({ref_modes} modes, solve_ivp)")
    ax.plot([peak_t], [1e3 * peak_w], "x", color="C3", ms=8,
            label=f"VBI-2D peak ({1e3 * peak_w:.5f} mm, {peak_t:.3f} s)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("mid-span deflection w [mm]")
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    ax.plot(t_body, a_fe, "-", color="C1", lw=1.6, label="cosim")
    ax.plot(t, a_ref, "--", color="k", lw=1.0, label="modal ODE")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("body acceleration [m/s²]")
    ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    return _validation_save(fig, path)
