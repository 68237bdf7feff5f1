"""Turning traffic at a deck's ends (real SUMO through libsumo): every axle follows the path its vehicle drove.

A two-way bridge (edges ``deck`` and ``-deck``: OSM's way of naming a street's reverse direction) between two
priority junctions, each with a road crossing it; the deck edges carry sidewalks. A five-axle articulated lorry
and a two-axle bus take every turn: each route enters the bridge by turning at one end and leaves it by
turning the other way at the other end, in both directions (left and right, entering and leaving, at each
end). A lorry is also inserted standing on the deck. Built with SUMO's netconvert at test time.

Before the axles followed their trail (cosim.core.axle_paths), a turning lorry's rear axles swung metres
sideways with its bumper, and the run stopped with "wheel path lies off the deck".
"""
from __future__ import annotations

import json
import shlex
import subprocess
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli, netconvert  # noqa: E402

from cosim.cli import main
from cosim.log import read_log
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_TRAFFIC, TOPIC_VEHICLES
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario
from cosim.sumo.network import locate_bridge

NODES = """<nodes>
    <node id="W"  x="-120.0" y="0.0"/>
    <node id="A"  x="0.0"    y="0.0" type="priority"/>
    <node id="AN" x="0.0"    y="120.0"/>
    <node id="AS" x="0.0"    y="-120.0"/>
    <node id="B"  x="40.0"   y="0.0" type="priority"/>
    <node id="BN" x="40.0"   y="120.0"/>
    <node id="BS" x="40.0"   y="-120.0"/>
    <node id="E"  x="160.0"  y="0.0"/>
</nodes>
"""
_ROAD = 'numLanes="1" speed="13.89" width="3.5"'
EDGES = "<edges>\n" + "\n".join(
    [f'    <edge id="deck" from="A" to="B" {_ROAD} sidewalkWidth="2.0" priority="2"/>',
     f'    <edge id="-deck" from="B" to="A" {_ROAD} sidewalkWidth="2.0" priority="2"/>']
    + [f'    <edge id="{a}_{d}" from="{a if d == "in" else j}" to="{j if d == "in" else a}" {_ROAD} priority="{p}"/>'
       for a, j, p in (("W", "A", 2), ("E", "B", 2), ("AN", "A", 1), ("AS", "A", 1), ("BN", "B", 1), ("BS", "B", 1))
       for d in ("in", "out")]) + "\n</edges>\n"
# Route r1: from the north road at A, left onto the deck (+x), right off it to the south at B; r2: right on at A,
# left off at B; r3, r4 the same the other way (-x). The lorry is cosim's library lorry for vClass trailer
# (EN 1991-2 FLM4 lorry 3, five axles, 12.4 m from first to last), the bus its library bus (two axles).
ROUTES = """<routes>
    <vType id="artic" vClass="trailer" length="16.5" maxSpeed="13.9" accel="1.0" decel="4.0" sigma="0"/>
    <vType id="citybus" vClass="bus" length="12.0" maxSpeed="13.9" accel="1.0" decel="4.0" sigma="0"/>
    <route id="r1" edges="AN_in deck BS_out"/>
    <route id="r2" edges="AS_in deck BN_out"/>
    <route id="r3" edges="BN_in -deck AS_out"/>
    <route id="r4" edges="BS_in -deck AN_out"/>
    <vehicle id="lorry1" type="artic" route="r1" depart="0" departSpeed="max"/>
    <vehicle id="lorry3" type="artic" route="r3" depart="0" departSpeed="max"/>
    <vehicle id="lorry2" type="artic" route="r2" depart="30" departSpeed="max"/>
    <vehicle id="lorry4" type="artic" route="r4" depart="30" departSpeed="max"/>
    <vehicle id="bus1" type="citybus" route="r1" depart="60" departSpeed="max"/>
    <vehicle id="bus3" type="citybus" route="r3" depart="60" departSpeed="max"/>
    <vehicle id="bus2" type="citybus" route="r2" depart="90" departSpeed="max"/>
    <vehicle id="bus4" type="citybus" route="r4" depart="90" departSpeed="max"/>
    <vehicle id="inserted" type="artic" depart="120" departPos="20" departSpeed="0">
        <route edges="deck BS_out"/></vehicle>
</routes>
"""
CONFIG = """<configuration>
    <input><net-file value="turns.net.xml"/><route-files value="turns.rou.xml"/></input>
</configuration>
"""
SCENARIO = """\
name = "turns"
[bridge]
spans = [{length}]
elements_per_span = 8
supports = ["pinned", "fork"]
[bridge.material]
E = 35e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 80.0
J = 5.0
z_c = -0.8
deck_y = [-3.6, 3.6]     # the carriageway (y = -3.5 to 3.5 m), not the sidewalks beyond it
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = {mid}
[traffic]
sumo_config = "turns.sumocfg"
edges = ["deck", "-deck"]
end = 150.0
seed = 7
[solver]
dt = 0.01
"""
VEHICLES = {"lorry1": 5, "lorry2": 5, "lorry3": 5, "lorry4": 5, "bus1": 2, "bus2": 2, "bus3": 2, "bus4": 2,
            "inserted": 5}
