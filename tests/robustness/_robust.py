"""Shared by the robustness tests: scenarios, SUMO files and the command-line helpers.

The command-line helpers of ``tests/integration/_cli.py`` are reused (the
command in this process, or a real ``python -m cosim`` process where the
process is the point: signals, exit statuses, start-up).
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "integration"))

from _cli import TWO_CARS, cli_env, cosim_cli, cosim_process  # noqa: E402, F401 - shared with the tests here


def assert_one_line(result, status: int, *fragments: str) -> str:  # noqa: ANN001 - CliResult
    """Assert that a command failed with exit ``status`` and one line ``cosim: error: ...`` on stderr holding
    every fragment, with no traceback; returns the line."""
    assert result.returncode == status, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: ") and "Traceback" not in result.stderr, lines
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]

#: TWO_CARS with a measured road profile next to it (an input file its log embeds), 4 s simulated.
PROFILED = TWO_CARS.replace('name = "two-cars"', 'name = "profiled"').replace(
    '[road]\nclass = "H"\nseed = 7', '[road]\nprofile = "data/road.csv"')
#: A gentle road profile over the 20 m deck and 1 m beyond.
ROAD_CSV = "x,r\n" + "".join(f"{-1.0 + 0.1 * i:.1f},{0.002 * ((i % 7) - 3) / 3:.6f}\n" for i in range(221))

#: The bundled network's 40 m bridge (explicit constants, 10 elements) under the bundled light demand, 20 s.
SUMO_SCENARIO = """\
name = "sumo-small"
[bridge]
spans = [40.0]
elements_per_span = 10
supports = ["pinned", "fork"]
[bridge.material]
E = 35e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[[sensors]]
name = "mid"
x = 20.0
[traffic]
sumo_config = "sumo/light.sumocfg"
step = 0.05
end = {end}
seed = 3
[solver]
dt = 0.025
[output]
rate_hz = 40.0
"""


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def sumo_folder(folder: Path) -> Path:
    """A copy of the bundled light demand (config, network, vehicle types, routes) in ``folder/sumo``."""
    from cosim.sumo import bundled_networks

    target = folder / "sumo"
    target.mkdir(parents=True, exist_ok=True)
    for name in ("light.sumocfg", "bridge.net.xml", "vtypes.add.xml", "light.rou.xml"):
        (target / name).write_bytes((bundled_networks() / name).read_bytes())
    return target


