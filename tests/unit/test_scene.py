"""The 3D scene of a log (cosim.log.scene): its geometry against the bridge's own static solution, its
vehicles against the logged contact forces, its scales against closed forms. Real logs, no mocks."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core.bridge import PointLoad, build_bridge
from cosim.core.coupling import BlockReport
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import HalfCar, QuarterCar
from cosim.core.vehicles.half_car import Axle
from cosim.log import TOPIC_SENSORS, TOPIC_VEHICLES, BlockLogger, LogRecorder, proto, read_log
from cosim.log.scene import (
    SAG_OF_SPAN,
    SCENE_MAX_DURATION,
    SceneWriter,
    plan_scene,
    scene_sensors,
    scene_wanted,
)
from cosim.log.schemas import TOPIC_SCENE, TOPIC_SCENE_STATIC, TOPIC_SCENE_TRANSFORM

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))


class Scenes:
    """A log recorder's writing side that keeps the scene messages, decoded (for the geometry alone)."""

    def __init__(self) -> None:
        self.messages: list[dict] = []
        self._decode = proto.decoder("foxglove.SceneUpdate", b"")  # Foxglove's own schema, from its package

    def spec(self, topic: str) -> proto.MessageSpec:
        return proto.spec_of(proto.TOPIC_MESSAGES[topic])

    def write_encoded(self, topic, times, datas) -> None:  # noqa: ANN001 - LogRecorder's signature
        self.messages += [self._decode(d) for d in datas]

    def write(self, topic, t, message) -> None:  # noqa: ANN001
        self.messages.append(message)


def entity(message: dict, name: str) -> dict:
    return next(e for e in message["entities"] if e["id"] == name)


@pytest.mark.parametrize("supports", [["pinned", "fork"], ["rigid-end", "rigid-end"]])
def test_the_drawn_deck_is_the_bridges_own_static_deflection_exaggerated(supports):
    """An eccentric 100 kN load between stations: the deck drawn from the hidden sensors against the FE static
    solution (BridgeModel.static, evaluated by StaticResult.field: an independent path to the same numbers).

    Reference: the model's static solution. Tolerances: exact at the stations (the drawing's centimetre);
    between them the cubic spline through 5 stations per 30 m span, within 5 % of the peak (measured 1.1 %
    and 3.9 %)."""
    bridge = build_bridge([30.0], 12, MAT, SEC, supports)
    static = bridge.static([PointLoad(11.0, 4.0, -1e5)])
    named = [Sensor("s", 11.0, 4.0)]
    plan = plan_scene(bridge, named, 0.005, exaggeration=1000.0, taken=["s"])
    assert plan.stations == (0.0, 7.5, 15.0, 22.5, 30.0)
    hidden = scene_sensors(plan)
    assert len(hidden) == 6 and plan.rows[0] == plan.rows[-1] == (-1, -1)  # held supports read nothing
    row = [static.field("w_deck", [s.x], s.y)[0] for s in [*named, *hidden]]
    empty = np.zeros((1, 0))
    report = BlockReport((), (), empty, np.zeros(0), empty, empty, np.zeros((1, 0), bool), empty, empty, empty,
                         np.array([row]), np.zeros((1, 0), bool))
    scenes = Scenes()
    SceneWriter(scenes, plan, first_column=1).write_block(np.array([0.1]), report)
    (message,) = scenes.messages
    points = entity(message, "deck")["triangles"][0]["points"]
    exact = np.array([static.field("w_deck", [p["x"]], p["y"])[0] * 1000.0 for p in points])
    drawn = np.array([p["z"] for p in points])
    peak = np.max(np.abs(exact))
    assert peak > 1.0  # the deck sags visibly: over a metre drawn
    at_station = np.isin([p["x"] for p in points], plan.stations)
    np.testing.assert_allclose(drawn[at_station], exact[at_station], atol=0.005 + 1e-9)
    assert np.max(np.abs(drawn - exact)) < 0.05 * peak
    # the twist: the loaded (left) edge sags more than the right one, as the FE solution says
    left = [p for p in points if p["y"] > 0 and p["x"] == 7.5]
    right = [p for p in points if p["y"] < 0 and p["x"] == 7.5]
    assert left[0]["z"] < right[0]["z"] - 0.1
    sphere = entity(message, "sensors")["spheres"][0]["pose"]["position"]
    assert sphere["z"] - 0.3 == pytest.approx(row[0] * 1000.0, abs=0.05 * peak)


def test_the_automatic_exaggeration_draws_the_reference_sag_as_a_twentieth_of_the_span():
    """A simply supported span with shear areas so large that Euler-Bernoulli holds: the reference vehicle's
    mid-span deflection P L^3 / (48 E I) (Timoshenko & Gere, Mechanics of Materials, table of beam
    deflections), times the exaggeration, is L/20 rounded down to 1, 2 or 5 times a power of ten."""
    stiff = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                              J=0.15, I_w=19.0, A_sy=1e6, A_sz=1e6, deck_y=(-6.6, 6.6))
    bridge = build_bridge([30.0], 20, MAT, stiff, ["pinned", "fork"])
    weight = 2e5
    sag = weight * 30.0**3 / (48 * MAT.E * stiff.I_y)  # 2.13 mm
    plan = plan_scene(bridge, [], 0.005, reference_weight=weight, reference_contact=5e4)
    ideal = SAG_OF_SPAN * 30.0 / sag  # 703
    assert plan.exaggeration == 500.0 and ideal / 2.5 <= plan.exaggeration <= ideal
    assert plan.newton_per_m == 2e4  # 50 kN drawn as 2.5 m
    assert plan_scene(bridge, [], 0.005, exaggeration=123.0).exaggeration == 123.0


