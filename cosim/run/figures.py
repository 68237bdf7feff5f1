"""Figures of runs and bridges: the values to draw, taken from a log or a model, handed to :mod:`cosim.plots`.

- :func:`plot_log_sensors`: a log's sensor time histories (``cosim plot``);
- :func:`plot_modes`: a bridge's mode shapes (``cosim modes --plot``).

The output file is checked before the work; :mod:`cosim.plots` draws.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from cosim import plots
from cosim.core.bridge import BridgeModel, ModalResult
from cosim.errors import CosimError
from cosim.log.reader import open_log, sensor_series

from .outputs import check_new_file
from .units import display_unit

#: Points along the bridge at which mode shapes are drawn.
MODE_SHAPE_POINTS = 401


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
    check_new_file(out, "plot", force)
    t, series = sensor_series(log, chosen)
    quantity = dict(zip(available, overview.quantities))
    units = {name: display_unit(quantity.get(name, "")) for name in chosen}
    scaled = {name: series[name] * units[name][1] for name in chosen}
    title = f"{overview.info.get('scenario', Path(log).stem)} — {Path(log).name} ({overview.status_word})"
    out.parent.mkdir(parents=True, exist_ok=True)
    return plots.sensor_histories(t, scaled, {name: unit for name, (unit, _) in units.items()}, title, out)


def plot_modes(bridge: BridgeModel, modal: ModalResult, path: str | os.PathLike[str], count: int) -> int:
    """Draw v, w and theta_x of the first ``count`` modes (at most :data:`cosim.plots.MAX_MODE_SHAPES`)
    along the bridge into ``path``; returns how many were drawn."""
    n = min(count, len(modal.f_hz), plots.MAX_MODE_SHAPES)
    x = np.linspace(0.0, bridge.length, MODE_SHAPE_POINTS)
    shapes = [{name: modal.field(i, name, x) for name in ("v", "w", "theta_x")} for i in range(n)]
    titles = [f"mode {i + 1}: {modal.f_hz[i]:.3f} Hz, {modal.kinds[i]}" for i in range(n)]
    supports_x = np.concatenate([[0.0], np.cumsum(bridge.spans)])
    half_width = max(abs(bridge.section.deck_y[0]), abs(bridge.section.deck_y[1]), 1.0)
    return plots.mode_shapes(x, shapes, titles, supports_x, half_width, Path(path))
