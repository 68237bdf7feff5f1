"""What MCAP logging costs: wall time with and without the log, and memory over long runs.

Run on demand (not a test)::

    python benchmarks/bench_logging.py [--minutes 10] [--reps 3] [--out FILE.md]

1. Time: the paper bridge (bundled ``paper-double-tee``: 40 m, 40 elements,
   direct basis, dt = 5 ms) with 8 quarter-cars on the deck for the whole run
   (both lanes, 4 each way, 0.06 m/s so that none leaves in 10 min),
   ``--minutes`` of simulated time logged at 100 Hz (every 2nd step). Timed
   side by side in interleaved rounds, best of ``--reps``:

   - no log: :func:`cosim.core.simulation.simulate` with ``collect=False`` (the
     time stepping alone, constant memory);
   - log: :func:`cosim.run.logged.run_logged` (what ``cosim run`` does after the
     bridge is built): the same time stepping plus the whole log (attachments,
     modes, sensors, vehicles, events, status; zstd chunks; finished file).

   The target of the issue: logging costs at most 20 % of the run's wall time.

2. Memory: peak resident memory (``resource.getrusage``) of a fresh process
   that runs 1 min and one that runs 30 min (``--long``) of the same
   scenario with the log. Streaming means the two are about the same.

BLAS is pinned to one thread, as in the test suite.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse
import json
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from _report import write_report  # noqa: E402 - benchmarks/, on sys.path when a script runs

from cosim.core.simulation import simulate  # noqa: E402
from cosim.run.logged import run_logged  # noqa: E402
from cosim.run.scenario import load_scenario, parse_scenario  # noqa: E402

SPEED = 0.06  # m/s: 40 m take 667 s
VEHICLES = 8


def scenario_text(minutes: float) -> str:
    """The paper bridge and sensors with 8 slow quarter-cars, ``minutes`` of simulated time, 100 Hz log."""
    paper = load_scenario("paper-double-tee").text
    bridge = paper[: paper.index("[[vehicles]]")]
    bridge = bridge[: bridge.rindex("\n\n") + 1]
    cars = []
    for i in range(VEHICLES):
        left = i % 2 == 0  # y > 0 drives along -x, y < 0 along +x
        cars.append(
            "[[vehicles]]\n"
            f'id = "QC-{i + 1}"\nmodel = "quarter-car"\n'
            f"m_v = {1000.0 * (1 + i % 3)}\nm_w = {100.0 * (1 + i % 3)}\n"
            f"k_v = {39478.4 * (1 + i % 3)}\nc_v = {5026.55 * (1 + i % 3)}\n"
            f"y = {3.325 if left else -3.325}\nspeed = {SPEED}\nentry_time = {0.5 * (i // 2)}\n"
            f'direction = "{"-x" if left else "+x"}"\n'
        )
    return (bridge.replace('name = "paper-double-tee"', 'name = "paper-8-cars"') + "\n".join(cars)
            + f'\n[road]\nclass = "smooth"\n\n[solver]\ndt = 0.005\nduration = {60.0 * minutes}\n\n'
              "[output]\nrate_hz = 100.0\n")


def time_once(scenario, bridge, folder: Path, logged: bool) -> float:
    if logged:
        log = folder / "bench.mcap"
        outcome = run_logged(scenario, log, force=True, bridge=bridge)
        assert outcome.samples == int(round(scenario.duration * 100)) + 1
        return outcome.wall_time
    started = time.perf_counter()
    simulate(bridge, scenario.build_vehicles(), scenario.duration, scenario.solver_settings(),
             scenario.sensors_core(), road=scenario.build_road(), output_every=scenario.output_every, collect=False)
    return time.perf_counter() - started


def memory_child(minutes: float) -> None:
    """In a fresh process: one logged run; print its peak RSS (kB) and the log size as JSON."""
    scenario = parse_scenario(scenario_text(minutes), "bench")
    with tempfile.TemporaryDirectory() as tmp:
        outcome = run_logged(scenario, Path(tmp) / "mem.mcap")
        size = outcome.log_bytes
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # kB on Linux
    print(json.dumps({"minutes": minutes, "peak_rss_kb": peak, "log_bytes": size, "wall": outcome.wall_time}))


def measure_memory(minutes: float) -> dict:
    out = subprocess.run([sys.executable, __file__, "--memory-child", str(minutes)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="simulated minutes of the timed runs")
    parser.add_argument("--reps", type=int, default=3, help="repetitions (best counts)")
    parser.add_argument("--long", type=float, default=30.0, help="simulated minutes of the long memory run")
    parser.add_argument("--out", help="also write the report to this Markdown file")
    parser.add_argument("--memory-child", type=float, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_child is not None:
        memory_child(args.memory_child)
        return 0

    scenario = parse_scenario(scenario_text(args.minutes), "bench")
    bridge = scenario.build_bridge()
    times: dict[str, list[float]] = {"no log": [], "log": []}
    with tempfile.TemporaryDirectory() as tmp:
        time_once(scenario, bridge, Path(tmp), False)  # warm-up: kernels compiled or loaded from cache
        for _ in range(args.reps):
            for name in times:
                times[name].append(time_once(scenario, bridge, Path(tmp), name == "log"))
        log_size = (Path(tmp) / "bench.mcap").stat().st_size
    best = {k: min(v) for k, v in times.items()}
    overhead = best["log"] / best["no log"] - 1.0
    short, long = measure_memory(1.0), measure_memory(args.long)

    simulated = 60.0 * args.minutes
    lines = [
        "# MCAP logging cost",
        "",
        f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, BLAS 1 thread.",
        f"Scenario: paper bridge (40 m, 40 elements, direct basis, dt = 5 ms), {VEHICLES} quarter-cars on the deck "
        f"all the time, {simulated:g} s simulated, log at 100 Hz ({int(simulated * 100) + 1} sensor samples and as "
        "many vehicle messages).",
        "",
        "| run | best wall time [s] | real-time factor | all repetitions [s] |",
        "|---|---|---|---|",
    ]
    for name, values in times.items():
        lines.append(f"| {name} | {best[name]:.3f} | {simulated / best[name]:.0f} | "
                     + ", ".join(f"{v:.3f}" for v in values) + " |")
    lines += [
        "",
        f"Logging overhead: {100 * overhead:.1f} % of the time stepping's wall time (target: at most 20 %); "
        f"log size {log_size / 1e6:.1f} MB ({log_size / simulated / 1e3:.1f} kB per simulated second).",
        "",
        "| memory run | simulated | peak RSS [MB] | log size [MB] | wall [s] |",
        "|---|---|---|---|---|",
        f"| short | {short['minutes']:g} min | {short['peak_rss_kb'] / 1e3:.0f} | {short['log_bytes'] / 1e6:.1f} | "
        f"{short['wall']:.1f} |",
        f"| long | {long['minutes']:g} min | {long['peak_rss_kb'] / 1e3:.0f} | {long['log_bytes'] / 1e6:.1f} | "
        f"{long['wall']:.1f} |",
        "",
        f"Peak memory ratio long/short: {long['peak_rss_kb'] / short['peak_rss_kb']:.2f} "
        f"for {long['minutes'] / short['minutes']:g} times the simulated time.",
    ]
    report = "\n".join(lines) + "\n"
    print(report)
    if args.out:
        write_report(report, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
