"""Every bundled scenario and example gives the numbers it gave before the package was reorganised.

Reference: the logs in ``logs/``, written by this test (``COSIM_WRITE_REFERENCE=1``)
with the code before the move (issue 9). Tolerance: 1e-9 of each channel's
peak. The move and the single compiled loop changed where code lives, not the
arithmetic (they passed at 1e-12); since then the direct basis solves blocks
with few vehicles on the model's complete modal basis, which is the same
solution with other round-off (issue 12 allows 1e-9 of the peak; measured at
most 4.7e-10, on an acceleration channel).
"""
from __future__ import annotations

import os

import pytest

from cosim import testing as ct

from .reference_runs import LOGS, RUNS, WRITE_ENV

REL_PEAK = 1e-9  # of each channel's peak over the stored samples


@pytest.mark.parametrize("name", sorted(RUNS))
def test_the_run_matches_the_log_written_before_the_move(name, tmp_path):
    base, overrides = RUNS[name]
    stored = LOGS / f"{name}.mcap"
    if os.environ.get(WRITE_ENV) and not stored.exists():
        LOGS.mkdir(exist_ok=True)
        ct.run(base, log=stored, **overrides)
        pytest.skip(f"wrote {stored}")
    res = ct.run(base, log=tmp_path / f"{name}.mcap", **overrides)
    ct.assert_matches_log(res, stored, rtol=REL_PEAK, atol=0.0)
