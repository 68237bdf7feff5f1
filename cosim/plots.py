"""Every figure cosim draws (matplotlib, Agg): the only module that imports matplotlib.

Functions take plain values (arrays, results) and a path, draw one figure
and write it; they neither read logs nor run anything. Callers check the
output path before the work (``cosim.run.outputs``).
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np
import numpy.typing as npt

from cosim.errors import CosimError

# --------------------------------------------------------------------------- common


# --------------------------------------------------------------------------- mode shapes


# --------------------------------------------------------------------------- logs (sensor time histories)


# --------------------------------------------------------------------------- studies


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
    fig, axes = _validation_figure(size=(7.0, 5.0))
    ax = axes[0, 0]
    for k, (label, n, err, order) in enumerate(zip(labels, counts, errors, expected_orders)):
        n, err = np.asarray(n), np.asarray(err, dtype=float)
        ax.loglog(n, err, "o-", color=f"C{k}", ms=4, label=label)
        ax.loglog(n, err[0] * (n / n[0]) ** -order, "--", color=f"C{k}", lw=0.8, label=f"slope {order:g}")
    _validation_log_ticks(ax, sorted({int(n) for group in counts for n in group}))
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
