"""The quasi-static run behind the dynamic amplification factor, against independent computations.

The influence ordinates come from one reciprocal solve per sensor
(Maxwell-Betti); the references here load the bridge directly with point
loads (``BridgeModel.static``), or use the closed form ``P L^3 / (48 E I)``.
"""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.bridge import PointLoad
from cosim.core.quasistatic import daf, influence, influence_vectors, quasi_static
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.testing import bridge as bridge_table
from cosim.testing import moving_force, scenario, sensor

G = 9.81
SENSORS = [Sensor("mid", 20.0, 1.875), Sensor("edge", 13.0, -5.0), Sensor("moment", 20.0, 0.0, "bending_moment"),
           Sensor("acc", 20.0, 0.0, "acceleration")]


@pytest.fixture(scope="module")
def girder():
    sc = scenario(bridge=bridge_table(40.0, elements_per_span=16),
                  sensors=[sensor(s.name, s.x, s.y, s.quantity) for s in SENSORS],
                  vehicles=[moving_force("F", 40000.0, y=1.875, speed=20.0)])
    return sc, sc.build_bridge()


def test_influence_ordinates_are_the_direct_static_solution(girder):
    _, model = girder
    g = influence_vectors(model, SENSORS)
    for x, y in [(3.3, 1.875), (20.0, 0.0), (27.1, -4.0), (40.0, 2.0), (0.0, 0.0)]:
        ordinates = influence(model, g, [x], [y])[:, 0]
        direct = model.static([PointLoad(x, y, 1.0)])
        assert ordinates[0] == pytest.approx(direct.deck_displacement(20.0, 1.875), rel=1e-10, abs=1e-22)
        assert ordinates[1] == pytest.approx(direct.deck_displacement(13.0, -5.0), rel=1e-10, abs=1e-22)
        assert ordinates[2] == pytest.approx(direct.field("bending_moment", 20.0)[0], rel=1e-10, abs=1e-12)
        assert np.isnan(ordinates[3])  # no static counterpart for an acceleration
    off = influence(model, g, [-0.5, 40.5], [0.0, 0.0])  # off the bridge
    assert off[:3].tolist() == [[0.0, 0.0]] * 3 and np.isnan(off[3]).all()


def test_quasi_static_run_of_a_moving_force_is_the_static_solution_at_every_sample(girder):
    sc, model = girder
    qs = quasi_static(model, sc.build_vehicles(), sc.duration, sc.solver.dt, SENSORS, G, output_every=10)
    weight = 40000.0 * G
    checked = 0
    for k in range(0, len(qs.t), 3):
        x = 20.0 * qs.t[k]
        if not 0.0 < x < 40.0:
            continue
        direct = model.static([PointLoad(x, 1.875, -weight)])
        assert qs.sensors["mid"][k] == pytest.approx(direct.deck_displacement(20.0, 1.875), rel=1e-9)
        assert qs.sensors["edge"][k] == pytest.approx(direct.deck_displacement(13.0, -5.0), rel=1e-9)
        assert qs.sensors["moment"][k] == pytest.approx(direct.field("bending_moment", 20.0)[0], rel=1e-9)
        checked += 1
    assert checked > 5
    assert np.isnan(qs.sensors["acc"]).all() and np.isnan(qs.peak["acc"])
    assert qs.vehicles == ["F"] and qs.heaviest == 40000.0 and qs.max_on_deck == 1
    # The peak at mid-span: the force over the sensor (a node), where the closed form holds up to shear
    # and twist: 40 t on a 40 m simply supported girder, E I = 35e9 * 3.0.
    euler = weight * 40.0**3 / (48 * 35e9 * 3.0)
    assert qs.peak["mid"] == pytest.approx(-model.static([PointLoad(20.0, 1.875, -weight)])
                                           .deck_displacement(20.0, 1.875), rel=1e-9)
    assert qs.peak["mid"] == pytest.approx(euler, rel=0.05)


def test_two_vehicles_superpose(girder):
    sc, model = girder
    two = scenario(sc, vehicles=[moving_force("A", 30000.0, y=1.875, speed=10.0),
                                 moving_force("B", 12000.0, y=-1.875, speed=8.0, direction="-x", entry_time=1.0)])
    qs = quasi_static(model, two.build_vehicles(), 4.0, 0.01, SENSORS[:1], G, output_every=50)
    for k, t in enumerate(qs.t):
        loads = [PointLoad(10.0 * t, 1.875, -30000.0 * G)]
        if t >= 1.0:
            loads.append(PointLoad(40.0 - 8.0 * (t - 1.0), -1.875, -12000.0 * G))
        assert qs.sensors["mid"][k] == pytest.approx(model.static(loads).deck_displacement(20.0, 1.875),
                                                     rel=1e-9, abs=1e-15)
    assert qs.vehicles == ["A", "B"] and qs.heaviest_id == "A" and qs.max_on_deck == 2


def test_a_crawling_force_has_a_daf_of_one(girder):
    """At 0.5 m/s the dynamic response is the static one: the DAF is 1 within 0.5 %."""
    sc, model = girder
    slow = scenario(sc, vehicles=[moving_force("F", 40000.0, y=1.875, speed=0.5)], solver={"dt": 0.02})
    res = simulate(model, slow.build_vehicles(), slow.duration, SolverSettings(dt=0.02), SENSORS[:3])
    qs = quasi_static(model, slow.build_vehicles(), slow.duration, 0.02, SENSORS[:3], G)
    for name in ("mid", "edge", "moment"):
        peak = max(-res.sensor_min[name], res.sensor_max[name])
        assert daf(peak, qs.peak[name]) == pytest.approx(1.0, abs=0.005), name


def test_daf_is_nan_without_a_static_peak():
    assert np.isnan(daf(1.0, 0.0)) and np.isnan(daf(1.0, float("nan")))
    assert daf(1.2, 1.0) == pytest.approx(1.2)
