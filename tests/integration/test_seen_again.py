"""A vehicle's loads are drawn for the direction it crosses the deck in (real SUMO): a vehicle that crosses
the deck, leaves the watched lanes and comes back the other way; a vehicle that turns onto the deck from a side
road.

A lorry drives west to east over the deck, on past the watched lanes, turns round at a dead end and crosses
back. With `[traffic.loads]` it draws its weights when first seen and again when seen again, for the direction
it then drives (Grave's model draws per direction: the two draws differ). Before the fix, the second draw kept
the first one's name (``lorry@lorry1``), under which every table of models already held the first draw's: the
deck carried the first crossing's axles while the load record gave the second's (and a draw with more axles
than the first named models that did not exist).

A lorry that comes down a side road joining the deck's east end from the north, heading south and a little
east, turns right onto the deck's westbound edge. At its first sight (on the side road, a watched lane) its
heading points along the axis, but it crosses the deck against it: its direction is that of the deck edge next
on its route, not its heading (before, it drew direction 1's weights). Built with SUMO's netconvert at test time.
"""
from __future__ import annotations

import subprocess

import pytest
from _cli import netconvert

from cosim.core.vehicles.registry import model_from_dict
from cosim.log import read_log
from cosim.log.schemas import TOPIC_TRAFFIC, TOPIC_VEHICLE_LOADS, TOPIC_VEHICLE_TYPES
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario
from cosim.run.simulate import plan_sumo
from cosim.sumo.adapter import SumoTraffic
from cosim.sumo.loads import VehicleLoads
from cosim.sumo.vtypes import LOADS_G

NODES = """<nodes>
    <node id="W" x="-200.0" y="0.0"/>
    <node id="A" x="0.0" y="0.0" type="priority"/>
    <node id="B" x="40.0" y="0.0" type="priority"/>
    <node id="E" x="240.0" y="0.0" type="priority"/>
    <node id="F" x="440.0" y="0.0"/>
</nodes>
"""
_ROAD = 'numLanes="1" speed="13.89" width="3.5"'
EDGES = "<edges>\n" + "\n".join(
    f'    <edge id="{e}" from="{a}" to="{b}" {_ROAD}/>'
    for e, a, b in (("w_in", "W", "A"), ("w_out", "A", "W"), ("deck", "A", "B"), ("-deck", "B", "A"),
                    ("e_out", "B", "E"), ("e_in", "E", "B"), ("f_out", "E", "F"), ("f_in", "F", "E"))) + "\n</edges>\n"
# f_out and f_in lie beyond the watched lanes (the deck's, the junctions' and the 200 m edges next to it): the
# lorry is forgotten there, turns round at F (netconvert's turnaround at a dead end) and is seen again on f_in.
ROUTES = """<routes>
    <vType id="lorry" vClass="truck" length="10.0" maxSpeed="13.9" accel="1.0" decel="4.0" sigma="0"/>
    <route id="there_and_back" edges="w_in deck e_out f_out f_in e_in -deck w_out"/>
    <vehicle id="lorry1" type="lorry" route="there_and_back" depart="0" departSpeed="max"/>
</routes>
"""
CONFIG = """<configuration>
    <input><net-file value="uturn.net.xml"/><route-files value="uturn.rou.xml"/></input>
</configuration>
"""
SCENARIO = """\
name = "seen-again"
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
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = 20.0
[traffic]
sumo_config = "uturn.sumocfg"
edges = ["deck", "-deck"]
end = 100.0
seed = 7
[traffic.loads]
model = "Auxerre"
seed = 2
[solver]
dt = 0.01
"""



# The side road: F's place taken by N, north of the deck's east end and a little west of it.
SIDE_NODES = NODES.replace('<node id="F" x="440.0" y="0.0"/>', '<node id="N" x="30.0" y="200.0"/>')
SIDE_EDGES = EDGES.replace('from="E" to="F"', 'from="N" to="B"').replace('from="F" to="E"', 'from="B" to="N"')
SIDE_ROUTES = ROUTES.replace('edges="w_in deck e_out f_out f_in e_in -deck w_out"', 'edges="f_out -deck w_out"')
# The junctions shorten the deck's lanes: the deck is A to B.
SIDE_SCENARIO = SCENARIO.replace('end = 100.0', 'axis = [[0.0, 0.0], [40.0, 0.0]]\nend = 60.0')


