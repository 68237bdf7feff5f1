"""The command line as users run it: its output and exit statuses (in this process through ``cosim.cli.main``),
and ``python -m cosim`` as a real process."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import cosim
from cosim.cli import main

REPO = Path(cosim.__file__).resolve().parents[1]
PAPER_TEXT = (REPO / "cosim" / "scenarios" / "paper-double-tee.toml").read_text(encoding="utf-8")


def _without_vehicles(text: str) -> str:
    """The paper's bridge and sensors, without its [[vehicles]] and [road]."""
    start = text.index("[[vehicles]]")
    start = text.rindex("\n\n", 0, start) + 1  # with the comment above the first vehicle
    return text[:start] + text[text.index("[solver]"):]


PAPER_STATIC_TEXT = _without_vehicles(PAPER_TEXT)


from _cli import cli_env, cosim_cli, cosim_process  # noqa: E402

# --------------------------------------------------------------------------- help


@pytest.mark.parametrize(
    ("args", "mentions"),
    [
        ((), ["modes", "run", "replay", "export", "info", "plot", "docs/scenario.md", "examples:"]),
        (("modes",), ["SCENARIO", "--count", "--json", "--plot", "examples:"]),
        (("run",), ["SCENARIO", "--out", "LOG.mcap", "--csv", "--force", "--quiet", "paper-double-tee", "examples:"]),
        (("replay",), ["LOG.mcap", "--scenario", "--out", "bit for bit", "examples:"]),
        (("export",), ["LOG.mcap", "--csv", "--topic", "/cosim/vehicles", "--from", "--to", "examples:"]),
        (("info",), ["LOG.mcap", "truncated", "--verify", "examples:"]),
        (("plot",), ["LOG.mcap", "--sensor", "-o", "--from", "--to", "examples:"]),
    ],
    ids=["cosim", "modes", "run", "replay", "export", "info", "plot"],
)
def test_help_exits_zero_and_describes_options(args: tuple[str, ...], mentions: list[str]) -> None:
    result = cosim_cli(*args, "--help")
    assert result.returncode == 0, result.stderr
    for word in mentions:
        assert word in result.stdout, word


#: What the help of cosim and of its commands must not load: each command imports them when it runs.
HEAVY = ("numpy", "scipy", "numba", "matplotlib", "mcap", "sumolib", "libsumo", "traci", "pydantic", "pandas",
         "dask", "distributed", "sectionproperties", "shapely", "tqdm")


@pytest.mark.parametrize("command", ["", "modes", "static", "run", "replay", "export", "info", "plot", "layout",
                                     "validate", "study", "dataset", "bridge"], ids=lambda c: c or "cosim")
def test_help_loads_no_heavy_library(command: str) -> None:
    """``cosim --help`` and ``cosim <command> --help`` build the whole parser and print, loading none of the
    libraries the commands work with (a fresh process: what a user's ``cosim ... --help`` loads)."""
    result = _loading(([command] if command else []) + ["--help"], HEAVY, REPO)
    assert result.stdout.splitlines()[-1] == "loaded: [] status: 0", result.stdout.splitlines()[-1]
    assert (f"usage: cosim {command}" if command else "usage: cosim [-h]") in result.stdout


def _loading(argv: list[str], libraries: tuple[str, ...], cwd: Path) -> subprocess.CompletedProcess[str]:
    """``cosim *argv`` in a fresh process, which prints as its last line which of ``libraries`` it loaded and
    ``main``'s status."""
    code = ("import sys\nfrom cosim.cli import main\n"
            "status = main(sys.argv[1:])\n"
            f"loaded = sorted({{name.split('.')[0] for name in sys.modules}} & set({libraries!r}))\n"
            "print('loaded:', loaded, 'status:', status)\n")
    result = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, cwd=cwd,
                            env=cli_env(), timeout=120)
    assert result.returncode == 0, result.stderr
    return result


#: What reading a log or a SUMO network must not load: the compiled kernels (numba), scipy, SUMO itself, the
#: scenario's validation and studies (a network is read with sumolib).
NOT_FOR_READING = ("numba", "scipy", "libsumo", "traci", "pydantic", "dask", "distributed", "sectionproperties")
_LOG = REPO / "tests" / "regression" / "logs" / "paper-bridge-traffic.mcap"
_NET = REPO / "sumo_networks" / "medium.sumocfg"


