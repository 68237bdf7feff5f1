"""Half-cars (one body on several axles) and unilateral tyres from SUMO vType params, with real SUMO."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from cosim.core.bridge import PointLoad
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.vehicles import HalfCar, TyreQuarterCar
from cosim.errors import SumoError
from cosim.run.scenario import load_scenario
from cosim.sumo import BridgeAxis, SumoTraffic, bundled_networks
from cosim.sumo.vtypes import vehicle_type

AXIS = BridgeAxis((0.0, 0.0), (40.0, 0.0))
G = 9.81
PARAMS = {"cosim.model": "half-car", "cosim.m_w": "4000", "cosim.k_v": "4.0e6", "cosim.c_v": "1.6e5",
          "cosim.k_t": "8.0e6", "cosim.c_t": "0", "cosim.axles": "2.0 8.0", "cosim.axle_loads": "0.3 0.7",
          "cosim.contact": "unilateral"}
HALF_CAR_TRUCK = (
    '<vType id="h40" vClass="truck" length="10" mass="40000" sigma="0" maxSpeed="20" accel="1" decel="4">'
    + "".join(f'<param key="{k}" value="{v}"/>' for k, v in PARAMS.items()) + "</vType>"
)


def _config(folder: Path, routes: str, end: float) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(bundled_networks() / "bridge.net.xml", folder / "bridge.net.xml")
    (folder / "test.rou.xml").write_text(f'<?xml version="1.0"?>\n<routes>\n{HALF_CAR_TRUCK}{routes}\n</routes>\n')
    cfg = folder / "test.sumocfg"
    cfg.write_text('<?xml version="1.0"?><configuration><input><net-file value="bridge.net.xml"/>'
                   '<route-files value="test.rou.xml"/></input>'
                   f'<time><begin value="0"/><end value="{end}"/></time></configuration>')
    return cfg


def test_a_half_car_vtype_is_one_body_whose_axles_carry_the_given_shares():
    typ = vehicle_type("h40", "truck", 10.0, 40000.0, PARAMS)
    model = typ.model
    assert isinstance(model, HalfCar) and model.pitch and model.unilateral
    assert [a.distance for a in model.axles] == [0.0, 6.0]
    assert model.total_mass == pytest.approx(40000.0, rel=1e-12)
    assert model.i_b == pytest.approx(36000.0 * 10.0**2 / 12, rel=1e-12)  # uniform 10 m body, m L^2 / 12
    # Two axles under a pitching body are statically determinate: the loads are the shares (lever rule).
    np.testing.assert_allclose(model.linear_system(G)["loads"], [0.3 * 40000 * G, 0.7 * 40000 * G], rtol=1e-9)
    keys = typ.axle_models()
    assert [k for k, _ in keys] == ["h40#0", "h40#1"] and all(m is model for _, m in keys)
    bounce = vehicle_type("b", "truck", 10.0, 40000.0, {**PARAMS, "cosim.pitch": "false"}).model
    assert isinstance(bounce, HalfCar) and not bounce.pitch
    tyre = vehicle_type("t", "truck", 10.0, 40000.0, {"cosim.model": "tyre-quarter-car",
                                                      "cosim.contact": "unilateral"}).model
    assert isinstance(tyre, TyreQuarterCar) and tyre.unilateral


@pytest.mark.parametrize("key, value, fragment", [
    ("cosim.contact", "sticky", "param `cosim.contact` must be bilateral or unilateral (got 'sticky')"),
    ("cosim.pitch", "maybe", "param `cosim.pitch` must be true or false (got 'maybe')"),
    ("cosim.i_b", "-1", "i_b"),
])
def test_bad_half_car_params_name_the_vtype(key, value, fragment):
    with pytest.raises(SumoError, match="vType h40") as err:
        vehicle_type("h40", "truck", 10.0, 40000.0, {**PARAMS, key: value})
    assert fragment in str(err.value)


def test_contact_is_not_a_param_of_the_plain_quarter_car():
    with pytest.raises(SumoError, match="`cosim.contact` is not used by model quarter-car"):
        vehicle_type("c", "passenger", 4.5, 1500.0, {"cosim.m_w": "150", "cosim.contact": "unilateral"})


def test_a_half_car_stopped_on_the_deck_gives_the_static_deflection(tmp_path):
    paper = load_scenario("paper-double-tee").build_bridge()
    stop = ('<vehicle id="q" type="h40" depart="0" departSpeed="10"><route edges="in_e pre_e bridge_e post_e out_e"/>'
            '<stop lane="bridge_e_0" endPos="26" duration="1000"/></vehicle>')
    cfg = _config(tmp_path, stop, end=300.0)
    with SumoTraffic(cfg, AXIS, step=0.05, end=300.0, half_width=6.655) as traffic:
        res = simulate(paper, traffic, 120.0, SolverSettings(dt=0.01), [Sensor("mid", 20.0, -1.875)])
        last = traffic.frames.frames[-1]
    assert last.ids == ("q#0", "q#1") and all(abs(v) < 1e-9 for v in last.v)
    model = traffic.models[last.types[0]]
    assert isinstance(model, HalfCar) and traffic.models[last.types[1]] is model
    assert last.x[0] - last.x[1] == pytest.approx(6.0, abs=1e-6)  # the axles 6 m apart along the axis
    # Reference: the beam's own static solution under the two axle loads (0.3 and 0.7 of 40 t, lever rule).
    loads = [PointLoad(x, y, -share * 40000 * G) for x, y, share in zip(last.x, last.y, (0.3, 0.7))]
    static = paper.static(loads).deck_displacement(20.0, -1.875)
    assert res.sensors["mid"][-1] == pytest.approx(static, rel=0.01)


def test_a_half_car_crossing_is_replayed_from_its_log_bit_for_bit(tmp_path):
    from cosim.log import TOPIC_SENSORS, BlockLogger, LogRecorder, TrafficLogger, read_log, traffic_from_log

    paper = load_scenario("paper-double-tee").build_bridge()
    drive = ('<vehicle id="a" type="h40" depart="0" departSpeed="15"><route edges="in_e pre_e bridge_e post_e out_e"/>'
             '</vehicle><vehicle id="b" type="h40" depart="2" departSpeed="15">'
             '<route edges="in_w pre_w bridge_w post_w out_w"/></vehicle>')
    cfg = _config(tmp_path, drive, end=100.0)
    sensors = [Sensor("mid", 20.0, -1.875)]
    path = tmp_path / "h.mcap"
    with LogRecorder(path, ["mid"]) as rec, BlockLogger(rec, ["mid"], 40.0) as logger:
        with SumoTraffic(cfg, AXIS, step=0.05, end=100.0, half_width=6.655, frame_sink=TrafficLogger(rec)) as traffic:
            live = simulate(paper, traffic, 30.0, SolverSettings(dt=0.005), sensors, output_every=2,
                            observers=[logger])
    log = read_log(path)
    replayed = simulate(paper, traffic_from_log(log, 40.0, 0.05), 30.0, SolverSettings(dt=0.005), sensors,
                        output_every=2)
    assert np.max(np.abs(live.sensors["mid"])) > 1e-3  # two 40 t half-cars: millimetres
    np.testing.assert_array_equal(replayed.sensors["mid"], live.sensors["mid"])
    assert len(log.topic(TOPIC_SENSORS)) == len(live.t) - 1
