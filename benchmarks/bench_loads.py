"""What real loads cost (issue 25, item 9): drawing them per vehicle, and streaming WIM records (run on demand).

    python benchmarks/bench_loads.py [--draws 100000] [--records 300000] [--out benchmarks/results/loads.md]

Draws: microseconds per truck load (Grave's model, Auxerre), per car load and per
wander offset, each a fresh vehicle id (as in a run: every vehicle is drawn once,
when it first appears), against what a run spends per vehicle: the default run's
wall time per vehicle and its coupled step (benchmarks/results/day.md: 994
vehicles in a simulated hour, 8.4 s for the direct basis without a log, 19 us a
step with 8 vehicles on the deck). Records: a generated CASTOR file (plain and
gzip) streamed by `read_records` in a fresh process: records per second and the
process's peak resident memory (VmHWM), for the whole file and for a tenth of it
(the same peak: constant memory).
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
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
    ap.add_argument("--records", type=int, default=300_000, help="records in the generated file (default 300,000)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "loads.md")
    args = ap.parse_args(argv)

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

    load = os.getloadavg()[0]
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
{(truck + lateral) / per_vehicle_us:.2%} of the run (the goal: under 1 %).

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