LANE_TOLERANCE = 1e-6  # m: an axle on the deck lies within its lane's width (round-off of the projection)



@pytest.fixture(scope="module")
def turns(tmp_path_factory):
    folder = tmp_path_factory.mktemp("turns")
    (folder / "turns.nod.xml").write_text(NODES)
    (folder / "turns.edg.xml").write_text(EDGES)
    subprocess.run([netconvert(), "--node-files", "turns.nod.xml", "--edge-files", "turns.edg.xml",
                    "-o", "turns.net.xml", "--offset.disable-normalization", "true", "--no-turnarounds", "true",
                    "--no-warnings", "true"], cwd=folder, check=True, capture_output=True, timeout=60)
    (folder / "turns.rou.xml").write_text(ROUTES)
    (folder / "turns.sumocfg").write_text(CONFIG)
    location = locate_bridge(folder / "turns.net.xml", ["deck", "-deck"])
    length = round(location.axis.length, 3)
    (folder / "turns.toml").write_text(SCENARIO.format(length=length, mid=round(length / 2, 3)))
    outcome = run_logged(load_scenario(folder / "turns.toml"), folder / "turns.mcap")
    return {"folder": folder, "log": read_log(folder / "turns.mcap"), "location": location, "length": length,
            "outcome": outcome}


def _lane_of(location, direction: int):
    (lane,) = [lane for lane in location.lanes if lane.direction == direction]
    return lane


def test_every_axle_on_the_deck_stays_within_its_lane_at_every_sumo_step_and_sample(turns):
    log, location, length = turns["log"], turns["location"], turns["length"]
    lanes = {1: _lane_of(location, 1), -1: _lane_of(location, -1)}
    direction = {v: (1 if v in ("lorry1", "lorry2", "bus1", "bus2", "inserted") else -1) for v in VEHICLES}
    on_deck = defaultdict(int)
    for frame in log.topic(TOPIC_TRAFFIC):  # every SUMO step: every axle near the deck as the adapter placed it
        for cid, x, y in zip(frame["ids"], frame["x"], frame["y"]):
            if 0.0 <= x <= length:
                lane = lanes[direction[cid.split("#")[0]]]
                assert abs(y - lane.y) <= lane.width / 2 + LANE_TOLERANCE, (frame["t"], cid, x, y, lane)
                on_deck[cid] += 1
    for message in log.topic(TOPIC_VEHICLES):  # every logged sample: the lateral offset the deck was loaded at
        for v in message["vehicles"]:
            lane = lanes[direction[v["id"].split("#")[0]]]
            assert abs(v["y"] - lane.y) <= lane.width / 2 + LANE_TOLERANCE, (message["t"], v)
    # Every axle of every vehicle was on the deck (none was lost on the way).
    assert set(on_deck) == {f"{v}#{k}" for v, n in VEHICLES.items() for k in range(n)}


