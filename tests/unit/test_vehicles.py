"""Vehicle models, scripted kinematics, roughness in the contact, lift-off accounting."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.bridge import build_bridge
from cosim.core.roughness import iso8608_profile
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar
from cosim.errors import ConfigError

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))


def test_parameters_are_validated_with_the_key_named():
    with pytest.raises(ConfigError, match="`m_v` must be"):
        QuarterCar(m_v=-1.0, m_w=100, k_v=4e4, c_v=5e3)
    with pytest.raises(ConfigError, match="`c_t` must be"):
        TyreQuarterCar(m_v=1e3, m_w=100, k_v=4e4, c_v=5e3, k_t=1e5, c_t=-1)
    with pytest.raises(ConfigError, match="`mass`"):
        MovingForce(0.0)
    with pytest.raises(ConfigError, match="`speed`"):
        ScriptedVehicle("x", MovingForce(1e3), 0.0, 0.0)


def test_golden_car_ratios():
    car = TyreQuarterCar.golden_car(250.0)
    # IRI reference quarter-car (Sayers et al. 1986): k_s/m_s 63.3, c_s/m_s 6, k_t/m_s 653, m_u/m_s 0.15.
    assert (car.k_v / 250, car.c_v / 250, car.k_t / 250, car.m_w / 250) == pytest.approx((63.3, 6.0, 653.0, 0.15))


def test_speed_profile_kinematics_are_consistent():
    veh = ScriptedVehicle("b", MovingForce(1e3), 0.0, 0.0, profile=((0.0, 20.0), (4.0, 0.0)))
    t = np.linspace(0, 6, 601)
    s, v, a = veh.distance(t)
    # Uniform braking from 20 m/s to rest in 4 s covers 40 m, then stands still.
    assert s[-1] == pytest.approx(40.0)
    np.testing.assert_allclose(np.gradient(s, t)[1:-1], v[1:-1], atol=0.2)
    assert a[0] == pytest.approx(-5.0) and a[-1] == 0.0
    traffic = ScriptedTraffic((veh,), 100.0)
    assert traffic.end_time() == float("inf")


def test_rough_road_makes_a_light_fast_car_lift_off_and_a_smooth_road_does_not():
    bridge = build_bridge([30.0], 15, MAT, SEC, ["rigid-end", "rigid-end"])
    car = TyreQuarterCar(m_v=400.0, m_w=60.0, k_v=2e4, c_v=1.5e3, k_t=2e5)
    traffic = ScriptedTraffic((ScriptedVehicle("light", car, 1.0, 35.0),), 30.0)
    rough = iso8608_profile("H", seed=11, x_start=-10, x_end=40, path_y=(1.0,))
    res = simulate(bridge, traffic, 0.9, SolverSettings(dt=0.001), [Sensor("mid", 15.0)], road=rough)
    assert res.liftoff_events > 0 and res.liftoff_steps >= res.liftoff_events
    assert np.min(res.vehicle("light")["contact_force"]) < 0
    smooth = simulate(bridge, traffic, 0.9, SolverSettings(dt=0.001), [Sensor("mid", 15.0)])
    assert smooth.liftoff_events == 0


def test_same_seed_gives_the_same_response():
    bridge = build_bridge([30.0], 10, MAT, SEC, ["rigid-end", "rigid-end"])
    traffic = ScriptedTraffic((ScriptedVehicle("q", QuarterCar(1e4, 1e3, 4e5, 2e4), 1.0, 20.0),), 30.0)
    runs = [
        simulate(bridge, traffic, 1.0, SolverSettings(dt=0.002), [Sensor("mid", 15.0, 1.0, "acceleration")],
                 road=iso8608_profile("C", seed=5, x_start=-10, x_end=40, path_y=(1.0,)))
        for _ in range(2)
    ]
    np.testing.assert_array_equal(runs[0].sensors["mid"], runs[1].sensors["mid"])
    assert np.max(np.abs(runs[0].sensors["mid"])) > 0
