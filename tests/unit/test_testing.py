"""The scripted-test API (:mod:`cosim.testing`): building scenarios, named results, helpers, assertions.

The helpers are checked against independent computations: peaks against the
sampled channels, the quasi-static peak and DAF against ``BridgeModel.static``,
the spectrum against a sine of known frequency and amplitude, the log
comparison against a run of a changed scenario.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cosim import testing as ct
from cosim.core.bridge import PointLoad
from cosim.errors import ConfigError

G = 9.81


def _girder(**overrides):
    base = dict(bridge=ct.bridge(40.0, elements_per_span=10),
                sensors=[ct.sensor("mid", 20.0, 1.875), ct.sensor("moment", 20.0, quantity="bending_moment"),
                         ct.sensor("acc", 20.0, quantity="acceleration")],
                vehicles=[ct.quarter_car("car", 2000.0, y=1.875, speed=15.0)],
                solver={"dt": 0.005}, output={"every": 1})
    base.update(overrides)
    return ct.scenario(**base)


@pytest.fixture(scope="module")
def girder():
    sc = _girder()
    return sc, sc.build_bridge()


def test_scenarios_are_built_from_tables_and_overrides_merge(girder, tmp_path):
    sc, _ = girder
    assert sc.bridge.spans == (40.0,) and [s.name for s in sc.sensors] == ["mid", "moment", "acc"]
    rough = ct.scenario(sc, road={"class": "B", "seed": 4}, solver={"duration": 3.0})
    assert rough.road.road_class == "B" and rough.road.seed == 4
    assert rough.solver.duration == 3.0 and rough.solver.dt == 0.005  # merged, not replaced
    smooth = ct.scenario(rough, road={"class": "smooth", "seed": None})
    assert smooth.road.seed is None and smooth.road.smooth
    two = ct.scenario(sc, vehicles=[ct.moving_force("a", 1000.0, 0.0, 10.0), ct.moving_force("b", 1000.0, 0.0, 9.0)])
    assert [v.id for v in two.vehicles] == ["a", "b"]  # arrays of tables are replaced
    path = tmp_path / "s.toml"
    path.write_text(sc.text)
    assert ct.scenario(path, name="renamed").title == "renamed"
    assert ct.scenario("paper-double-tee", solver={"duration": 1.0}).bridge.spans == (40.0,)
    with pytest.raises(ConfigError, match=r"solver\.dt: must be > 0"):
        ct.scenario(sc, solver={"dt": -1.0})
    with pytest.raises(ConfigError, match=r'road\.clas: unknown key; did you mean "class"'):
        ct.scenario(sc, road={"clas": "B"})


def test_quarter_car_parameters():
    car = ct.quarter_car("c", 1000.0, 0.0, 10.0, f_body=1.5, zeta=0.2, wheel_share=0.1)
    assert car["m_w"] == pytest.approx(100.0) and car["m_v"] == pytest.approx(900.0)
    assert math.sqrt(car["k_v"] / car["m_v"]) / (2 * math.pi) == pytest.approx(1.5)
    assert car["c_v"] / (2 * math.sqrt(car["k_v"] * car["m_v"])) == pytest.approx(0.2)


def test_named_results_peaks_and_vehicles(girder):
    sc, model = girder
    res = ct.run(sc, bridge_model=model)
    assert res.names == ["mid", "moment", "acc"] and "mid" in res and len(res["mid"]) == len(res.t)
    for name in res.names:  # logged at every step, so the peak over every step is the samples' peak
        assert ct.peak(res, name) == pytest.approx(np.max(np.abs(res[name])), rel=1e-12)
        assert res.minimum(name) == pytest.approx(res[name].min())
        assert res.maximum(name) == pytest.approx(res[name].max())
    car = res.vehicle("car")
    assert set(car) >= {"t", "x", "speed", "contact_force", "body_acceleration"}
    assert np.allclose(car["speed"], 15.0) and car["x"][0] >= 0.0 and car["x"][-1] <= 40.0
    assert np.mean(car["contact_force"]) == pytest.approx(2000.0 * G, rel=0.02)
    with pytest.raises(KeyError, match="no sensor 'nope'"):
        res["nope"]
    with pytest.raises(KeyError, match="no vehicle 'bus'"):
        res.vehicle("bus")


def test_daf_against_the_static_solution(girder):
    """The quasi-static peak at mid-span of a force that crosses it is the static deflection with the
    force on the sensor (the peak of its influence line); the DAF is the dynamic peak over that."""
    sc, model = girder
    res = ct.run(sc, vehicles=[ct.moving_force("F", 30000.0, y=1.875, speed=10.0)], bridge_model=model)
    static = model.static([PointLoad(20.0, 1.875, -30000.0 * G)])
    assert res.static_peak("mid") == pytest.approx(-static.deck_displacement(20.0, 1.875), rel=1e-9)
    # The moment sensor's largest static value, scanning the positions the force takes step by step.
    xs = 10.0 * 0.005 * np.arange(1, 801)
    moments = [model.static([PointLoad(x, 1.875, -30000.0 * G)]).field("bending_moment", 20.0)[0] for x in xs]
    assert res.static_peak("moment") == pytest.approx(max(moments), rel=1e-9)
    assert max(moments) == pytest.approx(30000.0 * G * 40.0 / 4, rel=0.01)  # P L / 4, up to the FE moment
    assert ct.daf(res, "mid") == pytest.approx(res.peak("mid") / -static.deck_displacement(20.0, 1.875), rel=1e-9)
    assert np.isnan(res.daf("acc"))
    k = int(np.argmin(np.abs(res.t - 1.3)))  # the force at x = 13 m
    assert res.static("mid")[k] == pytest.approx(
        model.static([PointLoad(10.0 * res.t[k], 1.875, -30000.0 * G)]).deck_displacement(20.0, 1.875), rel=1e-9)


def test_spectrum_and_dominant_frequency_of_a_known_sine():
    t = np.arange(0, 20.0, 0.005)
    x = 0.7 * np.sin(2 * np.pi * 3.2 * t) + 0.1 * np.sin(2 * np.pi * 11.0 * t) + 0.3
    f, amplitude = ct.spectrum(t, x)
    assert f[np.argmax(amplitude)] == pytest.approx(3.2, abs=0.01)
    assert amplitude.max() == pytest.approx(0.7, rel=0.02)
    assert ct.dominant_frequency(t, x) == pytest.approx(3.2, abs=0.003)
    assert ct.dominant_frequency(t, x, band=(5.0, 20.0)) == pytest.approx(11.0, abs=0.003)
    with pytest.raises(ValueError, match="uniformly spaced"):
        ct.spectrum(np.array([0.0, 0.1, 0.3, 0.4, 0.5]), np.zeros(5))


def test_assertions_say_what_was_expected(girder):
    sc, model = girder
    res = ct.run(sc, bridge_model=model)
    ct.assert_peak_below(res, "mid", 1.0)
    with pytest.raises(AssertionError, match=r"peak \|mid\| = .* mm, expected below 1e-06 mm"):
        ct.assert_peak_below(res, "mid", 1e-9)
    ct.assert_daf_below(res, "mid", 2.0)
    with pytest.raises(AssertionError, match=r"DAF of mid = .*expected below 0\.5"):
        ct.assert_daf_below(res, "mid", 0.5)
    ct.assert_deflection_below(res, "mid", 800.0)
    with pytest.raises(AssertionError, match=r"expected below L/1e\+09 = 40 m / 1e\+09"):
        ct.assert_deflection_below(res, "mid", 1e9)
    with pytest.raises(ValueError, match="needs a displacement sensor"):
        ct.assert_deflection_below(res, "acc")


def test_comparison_with_a_stored_log(girder, tmp_path):
    sc, model = girder
    stored = tmp_path / "stored.mcap"
    logged = ct.run(sc, log=stored, bridge_model=model)
    assert logged.log_path == stored
    in_memory = ct.run(sc, bridge_model=model)
    for name in in_memory.names:  # the log holds exactly the floats of the in-memory run
        assert np.array_equal(in_memory[name], logged[name])
    ct.assert_matches_log(in_memory, stored, rtol=0.0)
    heavier = ct.run(sc, vehicles=[ct.quarter_car("car", 2060.0, y=1.875, speed=15.0)], bridge_model=model)
    ct.assert_matches_log(heavier, stored, rtol=0.05)  # 3 % heavier: within 5 % of the peak
    with pytest.raises(AssertionError, match=r"mid: max \|difference\| = .* allowed"):
        ct.assert_matches_log(heavier, stored, rtol=0.01, sensors=["mid"])
    with pytest.raises(AssertionError, match="channel.s. nope missing"):
        ct.assert_matches_log(heavier, stored, sensors=["nope"])


def test_vehicle_samples_are_named_as_in_the_log(girder, tmp_path):
    from cosim.core.fields import VEHICLE_NUMBERS

    sc, model = girder
    from_log = ct.run(sc, log=tmp_path / "run.mcap", bridge_model=model).vehicle("car")
    in_memory = ct.run(sc, bridge_model=model).vehicle("car")
    assert list(from_log) == ["t", *VEHICLE_NUMBERS]  # the log's fields, the log's names ("speed")
    assert {"t", "x", "y", "speed", "contact_force", "body_acceleration"} <= set(in_memory) <= set(from_log)
    for name, values in in_memory.items():  # the same samples, float for float
        np.testing.assert_array_equal(values, from_log[name], err_msg=name)
