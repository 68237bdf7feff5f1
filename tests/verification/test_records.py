"""WIM records replayed as recorded (issue 25, item 8): the logged mid-span moment and deflection of a simply
supported beam against an independent influence-line superposition of the same records, and against pybtls
(BTLS's own C++ simulation) on the same file.

The reference superposition is computed here from the file's records alone: every axle of every record at
every sample, its first axle at the deck's entry end at the record's time, at the record's speed, its axles
at the recorded spacings behind it, each its recorded load; the closed-form influence lines of a simply
supported beam of span L at mid-span: the moment ``a (L - L/2) / L`` (a <= L/2) and the deflection
``a (3 L^2 - 4 a^2) / (48 E I)`` (symmetric).

One term is the finite-element model's, not the replay's: the moment sensor reads the element's curvature
(``M = E I w''``), and an Euler-Bernoulli beam element whose nodal displacements are exact misses, inside
the element, the moment of its loads with its ends held (the fixed-end moment): a load P at a distance
``alpha`` into the sensor's element of length ``l`` (``beta = l - alpha``) adds ``P alpha beta^2 / l^2`` at
its left end, where the sensor reads it. The reference adds that term; without it, cosim's moment differs
from the closed form by it alone (0.8 % of the peak with 2 m elements). The deflection at a node needs no
such term (nodal values are exact).
"""
from __future__ import annotations

import math
import random
import subprocess
import sys
from datetime import date
from pathlib import Path

import numpy as np
import pytest

from cosim.core.loads import VehicleRecord, load_model, write_records
from cosim.log import read_log
from cosim.log.schemas import TOPIC_VEHICLE_LOADS
from cosim.run.api import run_scenario
from cosim.run.simulate import simulate_scenario
from cosim.testing import scenario

L = 40.0
ELEMENT = 2.0  # m: 20 elements
E, I_Y = 3.5e10, 3.0
DT = 0.01
EVERY = 5  # logged samples every 0.05 s
TRUCKS = 320

SCENARIO = f"""
name = "records-verification"
[bridge]
spans = [{L}]
elements_per_span = {int(L / ELEMENT)}
supports = ["pinned", "fork"]
bending = "euler-bernoulli"
[bridge.material]
E = {E}
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = {I_Y}
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[[sensors]]
name = "moment"
x = {L / 2}
quantity = "bending_moment"
[[sensors]]
name = "deflection"
x = {L / 2}
[traffic.records]
file = "trucks.castor"
format = "castor"
via = "scripted"
model = "moving-force"
lanes = [{{lane = 1, y = -1.875, direction = "+x"}}, {{lane = 2, y = 1.875, direction = "-x"}}]
[solver]
method = "quasi-static"
dt = {DT}
[output]
every = {EVERY}
"""


def generate(path: Path, count: int, seed: int = 11) -> list[VehicleRecord]:
    """Grave trucks (Auxerre, cosim's draws) in two directions, one lane each, arriving at random (about 300
    an hour), in the formats' units (100 kg, dm, dm/s, hundredths of a second), dated as BTLS dates its own
    first day (1/1/00), each as long as its axles plus 2.5 m (BTLS keeps a vehicle on the bridge until its
    front has gone its length beyond the far end)."""
    model = load_model("Auxerre")
    rng = random.Random(seed)
    records, t, last = [], 5.0, {1: -10.0, 2: -10.0}
    for n in range(count):
        t += rng.expovariate(300 / 3600)
        direction = rng.choice((1, 2))
        t = max(t, last[direction] + 1.5)  # a lane's vehicles keep apart
        last[direction] = t
        load = model.draw(seed, f"truck{n}", direction)
        axles = tuple(max(1, round(w / 981.0)) * 981.0 for w in load.axle_loads)
        spacings = tuple(max(1, round(s * 10)) / 10 for s in load.axle_spacings)
        records.append(VehicleRecord(time=round(t, 2), lane=0, direction=direction, local_lane=1,
                                     speed=rng.randint(200, 260) / 10, gross_weight=sum(axles), axle_loads=axles,
                                     axle_spacings=spacings, length=round(sum(spacings) + 2.5, 1),
                                     origin=date(2000, 1, 1)))
    write_records(path, "castor", records)
    return records


