"""WIM record files (issue 25, items 2, 7, 8): cosim reads what pybtls writes and pybtls reads what cosim writes,
in each of the four formats, and every bad line is one error naming the file and the line.

The oracle is pybtls 1.0.1 (BTLS's own C++ reader and writer, ``Vehicle.cpp``; GPL-3.0, a test dependency only):
its ``garage.write_garage_file``/``read_garage_file`` and its traffic simulation's vehicle file.
"""
from __future__ import annotations

import gzip
import random
import subprocess
import sys
import tracemalloc
from datetime import date
from pathlib import Path

import pytest

from cosim.core.loads import FORMATS, VehicleRecord, btls_lane, read_records, survey, write_records
from cosim.errors import ConfigError

pb = pytest.importorskip("pybtls", reason="pybtls (the test extra) is the oracle")
from pybtls.lib.BTLS import Vehicle  # noqa: E402

CODES = {name: f.btls_code for name, f in FORMATS.items()}
LANES = (2, 2)  # two lanes each way: BTLS numbers direction 2's lane 1 as lane 4


def _vehicles(count: int, max_axles: int, seed: int = 3) -> list[Vehicle]:
    """pybtls vehicles on whole format units (100 kg, dm, dm/s, cm), in time order within one BTLS month."""
    rng = random.Random(seed)
    out, t = [], 3600.0 * 7 + 0.37
    for i in range(count):
        n = rng.randint(2, max_axles)
        weights = [rng.randint(20, 120) * 0.981 for _ in range(n)]  # x 100 kg -> kN as BTLS converts
        spacings = [rng.randint(11, 60) / 10 for _ in range(n - 1)] + [0.0]
        widths = [rng.randint(170, 210) / 100 for _ in range(n)]
        t += rng.randint(0, 400) / 100  # equal times happen (two lanes)
        day, rest = divmod(t, 86400.0)
        hour, rest = divmod(rest, 3600.0)
        minute, sec = divmod(rest, 60.0)
        v = Vehicle(n)
        v._set_all_properties((1000 + i, int(day) + 1, 3, 96, int(hour), int(minute), round(sec, 2), n, 2,
                               sum(weights), rng.randint(150, 300) / 10, round(sum(spacings) + 2.3, 1),
                               rng.randint(1, 2), rng.randint(1, 2), rng.randint(2, 19) / 10, weights, spacings,
                               widths))
        out.append(v)
    return out


def _props(v: Vehicle) -> dict:
    (head, day, month, year, hour, minute, sec, n, groups, gvw, speed, length, lane, direction, trans, aw, asp,
     at) = v._get_all_properties()
    return dict(head=head, day=day, seconds=hour * 3600 + minute * 60 + sec, n=n, gvw=gvw, speed=speed,
                length=length, lane=lane, direction=direction, trans=trans, aw=list(aw), asp=list(asp), at=list(at),
                global_lane=v._getGlobalLane(sum(LANES)), time=v.get_time())


