"""The first run after installing: numba compiling the solver, against a run with its kernels cached (on demand).

    python benchmarks/bench_compile.py [--out benchmarks/results/compile.md]   # about two minutes

cosim's kernels are compiled by numba at their first use and cached next to
their source (cosim.core.jit). This copies the installed package's sources
(no cache) into a scratch folder and runs, each in its own process with the
copy first on the path:

1. ``cosim run`` of the default scenario for one SUMO step with an empty
   cache (what a user's first ``cosim run`` after ``pip install`` waits for
   before its first time step), with numba's compile events recorded (the
   functions compiled and the seconds each took, nested ones included in the
   outer ones);
2. the same again, the kernels now in the cache;
3. with the cache still warm, a run of the same scenario on the modal basis,
   which shares the block loop's compiled code (no compile event expected).
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import tomllib
from _report import write_report  # benchmarks/ is on sys.path when a script runs

#: Runs `cosim run` in this process with numba's compile events recorded; prints them as JSON on the last line.
RECORDED = r"""
import json, sys, time
from numba.core import event
started, spans = {}, []
def key(ev):  # a compile's start and end are two events: the same dispatcher and argument types
    return id(ev.data["dispatcher"]), str(ev.data.get("args"))
class Recorder(event.Listener):
    def on_start(self, ev):
        started[key(ev)] = time.perf_counter()
    def on_end(self, ev):
        name = ev.data["dispatcher"].py_func.__qualname__
        spans.append((time.perf_counter() - started.pop(key(ev), time.perf_counter()), name))
event.register("numba:compile", Recorder())
import cosim
assert cosim.__file__.startswith(sys.argv[1]), cosim.__file__
from cosim.cli import main
main(sys.argv[2:])
print(json.dumps({"spans": spans}))
"""


def _run(copy: Path, args: list[str]) -> dict:
    env = dict(os.environ, PYTHONPATH=str(copy))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    started = time.perf_counter()
    # cwd: the copy's folder, so that `python -c` (the current folder first on its path) imports the copy
    done = subprocess.run([sys.executable, "-c", RECORDED, str(copy), *args], env=env, capture_output=True, text=True,
                          check=True, cwd=copy)
    out = json.loads(done.stdout.strip().splitlines()[-1])
    out["process"] = time.perf_counter() - started
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="benchmarks/results/compile.md")
    args = parser.parse_args()

    import cosim
    from cosim.run.scenario import load_scenario
    from cosim.run.toml_writer import toml_dumps

    source = Path(cosim.__file__).resolve().parent
    folder = Path(tempfile.mkdtemp(prefix="bench-compile-"))
    try:
        copy = folder / "site"
        shutil.copytree(source, copy / "cosim", ignore=shutil.ignore_patterns("__pycache__"))
        networks = source.parent / "sumo_networks"
        if networks.is_dir():
            shutil.copytree(networks, copy / "sumo_networks", ignore=shutil.ignore_patterns("__pycache__"))
        data = tomllib.loads(load_scenario("paper-bridge-traffic").text)
        data["traffic"]["end"] = data["traffic"]["step"]
        first = folder / "first-step.toml"
        first.write_text(toml_dumps(data), encoding="utf-8")
        data.setdefault("solver", {})["basis"] = "modal"
        modal = folder / "first-step-modal.toml"
        modal.write_text(toml_dumps(data), encoding="utf-8")
        run = ["run", "--quiet", "--force", "--out"]
        cold = _run(copy, [*run, str(folder / "cold.mcap"), str(first)])
        warm = _run(copy, [*run, str(folder / "warm.mcap"), str(first)])
        other = _run(copy, [*run, str(folder / "modal.mcap"), str(modal)])
    finally:
        shutil.rmtree(folder, ignore_errors=True)

    outer: dict[str, float] = {}
    for seconds, name in cold["spans"]:
        outer[name] = max(outer.get(name, 0.0), seconds)
    lines = [
        "# The first run after installing: compiling the solver",
        "",
        f"`python benchmarks/bench_compile.py`, {datetime.datetime.now():%Y-%m-%d %H:%M}, "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
        f"load average before: {os.getloadavg()[0]:.2f}. `cosim run` of the default scenario for one SUMO step "
        "(0.05 s), each in its own process, the package's sources copied without numba's cache.",
        "",
        "| run | whole process [s] | functions numba compiled | of which the block loop, `advance_block` [s] |",
        "|---|---|---|---|",
    ]
    for label, r in (("empty cache (a first run after installing)", cold), ("kernels cached", warm),
                     ("then the modal basis, cache warm", other)):
        loop = sum(s for s, n in r["spans"] if n == "advance_block")
        lines.append(f"| {label} | {r['process']:.1f} | {len(r['spans'])} | {loop:.1f} |")
    lines += ["", "The longest compilations of the first run (seconds, a function's own callees included):", "",
              "| function | s |", "|---|---|"]
    for name, seconds in sorted(outer.items(), key=lambda kv: -kv[1])[:15]:
        lines.append(f"| `{name}` | {seconds:.2f} |")
    write_report("\n".join(lines) + "\n", args.out)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
