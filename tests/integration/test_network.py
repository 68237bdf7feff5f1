"""A user's own city network: real SUMO (libsumo) on a cut of the Bologna "Andrea Costa" scenario.

tests/data/bologna (EPL-2.0, source in its README): ``west`` carries edges
39/40 and 41/42, two-way, one lane per direction, a priority junction at each
end; ``east`` edges 113/43[1], three lanes per direction with traffic lights
at both ends. Each test copies the files it runs into a folder of its own (the
"user's folder") and checks that nothing is written there.
"""
from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

from cosim.cli import main
from cosim.log import read_log, sensor_series
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_VEHICLES
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario
from cosim.run.simulate import plan_sumo
from cosim.sumo.adapter import MESSAGES_FILE, VEHICLE_TYPES_ATTACHMENT
from cosim.sumo.library import LORRY_3
from cosim.sumo.network import locate_bridge

DATA = Path(__file__).resolve().parents[1] / "data" / "bologna"
WEST_LENGTH = 40.971  # m: edges 39/40 along their carriageway's centre line (cosim bridge prints it)
EAST_LENGTH = 80.544  # m: edges 113/43[1]
END_TOLERANCE = 0.25  # m: an event is at a deck end within a step's travel (<= 20 m/s x dt = 0.01 s) + 0.05 m

SCENARIO = """\
name = "{name}"
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
deck_y = [{deck_lo}, {deck_hi}]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = {mid}
[traffic]
sumo_config = "{config}"
edges = {edges}
begin = {begin}
end = {end}
seed = 7
[solver]
dt = 0.01
[output]
rate_hz = 100.0
"""

# A five-axle articulated lorry with no mass and no cosim param (cosim's library: EN 1991-2 FLM4 lorry 3),
# over bridge 40 (junction 28 at its start, 31 at its end) and on over 41; a car whose route ends on the
# deck (it vanishes there); a bus (the library's, from the published vType) and cars the other way, over 39
# (the cut's own traffic there starts later than these runs last).
EXTRA_ROUTES = """<routes>
    <vType id="artic" vClass="trailer" length="16.5" maxSpeed="13.9" accel="1.0" decel="4.0" sigma="0"/>
    <vehicle id="lorry" type="artic" depart="2" departSpeed="max"><route edges="32 40 41 160"/></vehicle>
    <vehicle id="coach" type="bus" depart="4" departSpeed="max"><route edges="159 42 39 35"/></vehicle>
    <flow id="east" type="passenger1" begin="8" end="40" period="6" departSpeed="max">
        <route edges="159 42 39 35"/></flow>
    <vehicle id="parker" type="passenger1" depart="30" departSpeed="max" arrivalPos="20">
        <route edges="32 40"/></vehicle>
</routes>
"""


def _user_folder(folder: Path, side: str, extra_routes: str | None = None, processing: str = "") -> Path:
    """The cut's files in ``folder``, as a user keeps them, and its config (with extra routes and options)."""
    folder.mkdir(parents=True, exist_ok=True)
    for path in DATA.glob(f"{side}.*"):
        shutil.copy(path, folder / path.name)
    shutil.copy(DATA / "acosta_vtypes.add.xml", folder / "acosta_vtypes.add.xml")
    config = folder / f"{side}.sumocfg"
    text = config.read_text()
    if extra_routes is not None:
        (folder / "extra.rou.xml").write_text(extra_routes)
        text = text.replace(f'<route-files value="{side}.rou.xml.gz"/>',
                            f'<route-files value="{side}.rou.xml.gz,extra.rou.xml"/>')
    if processing:
        text = text.replace("</sumoConfiguration>", f"<processing>{processing}</processing></sumoConfiguration>")
    config.write_text(text)
    return config


def _scenario(folder: Path, config: Path, name: str, edges: list[str], length: float, deck: float,
              end: float, begin: float = 0.0) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(SCENARIO.format(name=name, length=length, deck_lo=-deck, deck_hi=deck, mid=round(length / 2, 3),
                                    config=config.name, edges=json.dumps(edges), end=end, begin=begin))
    return path


