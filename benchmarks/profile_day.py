"""Where a logged run's time goes: CPU per part of each process, and the floor a free log would give (on demand).

    python benchmarks/profile_day.py [--hours 1] [--out benchmarks/results/profile.md]

The default run's config (`cosim run` with no arguments: the paper bridge under
medium SUMO traffic, class A road, dt = 5 ms, log at 100 Hz) for `--hours`
simulated hours, each configuration in its own process (libsumo is a
per-process singleton), one after the other so that the ratios share the
machine's hour:

- SUMO alone (`SumoTraffic.advance` at every SUMO step, as bench_day.py);
- direct + log and modal-30 + log, with the 3D scene (as runs up to an hour
  have it: SUMO in the run's process) and without it (`/no-scene`, as runs over
  an hour: SUMO in a process of its own);
- the same four with a log writer that receives everything and writes nothing
  (`+null`): the floor of the design, what the run would cost with a free log.

Each part is timed with the CPU time of its own thread (`time.thread_time`)
around the functions named in the table, wrapped before the run starts, so
that the forked children (the log writer, SUMO's process) inherit the wrappers
and report their own parts when they end (the report counts the wrapped
calls: each costs about 2 µs here). The log's encodings themselves are
compared in bench_encoding.py.

This instruments private functions of cosim on purpose (it is a profile); a
renamed function fails the script with its name.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

from _report import write_report  # benchmarks/ is on sys.path when a script runs

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

HERE = Path(__file__).resolve().parent
RUNS = ("sumo", "direct+log", "direct+log+null", "modal+log", "modal+log+null", "direct+log/no-scene",
        "direct+log/no-scene+null", "modal+log/no-scene", "modal+log/no-scene+null")
DEFAULT_OUT = HERE / "results" / "profile.md"

# The parts, by process: (key, what the report calls it). zstd is inside the writer's parts above it.
PARTS = {
    "run": [
        ("sumo.step", "SUMO's steps (`libsumo.simulationStep`)"),
        ("sumo.adapter", "the adapter: SUMO read into frames (`SumoTraffic.advance` less steps)"),
        ("frames", "frame interpolation to the solver's steps (`FrameTraffic.block`, `SumoProcess.block`)"),
        ("handover", "hand-over of blocks to the log writer (`_BlockStream.on_block`: pickling, the pipe)"),
        ("framesink", "hand-over of SUMO frames to the log writer (`_FrameSink`)"),
        ("recv", "receiving SUMO's frames from its process (`Connection.recv`)"),
        ("extremes", "running extremes (`_Extremes.on_block`)"),
        ("main.rest", "the rest of the run's process (start-up, block loop, observers, progress)"),
        ("solver", "solver thread: `CoupledSystem.advance` (compiled step and its Python)"),
    ],
    "cosim-sumo": [
        ("sumo.step", "SUMO's steps (`libsumo.simulationStep`)"),
        ("sumo.adapter", "the adapter (`SumoTraffic.advance` less the steps)"),
        ("sumo.rest", "SUMO's start, packing frames, the pipe"),
    ],
    "cosim-log-writer": [
        ("recv", "receiving and unpickling blocks and frames"),
        ("scene", "the 3D scene (`SceneWriter.write_block`), its chunk writes included"),
        ("vehicles", "the vehicles on the deck (`BlockLogger._vehicles`), their chunk writes included"),
        ("events", "events on the deck (`BlockLogger._events`)"),
        ("piece", "sensors and status (`BlockLogger._write_piece` less the scene, vehicles and events)"),
        ("traffic", "SUMO frames (`TrafficLogger.write_frames`)"),
        ("zstd", "of all the above: zstd of the chunks (`zstandard.compress`)"),
        ("writer.rest", "the rest (closing, summary, file writes)"),
    ],
}

WORKER = r"""
import collections, json, sys, tempfile, threading, time
from pathlib import Path

mode, hours, report_dir = sys.argv[1], float(sys.argv[2]), Path(sys.argv[3])
null = mode.endswith("+null")
mode = mode.removesuffix("+null")
duration = 3600.0 * hours
cpu = collections.Counter()
calls = collections.Counter()

active = threading.local()  # the keys being timed in this thread: a part called inside itself counts once

def wrap(owner, name, key):
    original = getattr(owner, name)
    def timed(*args, **kwargs):
        keys = active.__dict__.setdefault("keys", set())
        if key in keys:
            return original(*args, **kwargs)
        keys.add(key)
        c0 = time.thread_time()
        try:
            return original(*args, **kwargs)
        finally:
            cpu[key] += time.thread_time() - c0
            calls[key] += 1
            keys.discard(key)
    setattr(owner, name, timed)