def _assert_same(records: list[VehicleRecord], vehicles: list[Vehicle], fmt: str) -> None:
    """cosim's records and BTLS's vehicles read from one file agree field by field (SI vs BTLS's kN and m)."""
    assert len(records) == len(vehicles)
    t0 = _props(vehicles[0])["time"]
    for r, v in zip(records, vehicles):
        p = _props(v)
        assert r.axle_count == p["n"]
        assert r.direction == p["direction"] and r.local_lane == p["lane"]
        assert r.lane == p["global_lane"] == btls_lane(r.direction, r.local_lane, LANES)
        # same integers converted by each: equal to the last bits (BTLS: 0.981 kN per 100 kg; cosim 981 N)
        assert r.gross_weight == pytest.approx(p["gvw"] * 1e3, rel=1e-12)
        assert r.axle_loads == pytest.approx([w * 1e3 for w in p["aw"]], rel=1e-12)
        assert r.axle_spacings == pytest.approx(p["asp"][:-1], rel=1e-12)
        assert r.trailing_spacing == pytest.approx(p["asp"][-1] if fmt == "mon" else 0.0, abs=1e-12)
        assert r.speed == pytest.approx(p["speed"], rel=1e-12)
        assert r.length == pytest.approx(p["length"], rel=1e-12)
        assert r.transverse == pytest.approx(p["trans"], rel=1e-12)
        if fmt == "ditis":
            assert r.track_widths == pytest.approx(p["at"], rel=1e-12)
        # BTLS's clock has 25-day months; within one month it counts as the calendar does (to 1e-5 s: BTLS's
        # get_time of year 96 loses the last digits)
        assert r.time - records[0].time == pytest.approx(p["time"] - t0, abs=1e-5)
    assert records[0].time == pytest.approx(_props(vehicles[0])["seconds"], abs=1e-6)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_cosim_reads_what_pybtls_writes(tmp_path: Path, fmt: str) -> None:
    vehicles = _vehicles(300, 9 if fmt == "castor" else 12)
    path = tmp_path / f"pybtls.{fmt}"
    pb.garage.write_garage_file(vehicles, path, CODES[fmt])
    records = list(read_records(path, fmt, LANES))
    _assert_same(records, pb.garage.read_garage_file(path, CODES[fmt]), fmt)
    # BTLS writes the year 96 as "96" (CASTOR, BeDIT, DITIS) or 96 + 2010 (MON: Vehicle::writeMONData)
    assert records[0].origin == date(2106 if fmt == "mon" else 1996, 3, 1)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_a_minute_btls_rounded_up_is_read_as_btls_reads_it(tmp_path: Path, fmt: str) -> None:
    """BTLS writes a time in a minute's last half-unit as 60000 ms (MON) or 60 s and 0 hundredths (the others)
    without carrying into the minute (found in a day of pybtls's generated traffic) and reads it back as the
    next minute's start: cosim reads the same time."""
    unit = FORMATS[fmt].time_unit
    vehicles = []
    for i, sec in enumerate((60 - unit / 3, 59.0 + unit, 60 - unit / 3, 0.0)):
        v = Vehicle(2)
        v._set_all_properties((1000 + i, 1, 3, 96, 7, 12 + i, sec, 2, 2, 2 * 9.81, 20.0, 5.0, 1, 1, 1.0,
                               [9.81, 9.81], [3.0, 0.0], [1.8, 1.8]))
        vehicles.append(v)
    path = tmp_path / f"pybtls.{fmt}"
    pb.garage.write_garage_file(vehicles, path, CODES[fmt])
    first = path.read_text(encoding="ascii").splitlines()[0]
    assert ("60000" if fmt == "mon" else "60 0") in first, first  # the rounded-up minute is in the file
    records = list(read_records(path, fmt, LANES))
    _assert_same(records, pb.garage.read_garage_file(path, CODES[fmt]), fmt)
    # the reference: 7:12 plus 60 s is 7:13:00, one minute and 1/3 unit before the last vehicle's 7:15:00
    assert records[3].time - records[0].time == pytest.approx(120.0, abs=1e-9)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_pybtls_reads_what_cosim_writes(tmp_path: Path, fmt: str) -> None:
    source = tmp_path / "source.mon"
    pb.garage.write_garage_file(_vehicles(300, 9 if fmt == "castor" else 12, seed=8), source, 4)
    records = list(read_records(source, "mon", LANES))
    written = tmp_path / f"cosim.{fmt}"
    assert write_records(written, fmt, records) == len(records)
    again = list(read_records(written, fmt, LANES))
    _assert_same(again, pb.garage.read_garage_file(written, CODES[fmt]), fmt)
    # and cosim reads its own file back to the format's rounding (MON: km/h; the others: dm/s, 100 kg)
    for a, b in zip(records, again):
        assert (a.time, a.lane, a.direction, a.axle_count) == (b.time, b.lane, b.direction, b.axle_count)
        assert b.gross_weight == pytest.approx(a.gross_weight, abs=FORMATS[fmt].weight / 2)
        assert b.speed == pytest.approx(a.speed, abs=FORMATS[fmt].speed / 2 + 1e-12)