@pytest.mark.parametrize("argv", [["info", str(_LOG), "--verify"], ["export", str(_LOG), "--csv", "out.csv"],
                                  ["plot", str(_LOG), "-o", "out.png"], ["layout", str(_LOG), "-o", "out.json"],
                                  ["bridge", str(_NET)], ["bridge", str(_NET), "--edge", "bridge_e"]],
                         ids=lambda a: "-".join(x for x in a if not x.startswith("/")))
def test_reading_a_log_or_a_network_loads_no_solver_and_no_sumo(argv: list[str], tmp_path: Path) -> None:
    """``cosim info``, ``export``, ``plot`` and ``layout`` of a SUMO run's log (its vehicle types attached), and
    ``cosim bridge`` of a network, load neither the numerical core's compiled kernels nor SUMO: ``cosim info``
    loaded numba through the adapter and took 1.4 s instead of 0.3 s, ``cosim bridge`` 1.4 s instead of 0.5 s
    (measured side by side on this machine)."""
    result = _loading(argv, NOT_FOR_READING, tmp_path)
    assert result.stdout.splitlines()[-1] == "loaded: [] status: 0", result.stdout.splitlines()[-1]


@pytest.mark.parametrize(("argv", "expected"), [
    (["export", "x.mcap", "--csv", "o.csv", "--from", "-1e5", "--to", "-5."], {"start": -1e5, "end": -5.0}),
    (["plot", "x.mcap", "-o", "f.png", "--fro", "-1e3", "--to", "-.5"], {"start": -1e3, "end": -0.5}),
    (["static", "s", "--load", "20", "3.325", "-100e3", "--load", "-1", "-2.5", "-3E3"],
     {"load": [[20.0, 3.325, -1e5], [-1.0, -2.5, -3e3]]}),
    (["bridge", "n.net.xml", "--edge", "-123#0", "--edge", "5", "--near", "-5", "3"],
     {"edge": ["-123#0", "5"], "near": [-5.0, 3.0]}),
], ids=["export", "plot-abbreviated", "static", "bridge"])
def test_values_that_begin_with_a_dash_are_values(argv: list[str], expected: dict) -> None:
    """A negative number after an option that takes numbers ("-1e5": an option to argparse before Python 3.13)
    and a SUMO edge id beginning with "-" are that option's values."""
    from cosim.cli.app import build_parser, values_kept

    args = vars(build_parser().parse_args(values_kept(argv)))
    assert {key: args[key] for key in expected} == expected


def test_python_m_cosim_is_the_command_line_with_its_exit_statuses(tmp_path: Path) -> None:
    """A real process: ``python -m cosim`` exits with main's status and prints errors on one line."""
    result = cosim_process("modes", str(tmp_path / "missing.toml"))
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith(f"cosim: error: {tmp_path / 'missing.toml'}: no such scenario file")
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


def test_version() -> None:
    result = cosim_cli("--version")
    assert result.returncode == 0 and result.stdout.strip() == f"cosim {cosim.__version__}"


def test_no_command_is_a_usage_error() -> None:
    result = cosim_cli()
    assert result.returncode == 2
    assert "usage: cosim" in result.stderr


def test_bad_option_value_is_a_usage_error() -> None:
    result = cosim_cli("modes", "paper-double-tee", "--count", "0")
    assert result.returncode == 2
    assert "--count" in result.stderr
    assert "Traceback" not in result.stderr


# --------------------------------------------------------------------------- errors


def test_malformed_scenario_exits_2_with_one_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER_TEXT.replace("thickness = 0.25", "thickness = -0.25", 1), encoding="utf-8")
    for command in ("modes", "run"):
        result = cosim_cli(command, str(bad))
        assert result.returncode == 2, result.stderr
        assert "Traceback" not in result.stderr
        lines = result.stderr.strip().splitlines()
        assert lines == [f"cosim: error: {bad}: bridge.section.plates[0].thickness: must be > 0 (got -0.25)"]
        assert result.stdout == ""


def test_missing_scenario_file_exits_2(tmp_path: Path) -> None:
    result = cosim_cli("modes", str(tmp_path / "missing.toml"))
    assert result.returncode == 2
    assert result.stderr.startswith(f"cosim: error: {tmp_path / 'missing.toml'}: no such scenario file")
    assert "Traceback" not in result.stderr


