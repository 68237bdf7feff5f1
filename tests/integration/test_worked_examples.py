"""The worked examples of docs/analysis.md, on short durations, with real SUMO and real MCAP logs.

1. Fatigue of a steel detail at three volumes (examples/studies/fatigue-volumes.toml): each run's damage
   equals an independent count (fatpack) of the history exported from its log, and per year is the day's
   scaled by the stated rule.
2. A characteristic mid-span moment (examples/studies/characteristic-moment.toml): the 1000-year value is
   the Gumbel quantile of an independent scipy fit of the table's maxima, inside its interval.
"""
from __future__ import annotations

from pathlib import Path

import fatpack
import numpy as np
import pandas as pd
import pytest
from scipy import stats

import cosim
from cosim.analysis import SECONDS_PER_YEAR
from cosim.log import sensor_series
from cosim.study import parse_study, run_study

EXAMPLES = Path(cosim.__file__).resolve().parents[1] / "examples" / "studies"


def _study(name: str, tmp_path, **replace: str):
    path = EXAMPLES / name
    text = path.read_text()
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    return parse_study(text, str(path), base_dir=EXAMPLES, output=tmp_path / "out")


def _fatpack_damage(history, category):
    """Miner sum by fatpack: its rainflow on the reversals, the residue as half cycles, its EN 1993-1-9 curve."""
    y = np.asarray(history, float)
    d = np.diff(y)
    keep = np.concatenate([[0], np.flatnonzero(d[:-1] * d[1:] < 0) + 1, [len(y) - 1]])
    cycles, residue = fatpack.find_rainflow_cycles(y[keep])
    ranges = np.abs(cycles[:, 1] - cycles[:, 0]) / 1e6 if len(cycles) else np.zeros(0)
    half = np.abs(np.diff(residue)) / 1e6
    counts = np.concatenate([np.ones(len(ranges)), 0.5 * np.ones(len(half))])
    pairs = np.column_stack([np.concatenate([ranges, half]), counts])
    return fatpack.TriLinearEnduranceCurve(float(category)).find_miner_sum(pairs)


def test_fatigue_of_a_steel_detail_at_three_volumes(tmp_path):
    study = _study("fatigue-volumes.toml", tmp_path, **{"duration = 86400.0": "duration = 30.0"})
    outcome = run_study(study, workers=0)
    table = outcome.table()
    assert list(table["status"]) == ["ok"] * 3
    for column in ("flange_east.damage", "flange_east.damage_per_year", "flange_east.equivalent_stress_range"):
        assert column in table and np.all(np.isfinite(table[column]))
    assert (outcome.study.output / "plots" / "flange_east.damage_per_year.png").is_file()
    for row in outcome.rows:
        _, series = sensor_series(outcome.study.output / row["log"], ["flange_east"])
        assert row["flange_east.damage"] == pytest.approx(_fatpack_damage(series["flange_east"], 71), rel=1e-9)
        # The stated rule: the run's traffic all year.
        assert row["flange_east.damage_per_year"] == pytest.approx(
            row["flange_east.damage"] * SECONDS_PER_YEAR / 30.0, rel=1e-12)
    assert table["vehicles"].iloc[-1] > table["vehicles"].iloc[0]  # 1000 vph brings more vehicles than 250


def test_a_characteristic_mid_span_moment(tmp_path):
    study = _study("characteristic-moment.toml", tmp_path,
                   **{"duration = 600.0": "duration = 60.0", "seeds = 20": "seeds = 6"})
    outcome = run_study(study, workers=0)
    assert outcome.characteristic is not None
    result = pd.read_csv(outcome.characteristic)
    assert len(result) == 1
    row = result.iloc[0]
    maxima = outcome.table()["mid_moment.max"].to_numpy(dtype=float)
    loc, scale = stats.gumbel_r.fit(maxima)  # independent: scipy directly on the table's column
    blocks = 1000.0 * SECONDS_PER_YEAR / 60.0
    assert row["value"] == pytest.approx(stats.gumbel_r.ppf(1 - 1 / blocks, loc, scale), rel=1e-9)
    assert row["lower"] < row["value"] < row["upper"]
    assert row["value"] > maxima.max()
    assert list((outcome.study.output / "plots").glob("return_level_mid_moment*.png"))
