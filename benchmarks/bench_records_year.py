"""A scripted year of WIM records in quasi-static, side by side with pybtls (issue 25, item 9; run on demand).

    python benchmarks/bench_records_year.py [--days 365] [--run-days 365] [--dt 0.1]
                                            [--out benchmarks/results/records-year.md]

1. Records: ``--days`` days of Auxerre trucks drawn with cosim's own Grave model (cosim.core.loads: the site's
   hourly truck flow per direction, FlowR.csv, as Poisson arrivals; each truck's class, gross weight, axle loads
   and spacings from its direction's parameters; its speed from the site's speed distribution), one lane per
   direction, in CASTOR's units (100 kg, dm, dm/s, hundredths), streamed into a gzip CASTOR file (never held)
   dated by the calendar, for cosim; then the same lines as plain text (BTLS reads no gzip) dated by BTLS's own
   calendar (25-day months, 10-month years: BTLS reads day 31 of a month as 5 days before the 1st of the next),
   for pybtls.
2. cosim, in a fresh process: the scenario (a 40 m simply supported beam, 40 elements, a mid-span moment sensor;
   ``[traffic.records] via = "scripted"``, ``model = "moving-force"``; ``[solver] method = "quasi-static"``,
   ``dt``): the whole file checked once (``Scenario.records_check``, what ``cosim run`` does before it writes
   anything), then ``simulate(..., collect=False)`` with an observer keeping each day's largest moment (no log:
   a year of samples is not a log one writes).
3. pybtls, in a fresh process, on the same records: the same span, its built-in influence line 1 (the mid-span
   moment of a simply supported beam), 2 lanes, the same time step, daily block maxima (``set_BM_output``).

Each tool's wall time (``time.perf_counter`` around the whole run, start-up included), the process's peak
resident memory (VmHWM) and the simulated years per hour of wall time; the daily maxima of the two side by side.
``--run-days`` below ``--days`` runs the first days of the file only (each tool on a file of those days) and
extrapolates to a year, and the report says so (pybtls's time grows faster than its days: compare runs of
several lengths).
"""
from __future__ import annotations

import argparse
import datetime
import gzip
import heapq
import json
import os
import platform
import random
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

from _report import write_report  # benchmarks/ is on sys.path when a script runs

from cosim.core.loads import FORMATS, VehicleRecord, load_model, write_records

HERE = Path(__file__).resolve().parent
L = 40.0
ORIGIN = datetime.date(2001, 1, 1)
SEED = 25

SCENARIO = """
name = "records-year"
[bridge]
spans = [{length}]
elements_per_span = 40
supports = ["pinned", "fork"]
bending = "euler-bernoulli"
[bridge.material]
E = 3.5e10
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[[sensors]]
name = "moment"
x = {mid}
quantity = "bending_moment"
[traffic.records]
file = "{file}"
format = "castor"
via = "scripted"
model = "moving-force"
lanes = [{{lane = 1, y = -1.875, direction = "+x"}}, {{lane = 2, y = 1.875, direction = "-x"}}]
end = {end}
[solver]
method = "quasi-static"
dt = {dt}
"""

COSIM = """
import json, sys, time
started = time.perf_counter()
import numpy as np
from cosim.core.simulation import simulate
from cosim.run.scenario import load_scenario
from cosim.run.simulate import scripted_traffic

scenario = load_scenario(sys.argv[1])
days = int(sys.argv[2])
check = scenario.records_check()  # every line of the file read and checked once, as a run does first
checked = time.perf_counter()


class Daily:
    def __init__(self):
        self.peak = np.zeros(days)

    def on_block(self, times, keep, report):
        day = np.minimum((times // 86400.0).astype(np.int64), days - 1)
        np.maximum.at(self.peak, day, report.sensors[:, 0])


daily = Daily()
bridge = scenario.build_bridge()
with scripted_traffic(scenario) as traffic:
    result = simulate(bridge, traffic, scenario.duration, solver=scenario.solver_settings(),
                      sensors=scenario.sensors_core(), output_every=10**9, collect=False, observers=[daily])
done = time.perf_counter()
hwm = [line for line in open("/proc/self/status") if line.startswith("VmHWM:")][0].split()[1]
print(json.dumps({"wall": done - started, "cpu": time.process_time(), "check": checked - started,
                  "simulate": done - checked,
                  "records": check.count, "duration": scenario.duration, "peak_mb": int(hwm) / 1024,
                  "daily": daily.peak.tolist()}))
"""