def test_main_returns_status_instead_of_exiting(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "typo.toml"
    bad.write_text(PAPER_TEXT.replace("spans = [40.0]", "spanz = [40.0]", 1), encoding="utf-8")
    assert main(["modes", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"cosim: error: {bad}: bridge.spanz: unknown key; did you mean \"spans\"?")
    assert main(["--help"]) == 0
    assert main(["frobnicate"]) == 2


def test_unwritable_output_fails_before_the_work(tmp_path: Path) -> None:
    static = tmp_path / "static.toml"
    static.write_text(PAPER_STATIC_TEXT, encoding="utf-8")
    result = cosim_cli("run", str(static), "--out", str(tmp_path / "no-such-dir" / "summary.json"))
    assert result.returncode == 2
    assert "does not exist" in result.stderr
    assert result.stdout == ""
    # With vehicles, --out is the MCAP log: its folder is created, unless a file is in the way.
    (tmp_path / "a-file").write_text("", encoding="utf-8")
    result = cosim_cli("run", "--out", str(tmp_path / "a-file" / "run.mcap"))
    assert result.returncode == 2
    assert result.stderr.strip() == (
        f"cosim: error: {tmp_path / 'a-file' / 'run.mcap'}: cannot create the folder for the log: "
        f"{str(tmp_path / 'a-file')!r} is a file"
    )
    assert result.stdout == ""


def test_out_is_the_log_and_static_runs_have_none(tmp_path: Path) -> None:
    result = cosim_cli("run", "--out", str(tmp_path / "run.csv"))
    assert result.returncode == 2
    assert "--out is the run's MCAP log (LOG.mcap); for a CSV of the sensors give --csv" in result.stderr
    static = tmp_path / "static.toml"
    static.write_text(PAPER_STATIC_TEXT, encoding="utf-8")
    result = cosim_cli("run", str(static), "--out", str(tmp_path / "run.mcap"))
    assert result.returncode == 2
    assert "no [[vehicles]], so there is no time simulation to log" in result.stderr
    assert not (tmp_path / "run.mcap").exists() and not (tmp_path / "run.csv").exists()


# --------------------------------------------------------------------------- results


def test_modes_json_is_parseable() -> None:
    result = cosim_cli("modes", "paper-double-tee", "--json", "--count", "6")
    assert result.returncode == 0, result.stderr
    payload = json.loads(result.stdout)  # nothing but JSON on stdout
    assert payload["scenario"] == "paper-double-tee"
    modes = payload["modes"]
    assert [m["n"] for m in modes] == [1, 2, 3, 4, 5, 6]
    for mode in modes:
        assert mode["f_hz"] > 0
        assert isinstance(mode["kind"], str) and mode["kind"]
        assert set(mode["participation"]) >= {"vertical", "lateral", "torsion"}
    f = [m["f_hz"] for m in modes]
    assert f == sorted(f)
    assert modes[0]["kind"] == "vertical"
    for key in ("A", "I_y", "I_z", "J", "I_w", "A_sy", "A_sz", "y_s", "z_s"):
        assert key in payload["section"]
    assert payload["damping"]["alpha"] > 0 and payload["damping"]["beta"] > 0


def test_modes_table_and_plot(tmp_path: Path) -> None:
    png = tmp_path / "modes.png"
    result = cosim_cli("modes", "paper-double-tee-asymmetric", "--count", "3", "--plot", str(png))
    assert result.returncode == 0, result.stderr
    for word in ("I_w", "shear centre", "f [Hz]", "vertical", "torsion"):
        assert word in result.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_run_without_vehicles_writes_the_static_summary(tmp_path: Path) -> None:
    static = tmp_path / "paper-static.toml"
    static.write_text(PAPER_STATIC_TEXT.replace('name = "paper-double-tee"', 'name = "paper-static"'), encoding="utf-8")
    out = tmp_path / "summary.json"
    result = cosim_cli("run", str(static), "--out", str(out), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "the scenario has no [[vehicles]]" in result.stdout
    assert not (tmp_path / "runs").exists()  # no time simulation, no log
    summary = json.loads(out.read_text(encoding="utf-8"))
    assert summary["scenario"] == "paper-static"
    assert len(summary["modes"]) == 10
    cases = {case["name"]: case for case in summary["static"]}
    axis, edge = cases["axis"], cases["left_edge"]
    assert axis["load"] == {"x": 20.0, "y": 0.0, "Fz": -100e3, "span": 1}
    assert edge["load"]["y"] == pytest.approx(6.655)
    # A downward load deflects the deck down; on the left edge it twists the
    # deck negatively, so the left edge goes down more than the axis.
    assert axis["sensors"]["node1"] < 0
    assert edge["sensors"]["node2"] < edge["sensors"]["node3"] < edge["sensors"]["node1"] < 0
    assert axis["sensors"]["node2"] == pytest.approx(axis["sensors"]["node1"], rel=1e-3)
