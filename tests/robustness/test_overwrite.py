"""Issue item 2: nothing is replaced without ``--force``, never a command's own input even with it,
and outputs are written whole or not at all (no temporary file left behind)."""
from __future__ import annotations

import shutil
from pathlib import Path

from _craft import edit_protobuf, rewrite
from _robust import PROFILED, ROAD_CSV, cosim_cli, write

from cosim.log import TOPIC_SENSORS

# A bridge without vehicles: `cosim run` does the modes and a static case, `--out` writes them as JSON.
STATIC = PROFILED[:PROFILED.index("[[vehicles]]")].replace('name = "profiled"', 'name = "static"')


def refused(result, *fragments: str) -> None:  # noqa: ANN001 - CliResult
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: ") and "Traceback" not in result.stderr, lines
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


def no_partial_files(folder: Path) -> None:
    left = [p.name for p in folder.rglob("*") if ".part" in p.name]
    assert not left, left


def test_export_never_replaces_the_log_it_reads(profiled_log: Path, tmp_path: Path) -> None:
    log = shutil.copy(profiled_log, tmp_path / "L.mcap")
    before = Path(log).read_bytes()
    refused(cosim_cli("export", str(log), "--csv", str(log), "--force", cwd=tmp_path), "is the log of this command",
            "even with --force")
    (tmp_path / "link.csv").symlink_to(log)  # the same file under another name
    refused(cosim_cli("export", str(log), "--csv", str(tmp_path / "link.csv"), "--force", cwd=tmp_path),
            "is the log of this command")
    (tmp_path / "fig.png").symlink_to(log)
    refused(cosim_cli("plot", str(log), "-o", str(tmp_path / "fig.png"), "--force", cwd=tmp_path),
            "is the log of this command")
    assert Path(log).read_bytes() == before
    no_partial_files(tmp_path)


def test_run_never_writes_its_csv_over_its_log_or_its_inputs(tmp_path: Path) -> None:
    scenario = write(tmp_path, "s.toml", PROFILED)
    write(tmp_path, "data/road.csv", ROAD_CSV)
    refused(cosim_cli("run", str(scenario), "--out", "o.mcap", "--csv", "o.mcap", "--force", cwd=tmp_path),
            "o.mcap", "is the run's log (--out)")
    refused(cosim_cli("run", str(scenario), "--out", "o.mcap", "--csv", "s.toml", "--force", cwd=tmp_path),
            "is the scenario of this command")
    refused(cosim_cli("run", str(scenario), "--out", "o.mcap", "--csv", "data/road.csv", "--force", cwd=tmp_path),
            "is an input file of the scenario (road.profile)")
    assert not (tmp_path / "o.mcap").exists() and scenario.read_text() == PROFILED
    assert (tmp_path / "data/road.csv").read_text() == ROAD_CSV


def test_a_static_run_refuses_an_existing_summary_and_never_replaces_its_scenario(tmp_path: Path) -> None:
    scenario = write(tmp_path, "nov.toml", STATIC)
    other = write(tmp_path, "other.json", "precious\n")
    refused(cosim_cli("run", str(scenario), "--out", str(other), cwd=tmp_path), "already exists", "--force")
    assert other.read_text() == "precious\n"
    refused(cosim_cli("run", str(scenario), "--out", str(scenario), "--force", cwd=tmp_path),
            "is the scenario of this command")
    assert scenario.read_text() == STATIC
    result = cosim_cli("run", str(scenario), "--out", str(other), "--force", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert other.read_text().startswith("{")
    no_partial_files(tmp_path)


def test_modes_plot_and_validate_refuse_to_overwrite(tmp_path: Path) -> None:
    scenario = write(tmp_path, "nov.toml", STATIC)
    figure = write(tmp_path, "modes.png", "precious")
    refused(cosim_cli("modes", str(scenario), "--plot", str(figure), cwd=tmp_path), "already exists", "--force")
    assert figure.read_text() == "precious"
    refused(cosim_cli("modes", str(scenario), "--plot", str(scenario), "--force", cwd=tmp_path),
            "is the scenario of this command")
    result = cosim_cli("modes", str(scenario), "--count", "3", "--plot", str(figure), "--force", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert figure.read_bytes().startswith(b"\x89PNG")
    report = write(tmp_path, "validation/report.md", "precious")
    refused(cosim_cli("validate", "--out", str(report.parent), cwd=tmp_path), "already holds a validation report")
    assert report.read_text() == "precious"
    no_partial_files(tmp_path)


def test_a_log_that_fails_half_way_through_an_export_leaves_no_csv(profiled_log: Path, tmp_path: Path) -> None:
    """The 300th sensor sample is crafted to be NaN (a valid protobuf double): the export stops there, and nothing
    is left."""
    seen = {"n": 0}

    def spoil(schema, topic: str, data: bytes) -> bytes:  # noqa: ANN001
        if topic == TOPIC_SENSORS:
            seen["n"] += 1
            if seen["n"] == 300:
                return edit_protobuf(schema, data, lambda m: setattr(m, "mid", float("nan")))
        return data

    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", raw=spoil)
    refused(cosim_cli("export", str(crafted), "--csv", str(tmp_path / "out.csv"), cwd=tmp_path),
            "/cosim/sensors", "mid: expected a finite number")
    assert not (tmp_path / "out.csv").exists()
    no_partial_files(tmp_path)