def reference(records: list[VehicleRecord], t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The closed-form mid-span moment (N m, sagging positive) and deflection (m, down negative) at times ``t``,
    and the moment sensor's element term (the fixed-end moment of the axles in the element right of mid-span)."""
    moment, deflection, element = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
    mid = L / 2
    for rec in records:
        behind = np.concatenate([[0.0], np.cumsum(rec.axle_spacings)])
        leaves = rec.time + (L + behind[-1]) / rec.speed
        k0, k1 = np.searchsorted(t, [rec.time, leaves], side="left")
        k1 = min(k1 + 1, len(t))
        tt = t[k0:k1]
        for load, back in zip(rec.axle_loads, behind):
            s = rec.speed * (tt - rec.time) - back
            x = s if rec.direction == 1 else L - s
            on = (x >= 0.0) & (x <= L)
            a = np.where(x <= mid, x, L - x)
            moment[k0:k1] += np.where(on, load * a * (L - mid) / L, 0.0)
            deflection[k0:k1] -= np.where(on, load * a * (3 * L**2 - 4 * a**2) / (48 * E * I_Y), 0.0)
            alpha = x - mid
            inside = (alpha >= 0.0) & (alpha <= ELEMENT)
            element[k0:k1] += np.where(inside, load * alpha * (ELEMENT - alpha) ** 2 / ELEMENT**2, 0.0)
    return moment, deflection, element


@pytest.fixture(scope="module")
def replayed(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("records")
    records = generate(folder / "trucks.castor", TRUCKS)
    (folder / "scenario.toml").write_text(SCENARIO, encoding="utf-8")
    done = run_scenario(folder / "scenario.toml", out=folder / "run.mcap")
    log = read_log(done.outcome.log_path)
    samples = log.topic("/cosim/sensors")
    t = np.array([m["t"] for m in samples])
    return folder, records, t, {n: np.array([m[n] for m in samples]) for n in ("moment", "deflection")}, log


def test_the_replay_is_the_influence_line_superposition_of_the_records(replayed) -> None:
    _, records, t, logged, log = replayed
    moment, deflection, element = reference(records, t)
    peak_m, peak_w = np.abs(moment).max(), np.abs(deflection).max()
    assert peak_m > 4e6 and t[-1] > records[-1].time  # trucks, and the last one has left
    # cosim = the closed form + the element's fixed-end term, to the rounding (measured 4e-13 of the peak)
    assert np.abs(logged["moment"] - (moment + element)).max() <= 1e-6 * peak_m
    assert np.abs(logged["deflection"] - deflection).max() <= 1e-6 * peak_w
    # the element term is all there is between cosim's moment and the closed form: at most 4/27 P l per axle
    off = np.abs(logged["moment"] - moment).max()
    assert 0.001 * peak_m < off <= 3 * 4 / 27 * max(max(r.axle_loads) for r in records) * ELEMENT
    # every record came onto the deck once, with its recorded axles
    loads = log.topic(TOPIC_VEHICLE_LOADS)
    assert [m["id"] for m in loads] == [f"trucks:{k + 1}" for k in range(TRUCKS)]
    for message, rec in zip(loads, records):
        assert message["axle_loads"] == pytest.approx(rec.axle_loads) and message["gvw"] == pytest.approx(
            rec.gross_weight)
        assert message["axle_spacings"] == pytest.approx(rec.axle_spacings)
        assert message["t"] == pytest.approx(math.ceil(rec.time / DT - 1e-9) * DT)  # the step it came on
        assert message["lane"] == str(rec.direction) and message["source"] == "records: trucks.castor"


PYBTLS = """
import sys
from pathlib import Path
import pybtls as pb
path, step, out = sys.argv[1], float(sys.argv[2]), sys.argv[3]
bridge = pb.Bridge(length={length}, no_lane=2)
line = pb.InfluenceLine("built-in")
line.set_IL(id=1, length={length})  # the mid-span moment of a simply supported beam
bridge.add_load_effect(inf_line_surf=line)
traffic = pb.TrafficLoader(no_lane=2)
traffic.add_traffic(Path(path), traffic_format=1)
config = pb.OutputConfig()
config.set_event_output(write_time_history=True)
sim = pb.Simulation(Path(out))
sim.add_sim(bridge=bridge, traffic=traffic, output_config=config, time_step=step, min_gvw=0, tag="th")
if __name__ == "__main__":
    sim.run(no_core=1)
"""


def pybtls_history(folder: Path, step: float) -> np.ndarray:
    """pybtls's time history of the mid-span moment (rows: t s, trucks, kN m) on the file, at ``step``."""
    pytest.importorskip("pybtls", reason="pybtls (the test extra) is the oracle")
    script = folder / "pybtls_run.py"
    script.write_text(PYBTLS.format(length=L), encoding="utf-8")
    out = folder / f"pybtls-{step:g}"
    subprocess.run([sys.executable, str(script), str(folder / "trucks.castor"), repr(step), str(out)], cwd=folder,
                   check=True, capture_output=True, timeout=600)
    (history,) = out.glob("th/TH_*.txt")
    return np.loadtxt(history, skiprows=1, ndmin=2)


def test_pybtls_on_the_same_file_at_the_same_step(replayed) -> None:
    """BTLS steps each event from its first vehicle's arrival (a record's time, in hundredths): at 0.01 s its
    instants are cosim's steps, and the two agree there to BTLS's printed precision (1 N m)."""
    folder, records, t, logged, _ = replayed
    btls = pybtls_history(folder, DT)
    step = np.rint(btls[:, 0] / DT).astype(np.int64)
    common = step % EVERY == 0  # the instants cosim logged
    at = np.searchsorted(t, btls[common, 0] - 1e-6)
    assert np.abs(t[at] - btls[common, 0]).max() < 1e-6 and common.sum() > 10_000
    _, _, element = reference(records, t[at])
    cosim = logged["moment"][at] / 1e3  # kN m, as BTLS writes it
    assert np.abs(cosim - element / 1e3 - btls[common, 2]).max() <= 1e-3 + 1e-9 * np.abs(cosim).max()
    # and without the element term, the difference is that term alone
    assert np.abs(cosim - btls[common, 2]).max() == pytest.approx(np.abs(element).max() / 1e3, abs=2e-3)


def test_pybtls_block_maxima_at_its_default_step(replayed) -> None:
    """At BTLS's default 0.1 s the two step grids differ (BTLS's starts at each event's first arrival, cosim's at
    t = 0): each block's maximum is the same continuous moment sampled on either grid, so they differ by at most
    the largest change of the moment in 0.1 s within the block, plus the element term."""
    folder, records, t, logged, _ = replayed
    btls = pybtls_history(folder, 0.1)
    coarse = simulate_scenario(scenario(folder / "scenario.toml", solver={"method": "quasi-static", "dt": 0.1}))
    block = 600.0  # s: ten-minute maxima
    fine = reference(records, np.arange(0.0, t[-1] + 0.1, 0.01))
    exact = fine[0]
    change = np.abs(exact[10:] - exact[:-10])  # the moment's change over 0.1 s
    measured, bounds = [], []
    for lo in np.arange(0.0, coarse.t[-1], block):
        mine = coarse.sensors["moment"][(coarse.t >= lo) & (coarse.t < lo + block)]
        theirs = btls[(btls[:, 0] >= lo) & (btls[:, 0] < lo + block), 2] * 1e3
        if not len(theirs):
            continue
        k = slice(int(lo / 0.01), int((lo + block) / 0.01))
        bound = change[k].max() + fine[2][k].max() + 1.0
        measured.append(abs(mine.max() - theirs.max()))
        bounds.append(bound)
        assert measured[-1] <= bound, (lo, mine.max(), theirs.max(), bound)
    assert len(measured) >= 5
