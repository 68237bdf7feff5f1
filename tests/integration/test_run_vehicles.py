"""``cosim run`` with scripted vehicles: the time simulation, its log, an optional CSV and the summary."""
from __future__ import annotations

import csv
import io
import re
from pathlib import Path

import numpy as np
import pytest
from _cli import TWO_CARS, cosim_cli

from cosim import cli
from cosim.cli import summary as cli_summary
from cosim.errors import ModelError
from cosim.log import TOPIC_SENSORS, read_log
from cosim.run import logged as runner

# The shared two cars without ids (they are V1, V2 by position) and sampled every 5th step.
TWO_CARS = (TWO_CARS.replace('id = "truck"\n', "").replace('id = "car"\n', "")
            + "[output]\nevery = 5\n")
STEPS = 2000  # 4 s at 2 ms
ROWS = STEPS // 5 + 1  # every 5th step, and t = 0


def scenario_file(tmp_path: Path, text: str = TWO_CARS, name: str = "two-cars.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def read_csv(path: Path) -> tuple[list[str], list[list[float]]]:
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return rows[0], [[float(v) for v in row] for row in rows[1:]]


def only_log(folder: Path) -> Path:
    logs = sorted(folder.glob("*.mcap"))
    assert len(logs) == 1, logs
    return logs[0]


def test_two_vehicles_end_to_end(tmp_path: Path) -> None:
    path = scenario_file(tmp_path)
    result = cosim_cli("run", str(path), "--csv", "run.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    # The light progress display (stderr is not a terminal here).
    assert re.search(r"Simulating 4 s:( \d+%)+ 100%", result.stderr), result.stderr

    log = only_log(tmp_path / "runs")  # default: runs/<name>-<date>-<time>.mcap
    assert re.fullmatch(r"two-cars-\d{8}-\d{6}\.mcap", log.name), log.name
    header, rows = read_csv(tmp_path / "run.csv")
    assert header == ["t", "mid", "mid_left_acc"]
    assert len(rows) == ROWS
    assert rows[0] == [0.0, 0.0, 0.0]
    assert rows[1][0] == pytest.approx(0.01) and rows[-1][0] == pytest.approx(4.0)

    out = result.stdout
    assert "V1  quarter-car" in out and "V2  golden-car" in out  # default ids
    assert "duration 4 s (last vehicle leaves the deck at 2 s, + 2 s)" in out
    assert f"Log: {Path('runs') / log.name}, sampled at 100 Hz (every 5 steps)" in out
    events = re.search(r"^Lift-off events: (\d+) \((\d+) vehicle-steps", out, flags=re.M)
    assert events is not None, out
    assert int(events[1]) > 0 and int(events[2]) >= int(events[1])  # a class H road lifts the wheels
    assert re.search(rf"^Time stepping: {STEPS} steps in [0-9.]+ s wall time; real-time factor [0-9.e+]+ "
                     r"\(simulated time / wall time\)$", out, flags=re.M), out
    assert re.search(r"^Effective-matrix factorisations: 1 \(direct basis", out, flags=re.M), out
    vehicle_rows = {line.split()[0]: line for line in out.splitlines() if re.match(r"  V\d ", line)}
    assert vehicle_rows["V1"].split()[1:4] == ["0.002", "-", "2.000"]  # on the deck, every step
    assert vehicle_rows["V1"].endswith("yes")
    sensors = {line.split()[0]: line.split() for line in out.splitlines() if line.startswith("  mid")}
    assert sensors["mid"][-1] == "mm" and sensors["mid_left_acc"][-1] == "m/s^2"
    # The summary's peaks are over every step, the CSV keeps every 5th: as low or lower, and close.
    mid_mm = [1e3 * row[1] for row in rows]
    assert float(sensors["mid"][-3]) <= min(mid_mm) + 1e-9
    assert float(sensors["mid"][-3]) == pytest.approx(min(mid_mm), rel=2e-2)
    assert f"Wrote the log {Path('runs') / log.name} (" in out
    assert f"Wrote {ROWS} rows to run.csv" in out


def test_default_run_is_ten_minutes_of_sumo_traffic(tmp_path: Path) -> None:
    result = cosim_cli("run", "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "Scenario: paper-bridge-traffic" in out and "Traffic: SUMO" in out and "medium demand" in out
    assert "Road: ISO 8608 class A, seed 1" in out
    on_deck = int(out.split("Vehicles: ")[1].split(" ")[0])
    assert on_deck > 100  # 10 min at 500 vehicles per hour and direction
    log = only_log(tmp_path / "runs")
    info = cosim_cli("info", str(log), cwd=tmp_path).stdout
    assert "/cosim/traffic" in info and "Truncated: no" in info
    # Both directions load the deck: the right edge (eastbound lane) and the left edge both go down.
    assert cosim_cli("export", str(log), "--csv", "default.csv", cwd=tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "default.csv")
    low = {name: min(row[i] for row in rows) for i, name in enumerate(header) if i}
    assert low["node2"] < -5e-3 and low["edge_right"] < -5e-3
    assert rows[-1][0] == pytest.approx(600.0)


def test_the_papers_two_quarter_cars(tmp_path: Path) -> None:
    result = cosim_cli("run", "paper-double-tee", "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # --quiet: no progress display
    assert "QC-1  quarter-car" in result.stdout and "QC-2  quarter-car" in result.stdout
    assert "Lift-off events: 0 " in result.stdout  # a smooth road
    log = only_log(tmp_path / "runs")
    assert cosim_cli("export", str(log), "--csv", "paper.csv", cwd=tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "paper.csv")
    assert header == ["t", "node1", "node2", "node3", "node3_acc"]
    assert len(rows) == 4001 and rows[-1][0] == pytest.approx(20.0)  # [output] every = 1
    # Both cars drive at y = +3.325 (left of the axis): the deck twists, the
    # left edge (node2) deflects most, the axis (node1) least.
    low = {name: min(row[i] for row in rows) for i, name in enumerate(header) if i}
    assert low["node2"] < low["node3"] < low["node1"] < 0


# --------------------------------------------------------------------------- in process


def run_main(*args: str) -> int:
    return cli.main(["run", *args])


def test_refuses_to_overwrite_without_force(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario_file(tmp_path)
    out = tmp_path / "deep" / "er" / "run.mcap"
    assert run_main(str(path), "--out", str(out), "--quiet") == 0  # folders created
    first = read_log(out).topic(TOPIC_SENSORS)
    capsys.readouterr()

    before = out.read_bytes()
    assert run_main(str(path), "--out", str(out)) == 2
    captured = capsys.readouterr()
    assert captured.err == f"cosim: error: {out}: already exists; refusing to overwrite the log (use --force)\n"
    assert captured.out == ""  # refused before the work
    assert out.read_bytes() == before

    assert run_main(str(path), "--out", str(out), "--force", "--quiet") == 0
    assert read_log(out).topic(TOPIC_SENSORS) == first  # the same run, the same numbers


def test_output_log_and_csv_from_the_scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    text = TWO_CARS.replace("every = 5", 'log = "results/cars.mcap"\ncsv = "results/cars.csv"\nevery = 100')
    path = scenario_file(tmp_path, text)
    monkeypatch.chdir(tmp_path)
    assert run_main(str(path), "--quiet") == 0
    header, rows = read_csv(tmp_path / "results" / "cars.csv")  # relative to the current folder
    assert len(rows) == STEPS // 100 + 1
    assert read_log(tmp_path / "results" / "cars.mcap").final_status["state"] == "finished"
    assert not (tmp_path / "runs").exists()
    out = capsys.readouterr().out
    assert "sampled at 5 Hz (every 100 steps)" in out


def test_vehicle_entering_after_the_run_is_reported(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = TWO_CARS.replace("entry_time = 0.5", "entry_time = 5.0").replace("dt = 0.002", "dt = 0.002\nduration = 1.0")
    path = scenario_file(tmp_path, text)
    assert run_main(str(path), "--out", str(tmp_path / "o.mcap"), "--quiet") == 0
    assert "V2  not on the deck during the run" in capsys.readouterr().out


def test_divergence_exits_1_with_a_finished_log(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    def diverge(bridge, traffic, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        traffic.block(np.array([0.002]))  # the time stepping starts, then fails
        raise ModelError("the solution diverged at t = 1.234 s (non-finite bridge acceleration)")

    monkeypatch.setattr(runner, "simulate", diverge)
    path = scenario_file(tmp_path)
    out, table = tmp_path / "o.mcap", tmp_path / "o.csv"
    assert run_main(str(path), "--out", str(out), "--csv", str(table), "--quiet") == 1
    err = capsys.readouterr().err
    assert err.startswith(f"cosim: error: {path}: the solution diverged at t = 1.234 s")
    assert "likely cause" in err and f'its log {out} is finished, status "error"' in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    status = read_log(out).final_status
    assert status["state"] == "error" and "diverged at t = 1.234 s" in status["message"]
    assert not table.exists()


def test_interrupt_exits_130_with_a_finished_log(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    def interrupted(bridge, traffic, *args, progress=None, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        traffic.block(np.array([0.002]))  # the time stepping starts
        progress(0.25)
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "simulate", interrupted)
    path = scenario_file(tmp_path)
    out = tmp_path / "o.mcap"
    assert run_main(str(path), "--out", str(out)) == 130
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == (f"cosim: interrupted by SIGINT at about t = 1 s of 4 s; the log up to there is in "
                                    f"{out} "
                                    '(finished, status "interrupted")')
    log = read_log(out)
    assert not log.truncated and log.final_status["state"] == "interrupted"


def test_progress_bar_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    progress = cli_summary.Progress(20.0, show=True)
    progress(0.5)
    progress(1.0)
    progress.close()
    text = terminal.getvalue()
    assert "Simulating" in text and "100%" in text and "20.0/20.0 s" in text

    quiet = Terminal()
    monkeypatch.setattr("sys.stderr", quiet)
    progress = cli_summary.Progress(20.0, show=False)
    progress(1.0)
    progress.close()
    assert quiet.getvalue() == ""


def test_a_compilation_before_the_first_step_is_announced_once(capsys: pytest.CaptureFixture[str]) -> None:
    # A first run after installing compiles the solver for about a minute with nothing else on the screen: the
    # display says so, once, when numba really compiles (a real compilation of a new function here).
    import numba

    def fresh(k: int):  # noqa: ANN202
        return numba.njit(cache=False)(lambda x: x + k)

    notice = cli_summary.CompileNotice()
    notice.start()
    try:
        fresh(1)(1.0)
        fresh(2)(1.0)  # a second compilation: no second line
    finally:
        notice.stop()
    fresh(3)(1.0)  # stopped: nothing
    err = capsys.readouterr().err
    assert err.count("Compiling cosim's solver") == 1 and err.endswith("before the first time step ...\n")
