"""Co-simulation cost against SUMO alone, at light, medium and heavy demand (run on demand).

    python benchmarks/bench_sumo.py [--minutes 10] [--out benchmarks/results/sumo.md]

For each bundled demand level, side by side in one run: SUMO alone (the same
config, step and subscriptions, no bridge), the co-simulation on the paper
bridge with the direct and the modal basis (dt = 5 ms), each without and with
the MCAP log at 100 Hz. Reports wall time, real-time factor (simulated time /
wall time) and the ratio to SUMO alone. Each configuration runs in its own
process (libsumo is a per-process singleton).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

from _report import write_report  # benchmarks/ is on sys.path when a script runs

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

LEVELS = ("light", "medium", "heavy")
MODES = ("sumo", "direct", "direct+log", "modal", "modal+log")

WORKER = r"""
import json, sys, tempfile, time
from pathlib import Path
from cosim.run.scenario import load_scenario
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.sumo.adapter import BridgeAxis, SumoTraffic, bundled_networks
from cosim.log.writer import BlockLogger, LogRecorder

level, mode, minutes = sys.argv[1], sys.argv[2], float(sys.argv[3])
duration = 60.0 * minutes
bridge = load_scenario("paper-double-tee").build_bridge()
axis = BridgeAxis((0.0, 0.0), (40.0, 0.0))
cfg = bundled_networks() / f"{level}.sumocfg"
sensors = [Sensor("n1", 20, 0.0), Sensor("n2", 20, 6.655), Sensor("n3", 20, 3.325),
           Sensor("a3", 20, 3.325, "acceleration")]
basis = mode.split("+")[0]
# Compile (or load) the kernels outside the timed part.
from cosim.core.traffic import ScriptedTraffic
warm = SolverSettings(dt=0.005, basis=basis if basis != "sumo" else "direct", modes=30)
simulate(bridge, ScriptedTraffic((), 40.0), 0.01, warm, sensors)
started = time.perf_counter()
vehicles = max_on = 0
if mode == "sumo":
    with SumoTraffic(cfg, axis, step=0.05, end=duration + 1, half_width=6.655) as tr:
        seen = set()
        for _ in range(int(round(duration / 0.05))):
            f = tr.advance()
            seen.update(f.ids)
        vehicles = len(seen)
else:
    solver = SolverSettings(dt=0.005, basis=basis, modes=30)
    if mode.endswith("+log"):
        path = Path(tempfile.mkdtemp()) / "run.mcap"
        names = [s.name for s in sensors]
        with LogRecorder(path, names) as rec, BlockLogger(rec, names, duration) as lg:
            with SumoTraffic(cfg, axis, step=0.05, end=duration + 1, half_width=6.655,
                             frame_sink=lg.traffic_sink()) as tr:
                res = simulate(bridge, tr, duration, solver, sensors, output_every=2, observers=[lg], collect=False)
    else:
        with SumoTraffic(cfg, axis, step=0.05, end=duration + 1, half_width=6.655) as tr:
            res = simulate(bridge, tr, duration, solver, sensors, output_every=2, collect=False)
    vehicles, max_on = len(res.vehicle_ids), res.max_on_deck
wall = time.perf_counter() - started
print(json.dumps({"wall": wall, "vehicles": vehicles, "max_on_deck": max_on}))
"""


def run_one(level: str, mode: str, minutes: float) -> dict:
    out = subprocess.run([sys.executable, "-c", WORKER, level, mode, str(minutes)], capture_output=True, text=True,
                         check=False)
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"exit {out.returncode}"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=10.0, help="simulated minutes per run (default 10)")
    ap.add_argument("--reps", type=int, default=2, help="repetitions, best taken (default 2)")
    ap.add_argument("--out", default="benchmarks/results/sumo.md")
    args = ap.parse_args()
    sim = 60.0 * args.minutes
    rows = []
    for level in LEVELS:
        best: dict[str, dict] = {}
        for _ in range(args.reps):
            for mode in MODES:
                r = run_one(level, mode, args.minutes)
                if "error" in r:
                    best[mode] = r
                elif mode not in best or r["wall"] < best[mode]["wall"]:
                    best[mode] = r
        sumo = best["sumo"].get("wall")
        for mode in MODES:
            r = best[mode]
            if "error" in r:
                rows.append(f"| {level} | {mode} | failed: {r['error']} | | | | |")
                continue
            ratio = f"{r['wall'] / sumo:.2f}" if sumo else "-"
            rows.append(f"| {level} | {mode} | {r['wall']:.2f} | {sim / r['wall']:.0f} | {ratio} | "
                        f"{r['vehicles']} | {r.get('max_on_deck', '') or ''} |")
            print(rows[-1], flush=True)
    table = "\n".join([
        f"# Co-simulation vs SUMO alone ({args.minutes:g} simulated minutes, paper bridge, dt = 5 ms, "
        "SUMO step 0.05 s, log at 100 Hz)", "",
        "| demand | run | wall [s] | real-time factor | / SUMO alone | vehicles | max on deck |",
        "|---|---|---|---|---|---|---|", *rows, "",
        "Best of the repetitions; each run in its own process; modal = 30 modes; the log holds sensors, "
        "vehicles, events and every SUMO frame.", ""])
    write_report(table, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