def _events(log) -> dict[str, list[tuple[str, float, float]]]:
    out = defaultdict(list)
    for m in log.topic(TOPIC_EVENTS):
        out[m["vehicle"]].append((m["event"], m["t"], m["x"]))
    return out


def _on_deck_samples(log) -> dict[str, list[tuple[float, float, float, float]]]:
    """Contact point id -> (t, x, y, contact force) at every logged sample with it on the deck."""
    out = defaultdict(list)
    for m in log.topic(TOPIC_VEHICLES):
        for v in m["vehicles"]:
            out[v["id"]].append((m["t"], v["x"], v["y"], v["contact_force"]))
    return out


def _crossings(log, length: float, rate_hz: float) -> tuple[dict, dict]:
    """Every contact point's events and samples, with the crossing rules checked for each:

    at most one "entered" and one "left", in that order; entered at one deck end and, if it left, left at
    the other; the samples between contiguous (one at every logged sample: it never vanished).
    """
    events, samples = _events(log), _on_deck_samples(log)
    end_t = log.final_status["t"]
    for cid, evs in events.items():
        kinds = [e for e, _, _ in evs if e in ("entered", "left")]
        assert kinds in (["entered"], ["entered", "left"]), f"{cid}: {evs}"
        (_, t_in, x_in), *rest = [e for e in evs if e[0] in ("entered", "left")]
        assert min(x_in, length - x_in) <= END_TOLERANCE, f"{cid} entered mid-deck: {evs}"
        t_out = rest[0][1] if rest else end_t
        t = np.array([s[0] for s in samples[cid]])
        # Contiguous: a sample at every logged time between the first and the last.
        assert len(t) and np.allclose(np.diff(t), 1.0 / rate_hz), f"{cid} vanished on the deck at some step"
        assert t[0] - t_in < 1.0 / rate_hz + 1e-9 and t_out - t[-1] < 1.0 / rate_hz + 1e-9, cid
    return events, samples


# --------------------------------------------------------------------------- the one-lane bridge, with a lorry