import libsumo, zstandard
import cosim.core.coupling, cosim.core.simulation, cosim.core.traffic, cosim.log.process, cosim.log.scene
import cosim.log.writer, cosim.run.sumo_process, cosim.sumo.adapter
from multiprocessing.connection import Connection
for owner, name, key in (
        (libsumo, "simulationStep", "sumo.step"),
        (cosim.sumo.adapter.SumoTraffic, "advance", "sumo.advance"),
        (cosim.core.traffic.FrameTraffic, "block", "frames"),
        (cosim.run.sumo_process.SumoProcess, "block", "frames"),
        (cosim.log.process._BlockStream, "on_block", "handover"),
        (cosim.log.process._FrameSink, "__call__", "framesink"),
        (cosim.core.simulation._Extremes, "on_block", "extremes"),
        (cosim.core.coupling.CoupledSystem, "advance", "solver"),
        (cosim.log.scene.SceneWriter, "write_block", "scene"),
        (cosim.log.writer.BlockLogger, "_write_piece", "piece.all"),
        (cosim.log.writer.BlockLogger, "_vehicles", "vehicles"),
        (cosim.log.writer.BlockLogger, "_events", "events"),
        (cosim.log.writer.TrafficLogger, "write_frames", "traffic"),
        (zstandard, "compress", "zstd"),
        (Connection, "recv", "recv")):
    wrap(owner, name, key)

def child_report(name, serve):
    def served(*args):
        cpu.clear()  # the counters came with the fork
        calls.clear()
        c0 = time.process_time()
        try:
            if null and name == "cosim-log-writer":
                return null_serve(*args)
            return serve(*args)
        finally:
            cpu["total"] = time.process_time() - c0
            cpu["calls"] = sum(calls.values())
            (report_dir / f"{name}.json").write_text(json.dumps(cpu))
    return served

def null_serve(commands, replies, path, names, scene):
    # Receives and unpickles everything, as the writer does, and writes nothing.
    path.write_bytes(b"")
    replies.send(("ready", None))
    while True:
        message = commands.recv()
        if message[0] == "close":
            replies.send(("closed", None))
            return

cosim.log.process._serve = child_report("cosim-log-writer", cosim.log.process._serve)
cosim.run.sumo_process._serve = child_report("cosim-sumo", cosim.run.sumo_process._serve)

sys.path.insert(0, sys.argv[4])
from _day import default_run
scenario, bridge = default_run(mode, hours)  # kernels compiled, 20 s of the traffic run untimed
from cosim.run.simulate import build_traffic
for path in report_dir.glob("*.json"):
    path.unlink()
cpu.clear()
calls.clear()
out = {"mode": sys.argv[1]}
started, process0 = time.perf_counter(), time.process_time()
if mode == "sumo":
    with build_traffic(scenario, process=False) as traffic:
        for _ in range(int(round(duration / scenario.traffic.step))):
            traffic.advance()
else:
    from cosim.run.logged import run_logged
    path = Path(tempfile.mkdtemp()) / "run.mcap"
    outcome = run_logged(scenario, path, bridge=bridge)
    out["log_bytes"] = outcome.log_bytes
