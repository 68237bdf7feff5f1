"""Every figure cosim draws (matplotlib, Agg): the only module that imports matplotlib.

Functions take plain values (arrays, results) and a path, draw one figure
and write it; they neither read logs nor run anything. Callers check the
output path before the work (``cosim.run.outputs``).
"""
from __future__ import annotations

# --------------------------------------------------------------------------- common
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np
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


# --------------------------------------------------------------------------- studies


# --------------------------------------------------------------------------- validation
