"""Run every bridge ``cosim bridge`` finds in a SUMO scenario, and check that every wheel stays on its lane.

    python examples/networks/every_bridge.py CONFIG.sumocfg [--out DIR] [--end SECONDS] [--limit N]

For each candidate (two-way pairs and one-way edges, as ``cosim bridge`` lists them) it writes a scenario whose
deck covers the candidate's carriageway (0.5 m to spare each side), runs it through the Python API for the
config's whole time (or ``--end``), and reads the log back: the run's status, how many wheels were on the deck,
the "offdeck" events, and every axle on the deck at every SUMO step within one of the deck's lanes (its
lateral position inside the lane's width). A table goes to the terminal and ``DIR/every_bridge.md``.

Issue 23 ran it on the Ingolstadt scenario that ships with SUMO (``tools/game/fkk_in.sumocfg`` of the
``eclipse-sumo`` package): see docs/own-network.md for the result.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from cosim.log import read_log
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_TRAFFIC
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario
from cosim.sumo.network import bridge_candidates, lane_shapes, locate_bridge, net_path, read_network

SCENARIO = """\
name = "{name}"
[bridge]
spans = [{length:.3f}]
elements_per_span = 16
supports = ["pinned", "fork"]
[bridge.material]
E = 35e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 8.0
I_y = 4.0
I_z = 100.0
J = 6.0
z_c = -0.8
deck_y = [{lo:.3f}, {hi:.3f}]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = {mid:.3f}
[traffic]
sumo_config = {config}
edges = {edges}
{end}
[solver]
dt = 0.01
basis = "modal"
"""


def check(log_path: Path, location, length: float) -> dict:
    """The run's status, its wheels on the deck, its offdeck events, and how far any axle on the deck was from
    the nearest lane of the network (deck lanes and the junction lanes at its ends): 0 when every axle on the
    deck was within a lane's width at every SUMO step."""
    net = read_network(location.net)
    middle = 0.5 * (np.asarray(location.axis.start) + np.asarray(location.axis.end))
    lanes = []
    for lane_id, pts in lane_shapes(location.net, (float(middle[0]), float(middle[1])), 0.5 * length + 30.0):
        lane = net.getLane(lane_id)
        if not set(lane.getPermissions()) - {"pedestrian"}:
            continue
        dense = np.concatenate([np.linspace(a, b, max(int(np.hypot(*(b - a)) / 0.1), 1) + 1)
                                for a, b in zip(pts[:-1], pts[1:])])
        x, y = location.axis.project(dense[:, 0], dense[:, 1])
        lanes.append((np.column_stack([x, y]), 0.5 * float(lane.getWidth())))
    log = read_log(log_path)
    worst, on_deck, wheels = 0.0, 0, set()
    for frame in log.topic(TOPIC_TRAFFIC):
        for cid, x, y in zip(frame["ids"], frame["x"], frame["y"]):
            if 0.0 <= x <= length:
                on_deck += 1
                wheels.add(cid)
                off = min(float(np.min(np.hypot(p[:, 0] - x, p[:, 1] - y))) - half for p, half in lanes)
                worst = max(worst, off)
    events = [m["event"] for m in log.topic(TOPIC_EVENTS)]
    return {"status": log.final_status["state"], "message": log.final_status.get("message", ""),
            "wheels": len(wheels), "axle_steps": on_deck, "off_lane_m": round(max(worst, 0.0), 3),
            "offdeck": events.count("offdeck")}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--out", type=Path, default=Path("every_bridge"))
    parser.add_argument("--end", type=float, default=None, help="SUMO end time, s (default: the config's)")
    parser.add_argument("--limit", type=int, default=None, help="at most this many candidates")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    config = args.config.resolve()
    rows = []
    candidates = bridge_candidates(net_path(config))[: args.limit]
    for k, cand in enumerate(candidates):
        location = locate_bridge(net_path(config), cand.edges)
        lo, hi = location.carriageway
        length = location.axis.length
        path = args.out / f"bridge{k:02d}.toml"
        path.write_text(SCENARIO.format(
            name=f"bridge{k:02d}", length=length, lo=lo - 0.5, hi=hi + 0.5, mid=length / 2,
            config=json.dumps(str(config)), edges=json.dumps(list(cand.edges)),
            end="" if args.end is None else f"end = {args.end}"))
        started = time.perf_counter()
        log = args.out / f"bridge{k:02d}.mcap"
        log.unlink(missing_ok=True)
        try:
            run_logged(load_scenario(path), log)
        except Exception as exc:  # noqa: BLE001 - a failed run is a row of the table, not the end of the sweep
            row = {"status": f"failed: {exc}"}
        else:
            row = check(log, location, length)
        row.update(edges=" ".join(cand.edges), length=round(length, 1), wall=round(time.perf_counter() - started, 1))
        rows.append(row)
        print(json.dumps(row), flush=True)
    lines = ["| edges | length [m] | status | wheels on the deck | axle-steps on it | farthest off a lane [m] "
             "| offdeck events | wall [s] |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['edges']} | {r['length']} | {r['status']} | {r.get('wheels', '')} | "
                     f"{r.get('axle_steps', '')} | {r.get('off_lane_m', '')} | {r.get('offdeck', '')} | {r['wall']} |")
    (args.out / "every_bridge.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0 if all(r["status"] == "finished" and r.get("off_lane_m", 1) <= 0.01 for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