def test_the_scene_is_on_for_runs_of_at_most_an_hour_unless_the_scenario_says():
    assert scene_wanted(None, SCENE_MAX_DURATION) and not scene_wanted(None, SCENE_MAX_DURATION + 0.01)
    assert not scene_wanted(False, 10.0) and scene_wanted(True, 1e5) and scene_wanted(250.0, 1e5)


def _run(path, scene: bool, duration: float = 2.0):
    """A 5-axle half-car and a quarter-car over a 30 m span, logged like cosim run does."""
    bridge = build_bridge([30.0], 10, MAT, SEC, ["rigid-end", "rigid-end"])
    truck = HalfCar(m_b=3.0e4, i_b=2e5, cg=4.0, axles=tuple(
        Axle(distance=x, m_w=800.0, k_s=1.5e6, c_s=2e4, k_t=3e6) for x in (0.0, 3.6, 7.2, 8.5, 9.8)))
    vehicles = (ScriptedVehicle("truck", truck, -1.9, 20.0),
                ScriptedVehicle("car", QuarterCar(1.4e3, 150.0, 6e4, 4e3), 1.9, 15.0, entry_time=0.2, direction=-1))
    sensors = [Sensor("mid", 15.0), Sensor("mid_acc", 15.0, 5.0, "acceleration")]
    names = [s.name for s in sensors]
    plan = plan_scene(bridge, sensors, 0.005, paths=[-1.9, 1.9], taken=names) if scene else None
    with LogRecorder(path, names, scene=scene) as rec:
        writer = SceneWriter(rec, plan, len(names)) if plan else None
        if writer is not None:
            writer.start()
        with BlockLogger(rec, names, duration, scene=writer) as logger:
            result = simulate(bridge, ScriptedTraffic(vehicles, 30.0), duration, SolverSettings(dt=0.005),
                              [*sensors, *(scene_sensors(plan) if plan else [])], output_every=2,
                              observers=[logger])
    return result, plan


@pytest.fixture(scope="module")
def scene_log(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "run.mcap"
    result, plan = _run(path, scene=True)
    return path, result, plan


def test_vehicles_are_drawn_where_the_log_has_them_with_their_contact_forces(scene_log):
    """Each scene against /cosim/vehicles at the same time (an independent record of the same run): an axle
    per contact point at its x, an arrow per contact on the deck as long as its force at the scene's scale."""
    path, _, plan = scene_log
    log = read_log(path)
    vehicles = {round(m["t"], 6): m["vehicles"] for m in log.topic(TOPIC_VEHICLES)}
    checked = 0
    for message in log.topic(TOPIC_SCENE):
        t = message["entities"][0]["timestamp"]["sec"] + message["entities"][0]["timestamp"]["nsec"] / 1e9
        on_deck = vehicles.get(round(t, 6), [])
        drawn = {e["id"]: e for e in message["entities"] if e["id"].startswith("vehicle ")}
        owners = {v["id"].split("#")[0] for v in on_deck}
        assert owners <= {name.removeprefix("vehicle ") for name in drawn}
        for v in on_deck:
            ent = drawn["vehicle " + v["id"].split("#")[0]]
            axle_x = [c["pose"]["position"]["x"] for c in ent["cylinders"]]
            assert min(abs(x - v["x"]) for x in axle_x) <= 0.005 + 1e-9
            lengths = [a["shaft_length"] + a["head_length"] for a in ent["arrows"]
                       if abs(a["pose"]["position"]["x"] - v["x"]) <= 0.005 + 1e-9]
            assert lengths and lengths[0] == pytest.approx(v["contact_force"] / plan.newton_per_m, abs=0.011)
            checked += 1
    assert checked > 50
    truck = next(e for m in log.topic(TOPIC_SCENE) for e in m["entities"] if e["id"] == "vehicle truck")
    assert len(truck["cylinders"]) == 5 and truck["cubes"][0]["size"]["x"] > 9.8  # over its five axles


def test_the_scene_changes_nothing_logged_and_its_sensors_stay_hidden(scene_log, tmp_path):
    path, result, plan = scene_log
    plain, _ = _run(tmp_path / "plain.mcap", scene=False)
    for name in ("mid", "mid_acc"):  # the hidden rows only read the state: the channels are the same, bit for bit
        np.testing.assert_array_equal(result.sensors[name], plain.sensors[name])
    log = read_log(path)
    assert set(log.topic(TOPIC_SENSORS)[5]) == {"t", "mid", "mid_acc"}
    assert read_log(tmp_path / "plain.mcap").messages.keys().isdisjoint(
        {TOPIC_SCENE, TOPIC_SCENE_STATIC, TOPIC_SCENE_TRANSFORM})
    (transform,) = log.topic(TOPIC_SCENE_TRANSFORM)
    assert transform["translation"]["x"] == -15.0 and transform["child_frame_id"] == "bridge"
    (static,) = log.topic(TOPIC_SCENE_STATIC)
    labels = entity(static, "labels")["texts"]
    assert [t["text"] for t in labels[:2]] == ["mid", "mid_acc"]
    assert f"x{plan.exaggeration:g}" in labels[-1]["text"]
    paths = entity(log.topic(TOPIC_SCENE)[3], "wheel paths")["lines"]
    assert sorted(line["points"][0]["y"] for line in paths) == [-1.9, 1.9]
