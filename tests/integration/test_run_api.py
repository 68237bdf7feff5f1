"""The library functions the command line calls, one per command (docs/architecture.md): called from Python,
they do the whole command and return a frozen outcome with what the command prints."""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from _cli import TWO_CARS

from cosim.run.api import LoggedRun, StaticRun, bridge_modes, run_scenario, static_loads
from cosim.run.export import write_layout
from cosim.run.loginfo import log_info
from cosim.run.replay import replay_log
from cosim.run.scenario import parse_scenario


@pytest.fixture(scope="module")
def logged(tmp_path_factory: pytest.TempPathFactory) -> tuple[LoggedRun, list[str]]:
    """The two cars of ``_cli.TWO_CARS`` run into a log and a CSV, with what the callbacks were told."""
    folder = tmp_path_factory.mktemp("api")
    heard: list[str] = []
    done = run_scenario(parse_scenario(TWO_CARS, "two-cars.toml", base_dir=folder), out=folder / "run.mcap",
                        csv=folder / "run.csv", checked=lambda s: heard.append(f"checked {s.title}"),
                        ready=lambda start: heard.append(f"ready {start.log_path.name} {start.duration:g}"),
                        progress=lambda fraction: heard.append("progress"))
    assert isinstance(done, LoggedRun)
    return done, heard


def test_run_scenario_runs_logs_and_exports_in_one_call(logged: tuple[LoggedRun, list[str]]) -> None:
    done, heard = logged
    start, outcome = done.start, done.outcome
    assert heard[:2] == ["checked two-cars", f"ready run.mcap {start.duration:g}"]
    assert heard[2:] and set(heard[2:]) == {"progress"}
    assert outcome.log_path == start.log_path and outcome.log_path.is_file()
    assert outcome.duration == start.duration == pytest.approx(4.0)
    assert start.bridge.length == 20.0 and start.plan is None and not start.replayed_frames
    assert done.csv_path is not None and done.csv_columns == ("t", "mid", "mid_left_acc")
    assert done.csv_rows == outcome.samples == len(done.csv_path.read_text().splitlines()) - 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        done.csv_rows = 0  # type: ignore[misc]


def test_replay_log_reproduces_the_run_bit_for_bit(logged: tuple[LoggedRun, list[str]], tmp_path: Path) -> None:
    done, _ = logged
    heard: list[str] = []
    replay = replay_log(done.outcome.log_path, out=tmp_path / "replay.mcap",
                        checked=lambda plan: heard.append(f"checked {plan.own}"),
                        ready=lambda start: heard.append(f"ready {start.log_path.name}"))
    assert heard == ["checked True", "ready replay.mcap"]
    assert replay.own and replay.log == done.outcome.log_path
    assert replay.outcome.log_path == tmp_path / "replay.mcap"
    assert replay.comparison.identical and replay.comparison.compared == done.outcome.samples
    assert replay.start.duration == done.start.duration


def test_log_info_and_write_layout_of_the_run(logged: tuple[LoggedRun, list[str]], tmp_path: Path) -> None:
    done, _ = logged
    info = log_info(done.outcome.log_path, verify=True)
    assert info.overview.complete and info.deck is None  # scripted vehicles: no SUMO vehicles to list
    shown = write_layout(done.outcome.log_path, tmp_path / "layout.json")
    assert json.loads((tmp_path / "layout.json").read_text()) and not shown.sumo
    assert [name for name, _ in shown.sensors] == ["mid", "mid_left_acc"]


def test_a_scenario_without_vehicles_gives_its_modes_and_static_case(tmp_path: Path) -> None:
    text = TWO_CARS[:TWO_CARS.index("[[vehicles]]")]
    scenario = parse_scenario(text, "no-vehicles.toml", base_dir=tmp_path)  # its name stays "two-cars"
    heard: list[str] = []
    done = run_scenario(scenario, out=tmp_path / "summary.json", checked=lambda s: heard.append(s.title),
                        ready=lambda start: heard.append("ready"))
    assert isinstance(done, StaticRun) and heard == ["two-cars"]
    assert len(done.modal.f_hz) == 10 and [c["name"] for c in done.cases] == ["axis", "left_edge"]
    assert done.summary_path == tmp_path / "summary.json"
    summary = json.loads(done.summary_path.read_text())
    assert summary["static"][0]["load"]["Fz"] == -100e3 and len(summary["modes"]) == 10


def test_bridge_modes_and_static_loads(tmp_path: Path) -> None:
    scenario = parse_scenario(TWO_CARS, "two-cars.toml", base_dir=tmp_path)
    modes = bridge_modes(scenario, 4, plot=tmp_path / "modes.png")
    assert len(modes.modal.f_hz) == 4 and modes.plotted == 4 and (tmp_path / "modes.png").is_file()
    loads = static_loads(scenario, [(10.0, 0.0, -1e5)])
    assert loads.response["loads"][0]["w"] < 0 and [s["name"] for s in loads.response["sensors"]] == [
        "mid", "mid_left_acc"]