@pytest.fixture(scope="module")
def west(tmp_path_factory):
    """``cosim run`` as a user runs it (a real process) on bridge 39/40, with only its edges named."""
    root = tmp_path_factory.mktemp("west")
    user = root / "user"
    config = _user_folder(user, "west", EXTRA_ROUTES)
    scenario = _scenario(user, config, "bologna-west", ["39", "40"], WEST_LENGTH, 4.5, 70.0)
    before = sorted(p.name for p in user.iterdir())
    out = root / "west.mcap"
    run = subprocess.run([sys.executable, "-m", "cosim", "run", str(scenario), "--out", str(out), "--quiet"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return {"run": run, "log": read_log(out), "path": out, "user": user, "before": before}


def test_every_axle_of_a_five_axle_lorry_crosses_from_one_deck_end_to_the_other_without_vanishing(west):
    """The issue's test: a 16.5 m, five-axle lorry over a bridge that ends in a junction, on a smooth road:
    each axle's contact is one contiguous interval from one deck end to the other, and nothing lifts off."""
    log = west["log"]
    events, samples = _crossings(log, WEST_LENGTH, 100.0)
    axles = [f"lorry#{k}" for k in range(5)]
    for cid in axles:
        (kind_in, t_in, x_in), (kind_out, t_out, x_out) = events[cid]
        # Edge 40 drives against +x (edge 39's direction): in at x = L, out at x = 0.
        assert kind_in == "entered" and x_in == pytest.approx(WEST_LENGTH, abs=END_TOLERANCE)
        assert kind_out == "left" and x_out == pytest.approx(0.0, abs=END_TOLERANCE)
        force = np.array([s[3] for s in samples[cid]])
        assert force.min() > 0.0
    # The axles follow each other at the library's spacings (EN 1991-2 FLM4 lorry 3: 3.2, 5.2, 1.3, 1.3 m):
    # x(t) of axle k+1 is axle k's, a spacing later (reference: the lorry's geometry).
    t0 = {cid: np.array([s[0] for s in samples[cid]]) for cid in axles}
    x0 = {cid: np.array([s[1] for s in samples[cid]]) for cid in axles}
    for k, spacing in enumerate(np.diff(LORRY_3.axles)):
        t_mid = t0[axles[k + 1]][len(t0[axles[k + 1]]) // 2]
        gap = np.interp(t_mid, t0[axles[k + 1]], x0[axles[k + 1]]) - np.interp(t_mid, t0[axles[k]], x0[axles[k]])
        assert gap == pytest.approx(spacing, abs=0.05)
    assert not [m for m in log.topic(TOPIC_EVENTS) if m["event"] == "liftoff"]


def test_the_run_is_as_before_axles_followed_their_trail_until_the_lorry_turns_onto_the_deck(west):
    """Issue 23: the junction bridge's results change only where a vehicle turns. Reference: this run's mid-span
    deflection before the axles followed their vehicle's path (tests/data/bologna/west-before-trails.npz,
    written by commit d8217b2's code), with the time its turning lorry's first axle reached the deck then. The
    series is the same to the bit until that moment; the lorry turns from edge 32 onto the deck at its x = L end,
    and with its axles on its lane (not on the line behind its turned bumper) they reach the deck 0.1 s later.
    After, the series stays within 2.5 % of its peak (measured: 2.2 %)."""
    before = np.load(DATA / "west-before-trails.npz")
    t, series = sensor_series(west["path"], ["mid"])
    now, old = series["mid"], before["mid"]
    assert np.array_equal(t, before["t"])
    changed = np.flatnonzero(now != old)
    assert changed.size and t[changed[0]] >= float(before["lorry_entered"]) - 1e-9
    entered = [m["t"] for m in west["log"].topic(TOPIC_EVENTS) if m["vehicle"] == "lorry#0" and m["event"] == "entered"]
    assert 0.0 < entered[0] - float(before["lorry_entered"]) < 0.2
    assert np.max(np.abs(now - old)) <= 0.025 * np.max(np.abs(old))


def test_traffic_crosses_in_both_directions_and_left_events_carry_the_exit_position(west):
    events, _ = _crossings(west["log"], WEST_LENGTH, 100.0)
    directions = defaultdict(int)
    for cid, evs in events.items():
        x_in = evs[0][2]
        directions["+x" if x_in < WEST_LENGTH / 2 else "-x"] += 1
        for _, _, x in evs:
            assert -END_TOLERANCE <= x <= WEST_LENGTH + END_TOLERANCE, f"{cid}: {evs}"
    assert directions["+x"] >= 4 and directions["-x"] >= 4, directions
    # A car whose route ends on the deck vanishes there: its "left" events say where it was last.
    for k in range(2):
        kinds = events[f"parker#{k}"]
        assert [e for e, _, _ in kinds] == ["entered", "left"]
        assert 10.0 < kinds[1][2] < WEST_LENGTH - 10.0, kinds


def test_the_run_names_where_the_bridge_is_and_every_vtype_with_its_sources(west):
    out = west["run"].stdout
    assert "bridge axis (741.97" in out and "(derived from edges 39, 40)" in out and f"{WEST_LENGTH:.3f} m" in out
    assert "Deck lanes: 39_0 (y = -1.60 m, +x), 40_0 (y = +1.60 m, -x)" in out
    lines = {line.split()[0]: line for line in out.splitlines() if line.startswith("  ") and "kg (" in line}
    assert "tyre-quarter-car, 49949 kg (cosim default: EN 1991-2 FLM4 lorry 3), 5 axles at 1.40, 4.60, 9.80, " \
           "11.10, 12.40 m (cosim default: EN 1991-2 FLM4 lorry 3)" in lines["artic"]
    assert "1500 kg (cosim default: car)" in lines["passenger1"] and "IRI golden car" in lines["passenger1"]
    assert "20387 kg (cosim default: bus (EN 1991-2 FLM4 lorry 1))" in lines["bus"]
    # The same table is in the log, with the sources cited.
    table = {t["type"]: t for t in json.loads(west["log"].attachments[VEHICLE_TYPES_ATTACHMENT])}
    assert table["artic"]["axles"] == pytest.approx(list(LORRY_3.axles)) and \
        table["artic"]["mass"] == pytest.approx(490e3 / 9.81)  # EN 1991-2 Table 4.7: 70+150+90+90+90 kN
    assert "EN 1991-2 Table 4.7, lorry 3" in table["artic"]["details"]["mass"]
    assert set(table) >= {"artic", "bus", "passenger1", "ignoring5"} and "private" not in table  # no distributions


def test_the_users_config_stays_theirs(west):
    """Its log, verbose and outputs go to a scratch folder: nothing next to the user's files, nothing from SUMO
    on the terminal, SUMO's messages in the log."""
    assert sorted(p.name for p in west["user"].iterdir()) == west["before"]
    run = west["run"]
    assert run.stderr == ""
    for chatter in ("Loading", "Simulation ended", "Performance", "Warning", "Statistics", "Inserted:"):
        assert chatter not in run.stdout
    messages = west["log"].attachments[MESSAGES_FILE].decode()
    assert "Loading net-file" in messages and "Simulation ended" in messages


def test_cosim_info_lists_the_sumo_vehicles(west, capsys):
    assert main(["info", str(west["path"])]) == 0
    out = capsys.readouterr().out
    assert "Vehicles (SUMO, " in out and "lorry" in out and "Vehicles (0)" not in out
    assert "artic (trailer): tyre-quarter-car, 49949 kg (cosim default: EN 1991-2 FLM4 lorry 3), 5 axle(s)" in out


# --------------------------------------------------------------------------- the three-lane bridge


@pytest.fixture(scope="module")
def east(tmp_path_factory):
    """Bridge 113/43[1] (three lanes each way, traffic lights at both ends), run through the Python API."""
    user = tmp_path_factory.mktemp("east")
    config = _user_folder(user, "east")
    # The cut's traffic on 113 starts at 61 s: the run covers SUMO's 55 to 130 s.
    scenario = load_scenario(_scenario(user, config, "bologna-east", ["113", "43[1]"], EAST_LENGTH, 13.0, 130.0,
                                       begin=55.0))
    out = user.parent / "east.mcap"
    run_logged(scenario, out)
    return read_log(out)


def test_a_multi_lane_bridge_carries_both_directions_lane_changes_and_queues_without_losing_an_axle(east):
    events, samples = _crossings(east, EAST_LENGTH, 100.0)
    entered_low = {cid for cid, evs in events.items() if evs[0][2] < EAST_LENGTH / 2}
    assert len(entered_low) >= 4 and len(events) - len(entered_low) >= 4  # both directions (axles)
    lanes = {cid: {round(s[2] / 3.2) for s in rows} for cid, rows in samples.items()}
    assert any(len(v) > 1 for v in lanes.values()), "expected a lane change on the deck"
    ys = np.array([s[2] for rows in samples.values() for s in rows])
    assert np.all(np.abs(ys) <= 12.66 + 1e-6)  # on the carriageway (lane centres at |y| <= 11.06 m)
    assert not [m for m in east.topic(TOPIC_EVENTS) if m["event"] == "liftoff"]


# --------------------------------------------------------------------------- the sublane model, the other bridge


def test_with_the_sublane_model_every_axle_crosses_whole_too(tmp_path):
    config = _user_folder(tmp_path / "user", "west", EXTRA_ROUTES, '<lateral-resolution value="0.8"/>')
    scenario = load_scenario(_scenario(tmp_path / "user", config, "sublane", ["41", "42"], 37.238, 4.5, 45.0))
    out = tmp_path / "sublane.mcap"
    run_logged(scenario, out)
    log = read_log(out)
    events, samples = _crossings(log, 37.238, 100.0)
    for k in range(5):  # the lorry goes on over 41 (edge 41 is +x here)
        assert [(e, round(x)) for e, _, x in events[f"lorry#{k}"]] == [("entered", 0), ("left", 37)]
    assert not [m for m in log.topic(TOPIC_EVENTS) if m["event"] == "liftoff"]


# --------------------------------------------------------------------------- locating a bridge


def test_the_axis_is_the_carriageway_centre_and_the_deck_the_lanes_extent():
    """Closed form from the network file: lanes 39_0 (742.49, 225.89) -> (703.68, 239.02) and 40_0
    (702.66, 235.99) -> (741.46, 222.86), both 3.2 m wide: the axis runs between them, along 39."""
    net = DATA / "west.net.xml.gz"
    loc = locate_bridge(net, ["39", "40"])
    a = np.array([742.49, 225.89]), np.array([703.68, 239.02])
    b = np.array([741.46, 222.86]), np.array([702.66, 235.99])
    along = (a[1] - a[0]) / np.linalg.norm(a[1] - a[0])
    normal = np.array([-along[1], along[0]])
    mid = 0.5 * (a[0] + b[0])
    start = np.array(loc.axis.start)
    assert float((start - mid) @ normal) == pytest.approx(0.0, abs=1e-3)  # on the line between the lanes
    direction = (np.array(loc.axis.end) - start) / loc.axis.length
    assert float(direction @ along) == pytest.approx(1.0, abs=1e-6)  # along 39's direction of travel
    half = float((a[0] - b[0]) @ normal) / 2  # lane centres either side of the axis
    assert [lane.y for lane in loc.lanes] == pytest.approx([-abs(half), abs(half)], abs=1e-3)
    assert loc.carriageway == pytest.approx((-abs(half) - 1.6, abs(half) + 1.6), abs=1e-3)
    assert loc.axis.length == pytest.approx(WEST_LENGTH, abs=1e-3)
    # One-way: only 39 named; the axis is its lane's centre, 40 is watched as the opposite direction.
    one = locate_bridge(net, ["39"])
    assert one.carriageway == pytest.approx((-1.6, 1.6)) and one.opposite == ("40",)


def _curved_bridge(folder: Path, heading_deg: float, length: float, bend: float) -> Path:
    """A two-way bridge of two lanes per direction from A to B at ``heading_deg``, its shape bending ``bend`` m
    to the left between 5 and 14 m from each end (past the junctions' edges: the lanes curve), with a crossing
    road at each end; built by netconvert."""
    import sumo

    c, s = math.cos(math.radians(heading_deg)), math.sin(math.radians(heading_deg))

    def at(u: float, v: float) -> str:  # local (along, left) -> network x,y
        return f"{100 + u * c - v * s:.6f},{200 + u * s + v * c:.6f}"

    nodes = {"A": (0, 0), "B": (length, 0), "An": (0, 60), "As": (0, -60), "Bn": (length, 60), "Bs": (length, -60)}
    (folder / "b.nod.xml").write_text("<nodes>" + "".join(
        f'<node id="{n}" x="{at(*uv).split(",")[0]}" y="{at(*uv).split(",")[1]}"/>' for n, uv in nodes.items())
        + "</nodes>")
    shape = " ".join([at(0, 0), at(5, 0), at(14, bend), at(length - 14, bend), at(length - 5, 0), at(length, 0)])
    back = " ".join(reversed(shape.split()))
    edges = [f'<edge id="AB" from="A" to="B" numLanes="2" width="3.2" shape="{shape}"/>',
             f'<edge id="BA" from="B" to="A" numLanes="2" width="3.2" shape="{back}"/>']
    for end in ("A", "B"):
        for side in ("n", "s"):
            edges += [f'<edge id="{end}{side}_in" from="{end}{side}" to="{end}" numLanes="1" width="3.2"/>',
                      f'<edge id="{end}{side}_out" from="{end}" to="{end}{side}" numLanes="1" width="3.2"/>']
    (folder / "b.edg.xml").write_text("<edges>" + "".join(edges) + "</edges>")
    net = folder / "b.net.xml"
    subprocess.run([str(Path(sumo.SUMO_HOME) / "bin" / "netconvert"), "-n", str(folder / "b.nod.xml"),
                    "-e", str(folder / "b.edg.xml"), "-o", str(net), "--no-turnarounds", "true",
                    "--offset.disable-normalization", "true"],
                   check=True, capture_output=True)
    return net


def test_any_orientation_and_a_short_curve_at_the_ends_keep_the_axis_on_the_carriageway_centre(tmp_path):
    """Closed form: netconvert lays each direction's lanes right of the shared shape, so the carriageway's centre
    is the shape's straight middle, ``bend`` left of the A-B line; lanes at +-1.6 and +-4.8 m (3.2 m wide);
    with the same crossing at both ends the lanes are symmetric, so the axis is parallel to A-B."""
    heading, length, bend = 127.0, 60.0, 1.5
    loc = locate_bridge(_curved_bridge(tmp_path, heading, length, bend), ["AB", "BA"])
    e = np.array([math.cos(math.radians(heading)), math.sin(math.radians(heading))])
    n = np.array([-e[1], e[0]])
    start, end = np.array(loc.axis.start), np.array(loc.axis.end)
    # Tolerances: the network file rounds coordinates to 0.01 m.
    assert abs(float((end - start) @ n)) / loc.axis.length < 0.02 / length  # the angle, rad
    assert float((start - np.array([100.0, 200.0])) @ n) == pytest.approx(bend, abs=0.01)
    assert sorted(lane.y for lane in loc.lanes) == pytest.approx([-4.8, -1.6, 1.6, 4.8], abs=0.01)
    assert loc.carriageway == pytest.approx((-6.4, 6.4), abs=0.01)
    assert length - 20.0 < loc.axis.length < length  # the lanes end at the junctions, inside A-B
    assert float((start - np.array([100.0, 200.0])) @ e) < 14.0  # ... where the shape still bends: they curve


def test_edges_alone_place_the_bridge_and_bad_ones_stop_before_anything_is_written(tmp_path, capsys):
    config = _user_folder(tmp_path, "west")
    good = load_scenario(_scenario(tmp_path, config, "good", ["39", "40"], WEST_LENGTH, 4.5, 30.0))
    plan = plan_sumo(good)
    assert plan.axis.length == pytest.approx(WEST_LENGTH) and "derived from edges 39, 40" in plan.axis_from
    cases = {
        "typo": (["39", "400"], WEST_LENGTH, 4.5, "has no edge '400' (did you mean 40"),
        "junction": (["39", ":31_1"], WEST_LENGTH, 4.5, "':31_1' is an internal (junction) edge"),
        "length": (["39", "40"], 30.0, 4.5, "are 40.971 m long along the derived axis, the bridge 30 m"),
        "narrow": (["39", "40"], WEST_LENGTH, 2.0, "reach y = -3.199 to 3.199 m from the derived axis"),
    }
    for name, (edges, length, deck, message) in cases.items():
        scenario = _scenario(tmp_path, config, name, edges, length, deck, 30.0)
        out = tmp_path / f"{name}.mcap"
        assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 2, name
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
        assert not out.exists()


def test_an_unknown_cosim_param_is_an_error_naming_the_closest_one(tmp_path, capsys):
    routes = EXTRA_ROUTES.replace('sigma="0"/>', 'sigma="0"><param key="cosim.kv" value="1e6"/></vType>')
    config = _user_folder(tmp_path, "west", routes)
    scenario = _scenario(tmp_path, config, "typo", ["39", "40"], WEST_LENGTH, 4.5, 30.0)
    assert main(["run", str(scenario), "--out", str(tmp_path / "typo.mcap"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "vType artic: unknown param `cosim.kv` (did you mean `cosim.k_v`?" in err
    assert not (tmp_path / "typo.mcap").exists()


def test_cosim_bridge_lists_candidates_and_prints_lines_that_run(tmp_path, capsys):
    config = _user_folder(tmp_path, "west")
    assert main(["bridge", str(config), "--near", "720", "230", "-n", "3"]) == 0
    out = capsys.readouterr().out
    first = [line for line in out.splitlines() if line.startswith("  --edge")][0]
    assert first.split()[:2] == ["--edge=39", "--edge=40"] and "two-way" in first and "41.0" in first
    assert main(["bridge", str(config), "--edge", "39", "--edge", "40", "--plot", str(tmp_path / "b.png")]) == 0
    out = capsys.readouterr().out
    assert (tmp_path / "b.png").stat().st_size > 10_000
    spans = [line for line in out.splitlines() if line.startswith("spans = ")][0]
    edges = [line for line in out.splitlines() if line.startswith("edges = ")][0]
    # The printed lines make a scenario whose bridge is where cosim bridge said.
    text = SCENARIO.format(name="pasted", length=1.0, deck_lo=-4.5, deck_hi=4.5, mid=20.0, config=config.name,
                           edges="[]", end=30.0, begin=0.0)
    text = text.replace("spans = [1.0]", spans.split("#")[0].strip()).replace("edges = []", edges)
    (tmp_path / "pasted.toml").write_text(text)
    plan = plan_sumo(load_scenario(tmp_path / "pasted.toml"))
    loc = locate_bridge(DATA / "west.net.xml.gz", ["39", "40"])
    assert math.dist(plan.axis.start, loc.axis.start) < 1e-3 and math.dist(plan.axis.end, loc.axis.end) < 1e-3
    assert main(["bridge", str(config), "--edge", "399"]) == 2
    assert "has no edge '399' (did you mean 39" in capsys.readouterr().err


# --------------------------------------------------------------------------- a study on the city's demand


def test_a_study_sweeps_vehicles_per_hour_on_a_city_demand_of_gzipped_routes(tmp_path):
    """A demand of individual vehicles (no <flow>) is scaled by SUMO's own ``scale``: rate / its own rate."""
    from cosim.study import load_study, run_study
    from cosim.sumo.files import read_demand

    config = _user_folder(tmp_path / "user", "west")
    _scenario(tmp_path / "user", config, "base", ["39", "40"], WEST_LENGTH, 4.5, 600.0)
    (tmp_path / "user" / "study.toml").write_text(
        '[study]\nname = "city"\nbase = "base.toml"\nduration = 120.0\n[sweep]\nvehicles_per_hour = [600.0, 4800.0]\n')
    outcome = run_study(load_study(tmp_path / "user" / "study.toml", output=tmp_path / "out"), workers=0,
                        plots=False)
    assert outcome.failed == []
    rows = {r["vehicles_per_hour"]: r for r in outcome.rows}
    assert rows[4800.0]["vehicles"] > 2 * rows[600.0]["vehicles"] > 0
    demand = read_demand(config)
    own_rate = demand.vehicles / ((demand.departures[1] - demand.departures[0]) / 3600.0)
    for rate in (600.0, 4800.0):
        sumo = next((outcome.study.output / "runs").glob(f"*vph-{rate:g}*")) / "sumo"
        assert (sumo / "west.rou.xml.gz").read_bytes() == (DATA / "west.rou.xml.gz").read_bytes()  # still gzipped
        scale = float(re.search(r'<scale value="([^"]+)"', (sumo / "west.sumocfg").read_text())[1])
        assert scale == pytest.approx(rate / own_rate, rel=1e-12)
