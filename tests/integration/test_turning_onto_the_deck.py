"""A vehicle first seen on a side road draws its loads for the direction it will cross the deck (real SUMO).

Grave's model draws per direction (1: along the bridge axis, 2: against it). A lorry comes down a side road
that joins the deck's east end from the north, heading south and a little east, and turns right onto the deck's
westbound edge. At its first sight (on the side road, a watched lane) its heading points along the axis, but it
crosses the deck against it: its direction is that of the deck edge next on its route, not its heading. Built
with SUMO's netconvert at test time.
"""
from __future__ import annotations

import subprocess

import pytest
from _cli import netconvert

from cosim.run.scenario import load_scenario
from cosim.run.simulate import plan_sumo
from cosim.sumo.adapter import SumoTraffic
from cosim.sumo.loads import VehicleLoads
from cosim.sumo.vtypes import LOADS_G

NODES = """<nodes>
    <node id="W" x="-200.0" y="0.0"/>
    <node id="A" x="0.0" y="0.0" type="priority"/>
    <node id="B" x="40.0" y="0.0" type="priority"/>
    <node id="E" x="240.0" y="0.0"/>
    <node id="N" x="30.0" y="200.0"/>
</nodes>
"""
_ROAD = 'numLanes="1" speed="13.89" width="3.5"'
EDGES = "<edges>\n" + "\n".join(
    f'    <edge id="{e}" from="{a}" to="{b}" {_ROAD}/>'
    for e, a, b in (("w_in", "W", "A"), ("w_out", "A", "W"), ("deck", "A", "B"), ("-deck", "B", "A"),
                    ("e_out", "B", "E"), ("e_in", "E", "B"), ("n_in", "N", "B"), ("n_out", "B", "N"))) + "\n</edges>\n"
ROUTES = """<routes>
    <vType id="lorry" vClass="truck" length="10.0" maxSpeed="13.9" accel="1.0" decel="4.0" sigma="0"/>
    <route id="down_and_west" edges="n_in -deck w_out"/>
    <vehicle id="lorry1" type="lorry" route="down_and_west" depart="0" departSpeed="max"/>
</routes>
"""
CONFIG = """<configuration>
    <input><net-file value="side.net.xml"/><route-files value="side.rou.xml"/></input>
</configuration>
"""
SCENARIO = """\
name = "turning-onto-the-deck"
[bridge]
spans = [40.0]
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
deck_y = [-3.6, 3.6]
[traffic]
sumo_config = "side.sumocfg"
edges = ["deck", "-deck"]
axis = [[0.0, 0.0], [40.0, 0.0]]  # the junctions shorten the deck's lanes: the deck is A to B
end = 60.0
seed = 7
[traffic.loads]
model = "Auxerre"
seed = 2
[solver]
dt = 0.01
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("side-road")
    (folder / "side.nod.xml").write_text(NODES)
    (folder / "side.edg.xml").write_text(EDGES)
    subprocess.run([netconvert(), "--node-files", "side.nod.xml", "--edge-files", "side.edg.xml",
                    "-o", "side.net.xml", "--offset.disable-normalization", "true", "--no-warnings", "true"],
                   cwd=folder, check=True, capture_output=True, timeout=60)
    (folder / "side.rou.xml").write_text(ROUTES)
    (folder / "side.sumocfg").write_text(CONFIG)
    (folder / "side.toml").write_text(SCENARIO)
    return folder


def test_a_vehicle_turning_onto_the_deck_draws_for_the_direction_it_crosses_it(folder):
    settings = plan_sumo(load_scenario(folder / "side.toml")).settings
    records, first_heading = [], None
    with SumoTraffic(settings=settings) as traffic:
        along = traffic.axis.unit()[0]
        while traffic.sumo_steps * settings.step < settings.end - settings.step and not records:
            frame = traffic.advance()
            if first_heading is None and "lorry1" in traffic.libsumo.vehicle.getIDList() and \
                    traffic.libsumo.vehicle.getLaneID("lorry1") == "n_in_0":
                first_heading = traffic.libsumo.vehicle.getAngle("lorry1")
            records += [r for r in frame.loads if r.id == "lorry1"]
        lorry = traffic.types["lorry"]
    # The precondition: seen first on the side road, heading south and a little east (SUMO's angle: degrees
    # clockwise from north), so a direction from its heading would be 1 (along the axis, +x).
    assert first_heading is not None and 170.0 < first_heading < 180.0 and along[0] > 0.99
    assert len(records) == 1
    draws = VehicleLoads(settings.loads)
    against, along_axis = draws.draw("lorry1", lorry, 2), draws.draw("lorry1", lorry, 1)
    assert against.vehicle_type is not None and along_axis.vehicle_type is not None
    assert against.vehicle_type.mass != along_axis.vehicle_type.mass  # the two directions draw differently
    # Reference: the draw for direction 2 (cosim.sumo.loads.VehicleLoads.draw), its weight as the record gives it.
    assert records[0].gvw == pytest.approx(against.vehicle_type.mass * LOADS_G, rel=1e-12)
