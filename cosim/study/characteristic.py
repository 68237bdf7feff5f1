"""Characteristic values of a study: the maxima of its seeds fitted with an extreme-value law (``[extremes]``).

Every run of one combination of the other axes is one block: its largest
value (``statistic = "max"``), its most negative one (``"min"``) or its
largest absolute one (``"peak"``) over every time step is one block maximum,
and the block is the run's duration. Those maxima are fitted with a Gumbel or
GEV law (:func:`cosim.analysis.extremes.fit_block_maxima`) and its value at
the return period (years) is the characteristic value, with the bootstrap
bounds. The runs must be independent and alike (same traffic, other seeds):
the assumptions docs/analysis.md states.
"""
from __future__ import annotations

import io
import itertools
import re
from pathlib import Path
from typing import Any

import numpy as np

from cosim.analysis.extremes import ReturnLevel, fit_block_maxima
from cosim.errors import ConfigError
from cosim.run.units import display_unit
from cosim.study.folder import PLOTS_FOLDER, write_file
from cosim.study.spec import Study

__all__ = ["CHARACTERISTIC_CSV", "characteristic_rows", "write_characteristic"]

CHARACTERISTIC_CSV = "characteristic.csv"


def _groups(study: Study) -> list[dict[str, Any]]:
    others = [a for a in study.axes if a != "seed"]
    return [dict(zip(others, combo)) for combo in itertools.product(*(study.axes[a] for a in others))]


def characteristic_rows(rows: list[dict[str, Any]], study: Study) -> list[tuple[dict[str, Any], ReturnLevel | None]]:
    """One row per combination of the non-seed axes and per sensor: the fitted characteristic value.

    A combination whose runs cannot be fitted (fewer than 5 finished seeds, all
    maxima equal) gets its row with the reason in ``error`` and no fit.
    """
    spec = study.extremes
    if spec is None:
        return []
    names = list(spec.sensors or [s.name for s in study.all_sensors])
    quantities = {s.name: s.quantity for s in study.all_sensors}
    out: list[tuple[dict[str, Any], ReturnLevel | None]] = []
    for group in _groups(study):
        runs = [r for r in rows if r.get("status") == "ok" and all(r.get(k) == v for k, v in group.items())]
        for name in names:
            column = f"{name}.{spec.statistic}"
            values = np.array([r.get(column) for r in runs if r.get(column) is not None], dtype=float)
            sign = -1.0 if spec.statistic == "min" else 1.0
            row: dict[str, Any] = {**group, "sensor": name, "quantity": quantities.get(name, ""),
                                   "statistic": spec.statistic, "distribution": spec.distribution,
                                   "return_period": spec.return_period, "confidence": spec.confidence,
                                   "runs": len(values)}
            durations = {r.get("duration") for r in runs}
            fit = None
            try:
                if len(durations) != 1:
                    raise ConfigError("the runs have different durations: their maxima are not of one block length")
                duration = durations.pop()
                if duration is None:
                    raise ConfigError("a run has no duration: its maxima have no block length")
                fit = fit_block_maxima(sign * values, float(duration), spec.return_period,
                                       distribution=spec.distribution, confidence=spec.confidence,
                                       bootstrap=spec.bootstrap, seed=spec.seed)
            except ConfigError as exc:
                row["error"] = str(exc)
            if fit is not None:
                lo, hi = sorted((sign * fit.lower, sign * fit.upper))
                row.update({"value": sign * fit.value, "lower": lo, "upper": hi, "block": fit.block,
                            **{f"param_{k}": v for k, v in fit.parameters.items()}, "error": ""})
            out.append((row, fit))
    return out


def write_characteristic(rows: list[dict[str, Any]], study: Study, output: Path,
                         plots: bool = True) -> tuple[Path | None, list[Path]]:
    """``characteristic.csv`` (SI units) and a return-level plot per fitted row (``plots/return_level_*.png``)."""
    import pandas as pd

    from cosim.plots import return_level_plot

    fitted = characteristic_rows(rows, study)
    if not fitted:
        return None, []
    frame = pd.DataFrame([r for r, _ in fitted])
    text = io.StringIO()
    frame.to_csv(text, index=False)
    path = output / CHARACTERISTIC_CSV
    write_file(path, text.getvalue())
    written: list[Path] = []
    if not plots:
        return path, written
    for row, fit in fitted:
        if fit is None:
            continue
        unit, factor = display_unit(row["quantity"])
        sign = -1.0 if row["statistic"] == "min" else 1.0
        data = np.sort(fit.samples)
        n = len(data)
        prob = (np.arange(1, n + 1) - 0.44) / (n + 0.12)  # Gringorten's plotting positions
        years = 1.0 / (1.0 - prob) / fit.rate
        curve_years = np.geomspace(max(years[0] * 0.5, 1e-9), fit.return_period * 3.0, 200)
        group = "_".join(f"{k}-{v}" for k, v in row.items() if k in study.axes)
        stem = re.sub(r"[^A-Za-z0-9_.-]", "_", f"return_level_{row['sensor']}" + (f"_{group}" if group else ""))
        target = (fit.return_period, row["value"] * factor, row["lower"] * factor, row["upper"] * factor)
        written.append(return_level_plot(
            years, sign * data * factor, curve_years, sign * fit.level(curve_years) * factor, target,
            label=f"{row['sensor']}: {row['statistic']} per run [{unit}]",
            title=f"{study.name}: {fit.distribution} fit of {n} runs of {fit.block:g} s "
                  f"({', '.join(f'{k} = {v}' for k, v in row.items() if k in study.axes) or 'the base'})",
            path=output / PLOTS_FOLDER / f"{stem}.png"))
    return path, written
