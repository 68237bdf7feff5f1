"""Each SUMO vehicle's own loads from a WIM-calibrated model (``[traffic.loads]``, issue 25), with real SUMO.

The bundled network and mix (sumo_networks/), two minutes of heavy demand: every vehicle that comes onto the
deck has its load record in the log (``/cosim/vehicle_loads``); a drawn truck's record is exactly what Grave's
model draws for its id and seed (an independent call of cosim.core.loads); the same scenario gives the same
loads in SUMO's own process and in the run's, and in a replay of the log; a vType with its own weights keeps
them; bad keys are one line, exit 2, nothing written.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli  # noqa: E402

from cosim.core.loads import load_model
from cosim.log import read_log
from cosim.log.schemas import TOPIC_VEHICLE_LOADS, TOPIC_VEHICLES
from cosim.run.logged import run_logged
from cosim.run.replay import replay_log
from cosim.run.scenario import load_scenario
from cosim.run.simulate import plan_sumo
from cosim.sumo.loads import VehicleLoads
from cosim.sumo.vtypes import LOADS_G

BUNDLED = Path(__file__).resolve().parents[2] / "cosim" / "scenarios" / "paper-bridge-traffic.toml"
LOADS = """[traffic.loads]
model = "Auxerre"
seed = 5
vtype_classes = {{ {mapping} }}
wander = "en1991-2"

[road]"""
MAPPING = 'car = "car", truck_loaded = [2, 3], truck_empty = [2, 3], artic_loaded = [4, 5], artic_empty = [4, 5]'


def _scenario(folder: Path, mapping: str = MAPPING, name: str = "loads") -> Path:
    text = BUNDLED.read_text()
    text = text[:text.index("[traffic.loads]")] + text[text.index("[road]"):]
    text = text.replace("end = 600.0", "end = 120.0").replace('sumo_config = "medium"', 'sumo_config = "heavy"')
    text = text.replace("[road]", LOADS.format(mapping=mapping), 1)
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loads")
    scenario = load_scenario(_scenario(folder))
    outcome = run_logged(scenario, folder / "loads.mcap")
    return {"folder": folder, "scenario": scenario, "outcome": outcome, "log": read_log(folder / "loads.mcap")}


def _records(log) -> dict[str, dict]:
    return {m["id"]: m for m in log.topic(TOPIC_VEHICLE_LOADS)}


def test_every_vehicle_on_the_deck_has_its_load_record_at_its_entry(run):
    log = run["log"]
    records = _records(log)
    on_deck = {v["id"].split("#")[0] for m in log.topic(TOPIC_VEHICLES) for v in m["vehicles"]}
    assert on_deck and set(records) == on_deck
    classes = {r["class"] for r in records.values()}
    assert "car" in classes and any(c.startswith("truck-") for c in classes), classes
    for r in records.values():
        assert r["n_axles"] == len(r["axle_loads"]) == len(r["axle_spacings"]) + 1
        assert math.isclose(sum(r["axle_loads"]), r["gvw"], rel_tol=1e-9)  # axle loads add up to the gross weight
        assert abs(r["wander"]) <= 0.2 + 1e-12 and r["lane"].startswith("bridge_")
    # The run's summary counts them per class.
    weights = run["outcome"].result.weights
    assert sum(w.count for w in weights.values()) == len(records)


def test_a_drawn_truck_is_what_grave_model_draws_for_its_id_and_seed(run):
    # Reference: cosim.core.loads' own draw for the same seed, id, direction and class (independent of the run).
    records = _records(run["log"])
    model = load_model("Auxerre")
    trucks = [r for r in records.values() if r["class"].startswith("truck-")]
    assert trucks
    for r in trucks:
        direction = 1 if r["id"].startswith("east") else 2  # east drives along +x (the bridge axis)
        load = model.draw(5, r["id"], direction, int(r["class"].split("-")[1]))
        assert r["gvw"] == pytest.approx(load.gross_weight, rel=1e-12)
        np.testing.assert_allclose(r["axle_loads"], load.axle_loads, rtol=1e-12)
        if not r["source"].endswith("scaled to the vType's length"):
            np.testing.assert_allclose(r["axle_spacings"], load.axle_spacings, rtol=1e-12)


def test_the_same_loads_in_sumos_own_process_and_in_a_replay(run, tmp_path):
    from cosim.core.simulation import simulate
    from cosim.run.simulate import build_traffic

    scenario = run["scenario"]
    records = _records(run["log"])
    # SUMO in the run's process, without a log: the blocks carry the same records.
    seen = {}

    class Keep:
        def on_block(self, times, keep, report):
            for r in report.loads:
                seen[r.id] = r

    with build_traffic(scenario, process=False) as traffic:
        simulate(scenario.build_bridge(), traffic, 120.0, scenario.solver_settings(), scenario.sensors_core(),
                 road=scenario.build_road(), output_every=scenario.output_every, observers=[Keep()], collect=False)
    assert set(seen) == set(records)
    for vid, r in seen.items():
        assert r.gvw == records[vid]["gvw"] and list(r.axle_loads) == records[vid]["axle_loads"]
    # A replay of the log re-drives the same vehicles with the same loads, and its log records them again.
    out = tmp_path / "replay.mcap"
    replay_log(run["folder"] / "loads.mcap", out=out)
    again = _records(read_log(out))
    assert again.keys() == records.keys()
    assert all(again[k]["axle_loads"] == records[k]["axle_loads"] and again[k]["t"] == records[k]["t"]
               for k in records)


def test_a_vtype_with_its_own_weights_keeps_them_unless_mapped(run):
    records = _records(run["log"])
    vans = [r for r in records.values() if r["class"] == "delivery"]  # the van sets its mass: not mapped here
    assert vans and all(r["gvw"] == pytest.approx(3000 * LOADS_G) and r["source"].startswith("vType van")
                        for r in vans)
    sumo = plan_sumo(run["scenario"])
    plan = VehicleLoads(sumo.settings.loads)
    types = {t.id: t for t in sumo.types}
    assert plan.plan(types["van"]) == "fixed" and plan.plan(types["car"]) == "car"
    assert plan.plan(types["artic_loaded"]) == (4, 5)


@pytest.mark.parametrize("bad, says", [
    ('model = "Auxerre"', 'traffic.loads.model: \'Nowhere\' is neither a bundled site'),
    ("vtype_classes", "traffic.loads.vtype_classes.artic_loadd: the demand has no vType 'artic_loadd' (did you mean "
                      "'artic_loaded'?"),
])
def test_bad_loads_keys_are_one_line_exit_2_and_nothing_written(tmp_path, bad, says):
    path = _scenario(tmp_path)
    text = path.read_text()
    if bad.startswith("model"):
        text = text.replace('model = "Auxerre"', 'model = "Nowhere"')
    else:
        text = text.replace("artic_loaded = [4, 5]", "artic_loadd = [4, 5]")
    path.write_text(text)
    result = cosim_cli("run", str(path), "--out", str(tmp_path / "x.mcap"), "--quiet", cwd=tmp_path)
    assert result.returncode == 2 and says in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / "x.mcap").exists()