PYBTLS = """
import json, sys, time
started = time.perf_counter()
from pathlib import Path
import numpy as np
import pybtls as pb

path, step, out, length, days = sys.argv[1], float(sys.argv[2]), sys.argv[3], float(sys.argv[4]), int(sys.argv[5])
bridge = pb.Bridge(length=length, no_lane=2)
line = pb.InfluenceLine("built-in")
line.set_IL(id=1, length=length)  # the mid-span moment of a simply supported beam
bridge.add_load_effect(inf_line_surf=line)
traffic = pb.TrafficLoader(no_lane=2)
traffic.add_traffic(Path(path), traffic_format=1)
config = pb.OutputConfig()
config.set_BM_output(write_summary=True, block_size_days=1)
sim = pb.Simulation(Path(out))
sim.add_sim(bridge=bridge, traffic=traffic, output_config=config, time_step=step, min_gvw=0, tag="bm")
if __name__ == "__main__":
    sim.run(no_core=1)
    done = time.perf_counter()
    daily = [0.0] * days
    (summary,) = Path(out).glob("bm/BM_S_*.txt")
    for row in summary.read_text().splitlines():
        fields = row.split()
        if len(fields) > 1:
            daily[int(fields[0]) - 1] = max(float(v) for v in fields[1:]) * 1e3  # kN m -> N m
    hwm = [line for line in open("/proc/self/status") if line.startswith("VmHWM:")][0].split()[1]
    import resource
    cpu = sum(getattr(resource.getrusage(who), f) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
              for f in ("ru_utime", "ru_stime"))
    print(json.dumps({"wall": done - started, "cpu": cpu, "peak_mb": int(hwm) / 1024, "daily": daily}))
"""


