"""The compiled running extremes of a run (cosim.core.simulation.block_extremes) against numpy's reductions."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.simulation import block_extremes


@pytest.mark.parametrize("seed", range(6))
def test_block_extremes_equal_numpys_masked_reductions(seed: int) -> None:
    rng = np.random.default_rng(seed)
    steps, n_sensors, q = rng.integers(1, 300), rng.integers(0, 12), rng.integers(0, 9)
    sensors = rng.normal(size=(steps, n_sensors))
    sensors[rng.random(sensors.shape) < 0.3] = np.nan  # sensors read only at some steps
    on_deck = rng.random((steps, q)) < 0.6
    force = rng.normal(1e4, 3e3, size=(steps, q))
    col_owner = np.sort(rng.integers(0, max(q, 1), size=q))  # axles of one vehicle are consecutive columns
    s_min, s_max = np.zeros(n_sensors), np.zeros(n_sensors)
    f_min, f_max = np.full(q, np.inf), np.full(q, -np.inf)
    most = block_extremes(sensors, s_min, s_max, on_deck, force, col_owner, f_min, f_max)
    # Reference: numpy's NaN-skipping and masked reductions (the code this kernel replaced).
    assert np.array_equal(s_min, np.fmin(0.0, np.fmin.reduce(sensors, axis=0, initial=np.inf)))
    assert np.array_equal(s_max, np.fmax(0.0, np.fmax.reduce(sensors, axis=0, initial=-np.inf)))
    assert np.array_equal(f_min, np.where(on_deck, force, np.inf).min(axis=0, initial=np.inf))
    assert np.array_equal(f_max, np.where(on_deck, force, -np.inf).max(axis=0, initial=-np.inf))
    vehicles_on = [len({int(col_owner[j]) for j in np.flatnonzero(row)}) for row in on_deck]
    assert most == (max(vehicles_on) if q else 0)


def test_the_force_ranges_of_a_long_run_stay_bounded_and_keep_what_a_summary_shows(monkeypatch) -> None:
    """A stream of vehicles (a year of records has millions of axles): the ranges kept stay under twice the bound,
    and the heaviest, every one that pulled and the fleet on the deck now are all there with their exact ranges
    (reference: every range kept, computed without the bound)."""
    from cosim.core import simulation
    from cosim.core.coupling import BlockReport

    monkeypatch.setattr(simulation, "MAX_FORCE_RANGES", 50)
    extremes = simulation._Extremes([])
    everything: dict[str, tuple[float, float]] = {}
    rng = np.random.default_rng(3)
    for block in range(400):
        ids = (f"v{block}#0", f"v{block}#1")
        force = rng.uniform(1e4, 9e4, size=(10, 2))
        if block % 97 == 0:
            force[3, 1] = -100.0  # a wheel that pulled
        on = np.ones((10, 2), dtype=bool)
        zeros = np.zeros((10, 2))
        report = BlockReport(ids, (), zeros, np.zeros(2), zeros, zeros, on, force, zeros, zeros, np.zeros((10, 0)),
                             np.zeros((10, 2), dtype=bool))
        extremes.on_block(np.arange(10) * 0.01, np.ones(10, dtype=bool), report)
        for j, vid in enumerate(ids):
            everything[vid] = (float(force[:, j].min()), float(force[:, j].max()))
        assert len(extremes.force) <= 2 * 50 + 2
    heaviest = sorted(everything, key=lambda k: everything[k][1], reverse=True)[:50]
    pulled = [k for k, (lo, _) in everything.items() if lo < 0]
    assert len(pulled) == 5
    for vid in heaviest + pulled + ["v399#0", "v399#1"]:
        assert tuple(extremes.force[vid]) == everything[vid], vid