def test_each_axle_has_one_contiguous_contact_interval_from_end_to_end(turns):
    log, length = turns["log"], turns["length"]
    events = defaultdict(list)
    for m in log.topic(TOPIC_EVENTS):
        events[m["vehicle"]].append((m["event"], m["t"], m["x"]))
    samples = defaultdict(list)
    for m in log.topic(TOPIC_VEHICLES):
        for v in m["vehicles"]:
            samples[v["id"]].append(m["t"])
    for vid, n in VEHICLES.items():
        for k in range(n):
            cid = f"{vid}#{k}"
            kinds = [e for e, _, _ in events[cid]]
            assert kinds == ["entered", "left"], (cid, events[cid])
            (_, t_in, x_in), (_, t_out, x_out) = events[cid]
            if vid != "inserted":  # crossed from one end to the other (to a step's travel)
                assert min(x_in, length - x_in) < 0.2 and min(x_out, length - x_out) < 0.2, (cid, events[cid])
            t = np.array(samples[cid])
            assert np.allclose(np.diff(t), 0.01), f"{cid}: its contact is not one interval"  # every 10 ms sample
            assert t[0] - t_in < 0.01 + 1e-9 and t_out - t[-1] < 0.01 + 1e-9
    assert not [m for m in log.topic(TOPIC_EVENTS) if m["event"] in ("liftoff", "offdeck")]
    assert log.final_status["state"] == "finished"


def test_a_lorry_inserted_on_the_deck_has_its_axles_on_its_lane_behind_it(turns):
    # Inserted standing with its bumper 20 m along edge "deck": its axles stand on its lane behind it, at the
    # library lorry's distances behind the bumper (EN 1991-2 FLM4 lorry 3 on a 16.5 m vType: 1.4, 4.6, 9.8,
    # 11.1, 12.4 m), from the lane's start (the deck's x = 0 here, to 0.01 m).
    log, location = turns["log"], turns["location"]
    lane = _lane_of(location, 1)
    first = next(f for f in log.topic(TOPIC_TRAFFIC) if "inserted#0" in f["ids"])
    at = {cid: (x, y) for cid, x, y in zip(first["ids"], first["x"], first["y"])}
    start = lane.x_range[0]
    for k, back in enumerate((1.4, 4.6, 9.8, 11.1, 12.4)):
        x, y = at[f"inserted#{k}"]
        assert x == pytest.approx(start + 20.0 - back, abs=0.01) and y == pytest.approx(lane.y, abs=1e-6)


def test_the_summary_names_no_wheel_off_the_deck(turns):
    result = turns["outcome"].result
    assert (result.offdeck_events, result.offdeck_steps) == (0, 0)