def test_a_day_of_pybtls_generated_traffic_is_read_as_pybtls_reads_it(tmp_path: Path) -> None:
    """pybtls's own Grave generator (Auxerre, one lane each way) writes a day of trucks in MON through its
    simulation's vehicle file; cosim reads it as BTLS does, and a gzipped copy identically. pybtls takes no seed
    (BTLS seeds from the clock): each run reads a different day, which is how a rounded-up minute was found."""
    script = tmp_path / "generate.py"
    script.write_text(GENERATE, encoding="utf-8")
    subprocess.run([sys.executable, str(script)], cwd=tmp_path, check=True, capture_output=True, timeout=300)
    (path,) = tmp_path.glob("out/*/generated.txt")
    records = list(read_records(path, "mon"))
    assert len(records) > 500
    vehicles = pb.garage.read_garage_file(path, 4)
    for r, v in zip(records, vehicles):
        assert r.gross_weight == pytest.approx(v.get_gvw() * 1e3, rel=1e-12)
        assert r.axle_loads == pytest.approx([w * 1e3 for w in v.get_axle_weights()], rel=1e-12)
        assert r.lane == v._getGlobalLane(2) and r.direction == v.get_direction()
    with open(path, "rb") as plain, gzip.open(tmp_path / "generated.gz", "wb") as packed:
        packed.write(plain.read())
    assert list(read_records(tmp_path / "generated.gz", "mon")) == records


GENERATE = """
import pybtls as pb
from pathlib import Path
bridge = pb.Bridge(length=20.0, no_lane=2)
lines = [pb.InfluenceLine("built-in") for _ in range(2)]
for il in lines:
    il.set_IL(id=1, length=20.0)
bridge.add_load_effect(inf_line_surf=lines)
traffic = pb.TrafficGenerator(no_lane=2)
for lane, direction in ((1, 1), (2, 2)):
    lfc = pb.LaneFlowComposition(lane_index=lane, lane_dir=direction)
    lfc.assign_lane_data(hourly_truck_flow=[20] * 24, hourly_car_flow=[0] * 24, hourly_speed_mean=[248] * 24,
                         hourly_speed_std=[10] * 24, hourly_truck_composition=[[23.0, 2.8, 31.7, 42.5]] * 24)
    traffic.add_lane(vehicle_gen=pb.VehicleGenGrave("Auxerre"), headway_gen=pb.HeadwayGenFreeflow(), lfc=lfc)
config = pb.OutputConfig()
config.set_vehicle_file_output(write_vehicle_file=True, vehicle_file_format=4, vehicle_file_name="generated.txt")
sim = pb.Simulation(Path("out"))
sim.add_sim(bridge=bridge, traffic=traffic, no_day=1, output_config=config, time_step=0.1, min_gvw=35, tag="g")
if __name__ == "__main__":
    sim.run(no_core=1)
"""


def test_lanes_are_numbered_as_btls_numbers_them() -> None:
    # Vehicle::getGlobalLane: direction 1's lane k is k; direction 2's lane k is N - k + 1
    assert [btls_lane(1, k, (2, 2)) for k in (1, 2)] == [1, 2]
    assert [btls_lane(2, k, (2, 2)) for k in (1, 2)] == [4, 3]
    assert btls_lane(2, 1, (1, 1)) == 2  # one lane each way: a file's direction 2 / lane 1 is lane 2


def test_a_file_is_streamed_in_constant_memory(tmp_path: Path) -> None:
    path = tmp_path / "big.castor"
    base = list(read_records(_castor(tmp_path), "castor"))[0]
    count = 10_000
    write_records(path, "castor", (VehicleRecord(**{**base.__dict__, "time": i * 0.5}) for i in range(count)))
    # a first pass fills CPython's free lists (up to 2000 tuples of each length are kept for reuse), which
    # tracemalloc would count as held: found when this test ran first in its process and saw 134-144 kB
    assert sum(1 for _ in read_records(path, "castor", (1, 1))) == count
    tracemalloc.start()
    seen = sum(1 for _ in read_records(path, "castor", (1, 1)))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert seen == count
    # a 780 kB file read holding at most a few records (a record is about 1 kB of Python objects)
    assert peak < 64 * 1024 < path.stat().st_size / 10, f"{peak:,} bytes held to read {path.stat().st_size:,}"


