"""What real loads cost (issue 25, item 9): drawing them per vehicle, whole runs with and without them, and
streaming WIM records (run on demand).

    python benchmarks/bench_loads.py [--draws 100000] [--runs 5] [--records 300000] [--out benchmarks/results/loads.md]

Draws: microseconds per truck load (Grave's model, Auxerre), per car load and per
wander offset, each a fresh vehicle id (as in a run: every vehicle is drawn once,
when it first appears), against what a run spends per vehicle: the default run's
wall time per vehicle and its coupled step (benchmarks/results/day.md: 994
vehicles in a simulated hour, 8.4 s for the direct basis without a log, 19 us a
step with 8 vehicles on the deck). Records: a generated CASTOR file (plain and
gzip) streamed by `read_records` in a fresh process: records per second and the
process's peak resident memory (VmHWM), for the whole file and for a tenth of it
(the same peak: constant memory).

Whole runs (``--runs N``, 0 to skip): the default run as users start it (``cosim run --quiet``, 10 simulated
minutes, logged, in a new process each time) with its ``[traffic.loads]``, with it but the cars keeping their vType,
and without that table, in turn (A B C A B C ..., after one round not counted): each process's wall time from its
start to its exit and its CPU time (user + system of it and its children, ``os.wait4``), the ratios of each round,
and the axles each case put on the deck. Then one more run with
loads, in a process whose ``VehicleLoads.draw`` and ``SumoTraffic._first_sight`` (the draw and what the adapter
makes of it: the vehicle's own axles and models) are timed: their share of that run's wall and CPU time.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _report import write_report  # benchmarks/ is on sys.path when a script runs

from cosim.core.loads import VehicleRecord, draw_car, load_model, wander, write_records

HERE = Path(__file__).resolve().parent

#: The default run, from benchmarks/results/day.md (1 simulated hour, direct basis, no log).
RUN_VEHICLES, RUN_WALL_S, STEP_US_8_VEHICLES = 994, 8.4, 19.0

READER = ("import sys, time\nfrom cosim.core.loads import read_records\nstarted = time.perf_counter()\n"
          "n = 0\nfor record in read_records(sys.argv[1], 'castor', (2, 2)):\n    n += 1\n"
          "    if n == int(sys.argv[2]):\n        break\nwall = time.perf_counter() - started\n"
          "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM:')][0].split()[1]\n"
          "print(n, wall, int(hwm) / 1024)")


#: A run of ``cosim`` in this process with VehicleLoads.draw and SumoTraffic._first_sight timed (their calls, wall
#: and CPU seconds, nested: _first_sight includes the draw), and the run's own wall and CPU (its children's too),
#: written as JSON to the file named by COSIM_BENCH_OUT. With its 3D scene (the default) the default run steps
#: SUMO, and so draws, in this process (without the scene SUMO has its own process, whose draws this would miss).
INSTRUMENTED = """\
import json, os, resource, sys, time
from cosim.sumo import adapter, loads
spent = {}
def timed(cls, name):
    original = getattr(cls, name)
    spent[name] = [0, 0.0, 0.0]
    def wrapper(*args, **kwargs):
        wall, cpu = time.perf_counter(), time.thread_time()
        try:
            return original(*args, **kwargs)
        finally:
            s = spent[name]
            s[0] += 1
            s[1] += time.perf_counter() - wall
            s[2] += time.thread_time() - cpu
    setattr(cls, name, wrapper)
timed(loads.VehicleLoads, "draw")
timed(adapter.SumoTraffic, "_first_sight")
from cosim.cli import main
started = time.perf_counter()
code = main(sys.argv[1:])
wall = time.perf_counter() - started
me, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
with open(os.environ["COSIM_BENCH_OUT"], "w") as out:
    json.dump({"code": code, "wall": wall, "cpu": me.ru_utime + me.ru_stime,
               "cpu_children": children.ru_utime + children.ru_stime, "spent": spent}, out)
"""


def without_loads(text: str) -> str:
    """The scenario's TOML without its ``[traffic.loads]`` table (and the comment lines just above it)."""
    lines = text.splitlines(keepends=True)
    heads = [i for i, line in enumerate(lines) if line.strip() == "[traffic.loads]"]
    if len(heads) != 1:
        raise SystemExit("the default scenario has no [traffic.loads] table to take out")
    start = end = heads[0]
    while start > 0 and lines[start - 1].startswith("#"):
        start -= 1
    end += 1
    while end < len(lines) and not lines[end].startswith("["):
        end += 1
    return "".join(lines[:start] + lines[end:])