def trucks(days: int, seed: int = SEED) -> Iterator[VehicleRecord]:
    """Auxerre trucks over ``days`` days, both directions merged in time order (the module's docstring)."""
    model = load_model("Auxerre")

    def direction(d: int) -> Iterator[tuple[float, int, VehicleRecord]]:
        rng = random.Random(seed * 10 + d)
        speeds = model.speed[d - 1].sampler()
        t, last, n = 0.0, -1e9, 0
        flows = model.truck_flow[d - 1]
        while True:
            hour = int(t // 3600.0)
            if hour >= 24 * days:
                return
            rate = flows[hour % 24] / 3600.0
            gap = rng.expovariate(rate) if rate > 0 else 3600.0
            if t + gap >= (hour + 1) * 3600.0:  # none left this hour: the next hour's rate from its start
                t = (hour + 1) * 3600.0
                continue
            t += gap
            n += 1
            load = model.draw(seed, f"d{d}.{n}", d)
            axles = tuple(max(1, round(w / 981.0)) * 981.0 for w in load.axle_loads)
            spacings = tuple(max(1, round(s * 10)) / 10 for s in load.axle_spacings)
            speed = round(max(speeds.draw(rng.random(), rng.random()), 5.0) * 10) / 10
            length = round(sum(spacings) + 2.5, 1)
            t = max(t, last + 1.0 + length / speed)  # a lane's trucks keep a second apart, bumper to bumper
            t = round(t, 2)
            if t >= 86400.0 * days:
                return
            last = t
            yield t, d, VehicleRecord(time=t, lane=0, direction=d, local_lane=1, speed=speed,
                                      gross_weight=sum(axles), axle_loads=axles, axle_spacings=spacings,
                                      length=length, origin=ORIGIN)

    for _, _, record in heapq.merge(direction(1), direction(2), key=lambda item: (item[0], item[1])):
        yield record


def btls_dated(src: Path, dst: Path) -> int:
    """The CASTOR file ``src`` (gzip, dated by the calendar from ORIGIN) as plain text (BTLS reads no gzip) with
    each line dated by BTLS's calendar: day index k -> day k % 25 + 1, month (k // 25) % 10 + 1, year k // 250
    (two digits)."""
    fmt = FORMATS["castor"]
    where = {name: (a, b) for name, a, b in fmt.header_slices}
    count = 0
    with gzip.open(src, "rt", encoding="ascii") as lines, open(dst, "w", encoding="ascii") as out:
        for line in lines:
            day = datetime.date(2000 + int(line[slice(*where["year"])]), int(line[slice(*where["month"])]),
                                int(line[slice(*where["day"])]))
            k = (day - ORIGIN).days
            fields = {"day": k % 25 + 1, "month": (k // 25) % 10 + 1, "year": k // 250}
            chars = list(line)
            for name, value in fields.items():
                a, b = where[name]
                chars[a:b] = f"{value:{b - a}d}" if name != "year" else f"{value:0{b - a}d}"
            out.write("".join(chars))
            count += 1
    return count


def child(script: str, *args: str, cwd: Path) -> dict:
    out = subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True, cwd=cwd,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join([str(HERE.parent),
                                                                         os.environ.get("PYTHONPATH", "")])})
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-3000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--days", type=int, default=365, help="days of records generated (default 365)")
    ap.add_argument("--run-days", type=int, default=None, help="days run by both tools (default: all)")
    ap.add_argument("--dt", type=float, default=0.1, help="time step of both tools, s (default 0.1, BTLS's)")
    ap.add_argument("--folder", type=Path, default=None, help="where the record files go (default: a temporary "
                                                               "folder, removed)")
    ap.add_argument("--reuse", action="store_true", help="use the record files already in --folder")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "records-year.md")
    args = ap.parse_args(argv)
    run_days = args.run_days or args.days
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="cosim-year-") as scratch:
        folder = args.folder or Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        started = time.perf_counter()
        if args.reuse:
            with gzip.open(folder / "year.castor.gz", "rt") as lines:
                count = sum(1 for _ in lines)
        else:
            count = write_records(folder / "year.castor.gz", "castor", trucks(args.days))
            btls_dated(folder / "year.castor.gz", folder / "year-btls.castor")
        written = time.perf_counter() - started
        cosim_file, btls_file = folder / "year.castor.gz", folder / "year-btls.castor"
        if run_days < args.days:  # the first run_days days of both files, so that each tool reads only those
            cosim_file, btls_file = folder / f"part{run_days}.castor.gz", folder / f"part{run_days}-btls.castor"
            fields = {name: (a, b) for name, a, b in FORMATS["castor"].header_slices}
            with gzip.open(folder / "year.castor.gz", "rt") as src, gzip.open(cosim_file, "wt") as dst:
                for line in src:
                    day = datetime.date(2000 + int(line[slice(*fields["year"])]), int(line[slice(*fields["month"])]),
                                        int(line[slice(*fields["day"])]))
                    if (day - ORIGIN).days >= run_days:
                        break
                    dst.write(line)
            with open(folder / "year-btls.castor") as src, open(btls_file, "w") as dst:
                for line in src:
                    k = ((int(line[slice(*fields["year"])]) * 10 + int(line[slice(*fields["month"])]) - 1) * 25
                         + int(line[slice(*fields["day"])]) - 1)
                    if k >= run_days:
                        break
                    dst.write(line)
        size = (folder / "year.castor.gz").stat().st_size / 1e6
        (folder / "year.toml").write_text(SCENARIO.format(length=L, mid=L / 2, file=cosim_file.name,
                                                          end=86400.0 * run_days, dt=args.dt), encoding="utf-8")
        mine = child(COSIM, str(folder / "year.toml"), str(run_days), cwd=folder)
        theirs = child(PYBTLS, str(btls_file), repr(args.dt), str(folder / f"btls-{run_days}"), repr(L),
                       str(run_days), cwd=folder)
    years = mine["duration"] / (365.0 * 86400.0)
    per_hour = {k: years / (r["wall"] / 3600.0) for k, r in (("cosim", mine), ("pybtls", theirs))}
    pairs = [(a, b) for a, b in zip(mine["daily"], theirs["daily"]) if a > 0 and b > 0]
    differences = [abs(a - b) / b for a, b in pairs]
    whole = run_days >= 365
    scale = 365.0 / run_days
    lines = [
        "# A scripted year of WIM records in quasi-static, and pybtls on the same records",
        "",
        f"{datetime.datetime.now():%Y-%m-%d %H:%M}, {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}; load average before: {load:.2f}. `python benchmarks/bench_records_year.py"
        + (f" --days {args.days}" if args.days != 365 else "")
        + (f" --run-days {run_days}" if run_days != args.days else "")
        + (f" --dt {args.dt:g}" if args.dt != 0.1 else "")
        + (f" --folder {args.folder} --reuse" if args.reuse else "") + "`.",
        "",
        f"Records: {count:,} Auxerre trucks over {args.days} days ({count / args.days:,.0f} a day, cosim's Grave "
        f"draws, both directions), a gzip CASTOR file of {size:.1f} MB"
        + (" (written by an earlier run of the script, --reuse). " if args.reuse else f", written in {written:.0f} s. ")
        + "Both tools ran "
        + ("the whole of it." if run_days >= args.days else
           f"its first {run_days} days ({mine['records']:,} records) and the year is extrapolated from them."),
        "",
        "| tool | simulated days | records | wall [s] | of which: start-up and the file checked first | CPU [s] | "
        "simulated years per hour of wall | per hour of CPU | a year would take [min] | peak memory [MB] |",
        "|---|---|---|---|---|---|---|---|---|---|",
        f"| cosim, quasi-static, dt = {args.dt:g} s | {mine['duration'] / 86400:.2f} | {mine['records']:,} | "
        f"{mine['wall']:.0f} | {mine['check']:.0f} | {mine['cpu']:.0f} | {per_hour['cosim']:.2f} | "
        f"{years / (mine['cpu'] / 3600.0):.2f} | {mine['wall'] * scale / 60 if not whole else mine['wall'] / 60:.1f} | "
        f"{mine['peak_mb']:.0f} |",
        f"| pybtls 1.0.1 (BTLS), time step {args.dt:g} s | {run_days} | the same | {theirs['wall']:.0f} | | "
        f"{theirs['cpu']:.0f} | {per_hour['pybtls']:.2f} | {years / (theirs['cpu'] / 3600.0):.2f} | "
        f"{theirs['wall'] * scale / 60 if not whole else theirs['wall'] / 60:.1f} | {theirs['peak_mb']:.0f} |",
        "",
        f"cosim / pybtls: wall time {mine['wall'] / theirs['wall']:.2f}, CPU time {mine['cpu'] / theirs['cpu']:.2f}. "
        f"Load average after: {os.getloadavg()[0]:.2f} (the machine is shared: CPU time is the steadier measure).",
        "",
        f"Daily maxima of the mid-span moment, {len(pairs)} days: they differ by at most {max(differences):.2%} "
        f"(median {sorted(differences)[len(differences) // 2]:.2%}); the largest is {max(mine['daily']) / 1e3:,.0f} "
        f"kN m (cosim) and {max(theirs['daily']) / 1e3:,.0f} kN m (pybtls).",
        "",
    ]
    write_report("\n".join(lines), args.out)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
