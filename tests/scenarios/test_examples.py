"""Scripted scenario tests of docs/studies.md, written with :mod:`cosim.testing` on the scenarios in examples/.

- a 40 t truck at 80 km/h on a class B road: the DAF at mid-span stays below
  the Eurocode-style bound, and the run matches its stored log;
- congested SUMO traffic queued on the deck: the deflection stays below L/800;
- the drive-by idea: a slow quarter-car's body acceleration spectrum peaks at
  the bridge's first frequency.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cosim
from cosim import testing as ct

EXAMPLES = Path(cosim.__file__).resolve().parents[1] / "examples" / "scenarios"

#: EN 1991-2, Annex B: the dynamic amplification factor phi_fat for a road surface of good
#: roughness (1.4 for medium). ISO 8608 class B is "good".
PHI_FAT_GOOD = 1.2


def test_a_40t_truck_at_80kmh_on_a_class_b_road_stays_below_the_eurocode_daf(run_scenario, cosim_log_snapshot):
    res = run_scenario(EXAMPLES / "truck-40t-class-b.toml", log=True)
    ct.assert_daf_below(res, "mid", PHI_FAT_GOOD)
    ct.assert_daf_below(res, "mid_moment", PHI_FAT_GOOD)
    assert res.daf("mid") > 1.0  # the rough road does amplify
    assert res.liftoff_events == 0
    cosim_log_snapshot(res, "truck-40t-class-b", rtol=1e-6)


def test_the_truck_daf_over_five_road_profiles(run_scenario):
    """Monte Carlo over the class B profile: the mean DAF below the bound, none above the medium-road one."""
    dafs = [run_scenario(EXAMPLES / "truck-40t-class-b.toml", road={"seed": seed}).daf("mid") for seed in range(1, 6)]
    assert np.mean(dafs) < PHI_FAT_GOOD
    assert max(dafs) < 1.4
    assert len(set(dafs)) == 5  # every seed is another road


def test_congested_traffic_deflects_the_deck_less_than_l_over_800(run_scenario):
    res = run_scenario(EXAMPLES / "congested-deck.toml")
    for name in ("mid", "mid_east", "mid_west"):
        ct.assert_deflection_below(res, name, 800.0)
    assert res.max_on_deck >= 8  # the queue stands on the deck: two 40 m lanes of slow vehicles
    slow = [np.mean(np.abs(res.vehicle(v)["speed"])) < 5.0 for v in res.vehicle_ids]
    assert sum(slow) >= 10
    assert res.daf("mid") == pytest.approx(1.0, abs=0.05)  # creeping traffic: close to static


def test_drive_by_a_slow_quarter_car_feels_the_first_bridge_frequency(run_scenario):
    res = run_scenario(EXAMPLES / "drive-by.toml")
    probe = res.vehicle("probe")
    f1 = res.frequencies(1)[0]
    seen = ct.dominant_frequency(probe["t"], probe["body_acceleration"], band=(0.6 * f1, 1.6 * f1))
    assert seen == pytest.approx(f1, rel=0.01)
    # ... and it is a peak, not the top of a slope: far above the spectrum around it.
    f, amplitude = ct.spectrum(probe["t"], probe["body_acceleration"])
    band = (f > 0.6 * f1) & (f < 1.6 * f1)
    assert amplitude[band].max() > 50 * np.median(amplitude[band])
    # The body's own 1.0 Hz dominates the whole spectrum: the bridge is a small signal in it.
    assert ct.dominant_frequency(probe["t"], probe["body_acceleration"]) == pytest.approx(1.0, rel=0.02)