# --------------------------------------------------------------------------- bad input: one line, file and line

GOOD = "1001 31296 0 0 0 0401 250120411 18 8050 8040 4513 45 0  0 0  0 0  0 0  0 0  0"  # 4 axles, 25 t, 40.1 m/s


def _castor(tmp_path: Path, *lines: str) -> Path:
    path = tmp_path / "wim.txt"
    path.write_text("\n".join(lines or (GOOD,)) + "\n", encoding="ascii")
    return path


def _line(**fields: str) -> str:
    """GOOD with CASTOR fields replaced (by their columns)."""
    columns = {"axles": (28, 29), "gvw": (21, 25), "w1": (34, 37), "s1": (37, 39), "w2": (39, 42),
               "s4": (52, 54), "w5": (54, 57), "direction": (29, 30), "lane": (30, 31), "second": (14, 16),
               "hundredths": (16, 18), "day": (4, 6), "month": (6, 8), "speed": (18, 21)}
    text = GOOD
    for name, value in fields.items():
        a, b = columns[name]
        text = text[:a] + value.rjust(b - a) + text[b:]
    return text


def test_the_good_line_reads_in_si_units(tmp_path: Path) -> None:
    (r,) = read_records(_castor(tmp_path), "castor")
    assert r.axle_count == 4 and r.gross_weight == 250 * 981.0
    assert r.axle_loads == (80 * 981.0, 80 * 981.0, 45 * 981.0, 45 * 981.0)
    assert r.axle_spacings == pytest.approx((5.0, 4.0, 1.3)) and r.length == pytest.approx(12.0)
    assert r.speed == pytest.approx(40.1) and r.time == 0.0 and r.origin == date(1996, 12, 3)
    assert (r.lane, r.direction, r.transverse, r.head, r.line) == (1, 1, pytest.approx(1.8), 1001, 1)


BAD = [
    ("wrong number of fields", _line(axles="5")[:-40], "the record says 5 axles"),
    ("zero weight", _line(w2="0"), "axle 2 weight is 0"),
    ("negative weight", _line(gvw="-250"), "gross weight is negative (-250); expected a value >= 0"),
    ("zero gross weight", _line(gvw="0"), "gross weight 0; a vehicle's weight must be positive"),
    ("loads do not add up", _line(gvw="300"), "the axle loads add up to 250 x 100 kg but the gross weight is 300"),
    ("spacing after the last axle", _line(s4="12"), "spacing 4-5 is given, but the record says 4 axles"),
    ("a spacing missing", _line(s1="0"), "spacing 1-2 is 0, but the record says 4 axles"),
    ("an axle past the count", _line(w5="10"), "axle 5 weight is given, but the record says 4 axles"),
    ("not a number", _line(speed="4x1"), "speed (columns 19-21) is '4x1'; expected an integer"),
    ("unknown direction", _line(direction="3"), "direction 3; CASTOR gives 1 or 2"),
    ("not a date", _line(day="30", month="2"), "the date 30/2/96 (day/month/year) is not a date"),
    ("no speed", _line(speed="0"), "speed 0"),
    ("past the minute", _line(second="61"), "the time within the minute is 61 s and 0 hundredths; expected 0-59"),
    ("past the next minute's start", _line(second="60", hundredths="1"), "is 60 s and 1 hundredths"),
]


@pytest.mark.parametrize("case, line, message", BAD, ids=[b[0] for b in BAD])
def test_a_bad_line_is_one_error_naming_the_file_and_line(tmp_path: Path, case: str, line: str, message: str):
    path = _castor(tmp_path, GOOD, line)
    with pytest.raises(ConfigError) as error:
        survey(path, "castor")
    text = str(error.value)
    assert text.startswith(f"{path}: line 2: ") and message in text and "\n" not in text, text


