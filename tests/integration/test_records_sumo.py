"""WIM records inserted into SUMO (``[traffic.records] via = "sumo"``, issue 25, items 2 and 8), with real SUMO
through libsumo (no mocks), on the bundled network (sumo_networks/bridge.net.xml: one lane each way, 80 km/h,
the 40 m deck from x = 0 to 40 m, 520 m of road before it and after it).

The record file is written here (gzip CASTOR): in each direction ten vehicles (cars and trucks of 2 to 5 axles,
each axle its own load), 6 s apart at one speed per lane, so that SUMO never has to slow one down; and one
more in the +x lane, 1 s behind the last and faster, which SUMO must hold back. References: the records as
written (their times, axles, spacings and loads in the format's units, so what the file holds exactly), the
network's lane centres (y = -1.88 m for +x, +1.88 m for -x, as netconvert wrote them), and
``cosim.core.loads.lane_wander`` for each vehicle's wander.
"""
from __future__ import annotations

import gzip
import json
import shutil
import subprocess
import sys
from dataclasses import replace
from datetime import date
from pathlib import Path

import pytest
from _cli import cosim_cli

from cosim.core.loads import VehicleRecord, lane_wander, write_records
from cosim.core.records_traffic import record_class
from cosim.log import read_log
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_VEHICLE_LOADS, TOPIC_VEHICLES
from cosim.run.scenario import load_scenario
from cosim.run.simulate import plan_sumo
from cosim.sumo import SumoTraffic, bundled_networks
from cosim.sumo.records import LOOKAHEAD, RECORD_VTYPES

T = 981.0  # N: 100 kg, CASTOR's unit of weight
L = 40.0
DT = 0.01
SEED = 7
#: (axle loads in 100 kg, spacings in m): a car, and trucks of 2, 3, 4 and 5 axles, each axle its own load.
KINDS = [((7, 9), (2.6,)), ((52, 98), (5.1,)), ((61, 83, 77), (4.3, 1.3)), ((64, 112, 71, 69), (3.6, 5.4, 1.3)),
         ((66, 104, 73, 75, 79), (3.3, 5.2, 1.3, 1.3))]
SPEED = {1: 21.3, 2: 19.4}  # m/s per direction (dm/s in the file)
LANE_Y = {1: -1.88, 2: 1.88}  # the network's lane centres, m
PURSUER_SPEED = 27.0

SCENARIO = f"""
name = "records-sumo"
[bridge]
spans = [{L}]
elements_per_span = 10
supports = ["pinned", "fork"]
[bridge.material]
E = 3.5e10
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[[sensors]]
name = "mid"
x = {L / 2}
[traffic]
sumo_config = "net.sumocfg"
step = 0.05
begin = 0.0
end = 130.0
axis = [[0.0, 0.0], [{L}, 0.0]]
[traffic.records]
file = "wim.castor.gz"
format = "castor"
via = "sumo"
lanes = [{{lane = 1, y = -1.875, direction = "+x"}}, {{lane = 2, y = 1.875, direction = "-x"}}]
wander = "en1991-2"
seed = {SEED}
[solver]
method = "quasi-static"
dt = {DT}
[output]
rate_hz = 20.0
"""


