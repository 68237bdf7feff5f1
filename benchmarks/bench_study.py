"""Speed-up of a traffic-volume study on local Dask workers.

The same study (SUMO traffic on the 40 m girder of
examples/scenarios/traffic-40m.toml, vehicles per hour x seeds) is run

- one run after another in this process (``workers = 0``, no Dask): the baseline;
- on a local Dask cluster of 1 worker process;
- on a local Dask cluster of N worker processes (default: one per CPU);

each into a fresh output folder, and the wall times of the whole study
(cluster start-up, runs, table; no plots) are compared. The rows must come out
identical (wall times aside) whatever the number of workers; the script checks.

    python benchmarks/bench_study.py                 # 8 runs of 300 s simulated
    python benchmarks/bench_study.py --quick         # 4 runs of 120 s
    python benchmarks/bench_study.py --out benchmarks/results/study.md
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import datetime  # noqa: E402
import platform  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
BASE = HERE.parent / "examples" / "scenarios" / "traffic-40m.toml"


TITLE = """# Study speed-up on local Dask workers

Written by `python benchmarks/bench_study.py` (see its docstring): the same
study run one after another in one process, on a local Dask cluster of 1
worker, and of N workers. The speed-up needs idle cores: the machine check
says how many cores' worth of CPU N pure-Python processes got at the time.
"""


def study_text(duration: float, volumes: list[float], seeds: list[int]) -> str:
    return (f'[study]\nname = "bench"\nbase = "{BASE.as_posix()}"\nduration = {duration!r}\nplots = false\n\n'
            f"[sweep]\nvehicles_per_hour = {volumes!r}\nseeds = {seeds!r}\n")


def _burn(n: int) -> float:
    """A pure-Python loop: CPU only, nothing shared."""
    import time

    started = time.perf_counter()
    total = 0
    for i in range(n):
        total += i * i
    return time.perf_counter() - started


def machine_parallelism(workers: int, n: int = 10_000_000) -> float:
    """How many cores' worth of work ``workers`` processes got at once: ``workers * t(1) / t(parallel)``.

    Two processes on two idle cores give about 2.0; about 1.0 means another
    program held the other core, and no study can be faster in parallel then.
    """
    import multiprocessing
    import time

    one = _burn(n)
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        pool.map(_burn, [n // 100] * workers)  # start-up outside the timing
        started = time.perf_counter()
        pool.map(_burn, [n] * workers)
        both = time.perf_counter() - started
    return workers * one / both


def main() -> int:
    from cosim.study import default_workers, parse_study, run_study

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="4 runs of 120 s instead of 8 of 300 s")
    parser.add_argument("--workers", type=int, default=default_workers(), help="the parallel cluster's size")
    parser.add_argument("--duration", type=float, help="simulated time per run, s (default 300, --quick 120)")
    parser.add_argument("--out", type=Path, help="also write the report (Markdown) here")
    parser.add_argument("--append", action="store_true", help="append to --out instead of replacing it")
    args = parser.parse_args()
    duration, volumes, seeds = (120.0, [500.0, 1000.0], [1, 2]) if args.quick else \
        (300.0, [250.0, 500.0, 1000.0, 1500.0], [1, 2])
    if args.duration:
        duration = args.duration
    text = study_text(duration, volumes, seeds)
    cases = [("one after another, in this process (no Dask)", 0), ("Dask, 1 local worker", 1),
             (f"Dask, {args.workers} local workers", args.workers)]
    before = machine_parallelism(args.workers)
    results = []
    with tempfile.TemporaryDirectory(prefix="cosim-bench-study-") as tmp:
        for label, workers in cases:
            study = parse_study(text, "bench-study.toml", base_dir=HERE, output=Path(tmp) / f"w{workers}")
            outcome = run_study(study, workers=workers, plots=False)
            if outcome.failed:
                raise SystemExit(f"{label}: runs failed: {outcome.failed}")
            run_sum = sum(r["wall_time_total"] for r in outcome.rows)
            results.append((label, workers, outcome.wall_time, run_sum, outcome.table()))
            print(f"{label}: {outcome.wall_time:.2f} s ({len(outcome.rows)} runs, sum of run times {run_sum:.2f} s)")
    after = machine_parallelism(args.workers)
    keep = [c for c in results[0][4].columns if not c.startswith("wall_time")]
    identical = all(r[4][keep].equals(results[0][4][keep]) for r in results[1:])
    base = results[0][2]
    lines = [
        f"## {len(volumes) * len(seeds)} runs of {duration:g} s",
        "",
        f"{datetime.date.today().isoformat()}, {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}, Python {platform.python_version()}",
        "",
        f"Study: {len(volumes) * len(seeds)} runs ({len(volumes)} volumes x {len(seeds)} seeds) of "
        f"{duration:g} s simulated each, SUMO medium mix on the 40 m girder of examples/scenarios/traffic-40m.toml "
        "(direct basis, dt = 10 ms), logs written, no plots.",
        "",
        f"Machine check: {args.workers} pure-Python processes got {before:.2f} cores' worth of CPU before the "
        f"study and {after:.2f} after ({args.workers}.0 = every core free; other programs on the machine lower it, "
        "and the study's speed-up with them).",
        "",
        "| how | wall time [s] | speed-up vs one after another |",
        "|---|---:|---:|",
    ]
    for label, _workers, wall, _run_sum, _ in results:
        lines.append(f"| {label} | {wall:.2f} | {base / wall:.2f} |")
    lines += ["", f"Rows identical whatever the number of workers (wall times aside): {'yes' if identical else 'NO'}"]
    overhead = results[1][2] - results[0][2]
    lines += ["", f"Fixed cost of Dask here: {overhead:.2f} s (1 worker minus in-process: cluster start-up, the "
              "worker importing cosim and loading the compiled kernels, shutdown); with it, the ideal on "
              f"{args.workers} workers is {overhead + base / args.workers:.2f} s."]
    report = "\n".join(lines) + "\n"
    print(report)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        previous = args.out.read_text() if args.out.exists() and args.append else TITLE
        args.out.write_text(previous + "\n" + report)
    return 0 if identical else 1


if __name__ == "__main__":
    raise SystemExit(main())
