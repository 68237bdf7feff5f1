"""``[traffic.records]`` (issue 25, items 2 and 7): its keys, their defaults and constraints, and the one-line
errors naming the file and the key (docs/scenario.md#trafficrecords)."""
from __future__ import annotations

from datetime import date
from pathlib import Path

import pytest

from cosim.core.loads import VehicleRecord, write_records
from cosim.core.records_traffic import RecordTraffic
from cosim.errors import ConfigError
from cosim.run.scenario import RING_DOWN, load_scenario
from cosim.run.simulate import build_traffic

T = 981.0

BASE = """
name = "records"
[bridge]
spans = [40.0]
elements_per_span = 8
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
[[sensors]]
name = "m"
x = 20.0
quantity = "bending_moment"
"""

RECORDS = """
[traffic.records]
file = "day.castor"
format = "castor"
via = "scripted"
lanes = [{lane = 1, y = -1.875, direction = "+x"}, {lane = 2, y = 1.875, direction = "-x"}]
"""


def records_file(folder: Path) -> Path:
    path = folder / "day.castor"
    records = [VehicleRecord(time=t, lane=0, direction=d, local_lane=1, speed=20.0, gross_weight=140 * T,
                             axle_loads=(50 * T, 90 * T), axle_spacings=(4.5,), origin=date(2024, 1, 2))
               for t, d in ((7200.5, 1), (7210.0, 2), (7300.0, 1))]
    write_records(path, "castor", records)
    return path


def load(tmp_path: Path, text: str) -> object:
    records_file(tmp_path)
    path = tmp_path / "s.toml"
    path.write_text(BASE + text, encoding="utf-8")
    return load_scenario(path)


def error(tmp_path: Path, text: str) -> str:
    with pytest.raises(ConfigError) as caught:
        load(tmp_path, text)
    return str(caught.value).splitlines()[0]


def test_records_driven_as_recorded_need_no_sumo(tmp_path: Path) -> None:
    sc = load(tmp_path, RECORDS)
    assert not sc.sumo and sc.scripted_records is not None and sc.sumo_config_path is None
    records = sc.records
    assert (records.via, records.axle_model, records.wander, records.seed, records.begin, records.end) == (
        "scripted", "tyre-quarter-car", "none", None, 0.0, None)
    # the default duration: the last record's vehicle leaves the deck (+ the ring-down)
    assert sc.duration == pytest.approx(7300.0 + (40.0 + 4.5) / 20.0 + RING_DOWN)
    assert sc.wheel_paths() == (-1.875, 1.875)
    traffic = build_traffic(sc)
    assert isinstance(traffic, RecordTraffic) and traffic.lanes_per_direction == (1, 1)
    block = traffic.start().block([7200.6])
    assert block.ids == ("day:1#0", "day:1#1") and block.models[0].kind == "tyre-quarter-car"
    assert block.models[1].total_mass == pytest.approx(90 * T / 9.81)
    traffic.close()


def test_a_window_sets_the_run_s_time_origin(tmp_path: Path) -> None:
    sc = load(tmp_path, RECORDS + 'begin = 7205.0\nend = 7300.0\nmodel = "moving-force"\n')
    assert sc.duration == pytest.approx(5.0 + 44.5 / 20.0 + RING_DOWN)
    block = build_traffic(sc).start().block([5.0])
    assert block.ids == ("day:2#0", "day:2#1") and block.x[0, 0] == 40.0 and block.models[0].kind == "moving-force"


def test_wander_needs_a_seed_and_spreads_the_wheel_paths(tmp_path: Path) -> None:
    sc = load(tmp_path, RECORDS + 'wander = "en1991-2"\nseed = 4\n')
    assert len(sc.wheel_paths()) > 2
    assert error(tmp_path, RECORDS + 'wander = 0.1\n').endswith(
        "s.toml: traffic.records.seed: required key is missing: wander = 0.1 is drawn per vehicle and needs a seed "
        "(an integer >= 0) so that it can be reproduced, e.g. seed = 1")
    assert "traffic.records.seed: only used with a wander" in error(tmp_path, RECORDS + "seed = 4\n")


