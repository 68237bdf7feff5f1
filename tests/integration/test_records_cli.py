"""WIM records through the command line (issue 25, items 2 and 7): bad records are one line naming the file and
the line, exit 2, nothing written; a run of records is logged (each vehicle's axles on and off the deck once,
each record's loads once) and replayed from its log alone."""
from __future__ import annotations

from datetime import date
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli

from cosim.core.loads import VehicleRecord, write_records
from cosim.log import read_log
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_VEHICLE_LOADS

T = 981.0

SCENARIO = """
name = "wim"
[bridge]
spans = [30.0]
elements_per_span = 10
supports = ["pinned", "fork"]
[bridge.material]
E = 3.5e10
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = 15.0
[traffic.records]
file = "wim.castor"
format = "castor"
via = "scripted"
lanes = [{lane = 1, y = -1.875, direction = "+x"}, {lane = 2, y = 1.875, direction = "-x"}]
[solver]
dt = 0.01
[output]
rate_hz = 20.0
"""


def records(count: int = 12) -> list[VehicleRecord]:
    out = []
    for n in range(count):
        loads = (50, 90, 70, 70) if n % 3 else (8, 7)
        spacings = (3.6, 5.4, 1.3) if n % 3 else (2.6,)
        axles = tuple(w * T for w in loads)
        out.append(VehicleRecord(time=3600.0 + 2.37 * n, lane=0, direction=1 + n % 2, local_lane=1,
                                 speed=18.0 + n % 4, gross_weight=sum(axles), axle_loads=axles,
                                 axle_spacings=spacings, length=sum(spacings) + 2.5, origin=date(2024, 5, 6)))
    return out


def folder_with(tmp_path: Path, lines: list[str] | None = None) -> Path:
    write_records(tmp_path / "wim.castor", "castor", records())
    if lines is not None:
        (tmp_path / "wim.castor").write_text("\n".join(lines) + "\n", encoding="ascii")
    (tmp_path / "wim.toml").write_text(SCENARIO, encoding="utf-8")
    return tmp_path


def assert_one_line_and_nothing_written(tmp_path: Path, starts: str) -> None:
    before = sorted(p.name for p in tmp_path.iterdir())
    result = cosim_cli("run", "wim.toml", "--out", "run.mcap", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: " + starts), result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # no log, no partial file, no runs/ folder


def test_a_lane_the_table_does_not_map_is_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    folder = folder_with(tmp_path)
    lines = (folder / "wim.castor").read_text().splitlines()
    lines[4] = lines[4][:30] + "2" + lines[4][31:]  # direction 1 / lane 2: with one lane of direction 2, lane 2
    (folder / "wim.castor").write_text("\n".join(lines) + "\n")
    assert_one_line_and_nothing_written(folder, "wim.castor: line 2: direction 2 / lane 1 is lane 3 as BTLS numbers "
                                                "them (2 lane(s) in direction 1, 1 in direction 2), which "
                                                "traffic.records.lanes does not map")


def test_times_going_backwards_are_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    folder = folder_with(tmp_path)
    lines = (folder / "wim.castor").read_text().splitlines()
    lines[6], lines[7] = lines[7], lines[6]
    (folder / "wim.castor").write_text("\n".join(lines) + "\n")
    assert_one_line_and_nothing_written(folder, "wim.castor: line 8: its time is 2.37 s before the previous "
                                                "record's (line 7); the records must be in time order")


def test_a_bad_record_is_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    folder = folder_with(tmp_path)
    lines = (folder / "wim.castor").read_text().splitlines()
    lines[9] = lines[9][:21] + " 999" + lines[9][25:]  # the gross weight no longer the axles' sum
    (folder / "wim.castor").write_text("\n".join(lines) + "\n")
    assert_one_line_and_nothing_written(folder, "wim.castor: line 10: the axle loads add up to")


def test_a_missing_file_is_one_line_naming_the_key(tmp_path: Path) -> None:
    folder = folder_with(tmp_path)
    (folder / "wim.castor").unlink()
    assert_one_line_and_nothing_written(folder, "wim.toml: traffic.records.file: file not found: ")


@pytest.fixture(scope="module")
def logged(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    folder = folder_with(tmp_path_factory.mktemp("wim"))
    result = cosim_cli("run", "wim.toml", "--out", "run.mcap", cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder, result


def test_a_run_of_records_is_logged_vehicle_by_vehicle(logged: tuple[Path, object]) -> None:
    folder, result = logged
    assert "Records: wim.castor (castor), 12 of its 12 records in the whole file" in result.stdout
    log = read_log(folder / "run.mcap")
    assert log.metadata["cosim"]["traffic"] == "records"
    assert "wim.castor" in log.attachments  # a replay needs nothing but the log
    loads = log.topic(TOPIC_VEHICLE_LOADS)
    assert [m["id"] for m in loads] == [f"wim:{k + 1}" for k in range(12)]
    assert [m["class"] for m in loads] == ["car" if k % 3 == 0 else "truck-4" for k in range(12)]
    events: dict[str, list[str]] = {}
    for m in log.topic(TOPIC_EVENTS):
        events.setdefault(m["vehicle"], []).append(m["event"])
    expected = {f"wim:{k + 1}#{a}" for k in range(12) for a in range(2 if k % 3 == 0 else 4)}
    assert set(events) == expected and all(e == ["entered", "left"] for e in events.values())
    # the run's t = 0 is midnight of the file's first day: the first vehicle comes at 3600 s
    assert loads[0]["t"] == pytest.approx(3600.0) and log.topic("/cosim/sensors")[-1]["t"] > 3626.0


def test_a_run_of_records_replays_from_its_log(logged: tuple[Path, object]) -> None:
    folder, _ = logged
    result = cosim_cli("replay", "run.mcap", "--out", "again.mcap", cwd=folder)
    assert result.returncode == 0, result.stderr
    a = read_log(folder / "run.mcap").topic("/cosim/sensors")
    b = read_log(folder / "again.mcap").topic("/cosim/sensors")
    assert np.array_equal([m["mid"] for m in a], [m["mid"] for m in b])