def timed_process(command: list[str]) -> tuple[float, float]:
    """(wall s, CPU s) of ``command`` in a new process, from its start to its exit (CPU: user + system of the
    process and the children it waited for, as the kernel accounts them when it is reaped)."""
    started = time.perf_counter()
    child = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - started
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed ({child.returncode}): {child.stderr.read().decode()[-2000:]}")
    child.stderr.close()
    return wall, usage.ru_utime + usage.ru_stime


#: The default scenario's mapping of its cars, and the same with the cars keeping their vType (one contact point).
CARS_DRAWN, CARS_FIXED = 'vtype_classes = { car = "car",', 'vtype_classes = { car = "fixed",'


def whole_runs(pairs: int, folder: Path) -> dict:
    """The default run with [traffic.loads], with it but its cars' weights fixed, and without it, in turn; then one
    instrumented run with them."""
    from cosim.run.scenario import load_scenario

    scenario = load_scenario("paper-bridge-traffic")
    fixed = folder / "paper-bridge-traffic-without-loads.toml"
    fixed.write_text(without_loads(scenario.text))
    if CARS_DRAWN not in scenario.text:
        raise SystemExit(f"the default scenario's [traffic.loads] has no {CARS_DRAWN!r} to change")
    cars = folder / "paper-bridge-traffic-cars-fixed.toml"
    cars.write_text(scenario.text.replace(CARS_DRAWN, CARS_FIXED))
    cosim = [sys.executable, "-m", "cosim", "run"]
    commands = {"loads": [*cosim, "--out", str(folder / "loads.mcap"), "--force", "--quiet"],
                "cars_fixed": [*cosim, str(cars), "--out", str(folder / "cars_fixed.mcap"), "--force", "--quiet"],
                "fixed": [*cosim, str(fixed), "--out", str(folder / "fixed.mcap"), "--force", "--quiet"]}
    timings: dict[str, list[tuple[float, float]]] = {name: [] for name in commands}
    for i in range(pairs + 1):  # the first round warms the caches up and is not counted
        for name, command in commands.items():
            result = timed_process(command)
            if i:
                timings[name].append(result)
    out = folder / "instrumented.json"
    subprocess.run([sys.executable, "-c", INSTRUMENTED, "run", "--out", str(folder / "instrumented.mcap"),
                    "--force", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                   env={**os.environ, "COSIM_BENCH_OUT": str(out)})
    instrumented = json.loads(out.read_text())
    if not instrumented["spent"]["draw"][0]:
        raise SystemExit("the instrumented run drew no loads: SUMO did not step in the run's process")
    vehicles = sum(1 for _ in _load_records(folder / "instrumented.mcap"))
    # What each case put on the deck (the vehicles' axles, from their load records) and logged.
    made = {name: {"vehicles": 0, "axles": 0, "log_mb": (folder / f"{name}.mcap").stat().st_size / 1e6}
            for name in commands}
    for name in commands:
        for _, record in _load_records(folder / f"{name}.mcap"):
            made[name]["vehicles"] += 1
            made[name]["axles"] += len(record["axle_loads"])
    return {"timings": timings, "instrumented": instrumented, "vehicles_on_deck": vehicles, "made": made}


def _load_records(log: Path):
    from cosim.log import iter_messages
    from cosim.log.schemas import TOPIC_VEHICLE_LOADS

    return iter_messages(log, [TOPIC_VEHICLE_LOADS])


def _spread(values: list[float], fmt: str = ".2f") -> str:
    return f"{format(statistics.median(values), fmt)} ({format(min(values), fmt)}-{format(max(values), fmt)})"


def whole_run_text(runs: dict) -> str:
    t = runs["timings"]
    wall = {k: [w for w, _ in v] for k, v in t.items()}
    cpu = {k: [c for _, c in v] for k, v in t.items()}
    ratio_wall = {k: [a / b for a, b in zip(wall[k], wall["fixed"])] for k in ("loads", "cars_fixed")}
    ratio_cpu = {k: [a / b for a, b in zip(cpu[k], cpu["fixed"])] for k in ("loads", "cars_fixed")}
    ins, made = runs["instrumented"], runs["made"]
    draw, first = ins["spent"]["draw"], ins["spent"]["_first_sight"]
    cpu_total = ins["cpu"] + ins["cpu_children"]
    n = len(ratio_wall["loads"])

    def made_text(k: str) -> str:
        return f"{made[k]['axles']} | {made[k]['log_mb']:.1f}"

    return f"""
## Whole runs: the default run with and without `[traffic.loads]` ({n} rounds, in turn)

`cosim run --quiet` (the default scenario: 10 simulated minutes of medium traffic, logged with its 3D scene), the
same with its cars keeping their vType's weight (`car = "fixed"` in `vtype_classes`: one contact point, 1.5 t;
the trucks still drawn) and the same without `[traffic.loads]` (every vehicle of a vType weighs what the vType
says), each in a new process, A B C A B C ... after one round not counted: median (min-max) of the whole process,
start-up included; the ratios to the run without, round by round. Axles: those of the vehicles that came onto the
deck (their load records), every one stepped, coupled and logged.

| run | wall [s] | CPU, user + system [s] | / without: wall | / without: CPU | axles on the deck | log [MB] |
|---|---|---|---|---|---|---|
| with `[traffic.loads]` (Auxerre, the default) | {_spread(wall["loads"])} | {_spread(cpu["loads"])} | \
{_spread(ratio_wall["loads"], ".3f")} | {_spread(ratio_cpu["loads"], ".3f")} | {made_text("loads")} |
| with it, the cars' weights fixed | {_spread(wall["cars_fixed"])} | {_spread(cpu["cars_fixed"])} | \
{_spread(ratio_wall["cars_fixed"], ".3f")} | {_spread(ratio_cpu["cars_fixed"], ".3f")} | {made_text("cars_fixed")} |
| without (the vTypes' fixed weights) | {_spread(wall["fixed"])} | {_spread(cpu["fixed"])} | | | \
{made_text("fixed")} |

The runs drive the same SUMO vehicles ({made["fixed"]["vehicles"]} onto the deck) but not the same model: a drawn
car has two axles where its vType has one contact point, a drawn truck its class's axles. The ratios are the cost
of that richer model as well as of drawing it; the draw alone is the next table.

What the draws themselves take, in one more run with loads whose `VehicleLoads.draw` and
`SumoTraffic._first_sight` were timed (with its 3D scene the default run steps SUMO, and so draws, in the run's
process):

| | calls | wall [ms] | CPU [ms] | share of the run's wall ({ins["wall"]:.2f} s) | \
share of its CPU ({cpu_total:.2f} s, its children's included) |
|---|---|---|---|---|---|
| `VehicleLoads.draw` (class, gross weight, axles, wander) | {draw[0]} | {draw[1] * 1e3:.1f} | {draw[2] * 1e3:.1f} | \
{draw[1] / ins["wall"]:.3%} | {draw[2] / cpu_total:.3%} |
| `SumoTraffic._first_sight` (the draw and the vehicle's own axles and models) | {first[0]} | {first[1] * 1e3:.1f} | \
{first[2] * 1e3:.1f} | {first[1] / ins["wall"]:.3%} | {first[2] / cpu_total:.3%} |

{draw[0]} vehicles were drawn ({runs["vehicles_on_deck"]} came onto the deck): \
{draw[1] / max(draw[0], 1) * 1e6:.0f} us a draw in the run. The CPU columns are the measure (each call's thread \
time against the run's process time): on shared cores a call's wall time also counts the time the thread waited \
for a core.
"""


def per_call_us(function, count: int) -> float:
    started = time.perf_counter()
    for i in range(count):
        function(i)
    return (time.perf_counter() - started) / count * 1e6


def read_in_child(path: Path, limit: int) -> tuple[int, float, float]:
    """(records, wall s, peak resident MB) of streaming ``path`` in a new process, stopping after ``limit``."""
    out = subprocess.run([sys.executable, "-c", READER, str(path), str(limit)], capture_output=True, text=True,
                         check=True)
    n, wall, peak = out.stdout.split()
    return int(n), float(wall), float(peak)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--draws", type=int, default=100_000, help="vehicles drawn per kind (default 100,000)")
    ap.add_argument("--runs", type=int, default=5, help="rounds of whole default runs with loads, with loads but "
                    "the cars' weights fixed, and without loads (default 5; 0: none)")
    ap.add_argument("--records", type=int, default=300_000, help="records in the generated file (default 300,000)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "loads.md")
    args = ap.parse_args(argv)

    load = os.getloadavg()[0]
    runs_text = ""
    if args.runs > 0:
        with tempfile.TemporaryDirectory() as folder:
            runs_text = whole_run_text(whole_runs(args.runs, Path(folder)))
    model = load_model("Auxerre")
    truck = per_call_us(lambda i: model.draw(1, f"truck{i}", 1 + i % 2), args.draws)
    car = per_call_us(lambda i: draw_car(1, f"car{i}"), args.draws)
    lateral = per_call_us(lambda i: wander(1, f"veh{i}"), args.draws)
    per_vehicle_us = RUN_WALL_S / RUN_VEHICLES * 1e6

    base = VehicleRecord(time=0.0, lane=1, direction=1, local_lane=1, speed=24.8, gross_weight=412 * 981.0,
                         axle_loads=(62 * 981.0, 140 * 981.0, 70 * 981.0, 70 * 981.0, 70 * 981.0),
                         axle_spacings=(3.2, 5.4, 1.3, 1.3), length=16.5, transverse=1.8)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name in ("wim.castor", "wim.castor.gz"):
            path = Path(folder) / name
            started = time.perf_counter()
            write_records(path, "castor", (VehicleRecord(**{**base.__dict__, "time": i * 0.3,
                                                            "direction": 1 + i % 2, "local_lane": 1 + i % 2})
                                           for i in range(args.records)))
            written = time.perf_counter() - started
            n, wall, peak = read_in_child(path, args.records)
            tenth_n, _, tenth_peak = read_in_child(path, args.records // 10)
            rows.append(f"| {name} | {n:,} | {path.stat().st_size / 1e6:.1f} | {n / wall:,.0f} | "
                        f"{wall / n * 1e6:.1f} | {peak:.0f} | {tenth_peak:.0f} ({tenth_n:,} records) | "
                        f"{args.records / written:,.0f} |")

    text = f"""# Real loads: drawing them and streaming WIM records

{datetime.datetime.now():%Y-%m-%d %H:%M}, {platform.machine()}, {os.cpu_count()} cores, Python \
{platform.python_version()}; load average before: {load:.2f}. `python benchmarks/bench_loads.py`.

## Drawing a vehicle's loads ({args.draws:,} vehicles each, a new id each)

| draw | us per vehicle | per second | / the default run's wall per vehicle ({per_vehicle_us:,.0f} us) | \
in coupled steps (8 vehicles, {STEP_US_8_VEHICLES:g} us) |
|---|---|---|---|---|
| truck (Grave, Auxerre) | {truck:.1f} | {1e6 / truck:,.0f} | {truck / per_vehicle_us:.2%} | \
{truck / STEP_US_8_VEHICLES:.1f} |
| car | {car:.1f} | {1e6 / car:,.0f} | {car / per_vehicle_us:.2%} | {car / STEP_US_8_VEHICLES:.1f} |
| wander (EN 1991-2) | {lateral:.1f} | {1e6 / lateral:,.0f} | {lateral / per_vehicle_us:.2%} | \
{lateral / STEP_US_8_VEHICLES:.1f} |

Every vehicle is drawn once, when it first appears: in the default run ({RUN_VEHICLES} vehicles in a simulated \
hour, {RUN_WALL_S:g} s of wall time on the direct basis without a log, benchmarks/results/day.md), a truck load \
and a wander offset for every vehicle would add {(truck + lateral) * RUN_VEHICLES / 1e6:.3f} s, \
{(truck + lateral) / per_vehicle_us:.2%} of the run (the goal: under 1 %): an estimate, the draws timed now \
against a run timed on another day; the draws inside a run are measured below.
""" + runs_text + f"""
## Streaming WIM records (CASTOR, {args.records:,} records, read in a fresh process)

| file | records | MB | records per second | us per record | peak memory [MB] | peak reading a tenth | \
written per second |
|---|---|---|---|---|---|---|---|
""" + "\n".join(rows) + """

Peak memory is the reading process's (the interpreter, numpy, scipy and cosim's imports included): the same for \
the whole file and for a tenth of it, so memory does not grow with the file.
"""
    write_report(text, args.out)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