def records() -> list[VehicleRecord]:
    """Ten vehicles a direction, 6 s apart, and a pursuer: in time order, as the file has them."""
    out = []
    for n in range(20):
        direction = 1 + n % 2
        loads, spacings = KINDS[(n // 2) % len(KINDS)]
        axles = tuple(w * T for w in loads)
        out.append(VehicleRecord(time=40.0 + 3.0 * n, lane=0, direction=direction, local_lane=1,
                                 speed=SPEED[direction], gross_weight=sum(axles), axle_loads=axles,
                                 axle_spacings=spacings, origin=date(2024, 5, 6)))
    last = out[-2]  # the last of direction 1, at 94 s
    loads, spacings = KINDS[3]
    axles = tuple(w * T for w in loads)
    out.append(VehicleRecord(time=last.time + 1.0, lane=0, direction=1, local_lane=1, speed=PURSUER_SPEED,
                             gross_weight=sum(axles), axle_loads=axles, axle_spacings=spacings,
                             origin=date(2024, 5, 6)))
    return sorted(out, key=lambda r: r.time)


def folder_with(folder: Path, scenario: str = SCENARIO) -> Path:
    """The bundled network with a config that has no demand of its own (only the records drive), the record file
    and the scenario."""
    shutil.copy(bundled_networks() / "bridge.net.xml", folder / "bridge.net.xml")
    (folder / "net.sumocfg").write_text(
        '<?xml version="1.0"?><configuration><input><net-file value="bridge.net.xml"/></input>'
        '<time><begin value="0"/><end value="130"/></time></configuration>', encoding="utf-8")
    write_records(folder / "wim.castor.gz", "castor", records())
    (folder / "wim.toml").write_text(scenario, encoding="utf-8")
    return folder


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    folder = folder_with(tmp_path_factory.mktemp("records-sumo"))
    result = cosim_cli("run", "wim.toml", "--out", "run.mcap", cwd=folder)
    assert result.returncode == 0, result.stderr
    log = read_log(folder / "run.mcap")
    return {"folder": folder, "stdout": result.stdout, "log": log,
            "loads": {m["id"]: m for m in log.topic(TOPIC_VEHICLE_LOADS)}}


def test_the_summary_says_the_config_brings_no_vehicle_types_of_its_own(run: dict) -> None:
    # The config has no demand (folder_with): no empty "Vehicle types (0)" table.
    assert "Vehicle types: none (no vehicle, trip or flow in the SUMO config's files); the WIM records (above) " \
           "bring their own" in run["stdout"]
    assert "Vehicle types (" not in run["stdout"]
    info = cosim_cli("info", "run.mcap", cwd=run["folder"])
    assert info.returncode == 0, info.stderr
    assert "Vehicle types: none in the SUMO config's files (vehicle-types.json)" in info.stdout
    assert "Vehicle types (" not in info.stdout


def test_every_record_comes_onto_the_deck_once_with_its_recorded_loads(run: dict) -> None:
    assert "each inserted into SUMO upstream of the deck" in run["stdout"]
    loads = run["loads"]
    written = records()
    assert len(run["log"].topic(TOPIC_VEHICLE_LOADS)) == len(loads) == len(written)  # each once
    for line, rec in enumerate(written, start=1):
        m = loads[f"wim:{line}"]
        assert m["n_axles"] == rec.axle_count and m["class"] == record_class(rec)
        assert m["axle_loads"] == pytest.approx(rec.axle_loads, rel=1e-12)  # front first, each its own
        assert m["axle_spacings"] == pytest.approx(rec.axle_spacings, rel=1e-12)
        assert m["gvw"] == pytest.approx(rec.gross_weight, rel=1e-12)
        assert m["source"] == "records: wim.castor.gz"
        assert m["lane"] == ("bridge_e_0" if rec.direction == 1 else "bridge_w_0")  # its lane, SUMO's id
        wander = lane_wander(SEED, f"wim:{line}", "en1991-2")
        assert m["wander"] == pytest.approx(wander, abs=1e-12)
        assert m["y"] == pytest.approx(LANE_Y[rec.direction] + wander, abs=1e-9)


def test_each_record_crosses_the_deck_in_one_piece(run: dict) -> None:
    """At every logged sample, a record's axles on the deck are consecutive axles, front first in its direction,
    at its recorded spacings (a straight road: 1e-6 m), each carrying its recorded load (quasi-static: the contact
    force is the axle's static load, mass x 9.81 = the load, 1e-9); every axle comes on and goes off once."""
    written = {f"wim:{line}": rec for line, rec in enumerate(records(), start=1)}
    seen: dict[str, set[int]] = {vid: set() for vid in written}
    for message in run["log"].topic(TOPIC_VEHICLES):
        by_vehicle: dict[str, dict[int, dict]] = {}
        for contact in message["vehicles"]:
            vid, _, k = contact["id"].partition("#")
            by_vehicle.setdefault(vid, {})[int(k)] = contact
        for vid, axles in by_vehicle.items():
            rec = written[vid]
            order = sorted(axles)
            assert order == list(range(order[0], order[-1] + 1)), (vid, order)  # no axle missing in between
            seen[vid].update(order)
            way = 1.0 if rec.direction == 1 else -1.0
            for k in order:
                assert axles[k]["contact_force"] == pytest.approx(rec.axle_loads[k], rel=1e-9)
                assert axles[k]["y"] == pytest.approx(axles[order[0]]["y"], abs=1e-9)
                if k + 1 in axles:
                    gap = way * (axles[k]["x"] - axles[k + 1]["x"])
                    assert gap == pytest.approx(rec.axle_spacings[k], abs=1e-6), (vid, k, message["t"])
    assert all(seen[vid] == set(range(rec.axle_count)) for vid, rec in written.items())
    events: dict[str, list[str]] = {}
    for m in run["log"].topic(TOPIC_EVENTS):
        events.setdefault(m["vehicle"], []).append(m["event"])
    assert set(events) == {f"{vid}#{k}" for vid, rec in written.items() for k in range(rec.axle_count)}
    assert all(e == ["entered", "left"] for e in events.values())


def test_an_undisturbed_record_reaches_the_deck_at_its_time_a_held_back_one_later(run: dict) -> None:
    """The first axle's crossing of the entry end (x = 0 along +x, x = L along -x), from its "entered" event
    (the first step on the deck, at x, at the record's constant speed), against the record's time: 1e-6 s for
    the vehicles nothing slows down, at their recorded speed; the pursuer, 1 s behind a 21.3 m/s vehicle at
    27 m/s, is held back by SUMO's car following: it comes later (measured: 1.0 s), slower (22.4 m/s)."""
    entered = {m["vehicle"]: m for m in run["log"].topic(TOPIC_EVENTS) if m["event"] == "entered"}
    loads = run["loads"]
    written = records()
    pursuer = max(range(len(written)), key=lambda i: written[i].speed) + 1
    for line, rec in enumerate(written, start=1):
        vid = f"wim:{line}"
        first = entered[f"{vid}#0"]
        speed = loads[vid]["speed"]
        into = first["x"] if rec.direction == 1 else L - first["x"]
        crossed = first["t"] - into / speed
        if line == pursuer:
            assert crossed > rec.time + 0.5 and speed < PURSUER_SPEED - 2.0, (crossed, rec.time, speed)
            continue
        assert speed == pytest.approx(rec.speed, rel=1e-9)
        assert crossed == pytest.approx(rec.time, abs=1e-6), vid
        assert first["t"] - DT < rec.time + 1e-9 <= first["t"] + 1e-9  # and the load record is of that step
        assert loads[vid]["t"] == pytest.approx(first["t"])


def test_sumo_in_its_own_process_inserts_the_same_records(run: dict) -> None:
    """Without a log, SUMO steps in a child process (cosim.run.sumo_process): the records are inserted there, and
    the deck's mid-span deflection is the logged run's (SUMO in the run's process), bit for bit."""
    from cosim.run.simulate import simulate_scenario

    scenario = load_scenario(run["folder"] / "wim.toml")
    result = simulate_scenario(scenario)
    logged = run["log"].topic("/cosim/sensors")
    assert len(result.t) == len(logged)
    assert [float(v) for v in result.sensors["mid"]] == [m["mid"] for m in logged]
    assert min(m["mid"] for m in logged) < -1e-3  # the records loaded it (a mm and more)


def test_the_log_replays_the_records_bit_for_bit(run: dict) -> None:
    """A replay takes the frames and each record's axle models from the log alone (SUMO is not run again)."""
    result = cosim_cli("replay", "run.mcap", "--out", "replay.mcap", cwd=run["folder"])
    assert result.returncode == 0, result.stderr
    assert "identical, bit for bit" in result.stdout, result.stdout


def test_the_records_are_read_a_lookahead_ahead_of_sumo(tmp_path: Path) -> None:
    """The file is streamed: after each SUMO step to time t, exactly the records due by t + LOOKAHEAD have been
    added (reference: the record times as written, here 15 s apart over 5 minutes), the later ones not yet read;
    a record is held until it leaves the network."""
    folder = folder_with(tmp_path, SCENARIO.replace("end = 130.0", "end = 400.0"))
    spread = [replace(r, time=40.0 + 15.0 * n) for n, r in enumerate(records())]
    write_records(folder / "wim.castor.gz", "castor", spread)
    scenario = load_scenario(folder / "wim.toml")
    traffic = SumoTraffic(settings=plan_sumo(scenario).settings)
    times = [r.time for r in spread]
    with traffic:
        feed = traffic._feed
        assert feed is not None
        sumo, arrived = traffic.libsumo, set()
        for _ in range(int(round(90.0 / 0.05))):
            before = sumo.simulation.getTime()
            traffic.advance()
            arrived.update(sumo.simulation.getArrivedIDList())
            assert feed.added == sum(t <= before + LOOKAHEAD for t in times)
            assert set(feed.live) == {f"wim:{line}" for line in range(1, feed.added + 1)} - arrived
        assert feed.added == 12 and len(times) == 21  # at 90 s: those due by 210 s
        assert len(feed.live) == 10  # the first two have left the network (at about 69 and 84 s)


def test_the_records_vtypes_are_sumos_own_vclass_defaults(tmp_path: Path) -> None:
    """Reference: what SUMO (the installed release) makes of a vType that gives only its vClass."""
    xml = "".join(f'<vType id="{vclass}" vClass="{vclass}"/>' for _, vclass, _ in RECORD_VTYPES.values())
    (tmp_path / "types.rou.xml").write_text(f"<routes>{xml}</routes>", encoding="utf-8")
    shutil.copy(bundled_networks() / "bridge.net.xml", tmp_path / "bridge.net.xml")
    script = ("import json, libsumo as ls\n"
              "ls.start(['sumo', '-n', 'bridge.net.xml', '-r', 'types.rou.xml', '--no-step-log', 'true'])\n"
              "vt = ls.vehicletype\n"
              "print(json.dumps({c: [vt.getLength(c), vt.getMinGap(c), vt.getAccel(c), vt.getDecel(c), "
              f"vt.getEmergencyDecel(c), vt.getWidth(c)] for c in {[v for _, v, _ in RECORD_VTYPES.values()]!r}}}))\n"
              "ls.close()\n")
    out = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, check=True,
                         timeout=120)
    sumo = json.loads(out.stdout.strip().splitlines()[-1])
    for _, vclass, values in RECORD_VTYPES.values():
        assert sumo[vclass] == pytest.approx(list(values), abs=1e-12), vclass


def assert_one_line_and_nothing_written(folder: Path, starts: str) -> None:
    before = sorted(p.name for p in folder.iterdir())
    result = cosim_cli("run", "wim.toml", "--out", "run.mcap", cwd=folder)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: " + starts), result.stderr
    assert sorted(p.name for p in folder.iterdir()) == before  # no log, no partial file, no runs/ folder


def test_a_lane_on_no_network_lane_of_its_direction_is_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    folder = folder_with(tmp_path, SCENARIO.replace('y = 1.875, direction = "-x"', 'y = 1.875, direction = "+x"'))
    assert_one_line_and_nothing_written(
        folder, "wim.toml: traffic.records.lanes[1]: lane 2 (y = +1.875 m, +x) lies on no lane of bridge.net.xml "
                "that drives +x over the deck")


def test_a_bad_record_is_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    folder = folder_with(tmp_path, SCENARIO.replace('file = "wim.castor.gz"', 'file = "bad.castor"'))
    text = gzip.decompress((folder / "wim.castor.gz").read_bytes()).decode().splitlines()
    text[5], text[6] = text[6], text[5]
    (folder / "bad.castor").write_text("\n".join(text) + "\n", encoding="ascii")
    assert_one_line_and_nothing_written(folder, "bad.castor: line 7: its time is 3 s before the previous record's")


def test_sumo_time_is_the_records_clock(tmp_path: Path) -> None:
    """Only the records within SUMO's begin and end run: none in [0, 30) s is a window without records."""
    folder = folder_with(tmp_path, SCENARIO.replace("end = 130.0", "end = 30.0"))
    assert_one_line_and_nothing_written(folder, "wim.toml: traffic.records: no record of ")


# --------------------------------------------------------------------------- a city bridge, with the city's traffic

BOLOGNA = Path(__file__).resolve().parents[1] / "data" / "bologna"
EAST_LENGTH = 80.544  # m: edges 113/43[1] (tests/integration/test_network.py)
#: BTLS lanes of the three-lane carriageway each way, onto the network's lane centres (cosim.sumo.records.deck_lanes
#: prints them: 113_0..2 at y = -11.06, -7.86, -4.66 m along +x; 43[1]_0..2 at +11.06, +7.86, +4.66 m along -x):
#: direction 1's lanes 1-3 from the outer lane in, direction 2's lanes numbered on from the far side (4 is its
#: inner lane, 6 its outer one).
EAST_LANES = [(1, -11.06, "+x"), (2, -7.86, "+x"), (3, -4.66, "+x"), (4, 4.66, "-x"), (5, 7.86, "-x"),
              (6, 11.06, "-x")]

EAST_SCENARIO = f"""
name = "records-bologna"
[bridge]
spans = [{EAST_LENGTH}]
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
deck_y = [-13.0, 13.0]
[[sensors]]
name = "mid"
x = {EAST_LENGTH / 2}
[traffic]
sumo_config = "east.sumocfg"
edges = ["113", "43[1]"]
begin = 55.0
end = 200.0
seed = 7
[traffic.records]
file = "east.castor"
format = "castor"
via = "sumo"
lanes = [{", ".join(f'{{lane = {k}, y = {y}, direction = "{d}"}}' for k, y, d in EAST_LANES)}]
[solver]
method = "quasi-static"
dt = 0.01
[output]
rate_hz = 20.0
"""


def east_records() -> list[VehicleRecord]:
    """Two vehicles in each of the six lanes between 70 and 125 s (the city's own traffic on 113 starts at 61 s),
    a lane's second 25 s after its first; castor's direction 2 / lane k is BTLS lane 7 - k."""
    out = []
    for n in range(12):
        lane = 1 + n % 6
        direction, local = (1, lane) if lane <= 3 else (2, 7 - lane)
        loads, spacings = KINDS[n % len(KINDS)]
        axles = tuple(w * T for w in loads)
        out.append(VehicleRecord(time=70.0 + 4.5 * n + (3.0 if n >= 6 else 0.0), lane=0, direction=direction,
                                 local_lane=local, speed=12.5, gross_weight=sum(axles), axle_loads=axles,
                                 axle_spacings=spacings, origin=date(2025, 7, 3)))
    return out


def test_on_a_city_bridge_with_traffic_lights_every_record_crosses_whole(tmp_path: Path) -> None:
    """Bridge 113/43[1] of the Bologna cut (three lanes each way, traffic lights at both ends, junctions with
    internal lanes, the city's morning traffic): each record is routed from its lane upstream through the
    junctions, and comes onto the deck once with all its axles, front first in its direction, at its recorded
    spacings (along the axis: within 2 %, for a lane change's slant), each carrying its recorded load (1e-9),
    whenever SUMO's lights and queues let it."""
    for path in BOLOGNA.glob("east.*"):
        shutil.copy(path, tmp_path / path.name)
    shutil.copy(BOLOGNA / "acosta_vtypes.add.xml", tmp_path / "acosta_vtypes.add.xml")
    written = east_records()
    write_records(tmp_path / "east.castor", "castor", written)
    (tmp_path / "east.toml").write_text(EAST_SCENARIO, encoding="utf-8")
    result = cosim_cli("run", "east.toml", "--out", "run.mcap", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    log = read_log(tmp_path / "run.mcap")
    loads = {m["id"]: m for m in log.topic(TOPIC_VEHICLE_LOADS) if m["id"].startswith("east:")}
    assert set(loads) == {f"east:{line}" for line in range(1, 13)}
    lanes = {1: "113_0", 2: "113_1", 3: "113_2", 4: "43[1]_2", 5: "43[1]_1", 6: "43[1]_0"}
    on_lane = 0
    for line, rec in enumerate(written, start=1):
        m = loads[f"east:{line}"]
        assert m["axle_loads"] == pytest.approx(rec.axle_loads, rel=1e-12) and m["n_axles"] == rec.axle_count
        assert m["lane"].rsplit("_", 1)[0] == ("113" if rec.direction == 1 else "43[1]")  # its direction's deck
        on_lane += m["lane"] == lanes[1 + (line - 1) % 6]
    assert on_lane >= 6  # most keep the lane they were given (SUMO may change lanes on the way)
    seen: dict[str, set[int]] = {vid: set() for vid in loads}
    for message in log.topic(TOPIC_VEHICLES):
        by_vehicle: dict[str, dict[int, dict]] = {}
        for contact in message["vehicles"]:
            vid, _, k = contact["id"].partition("#")
            if vid in seen:
                by_vehicle.setdefault(vid, {})[int(k)] = contact
        for vid, axles in by_vehicle.items():
            rec = written[int(vid.split(":")[1]) - 1]
            order = sorted(axles)
            assert order == list(range(order[0], order[-1] + 1)), (vid, order)
            seen[vid].update(order)
            way = 1.0 if rec.direction == 1 else -1.0
            for k in order:
                assert axles[k]["contact_force"] == pytest.approx(rec.axle_loads[k], rel=1e-9)
                if k + 1 in axles:
                    gap = way * (axles[k]["x"] - axles[k + 1]["x"])
                    assert gap == pytest.approx(rec.axle_spacings[k], rel=0.02), (vid, k, message["t"])
    assert all(seen[f"east:{line}"] == set(range(rec.axle_count)) for line, rec in enumerate(written, start=1))
