"""Shared by the command-line tests: run the ``cosim`` command line in this process (or, where a real
process is the point, as ``python -m cosim``), a small scenario, and bundled scenarios with a few keys changed."""
from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import tomllib

import cosim
from cosim.cli import main
from cosim.run.scenario import Scenario, load_scenario, parse_scenario
from cosim.run.toml_writer import toml_dumps

REPO = Path(cosim.__file__).resolve().parents[1]


@dataclass(frozen=True)
class CliResult:
    """What a command left behind: its exit status and everything it printed."""

    returncode: int
    stdout: str
    stderr: str


def cosim_cli(*args: str, cwd: Path | None = None) -> CliResult:
    """``cosim ARGS`` in this process (:func:`cosim.cli.main`), in ``cwd`` (default: the checkout), with
    stdout and stderr captured. Use :func:`cosim_process` where a real process is the point."""
    out, err = io.StringIO(), io.StringIO()
    previous = Path.cwd()
    os.chdir(cwd or REPO)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = main(list(args))
            except SystemExit as exc:  # main returns its status; a stray exit is still an exit status
                status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        os.chdir(previous)
    return CliResult(status, out.getvalue(), err.getvalue())


def cli_env() -> dict[str, str]:
    """The environment of a cosim subprocess: this checkout first on the path, no display for plots."""
    environ = dict(os.environ)
    environ["PYTHONPATH"] = os.pathsep.join([str(REPO), environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    environ["MPLBACKEND"] = "Agg"
    return environ


def cosim_process(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run ``python -m cosim ARGS`` as a real process against this checkout in ``cwd`` (default: the checkout)."""
    return subprocess.run([sys.executable, "-m", "cosim", *args], capture_output=True, text=True,
                          cwd=cwd or REPO, env=cli_env(), timeout=300)


# A 20 m single span with explicit constants and 8 elements (fast to build and
# run): a quarter-car along +x and a golden car along -x on a class H road
# (very rough: the light wheels lose contact), dt = 2 ms. No duration: the run
# lasts until the last vehicle leaves (2.0 s) + 2 s.
TWO_CARS = """\
name = "two-cars"
[bridge]
spans = [20.0]
elements_per_span = 8
supports = ["pinned", "fork"]
[bridge.material]
E = 30e9
nu = 0.2
rho = 2500
[bridge.section.constants]
A = 2.0
I_y = 0.5
I_z = 8.0
J = 0.2
deck_y = [-3.0, 3.0]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = 10.0
[[sensors]]
name = "mid_left_acc"
x = 10.0
y = 2.0
quantity = "acceleration"
[[vehicles]]
id = "truck"
model = "quarter-car"
m_v = 1000.0
m_w = 100.0
k_v = 4e4
c_v = 5e3
y = 1.5
speed = 10.0
[[vehicles]]
id = "car"
model = "golden-car"
m_v = 300.0
y = -1.5
speed = 25.0
entry_time = 0.5
direction = "-x"
[road]
class = "H"
seed = 7
[solver]
dt = 0.002
"""


def bundled_scenario(name: str, *, end: float | None = None, dt: float | None = None,
                     scene: bool | None = None) -> Scenario:
    """The bundled scenario ``name`` with its SUMO run's ``[traffic] end`` (s), ``[solver] dt`` (s) and
    ``[output] scene`` changed, as a user's edited copy of it would be."""
    base = load_scenario(name)
    data = tomllib.loads(base.text)
    if end is not None:
        data["traffic"]["end"] = end
    if dt is not None:
        data["solver"]["dt"] = dt
    if scene is not None:
        data.setdefault("output", {})["scene"] = scene
    return parse_scenario(toml_dumps(data), name, base_dir=base.base_dir)


def broken_sumo_configs(folder: Path) -> tuple[Path, Path]:
    """Two SUMO configs written into ``folder``: one cosim cannot read (its network is missing) and one cosim
    reads but SUMO cannot load (a route over an edge the bundled network does not have)."""
    import shutil

    from cosim.sumo.adapter import bundled_networks

    broken = folder / "broken.sumocfg"
    broken.write_text("<configuration><input><net-file value='nope.net.xml'/></input></configuration>")
    shutil.copy(bundled_networks() / "bridge.net.xml", folder / "bridge.net.xml")
    (folder / "bad.rou.xml").write_text('<routes><vehicle id="v" depart="0"><route edges="nowhere"/></vehicle>'
                                        '</routes>')
    unknown = folder / "unknown.sumocfg"
    unknown.write_text('<configuration><input><net-file value="bridge.net.xml"/><route-files value="bad.rou.xml"/>'
                       '</input></configuration>')
    return broken, unknown


def netconvert() -> str:
    """SUMO's netconvert, from the eclipse-sumo package (a dependency), for networks built at test time."""
    import sumo

    return str(Path(sumo.SUMO_HOME) / "bin" / "netconvert")
