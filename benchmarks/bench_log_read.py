"""Reading a long log: `cosim info`, `export` and `plot`, whole and in a window (run on demand).

    python benchmarks/bench_log_read.py LOG.mcap [--window 600] [--out benchmarks/results/log_read.md]

Each command runs in its own process (as a user runs it), one after another;
reported: wall time, peak resident memory (VmHWM, which unlike ru_maxrss is
not inherited across exec) and, for reference, the same for `cosim --version`
(the interpreter and cosim's imports: what every command pays before it reads
anything). The window is the log's middle `--window` seconds. Make a long log
with `cosim run` of a scenario with a long `[traffic] end` (the default
scenario with `end = 7200` writes a 2 h, 120 MB log).
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

HERE = Path(__file__).resolve().parent

CHILD = ("import sys\nfrom cosim.cli import main\nstatus = main(sys.argv[1:])\n"
         "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM:')][0].split()[1]\n"
         "print(int(hwm) / 1024, file=sys.stderr)\nsys.exit(status)")


def run(args: list[str]) -> tuple[float, float, str]:
    """Wall time (s), peak resident memory (MB) and the last line printed by ``cosim ARGS`` in a new process."""
    env = dict(os.environ, MPLBACKEND="Agg")
    started = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CHILD, *args], capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - started
    *errors, peak = out.stderr.strip().splitlines() or ["0"]
    if out.returncode != 0:
        raise SystemExit(f"cosim {' '.join(args)} failed: {' '.join(errors)}")
    last = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else ""
    return wall, float(peak), last


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log", type=Path)
    ap.add_argument("--window", type=float, default=600.0, help="seconds of simulated time (default 600)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "log_read.md")
    args = ap.parse_args(argv)
    from cosim.log.reader import open_log

    overview = open_log(args.log, check="summary")
    middle = 0.5 * (overview.start_time + overview.end_time)
    t0, t1 = middle - 0.5 * args.window, middle + 0.5 * args.window
    window = ["--from", f"{t0:g}", "--to", f"{t1:g}"]
    with tempfile.TemporaryDirectory() as scratch:
        csv, png = str(Path(scratch) / "o.csv"), str(Path(scratch) / "o.png")
        cases = [
            ("cosim --version (start-up)", ["--version"]),
            ("info", ["info", str(args.log)]),
            ("info --verify", ["info", "--verify", str(args.log)]),
            (f"export, {args.window:g} s window", ["export", str(args.log), "--csv", csv, "--force", *window]),
            ("export, whole log", ["export", str(args.log), "--csv", csv, "--force"]),
            (f"plot, {args.window:g} s window", ["plot", str(args.log), "-o", png, "--force", *window]),
            ("plot, whole log", ["plot", str(args.log), "-o", png, "--force"]),
        ]
        rows = []
        for name, cmd in cases:
            wall, peak, last = run(cmd)
            print(f"{name}: {wall:.2f} s, {peak:.0f} MB  ({last[:100]})", flush=True)
            rows.append((name, wall, peak))
    lines = [
        f"# Reading a log of {overview.end_time - overview.start_time:g} s: scenario "
        f"{overview.info.get('scenario', '?')} ({overview.info.get('basis', '?')} basis), "
        f"{overview.size / 1e6:.0f} MB, {overview.chunks} chunks",
        "",
        f"{datetime.datetime.now():%Y-%m-%d %H:%M}, {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}; load average before: {os.getloadavg()[0]:.2f}. "
        f"Each command in its own process; window t = {t0:g} to {t1:g} s.",
        "",
        "| command | wall [s] | peak memory [MB] |",
        "|---|---|---|",
        *[f"| {name} | {wall:.2f} | {peak:.0f} |" for name, wall, peak in rows],
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    write_report(text, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
