"""Issue item 5: every size an input controls is bounded before it is allocated; the error is one line
naming the key, the limit and the environment variable that raises it, exit 2, nothing written."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from _craft import bomb, rewrite
from _robust import PROFILED, ROAD_CSV, SUMO_SCENARIO, assert_one_line, cli_env, cosim_cli, sumo_folder, write

from cosim.core.limits import MAX_CHUNK_BYTES, MAX_DOFS
from cosim.errors import ConfigError

STATIC = PROFILED[:PROFILED.index("[[vehicles]]")]
PAPER_PLATES = """\
name = "plates"
[bridge]
spans = [40.0]
elements_per_span = 4
supports = ["fork", "fork"]
[bridge.material]
E = 33e9
nu = 0.2
rho = 2500.0
[bridge.section]
mesh_size = {mesh}
[[bridge.section.plates]]
start = [-6.655, 0.0]
end = [6.655, 0.0]
thickness = 0.25
[[bridge.section.plates]]
start = [3.325, 0.0]
end = [3.325, -2.0]
thickness = 0.4
"""


def assert_limit_error(result, *fragments: str) -> str:  # noqa: ANN001 - CliResult
    """Assert that a command was refused (exit 2, one line) for a bounded input, naming the environment
    variable that raises the bound; returns the line."""
    return assert_one_line(result, 2, "is more than the limit of",
                           "raise it with the environment variable COSIM_MAX_", *fragments)


def test_elements_per_span_is_bounded_before_the_model_is_assembled(tmp_path: Path) -> None:
    write(tmp_path, "data/road.csv", ROAD_CSV)
    scenario = write(tmp_path, "huge.toml", PROFILED.replace("elements_per_span = 8", "elements_per_span = 100000000"))
    line = assert_limit_error(cosim_cli("run", str(scenario), "--out", "o.mcap", cwd=tmp_path),
                              "huge.toml: bridge: `elements_per_span`", "700,000,007 DOFs", "COSIM_MAX_DOFS")
    assert "100,000,000 elements" in line and not (tmp_path / "o.mcap").exists()


def test_a_limit_is_raised_with_its_environment_variable(monkeypatch: pytest.MonkeyPatch) -> None:
    MAX_DOFS.check(MAX_DOFS.default, "key")  # at the limit: fine
    with pytest.raises(ConfigError, match="COSIM_MAX_DOFS"):
        MAX_DOFS.check(MAX_DOFS.default + 1, "key")
    monkeypatch.setenv("COSIM_MAX_DOFS", "5e6")
    MAX_DOFS.check(MAX_DOFS.default + 1, "key")
    monkeypatch.setenv("COSIM_MAX_DOFS", "lots")
    with pytest.raises(ConfigError, match="environment variable COSIM_MAX_DOFS: expected an integer >= 1"):
        MAX_DOFS.check(1, "key")


def test_a_fine_section_mesh_is_bounded_before_meshing(tmp_path: Path) -> None:
    scenario = write(tmp_path, "plates.toml", PAPER_PLATES.format(mesh=1e-5))
    assert_limit_error(cosim_cli("modes", str(scenario), cwd=tmp_path), "plates.toml: bridge.section: `mesh_size`",
                       "COSIM_MAX_SECTION_TRIANGLES")


def test_a_study_of_a_hundred_million_seeds_is_refused_at_once(tmp_path: Path) -> None:
    sumo_folder(tmp_path)
    write(tmp_path, "base.toml", SUMO_SCENARIO.format(end=60.0))
    study = write(tmp_path, "s.toml", '[study]\nbase = "base.toml"\n[sweep]\nseeds = 100000000\n')
    result = cosim_cli("study", str(study), "--workers", "0", cwd=tmp_path)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert "sweep.seeds: 100,000,000 seeds is more than the limit of 10,000 runs" in result.stderr
    assert "COSIM_MAX_RUNS" in result.stderr and not (tmp_path / "studies").exists()
    study = write(tmp_path, "s.toml", '[study]\nbase = "base.toml"\n[sweep]\nseeds = 200\n'
                                      'vehicles_per_hour = [' + ", ".join(str(100.0 + i) for i in range(60)) + "]\n")
    assert_limit_error(cosim_cli("study", str(study), "--workers", "0", cwd=tmp_path), "s.toml: sweep", "12,000 runs",
                       "COSIM_MAX_RUNS")


def test_a_road_profile_with_a_tiny_spacing_is_refused(tmp_path: Path) -> None:
    write(tmp_path, "data/road.csv", "x,r\n-1.0,0.0\n-0.999999999999,0.0\n21.0,0.001\n")
    scenario = write(tmp_path, "s.toml", PROFILED)
    assert_limit_error(cosim_cli("run", str(scenario), cwd=tmp_path), "s.toml: road.profile:", "COSIM_MAX_ROAD_POINTS")


def test_an_iso_road_on_a_very_long_bridge_is_refused_before_the_grid(tmp_path: Path) -> None:
    undamped = STATIC.replace('[bridge.damping]\nratios = [0.02, 0.02]\nmodes = ["vertical-1", "torsion-1"]\n', "")
    scenario = write(tmp_path, "long.toml", undamped.replace("spans = [20.0]", "spans = [1e6]") + (
        '[[vehicles]]\nmodel = "moving-force"\nmass = 1000.0\ny = 0.0\nspeed = 10.0\n'
        '[road]\nclass = "A"\nseed = 1\n[solver]\nduration = 1.0\n'))
    assert_limit_error(cosim_cli("run", str(scenario), cwd=tmp_path), "long.toml: road: `class`",
                       "COSIM_MAX_ROAD_POINTS")


def test_a_run_of_too_many_steps_is_refused_before_its_log(tmp_path: Path) -> None:
    write(tmp_path, "data/road.csv", ROAD_CSV)
    scenario = write(tmp_path, "s.toml", PROFILED.replace("[solver]\ndt = 0.002", "[solver]\ndt = 0.002\n"
                                                                                  "duration = 1e9"))
    assert_limit_error(cosim_cli("run", str(scenario), "--out", "o.mcap", cwd=tmp_path), "s.toml: solver.duration",
                       "500,000,000,000 time steps", "COSIM_MAX_STEPS")
    assert not (tmp_path / "o.mcap").exists()


def _peak_memory_mb(*args: str, cwd: Path) -> tuple[subprocess.CompletedProcess[str], float]:
    """``cosim ARGS`` in a real process; its exit and its peak resident memory (VmHWM), MB."""
    # VmHWM, not ru_maxrss: Linux keeps ru_maxrss across exec, so a child of a big pytest would report pytest's.
    code = ("import sys\nfrom cosim.cli import main\nstatus = main(sys.argv[1:])\n"
            "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM:')][0].split()[1]\n"
            "print(int(hwm) / 1024, file=sys.stderr)\nsys.exit(status)")
    result = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd,
                            env=cli_env(), timeout=120)
    *lines, peak = result.stderr.strip().splitlines()
    return subprocess.CompletedProcess(result.args, result.returncode, result.stdout, "\n".join(lines)), float(peak)


def test_a_33_kb_log_claiming_a_1_gb_chunk_is_refused_in_little_memory(tmp_path: Path) -> None:
    """Its chunk really holds 1 GB of zeros: the claim is refused before anything is decompressed."""
    log = bomb(tmp_path / "bomb.mcap", claimed=1 << 30)
    assert log.stat().st_size < 100_000
    result, peak = _peak_memory_mb("info", str(log), cwd=tmp_path)
    assert "chunk 1" in assert_limit_error(result, "1,073,741,824 bytes", "COSIM_MAX_CHUNK_BYTES")
    assert peak < 300, peak  # the imports take ~140 MB; the chunk would take 1000+
    assert_limit_error(cosim_cli("export", str(log), "--csv", str(tmp_path / "o.csv"), cwd=tmp_path),
                       "COSIM_MAX_CHUNK_BYTES")
    assert not (tmp_path / "o.csv").exists()


def test_a_chunk_that_lies_about_its_size_cannot_be_decompressed_past_its_claim(tmp_path: Path) -> None:
    """The same 1 GB of zeros claiming 1 MB: decompression stops at the claim."""
    log = bomb(tmp_path / "liar.mcap", claimed=1 << 30)
    raw = bytearray(log.read_bytes())
    at = raw.index((1 << 30).to_bytes(8, "little"))
    raw[at:at + 8] = (1 << 20).to_bytes(8, "little")
    log.write_bytes(bytes(raw))
    result = cosim_cli("info", str(log), cwd=tmp_path)
    assert result.returncode == 2 and "cannot be decompressed" in result.stderr, result.stderr
    assert MAX_CHUNK_BYTES.value() >= 1 << 20


def test_a_log_claiming_a_billion_seconds_replays_no_further_than_its_samples(sumo_log: Path, tmp_path: Path) -> None:
    """The metadata says 1e9 s and the last message sits at 1e9 s: the replay still covers only what the
    log's sensor samples span (80 s), and a log whose scenario asks for too many steps is refused."""
    crafted = rewrite(sumo_log, tmp_path / "long.mcap", metadata={"cosim": {"duration": "1e9"}})
    result = cosim_cli("replay", str(crafted), "--out", str(tmp_path / "r.mcap"), "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "duration 80 s" in result.stdout