def _build(folder, nodes: str, edges: str, routes: str, scenario: str) -> None:
    """The network (netconvert), its routes, the SUMO config and the scenario, named uturn.* in ``folder``."""
    (folder / "uturn.nod.xml").write_text(nodes)
    (folder / "uturn.edg.xml").write_text(edges)
    subprocess.run([netconvert(), "--node-files", "uturn.nod.xml", "--edge-files", "uturn.edg.xml",
                    "-o", "uturn.net.xml", "--offset.disable-normalization", "true", "--no-warnings", "true"],
                   cwd=folder, check=True, capture_output=True, timeout=60)
    (folder / "uturn.rou.xml").write_text(routes)
    (folder / "uturn.sumocfg").write_text(CONFIG)
    (folder / "uturn.toml").write_text(scenario)


@pytest.fixture(scope="module")
def crossings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("seen-again")
    _build(folder, NODES, EDGES, ROUTES, SCENARIO)
    run_logged(load_scenario(folder / "uturn.toml"), folder / "uturn.mcap")
    return read_log(folder / "uturn.mcap").messages


def test_each_crossing_loads_the_deck_with_the_weights_its_record_gives(crossings):
    records = [data for _, data in crossings[TOPIC_VEHICLE_LOADS]]
    assert [r["id"] for r in records] == ["lorry1", "lorry1"]  # one record per crossing
    assert records[0]["gvw"] != records[1]["gvw"]  # the precondition: the two directions drew differently
    models = {data["type"]: model_from_dict(data["model"]) for _, data in crossings[TOPIC_VEHICLE_TYPES]}
    frames = [data for _, data in crossings[TOPIC_TRAFFIC]]
    for record in records:
        # The first SUMO frame from the record's time on (its first axle onto the deck): the models it names.
        frame = next(f for f in frames if f["t"] >= record["t"] - 1e-9)
        types = [typ for vid, typ in zip(frame["ids"], frame["types"]) if vid.startswith("lorry1")]
        assert len(types) == record["n_axles"]
        weights = [models[typ].total_mass * LOADS_G for typ in types]
        # The record's axle loads are the drawn vehicle's (cosim.sumo.adapter._entering): the same numbers.
        assert weights == pytest.approx(record["axle_loads"], rel=1e-12)


def test_the_second_draw_has_a_name_of_its_own_and_the_first_keeps_its_own(crossings):
    names = {data["type"] for _, data in crossings[TOPIC_VEHICLE_TYPES]}
    assert {n.split("#")[0] for n in names} == {"lorry@lorry1", "lorry@lorry1/2"}


def test_a_vehicle_turning_onto_the_deck_draws_for_the_direction_it_crosses_it(tmp_path):
    # f_out is the side road here (N to B): the lorry heads south-east on it and turns right onto -deck.
    _build(tmp_path, SIDE_NODES, SIDE_EDGES, SIDE_ROUTES, SIDE_SCENARIO)
    settings = plan_sumo(load_scenario(tmp_path / "uturn.toml")).settings
    records, first_heading = [], None
    with SumoTraffic(settings=settings) as traffic:
        along = traffic.axis.unit()[0]
        while traffic.sumo_steps * settings.step < settings.end - settings.step and not records:
            frame = traffic.advance()
            if first_heading is None and "lorry1" in traffic.libsumo.vehicle.getIDList():
                first_heading = traffic.libsumo.vehicle.getAngle("lorry1")
            records += [r for r in frame.loads if r.id == "lorry1"]
        lorry = traffic.types["lorry"]
    # The precondition: it is seen first on the side road (watched: it leads to the deck), heading south and a
    # little east (SUMO's angle: degrees clockwise from north): a direction from its heading would be 1 (+x).
    assert first_heading is not None and 170.0 < first_heading < 180.0 and along[0] > 0.99
    assert len(records) == 1
    draws = VehicleLoads(settings.loads)
    against, along_axis = draws.draw("lorry1", lorry, 2), draws.draw("lorry1", lorry, 1)
    assert against.vehicle_type is not None and along_axis.vehicle_type is not None
    assert against.vehicle_type.mass != along_axis.vehicle_type.mass  # the two directions draw differently
    # Reference: the draw for direction 2 (cosim.sumo.loads.VehicleLoads.draw), its weight as the record gives it.
    assert records[0].gvw == pytest.approx(against.vehicle_type.mass * LOADS_G, rel=1e-12)