def test_times_going_backwards_are_refused(tmp_path: Path) -> None:
    path = _castor(tmp_path, _line(second="5"), GOOD)
    with pytest.raises(ConfigError, match=r"wim.txt: line 2: its time is 5 s before the previous record's "
                                          r"\(line 1\).*sort the file by time"):
        list(read_records(path, "castor"))


def test_a_lane_beyond_the_lane_counts_is_refused(tmp_path: Path) -> None:
    path = _castor(tmp_path, GOOD, _line(direction="2", lane="3"))
    with pytest.raises(ConfigError, match="line 2: lane 3 of direction 2, but there are 1 lane"):
        list(read_records(path, "castor", (2, 1)))


def test_other_bad_files(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="'wim' is not a WIM record format; expected one of castor"):
        read_records(_castor(tmp_path), "wim")
    path = tmp_path / "long.txt"
    path.write_bytes(b"1" * 10_000 + b"\n")
    with pytest.raises(ConfigError, match="long.txt: line 1: longer than 4096 characters"):
        survey(path, "castor")
    path.write_bytes(GOOD.encode() + b"\n" + "é".encode() + b"\n")
    with pytest.raises(ConfigError, match="long.txt: line 2: not ASCII text"):
        survey(path, "castor")
    packed = tmp_path / "cut.gz"
    packed.write_bytes(gzip.compress((GOOD + "\n").encode() * 2000)[:300])
    with pytest.raises(ConfigError, match="cut.gz: line .*: the gzip data is corrupt or cut short"):
        survey(packed, "castor")
    with pytest.raises(ConfigError, match="no records"):
        survey(_castor(tmp_path, ""), "castor")
    with pytest.raises(ConfigError, match="cannot read it"):
        survey(tmp_path / "missing.txt", "castor")


def test_the_record_limit_is_checked_while_streaming(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COSIM_MAX_WIM_RECORDS", "2")
    with pytest.raises(ConfigError, match="line 3: 3 records is more than the limit of 2 records.*"
                                          "COSIM_MAX_WIM_RECORDS"):
        survey(_castor(tmp_path, GOOD, GOOD, GOOD), "castor")


def test_writing_refuses_what_the_format_cannot_hold(tmp_path: Path) -> None:
    (r,) = read_records(_castor(tmp_path), "castor")
    heavy = VehicleRecord(**{**r.__dict__, "gross_weight": 2e7})
    with pytest.raises(ConfigError, match="record 1 .*gross weight is 20387 in CASTOR's units, which does not fit 4"):
        write_records(tmp_path / "out.txt", "castor", [heavy])
    assert not (tmp_path / "out.txt").exists()
    many = VehicleRecord(**{**r.__dict__, "axle_loads": (1e4,) * 10, "axle_spacings": (1.2,) * 9})
    with pytest.raises(ConfigError, match="10 axles and 9 spacings; CASTOR takes 1 to 9 axles"):
        write_records(tmp_path / "out.txt", "castor", [many])


def test_a_mon_line_padded_with_empty_axles_reads_as_btls_reads_it(tmp_path: Path) -> None:
    """Older BTLS releases wrote MON records padded with zero axles (as BTLS's example traffic file is);
    BTLS reads the record's axles and ignores the rest, and so does cosim."""
    header = "    42231 1 12010 0 015417 2 2  1295 78 2907111800"  # 2 axles, 1295 kg, 78 km/h, lane 1, direction 2
    axles = "  596 2907  699    0"
    path = tmp_path / "padded.mon"
    path.write_text(header + axles + "    0    0" * 20 + "\n", encoding="ascii")
    (r,) = read_records(path, "mon")
    vehicles = pb.garage.read_garage_file(path, 4)
    assert r.gross_weight == pytest.approx(vehicles[0].get_gvw() * 1e3, rel=1e-12) == 1295 * 9.81
    assert r.axle_spacings == (2.907,) and r.direction == 2 and r.speed == pytest.approx(78 / 3.6)
    path.write_text(header + axles + "    0   12" + "\n", encoding="ascii")
    with pytest.raises(ConfigError, match="line 1: axle 3 weight is given|line 1: spacing 3-4 is given"):
        survey(path, "mon")