def test_cosim_bridge_prints_commands_that_work_pasted_for_a_negative_edge_id(turns, capsys):
    net = turns["folder"] / "turns.net.xml"
    assert main(["bridge", str(net)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if "--edge=-deck" in line)
    options = shlex.split(row.split("two-way")[0])
    assert sorted(options) == ["--edge=-deck", "--edge=deck"]  # the shell's reading of the printed options
    assert main(["bridge", str(net), *options]) == 0
    out = capsys.readouterr().out
    assert f"Bridge on edges {options[0][7:]}, {options[1][7:]}" in out
    assert "sidewalk deck_0" in out and "not loaded" in out  # the sidewalks the deck need not cover
    # The form argparse alone would refuse ("expected one argument") works too.
    assert main(["bridge", str(net), "--edge", "deck", "--edge", "-deck"]) == 0


# --------------------------------------------------------------------------- a wheel beside the deck's surface


def test_a_wheel_beside_the_deck_is_an_event_and_the_run_goes_on(tmp_path):
    # The bundled straight road (lane centres y = -1.88 and +1.88 m in its network file) under a deck from y = -1
    # to 3 m, placed by its axis (no edges named, so no lane check): the eastbound wheels run 0.88 m beside its
    # surface. They load nothing, each crossing is an "offdeck" event with its y, the summary counts them, and the
    # run ends normally.
    text = (Path(__file__).resolve().parents[2] / "cosim" / "scenarios" / "paper-bridge-traffic.toml").read_text()
    text = text.replace("end = 600.0", "end = 40.0").replace("sumo_config = \"medium\"", "sumo_config = \"heavy\"")
    text = text[:text.index("[traffic.loads]")] + text[text.index("[road]"):]  # the vTypes' own weights, no wander
    text = text.replace("[[bridge.section.plates]]                   # deck plate, edges at y = +-6.655 m\n"
                        "start = [-6.655, 0.0]\nend = [6.655, 0.0]",
                        "[[bridge.section.plates]]\nstart = [-1.0, 0.0]\nend = [3.0, 0.0]")
    text = text.replace("start = [-3.325, 0.0]\nend = [-3.325, -2.0]", "start = [-0.5, 0.0]\nend = [-0.5, -2.0]")
    text = text.replace("start = [3.325, 0.0]\nend = [3.325, -2.0]", "start = [2.5, 0.0]\nend = [2.5, -2.0]")
    text = text.replace("y = 6.655", "y = 3.0").replace("y = -6.655", "y = -1.0").replace("y = 3.325", "y = 2.5")
    (tmp_path / "narrow.toml").write_text(text)
    run = cosim_cli("run", "narrow.toml", "--out", "narrow.mcap", "--quiet", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    log = read_log(tmp_path / "narrow.mcap")
    assert log.final_status["state"] == "finished"
    off = [m for m in log.topic(TOPIC_EVENTS) if m["event"] == "offdeck"]
    assert off and all(m["y"] == pytest.approx(-1.875, abs=0.01) and 0.0 <= m["x"] <= 40.0 for m in off)
    # Each offdeck wheel never loaded the deck: no sample of it on the deck, no "entered" event.
    beside = {m["vehicle"] for m in off}
    entered = {m["vehicle"] for m in log.topic(TOPIC_EVENTS) if m["event"] == "entered"}
    assert not beside & entered and entered  # the westbound wheels (y = +1.875 m) did load it
    assert not any(v["id"] in beside for m in log.topic(TOPIC_VEHICLES) for v in m["vehicles"])
    summary = [line for line in run.stdout.splitlines() if line.startswith("Off the deck:")]
    assert summary and f"{len(off)} times a wheel went beside the deck's surface" in summary[0], run.stdout


# --------------------------------------------------------------------------- a network nobody on the team made


INGOLSTADT_EDGES = ["-148050455#0", "148050455#0"]  # Ringlerstraße, 75 m, one lane each way plus sidewalks


def test_the_ingolstadt_bridge_of_the_issue_runs_to_its_end_with_every_wheel_on_its_lane(tmp_path):
    # The Ingolstadt scenario that ships with SUMO (eclipse-sumo's tools/game/fkk_in.sumocfg), the two-way bridge
    # that `cosim bridge` suggests there, the deck of the issue's report (y = -4.5 to 4.5 m), the config's whole
    # 180 s. Before axles followed their trail, this run stopped at 20 % ("wheel path y = 5.1357 m lies off the
    # deck"): vehicles turn into the junctions at both deck ends.
    import sumo

    config = Path(sumo.SUMO_HOME) / "tools" / "game" / "fkk_in.sumocfg"
    location = locate_bridge(config.parent / "fkk_in" / "ingolstadt.net.xml.gz", INGOLSTADT_EDGES)
    text = SCENARIO.format(length=round(location.axis.length, 3), mid=37.66)
    text = text.replace('sumo_config = "turns.sumocfg"', f"sumo_config = {json.dumps(str(config))}")
    text = text.replace('edges = ["deck", "-deck"]', f"edges = {json.dumps(INGOLSTADT_EDGES)}")
    text = text.replace("end = 150.0", "end = 180.0").replace("deck_y = [-3.6, 3.6]", "deck_y = [-4.5, 4.5]")
    (tmp_path / "ingol.toml").write_text(text)
    run_logged(load_scenario(tmp_path / "ingol.toml"), tmp_path / "ingol.mcap")
    log = read_log(tmp_path / "ingol.mcap")
    assert log.final_status["state"] == "finished" and log.final_status["t"] == 180.0
    length = location.axis.length
    wheels = set()
    for frame in log.topic(TOPIC_TRAFFIC):
        for cid, x, y in zip(frame["ids"], frame["x"], frame["y"]):
            if 0.0 <= x <= length:
                assert any(abs(y - lane.y) <= lane.width / 2 + LANE_TOLERANCE for lane in location.lanes), \
                    (frame["t"], cid, x, y)
                wheels.add(cid)
    assert len(wheels) >= 40  # the traffic of the 180 s (62 axles measured)
    kinds = defaultdict(list)
    for m in log.topic(TOPIC_EVENTS):
        kinds[m["vehicle"]].append(m["event"])
    assert not [v for v, k in kinds.items() if "offdeck" in k or k not in (["entered"], ["entered", "left"])]