@pytest.mark.parametrize("extra, key, fragment", [
    ('format = "wim"', "traffic.records.format", 'expected one of: castor, bedit, ditis, mon'),
    ("via = \"bus\"", "traffic.records.via", "scripted, sumo"),
    ('model = "half-car"', "traffic.records.model", "tyre-quarter-car, moving-force"),
    ("end = 7000.0\nbegin = 7100.0", "traffic.records.end", "must be after begin = 7100.0 s"),
])
def test_bad_keys_name_the_key(tmp_path: Path, extra: str, key: str, fragment: str) -> None:
    lines = [line for line in RECORDS.splitlines() if not line.startswith(extra.split(" ")[0] + " ")]
    message = error(tmp_path, "\n".join(lines) + "\n" + extra + "\n")
    assert f"s.toml: {key}: " in message and fragment in message, message


def test_lanes_are_checked(tmp_path: Path) -> None:
    twice = RECORDS.replace("lane = 2,", "lane = 1,")
    assert "traffic.records.lanes[1].lane: lane 1 is given twice (also lanes[0])" in error(tmp_path, twice)
    off = RECORDS.replace("y = 1.875", "y = 6.0")
    assert "traffic.records.lanes[1].y: must lie on the deck, -5 <= y <= 5 m (got 6.0)" in error(tmp_path, off)
    empty = RECORDS.replace('lanes = [{lane = 1, y = -1.875, direction = "+x"}, {lane = 2, y = 1.875, '
                            'direction = "-x"}]', "lanes = []")
    assert "traffic.records.lanes: expected at least one lane" in error(tmp_path, empty)
    way = RECORDS.replace('"-x"', '"west"')
    assert "traffic.records.lanes[1].direction" in error(tmp_path, way)


def test_the_file_must_be_there(tmp_path: Path) -> None:
    message = error(tmp_path, RECORDS.replace("day.castor", "other.castor"))
    assert message.endswith(f"s.toml: traffic.records.file: file not found: {tmp_path / 'other.castor'} (a relative "
                            "path is relative to the scenario file's folder)"), message


def test_via_and_sumo_keys_go_together(tmp_path: Path) -> None:
    assert "traffic.records.via: required key is missing" in error(tmp_path, RECORDS.replace('via = "scripted"\n', ""))
    message = error(tmp_path, RECORDS.replace('"scripted"', '"sumo"'))
    assert 'traffic.sumo_config: required key is missing: records with via = "sumo" are inserted into a SUMO' in message
    message = error(tmp_path, '[traffic]\nend = 900.0\n' + RECORDS)
    assert "traffic.end: only used with sumo_config (SUMO traffic)" in message, message
    message = error(tmp_path, '[traffic]\nsumo_config = "light"\n' + RECORDS)
    assert 'traffic.records.via: records with via = "scripted" run without SUMO' in message, message
    message = error(tmp_path, '[traffic]\nseed = 3\n')
    assert "traffic.sumo_config: required key is missing: give sumo_config" in message, message


def test_records_via_sumo_take_the_sumo_keys(tmp_path: Path) -> None:
    sc = load(tmp_path, '[traffic]\nsumo_config = "light"\nend = 120.0\n' + RECORDS.replace('"scripted"', '"sumo"'))
    assert sc.sumo and sc.records is not None and sc.scripted_records is None and sc.duration == 120.0
    message = error(tmp_path, '[traffic]\nsumo_config = "light"\n' + RECORDS.replace('"scripted"', '"sumo"')
                    + 'model = "moving-force"\n')
    assert 'traffic.records.model: only used with via = "scripted"' in message, message


def test_a_window_without_records_and_a_bad_record_are_one_line_errors_before_anything_runs(tmp_path: Path) -> None:
    sc = load(tmp_path, RECORDS + "begin = 80000.0\n")
    with pytest.raises(ConfigError) as caught:
        sc.duration  # noqa: B018 - the window is read here
    assert str(caught.value) == (
        f"{tmp_path / 's.toml'}: traffic.records: no record of {tmp_path / 'day.castor'} lies in the window, begin = "
        "80000 s on (its 3 records run from 7200.5 to 7300 s after midnight of its first day, 2024-01-02); change "
        "begin and end")
    sc = load(tmp_path, RECORDS.replace("lane = 2,", "lane = 3,"))
    with pytest.raises(ConfigError) as caught:
        build_traffic(sc)
    assert str(caught.value).startswith(f"{tmp_path / 'day.castor'}: line 2: direction 2 / lane 1 is lane 2 as BTLS "
                                        "numbers them (1 lane(s) in direction 1, 1 in direction 2), which "
                                        "traffic.records.lanes does not map (it maps lane(s) 1, 3)")