out["wall"] = time.perf_counter() - started
out["process"] = time.process_time() - process0
out["run"] = dict(cpu, calls=sum(calls.values()))
out["children"] = {p.stem: json.loads(p.read_text()) for p in report_dir.glob("*.json")}
print(json.dumps(out))
"""


def run_one(mode: str, hours: float, report_dir: Path) -> dict:
    out = subprocess.run([sys.executable, "-c", WORKER, mode, str(hours), str(report_dir), str(HERE)],
                         capture_output=True, text=True, check=False, env=dict(os.environ))
    if out.returncode != 0:
        tail = out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"exit {out.returncode}"
        return {"mode": mode, "error": tail}
    return json.loads(out.stdout.strip().splitlines()[-1])


def parts_of(result: dict) -> dict[str, dict[str, float]]:
    """CPU seconds per part and process, the derived parts (the rests, the adapter) worked out."""
    run = dict(result["run"])
    out: dict[str, dict[str, float]] = {}
    if "sumo.advance" in run:
        run["sumo.adapter"] = run.pop("sumo.advance") - run.get("sumo.step", 0.0)
    # Receiving SUMO's frames happens inside the frame interpolation (SumoProcess.block), so it is not added.
    counted = sum(run.get(k, 0.0) for k in ("sumo.step", "sumo.adapter", "frames", "handover", "framesink",
                                             "extremes", "solver"))
    run["main.rest"] = result["process"] - counted
    run["total"] = result["process"]
    out["run"] = run
    for name, child in result.get("children", {}).items():
        child = dict(child)
        if name == "cosim-sumo":
            child["sumo.adapter"] = child.pop("sumo.advance", 0.0) - child.get("sumo.step", 0.0)
            child["sumo.rest"] = child["total"] - child.get("sumo.step", 0.0) - child["sumo.adapter"]
        else:
            child["piece"] = child.pop("piece.all", 0.0) - sum(child.get(k, 0.0) for k in ("scene", "vehicles",
                                                                                            "events"))
            child["writer.rest"] = child["total"] - sum(child.get(k, 0.0) for k in ("recv", "scene", "vehicles",
                                                                                     "events", "piece", "traffic"))
        out[name] = child
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hours", type=float, default=1.0, help="simulated hours per run (default 1)")
    ap.add_argument("--only", nargs="*", choices=RUNS, help="only these runs (SUMO alone is always run)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    runs = ["sumo", *[r for r in RUNS if r != "sumo" and (not args.only or r in args.only)]]
    started = datetime.datetime.now()
    results = []
    with tempfile.TemporaryDirectory(prefix="cosim-profile-") as report_dir:  # the children's parts
        for mode in runs:
            r = run_one(mode, args.hours, Path(report_dir))
            print(json.dumps(r), flush=True)
            results.append(r)
    sumo = next((r["wall"] for r in results if r["mode"] == "sumo" and "wall" in r), None)
    lines = [
        f"# Where a logged run's time goes: {args.hours:g} simulated hour(s) of the default run",
        "",
        f"{started:%Y-%m-%d %H:%M}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}; load average before: {os.getloadavg()[0]:.2f}. "
        "Each run in its own process, one after the other; CPU seconds per part from the thread CPU time "
        "around the functions named (benchmarks/profile_day.py).",
        "",
        "## Wall time against SUMO alone, and the floor with a free log",
        "",
        "`+null`: the log writer process receives and unpickles everything and writes nothing.",
        "",
        "| run | wall [s] | / SUMO alone | CPU, all processes [s] |",
        "|---|---|---|---|",
    ]
    for r in results:
        if "error" in r:
            lines.append(f"| {r['mode']} | failed: {r['error']} | | |")
            continue
        children = sum(c.get("total", 0.0) for c in r.get("children", {}).values())
        ratio = f"{r['wall'] / sumo:.2f}" if sumo else "-"
        lines.append(f"| {r['mode']} | {r['wall']:.1f} | {ratio} | {r['process'] + children:.1f} |")
    lines += ["", "## CPU seconds per part (runs with the real log)", ""]
    shown = [r for r in results if "error" not in r and not r["mode"].endswith("+null")]
    parts = {r["mode"]: parts_of(r) for r in shown if r["mode"] != "sumo"}
    sumo_parts = next((r["run"] for r in shown if r["mode"] == "sumo"), {})
    if sumo_parts:
        lines.append(f"SUMO alone: {sumo_parts.get('sumo.step', 0.0):.1f} s in SUMO's steps, "
                     f"{sumo_parts.get('sumo.advance', 0.0) - sumo_parts.get('sumo.step', 0.0):.1f} s in the "
                     "adapter, for the same traffic.")
        lines.append("")
    modes = list(parts)
    lines += ["| process | part | " + " | ".join(modes) + " |", "|---|---|" + "---|" * len(modes)]
    for process, rows in PARTS.items():
        if not any(process in parts[m] for m in modes):
            continue
        for key, label in rows:
            cells = [f"{parts[m][process][key]:.2f}" if process in parts[m] and key in parts[m][process] else ""
                     for m in modes]
            if any(cells):
                lines.append(f"| {process} | {label} | " + " | ".join(cells) + " |")
        totals = [f"**{parts[m][process]['total']:.2f}**" if process in parts[m] else "" for m in modes]
        lines.append(f"| {process} | **all of its CPU** | " + " | ".join(totals) + " |")
        counts = [f"{parts[m][process].get('calls', 0):,.0f}" if process in parts[m] else "" for m in modes]
        lines.append(f"| {process} | wrapped calls (the profile's own cost: about 2 us each) | " + " | ".join(counts)
                     + " |")
    lines += ["", "The log's encodings compared on an hour of messages: benchmarks/results/encoding.md "
              "(bench_encoding.py)."]
    text = "\n".join(lines).rstrip() + "\n"
    print(text)
    write_report(text, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
