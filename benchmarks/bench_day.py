"""A day of traffic: co-simulation against SUMO alone, real-time factors, step costs, memory (run on demand).

    python benchmarks/bench_day.py [--hours 1] [--reps 1] [--out benchmarks/results/day.md]
    python benchmarks/bench_day.py --hours 1 --reps 2 --day-hours 24  # issue 27's goals, in one run

Side by side in one run, on the default run's config (`cosim run` with no
arguments: the paper bridge under medium SUMO traffic, class A road, dt = 5 ms,
log at 100 Hz), for the chosen number of simulated hours:

- a plain libsumo loop: the same SUMO config, step, end and seed, `simulationStep`
  until the end and nothing read (issue 27's yardstick);
- SUMO alone: the same config and step through cosim's adapter (`SumoTraffic.advance`
  for every SUMO step: the vehicles near the deck read and turned into contact points, no bridge);
- the co-simulation with the direct (full FE) and the modal (30 modes) basis,
  with and without the MCAP log, through the same code as `cosim run`
  (`run_logged` with the log; `simulate` in constant memory without, with SUMO
  stepped in a child process as `build_traffic` gives it: `cosim.run.sumo_process`);
- direct + log with the log encoded in a thread of the run's process
  (`direct+log/thread`) instead of the log writer process (`cosim.log.process`);
- direct + log and modal + log without the 3D scene (`/no-scene`), as a run longer than an hour has them by
  default: SUMO then steps in a child process beside the log writer's (`cosim.run.logged`);
- the real-time factor of direct + log at dt = 5 ms and 1 ms;
- wall time, the ratio to SUMO alone, peak memory (max RSS of the run and of its largest child process: the
  log writer or SUMO's) and log size.

Each configuration runs in its own process (libsumo is a per-process
singleton), timed from its first step (kernels compiled and 20 s of traffic
run before); ratios come from the same run, so machine speed cancels. Then
whole processes, as a user runs them (`--skip-whole` leaves them out):
`cosim run` of the default scenario for the same hours, its log written,
against a plain libsumo loop over the same config, in turn, ratio pair by
pair; and start-up: Python's own start, `cosim --help`, `cosim info` of the
hour's log, and `cosim run` for one SUMO step (start-up to the first step,
then closing its log); and the log writer's CPU per simulated hour per
topic (direct + log with its scene, timed as benchmarks/profile_day.py
times it). Then, in this process: microseconds per step with 0/1/8/16/64 quarter-cars on the
deck for both bases (benchmarks/bench_step.py's set-up), and OpenSeesPy per
step with 8 moving forces when it is installed (`pip install '.[bench]'`).
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _report import write_report  # benchmarks/ is on sys.path when a script runs

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

HERE = Path(__file__).resolve().parent
RUNS = ("libsumo", "sumo", "direct", "direct+log", "direct+log/thread", "direct+log/no-scene", "modal", "modal+log",
        "modal+log/no-scene", "direct+log@1ms")
DEFAULT_OUT = HERE / "results" / "day.md"

WORKER = r"""
import json, resource, sys, tempfile, time
from pathlib import Path

mode, hours = sys.argv[1], float(sys.argv[2])
sys.path.insert(0, sys.argv[3])
from _day import default_run
duration = 3600.0 * hours
scenario, bridge = default_run(mode, hours)  # kernels compiled, 20 s of the traffic run untimed
from cosim.core.simulation import simulate
out = {"log_bytes": 0}
started = time.perf_counter()
if mode == "libsumo":  # the baseline of issue 27: SUMO's own loop over the same config, nothing read from it
    from _day import plain_libsumo
    from cosim.run.simulate import plan_sumo
    s = plan_sumo(scenario).settings
    plain_libsumo(str(s.config), s.step, duration, s.seed)
elif mode == "sumo":
    from cosim.run.simulate import build_traffic
    with build_traffic(scenario, process=False) as traffic:  # SUMO and the adapter, in this process
        for _ in range(int(round(duration / scenario.traffic.step))):
            traffic.advance()
elif "+log" in mode:
    from cosim.run.logged import run_logged
    path = Path(tempfile.mkdtemp()) / "run.mcap"
    outcome = run_logged(scenario, path, bridge=bridge, writer="thread" if mode.endswith("/thread") else "auto")
    out["log_bytes"] = outcome.log_bytes
    out["vehicles"] = len({v.split("#")[0] for v in outcome.on_deck})
else:
    from cosim.run.simulate import build_traffic
    with build_traffic(scenario) as traffic:
        res = simulate(bridge, traffic, duration, scenario.solver_settings(), scenario.sensors_core(),
                       road=scenario.build_road(), output_every=scenario.output_every, collect=False)
    out["vehicles"] = len({v.split("#")[0] for v in res.vehicle_ids})
out["wall"] = time.perf_counter() - started
out["max_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
out["writer_rss_mb"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0  # the log writer or SUMO
print(json.dumps(out))
"""


def run_one(mode: str, hours: float) -> dict:
    env = dict(os.environ)
    out = subprocess.run([sys.executable, "-c", WORKER, mode, str(hours), str(HERE)], capture_output=True,
                         text=True, check=False, env=env)
    if out.returncode != 0:
        tail = out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"exit {out.returncode}"
        return {"error": tail}
    return json.loads(out.stdout.strip().splitlines()[-1])


def step_costs(reps: int) -> list[tuple[str, int, float]]:
    """Microseconds of process time per step, paper bridge, quarter-cars on the deck (bench_step's set-up)."""
    sys.path.insert(0, str(HERE))
    import bench_step as bs

    from cosim.core.vehicles import QuarterCar

    paper = bs.paper_bridge()
    qc = QuarterCar(1000.0, 100.0, 39478.4, 5026.55)
    steps = 2000
    rows = []
    for basis, modes in (("direct", None), ("modal", 30)):
        make, _ = bs.cosim_factory(paper, basis, modes)
        for q in (0, 1, 8, 16, 64):
            block = bs.fleet(q, qc, steps, paper.length)
            make().advance(block)  # compile / warm up
            best = float("inf")
            for _ in range(reps):
                system = make()
                t0 = time.process_time()
                system.advance(block)
                best = min(best, time.process_time() - t0)
            rows.append((basis if modes is None else f"{basis}-{modes}", q, 1e6 * best / steps))
    return rows


def opensees_cost() -> float | None:
    """OpenSeesPy microseconds per step with 8 moving forces (bench_step's model), or None without it."""
    sys.path.insert(0, str(HERE))
    import bench_step as bs

    ops, _why = bs.import_opensees()
    if ops is None:
        return None
    from cosim.core.vehicles import MovingForce

    paper = bs.paper_bridge()
    block = bs.fleet(8, MovingForce(1100.0), 500, paper.length)
    mid = bs.opensees_build(ops, paper)
    t0 = time.perf_counter()
    bs.opensees_run(ops, paper, block, mid)
    return 1e6 * (time.perf_counter() - t0) / 500


PLAIN_LIBSUMO = r"""
import sys
sys.path.insert(0, sys.argv[1])
from _day import plain_libsumo
plain_libsumo(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]) if sys.argv[5] != "None" else None)
"""


def _timed(cmd: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds (user + system, the process and everything it waited for) of one whole process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        tail = out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"exit {out.returncode}"
        raise RuntimeError(f"{' '.join(cmd[:4])}...: {tail}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def whole_processes(hours: float, reps: int, day_hours: float = 0.0) -> list[str]:
    """`cosim run` of the default scenario for ``hours`` as a user runs it (a whole process, its start-up and
    its log included) against a plain libsumo loop over the same SUMO config, step, end and seed, in turn
    (A B A B ...: the ratio is taken pair by pair); then start-up: Python's own, `cosim --help`, `cosim info` of
    the hour's log, and `cosim run` of the same scenario for one SUMO step (start-up to the first step, plus
    closing the log); with ``day_hours``, one `cosim run` of that many hours too (issue 27's day: no 3D scene
    past an hour, SUMO in its own process)."""
    import tomllib

    from cosim.run.scenario import load_scenario
    from cosim.run.simulate import plan_sumo
    from cosim.run.toml_writer import toml_dumps

    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # as an installed package runs: its modules compiled once
    folder = Path(tempfile.mkdtemp(prefix="bench-day-"))
    base = load_scenario("paper-bridge-traffic")
    data = tomllib.loads(base.text)
    data["traffic"]["end"] = 3600.0 * hours
    (folder / "day.toml").write_text(toml_dumps(data), encoding="utf-8")
    data["traffic"]["end"] = data["traffic"]["step"]
    (folder / "first-step.toml").write_text(toml_dumps(data), encoding="utf-8")
    data["traffic"]["end"] = 3600.0 * day_hours
    (folder / "day-long.toml").write_text(toml_dumps(data), encoding="utf-8")
    settings = plan_sumo(base).settings
    plain = [sys.executable, "-c", PLAIN_LIBSUMO, str(HERE), str(settings.config), repr(settings.step),
             repr(3600.0 * hours), str(settings.seed)]
    cosim = [sys.executable, "-m", "cosim", "run", str(folder / "day.toml"), "--out", str(folder / "run.mcap"),
             "--force", "--quiet"]
    first = [sys.executable, "-m", "cosim", "run", str(folder / "first-step.toml"), "--out",
             str(folder / "first.mcap"), "--force", "--quiet"]
    python = [sys.executable, "-c", "pass"]
    helps = [sys.executable, "-m", "cosim", "--help"]
    info = [sys.executable, "-m", "cosim", "info", str(folder / "run.mcap")]
    _timed(first, env)  # compiled kernels in numba's cache, modules compiled, the section in its cache
    runs: dict[str, list[tuple[float, float]]] = {"cosim": [], "plain": []}
    for _ in range(reps):
        runs["cosim"].append(_timed(cosim, env))
        runs["plain"].append(_timed(plain, env))
    log_mb = (folder / "run.mcap").stat().st_size / 1e6
    starts: dict[str, list[float]] = {"python": [], "help": [], "info": [], "first": []}
    for _ in range(5):
        starts["python"].append(_timed(python, env)[0])
        starts["help"].append(_timed(helps, env)[0])
        starts["info"].append(_timed(info, env)[0])
        starts["first"].append(_timed(first, env)[0])
    day = None
    if day_hours > 0:
        day = _timed([sys.executable, "-m", "cosim", "run", str(folder / "day-long.toml"), "--out",
                      str(folder / "day.mcap"), "--force", "--quiet"], env)
        day_mb = (folder / "day.mcap").stat().st_size / 1e6
    shutil.rmtree(folder, ignore_errors=True)
    ratios = [c[0] / p[0] for c, p in zip(runs["cosim"], runs["plain"])]
    med = statistics.median
    py = med(starts["python"])
    lines = [
        f"## Whole processes: `cosim run` against a plain libsumo loop ({hours:g} simulated hour(s))", "",
        "`cosim run` of the default scenario with `[traffic] end` set to the hours, its log written (as a user "
        "runs it: start-up, section from its cache, SUMO, the solver, the log writer, the summary), against a "
        "Python process that starts libsumo on the same SUMO config, step, end and seed and calls "
        f"`simulationStep` until the end, nothing read. In turn, {reps} pair(s); the ratio pair by pair; "
        "median (range).", "",
        "| process | wall [s] | CPU [s] (all its processes) |", "|---|---|---|",
        f"| `cosim run` | {med(w for w, _ in runs['cosim']):.1f} | {med(c for _, c in runs['cosim']):.1f} |",
        f"| plain libsumo loop | {med(w for w, _ in runs['plain']):.1f} | {med(c for _, c in runs['plain']):.1f} |",
        "",
        f"**`cosim run` / plain libsumo: {med(ratios):.2f}** ({min(ratios):.2f}-{max(ratios):.2f}); "
        f"the log: {log_mb:.1f} MB.", "",
        "## Start-up (whole processes, median of 5)", "",
        "| process | wall [s] | above Python's own start [s] |", "|---|---|---|",
        f"| `python -c pass` | {py:.2f} | |",
        f"| `cosim --help` | {med(starts['help']):.2f} | {med(starts['help']) - py:.2f} |",
        f"| `cosim info` of the hour's log | {med(starts['info']):.2f} | {med(starts['info']) - py:.2f} |",
        f"| `cosim run` for one SUMO step (start-up to the first step, then closing the log) | "
        f"{med(starts['first']):.2f} | {med(starts['first']) - py:.2f} |",
    ]
    if day is not None:
        lines += ["", f"## {day_hours:g} simulated hours in one `cosim run` (a whole process, once)", "",
                  f"Wall {day[0]:.0f} s ({day[0] / 60:.1f} min), CPU {day[1]:.0f} s (all its processes); "
                  f"real-time factor {3600.0 * day_hours / day[0]:.0f}; the log {day_mb:.0f} MB. Past an hour "
                  "the 3D scene is off by default, and SUMO steps in a process of its own."]
    return lines


def writer_topics(hours: float) -> list[str]:
    """The log writer's CPU per simulated hour per topic in the default run (direct + log, its 3D scene), each
    part timed with the writer thread's CPU time around the function that writes it (profile_day.py's worker)."""
    import profile_day

    with tempfile.TemporaryDirectory() as folder:
        result = profile_day.run_one("direct+log", hours, Path(folder))
    if "error" in result:
        return ["## The log writer's CPU per topic", "", f"failed: {result['error']}"]
    writer = profile_day.parts_of(result).get("cosim-log-writer", {})
    topics = [("scene", "`/cosim/scene` (3D scene)"), ("vehicles", "`/cosim/vehicles`"),
              ("piece", "`/cosim/sensors` and `/cosim/status`"), ("traffic", "`/cosim/traffic` (SUMO's frames)"),
              ("events", "`/cosim/events`"), ("recv", "receiving blocks and frames from the run"),
              ("writer.rest", "the rest (closing, summary, attachments)")]
    lines = ["## The log writer's CPU per topic (direct + log, with the 3D scene; profile_day.py's parts)", "",
             "| topic | CPU s per simulated hour |", "|---|---|"]
    lines += [f"| {label} | {writer.get(key, 0.0) / hours:.2f} |" for key, label in topics]
    lines += [f"| of these, zstd of the chunks | {writer.get('zstd', 0.0) / hours:.2f} |",
              f"| **the writer's process** | **{writer.get('total', 0.0) / hours:.2f}** |"]
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hours", type=float, default=1.0, help="simulated hours per run (default 1)")
    ap.add_argument("--reps", type=int, default=1, help="repetitions of each run, the best counts (default 1)")
    ap.add_argument("--only", nargs="*", choices=RUNS, help="only these runs (SUMO alone is always run)")
    ap.add_argument("--skip-steps", action="store_true", help="leave out the per-step costs and OpenSeesPy")
    ap.add_argument("--day-hours", type=float, default=0.0,
                    help="also one whole `cosim run` of this many simulated hours (issue 27's goal: 24)")
    ap.add_argument("--skip-whole", action="store_true",
                    help="leave out the whole processes (cosim run against a plain libsumo loop) and start-up")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    runs = ["sumo", *[r for r in RUNS if r != "sumo" and (not args.only or r in args.only)]]
    started = datetime.datetime.now()
    best: dict[str, dict] = {}
    ratios: dict[str, list[float]] = {mode: [] for mode in runs}  # per repetition: against that repetition's SUMO
    plain: dict[str, list[float]] = {mode: [] for mode in runs}  # and against its plain libsumo loop
    for _ in range(args.reps):
        sumo_now = None
        walls: dict[str, float] = {}
        for mode in runs:
            r = run_one(mode, args.hours)
            print(mode, r, flush=True)
            if "error" in r or mode not in best or r["wall"] < best[mode].get("wall", float("inf")):
                best[mode] = r
            if "error" not in r:
                walls[mode] = r["wall"]
                if mode == "sumo":
                    sumo_now = r["wall"]
                elif sumo_now:
                    ratios[mode].append(r["wall"] / sumo_now)
        if "libsumo" in walls:
            for mode, wall in walls.items():
                plain[mode].append(wall / walls["libsumo"])
    sim = 3600.0 * args.hours

    def spread(values: list[float]) -> str:
        if not values:
            return "-"
        return f"{statistics.median(values):.2f}" + (f" ({min(values):.2f}-{max(values):.2f})"
                                                     if len(values) > 1 else "")

    lines = [
        f"# A day of traffic: {args.hours:g} simulated hour(s) of the default run",
        "",
        f"{started:%Y-%m-%d %H:%M}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}; load average before: {os.getloadavg()[0]:.2f}.",
        "Paper bridge, medium SUMO demand (bundled), class A road, SUMO step 0.05 s, dt = 5 ms unless noted, "
        "log at 100 Hz; each run in its own process. Wall times: the best of "
        f"{args.reps}; ratios: each run against SUMO alone of the same repetition (run first in it), the "
        "median over the repetitions and, in brackets, their range.",
        "",
        "Peak memory: the run's process, and its largest child (a fork: pages it shares with the run count in "
        "both): the log writer process with a log, SUMO's process without (`cosim.run.sumo_process`); with a log "
        "but no scene, both are children.",
        "",
        "Timed from the first step (start-up left out: the whole processes below include it). `/ plain "
        "libsumo`: against the plain libsumo loop of the same repetition.",
        "",
        "| run | wall [s] | real-time factor | / SUMO alone | / plain libsumo | peak memory [MB] | log [MB] | "
        "vehicles |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for mode in runs:
        r = best[mode]
        if "error" in r:
            lines.append(f"| {mode} | failed: {r['error']} | | | | | | |")
            continue
        ratio = "1.00" if mode == "sumo" else spread(ratios[mode])
        log_mb = f"{r['log_bytes'] / 1e6:.1f}" if r.get("log_bytes") else ""
        memory = f"{r['max_rss_mb']:.0f}" + (f" + {r['writer_rss_mb']:.0f}" if r.get("writer_rss_mb") else "")
        lines.append(f"| {mode} | {r['wall']:.1f} | {sim / r['wall']:.0f} | {ratio} | {spread(plain[mode])} | "
                     f"{memory} | {log_mb} | {r.get('vehicles', '')} |")
    if not args.skip_whole:
        lines += ["", *whole_processes(args.hours, max(args.reps, 1), args.day_hours)]
        lines += ["", *writer_topics(args.hours)]
    if not args.skip_steps:
        lines += ["", "## Microseconds per step (process time, paper bridge, quarter-cars on the deck)", "",
                  "| basis | 0 | 1 | 8 | 16 | 64 |", "|---|---|---|---|---|---|"]
        costs = step_costs(reps=3)
        for basis in dict.fromkeys(b for b, _, _ in costs):
            lines.append(f"| {basis} | " + " | ".join(f"{c:.1f}" for b, _, c in costs if b == basis) + " |")
        ops = opensees_cost()
        if ops is None:
            lines += ["", "OpenSeesPy: not installed (pip install '.[bench]')"]
        else:
            direct8 = next(c for b, n, c in costs if b.startswith("direct") and n == 8)
            lines += ["", f"OpenSeesPy, 8 moving forces: {ops:.0f} us/step, {ops / direct8:.0f} x cosim direct "
                      "with 8 quarter-cars (more physics: the vehicles' own dynamics)"]
    text = "\n".join(lines).rstrip() + "\n"
    print(text)
    write_report(text, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
