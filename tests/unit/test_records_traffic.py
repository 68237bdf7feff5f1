"""WIM records as traffic (issue 25, item 2): cosim.core.records_traffic.RecordTraffic and check_records.

Each record's axles are checked where they must be at every step (its recorded time at the deck's entry end,
its recorded speed, its spacings behind the front axle, its lane's path and direction), against positions
worked out here from the record alone; the same records as scripted moving forces (one per axle, each
entering its spacing later) give the same response in a dynamic and a quasi-static run, quiet stretches
skipped or not; the file is streamed (records read just ahead of the run); bad records name the file and line.
"""
from __future__ import annotations

import math
from datetime import date
from pathlib import Path

import numpy as np
import pytest

from cosim.core.bridge import PointLoad
from cosim.core.loads import VehicleRecord, write_records
from cosim.core.loads.draws import G
from cosim.core.quasistatic import (
    QuasiStaticSystem,
    influence,
    influence_polynomials,
    influence_vectors,
    static_block,
)
from cosim.core.records_traffic import (
    LIGHT_WEIGHT,
    RecordLane,
    RecordTraffic,
    check_records,
    moving_forces,
    record_class,
    record_id_prefix,
)
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle, TrafficBlock, TrafficSource
from cosim.core.vehicles import MovingForce
from cosim.errors import ConfigError
from cosim.testing import bridge as bridge_table
from cosim.testing import moving_force, scenario

L = 40.0
LANES = (RecordLane(1, -1.875, 1), RecordLane(2, 1.875, -1))
T = 981.0  # N: 100 kg, the formats' unit


def record(time: float, direction: int, speed: float, loads: tuple[int, ...], spacings: tuple[float, ...],
           local_lane: int = 1) -> VehicleRecord:
    axles = tuple(w * T for w in loads)
    return VehicleRecord(time=time, lane=0, direction=direction, local_lane=local_lane, speed=speed,
                         gross_weight=sum(axles), axle_loads=axles, axle_spacings=spacings, origin=date(2024, 3, 4))


RECORDS = [
    record(3.0, 1, 22.5, (60, 100, 80, 80, 80), (3.2, 5.2, 1.3, 1.3)),
    record(4.5, 2, 25.0, (50, 90), (4.5,)),
    record(9.27, 1, 13.9, (8, 7), (2.7,)),           # a car
    record(30.0, 2, 30.1, (70, 120, 120), (4.2, 1.3)),
    record(30.0, 1, 20.0, (70, 130), (4.5,)),        # the same time, the other lane
    record(95.5, 1, 24.0, (65, 95, 85, 85), (3.4, 6.0, 1.3)),
]


@pytest.fixture
def castor(tmp_path: Path) -> Path:
    path = tmp_path / "site.castor"
    write_records(path, "castor", RECORDS)
    return path


def expected_axles(rec: VehicleRecord, lane: RecordLane, t: float, begin: float = 0.0) -> list[float]:
    """Each axle's x at t, from the record alone: its first axle at the entry end at its time."""
    behind = np.concatenate([[0.0], np.cumsum(rec.axle_spacings)])
    s = rec.speed * (t - (rec.time - begin)) - behind
    return list(s if lane.direction > 0 else L - s)


def test_every_axle_drives_at_its_recorded_time_speed_lane_and_spacing(castor: Path) -> None:
    traffic = RecordTraffic(castor, "castor", LANES, L).start()
    dt = 0.01
    seen: set[str] = set()
    lane_of = {1: LANES[0], 2: LANES[1]}
    records = {f"site:{k + 1}": r for k, r in enumerate(RECORDS)}
    for start in range(0, 12000, 150):
        times = dt * np.arange(start + 1, start + 151)
        block = traffic.block(times)
        owners: dict[str, list[int]] = {}
        for j, cid in enumerate(block.ids):
            owners.setdefault(cid.split("#")[0], []).append(j)
        for vid, cols in owners.items():
            rec = records[vid]
            lane = lane_of[rec.direction]  # one lane each way: BTLS's lanes 1 and 2
            assert [block.ids[j] for j in cols] == [f"{vid}#{k}" for k in range(rec.axle_count)]
            for k, t in enumerate(times):
                assert block.x[k, cols] == pytest.approx(expected_axles(rec, lane, t), abs=1e-9)
            assert np.all(block.v[:, cols] == lane.direction * rec.speed) and np.all(block.a[:, cols] == 0)
            assert np.all(block.y[cols] == lane.y)
            assert [m.total_mass * G for j in cols for m in [block.models[j]]] == pytest.approx(rec.axle_loads)
            # in the block only while an axle is on the deck at one of its steps
            assert ((block.x[:, cols] >= 0) & (block.x[:, cols] <= L)).any()
        for load in block.loads:
            assert load.id not in seen
            seen.add(load.id)
            rec = records[load.id]
            assert load.lane == str(rec.direction) and load.source == "records: site.castor"
            assert load.axle_loads == rec.axle_loads and load.gvw == rec.gross_weight
            assert load.axle_spacings == pytest.approx(rec.axle_spacings) and load.speed == rec.speed
            assert load.vehicle_class == ("car" if rec.gross_weight < LIGHT_WEIGHT else f"truck-{rec.axle_count}")
            assert load.wander == 0.0 and load.y == lane_of[rec.direction].y
    assert seen == set(records)  # every record came onto the deck, each once
    traffic.close()


def test_a_vehicle_is_in_no_block_before_its_time_and_none_after_its_last_axle_left(castor: Path) -> None:
    traffic = RecordTraffic(castor, "castor", LANES, L).start()
    first = RECORDS[0]
    leave = first.time + (L + sum(first.axle_spacings)) / first.speed
    assert traffic.block(np.array([2.98, 2.99])).ids == ()
    entering = traffic.block(np.array([3.0]))
    assert entering.ids[0] == "site:1#0" and entering.x[0, 0] == 0.0 and [r.id for r in entering.loads] == ["site:1"]
    assert "site:1#4" in traffic.block(np.array([leave - 1e-6])).ids
    assert not any(i.startswith("site:1#") for i in traffic.block(np.array([leave + 1e-6, leave + 0.01])).ids)


def test_the_window_begins_the_run_and_ends_the_records(castor: Path) -> None:
    check = check_records(castor, "castor", LANES, L, begin=9.0, end=95.5)
    assert check.count == 3 and (check.first, check.last) == (9.27, 30.0)
    leaves = [r.time - 9.0 + (L + sum(r.axle_spacings)) / r.speed for r in RECORDS[2:5]]
    assert check.leave == pytest.approx(max(leaves))
    assert dict(check.per_lane) == {1: 2, 2: 1} and check.heaviest == pytest.approx(310 * T)
    traffic = RecordTraffic(castor, "castor", LANES, L, begin=9.0, end=95.5,
                            lanes_per_direction=check.lanes_per_direction).start()
    block = traffic.block(np.arange(1, 10001) * 0.01)  # run time 0.01 ... 100 s
    assert {c.split("#")[0] for c in block.ids} == {"site:3", "site:4", "site:5"}
    car = [j for j, c in enumerate(block.ids) if c.startswith("site:3#")]
    assert block.x[26, car[0]] == pytest.approx(0.0, abs=1e-9)  # t = 0.27 s of the run: 9.27 s of the file
    assert traffic.next_entry == math.inf  # the record at 95.5 s is past the window


def test_the_file_is_streamed_records_read_just_ahead_and_quiet_stretches_known(castor: Path) -> None:
    traffic = RecordTraffic(castor, "castor", LANES, L).start()
    assert traffic.read == 0 and traffic.next_entry == 3.0
    assert traffic.quiet_until(0.0) == 3.0  # nothing on its way: quiet until the first record
    traffic.block(np.array([1.0, 2.0]))
    assert traffic.read == 0
    traffic.block(np.array([3.0, 4.0]))
    assert traffic.read == 1 and traffic.next_entry == 4.5
    assert traffic.quiet_until(4.0) == 4.0  # the first is on the deck
    traffic.block(np.array([20.0, 29.0]))
    assert traffic.read == 3 and len(traffic._active) <= 3
    assert traffic.quiet_until(29.0) == 30.0  # they all left: quiet until the next two
    traffic.block(np.array([50.0, 60.0]))
    assert traffic.read == 5 and traffic._active == []  # vehicles gone are forgotten
    traffic.close()


def test_wander_is_drawn_per_vehicle_to_its_own_left(castor: Path) -> None:
    traffic = RecordTraffic(castor, "castor", LANES, L, wander="en1991-2", seed=3).start()
    block = traffic.block(np.arange(1, 5001) * 0.02)
    again = RecordTraffic(castor, "castor", LANES, L, wander="en1991-2", seed=3).start().block(
        np.arange(1, 5001) * 0.02)
    assert block.loads == again.loads and np.array_equal(block.y, again.y)
    offsets = {r.wander for r in block.loads}
    assert offsets <= {-0.2, -0.1, 0.0, 0.1, 0.2} and len(offsets) > 1
    for r in block.loads:
        lane = LANES[0] if r.lane == "1" else LANES[1]
        assert r.y == pytest.approx(lane.y + lane.direction * r.wander)  # -x: the vehicle's left is -y
        cols = [j for j, c in enumerate(block.ids) if c.startswith(r.id + "#")]
        assert np.all(block.y[cols] == r.y)


def test_ids_and_classes() -> None:
    assert record_id_prefix("a/b/day 1.castor.gz") == "day_1"
    assert record_id_prefix("x.mon") == "x"
    assert record_class(record(0, 1, 20, (17, 17), (2.6,))) == "car"  # 3400 kg
    assert record_class(record(0, 1, 20, (18, 18), (2.6,))) == "truck-2"  # 3600 kg: above a car's 3500 kg
    assert record_class(record(0, 1, 20, (40, 50, 50), (4.0, 1.3))) == "truck-3"
    assert moving_forces(record(0, 1, 20, (40, 50), (4.0,))) == (MovingForce(40 * T / G), MovingForce(50 * T / G))


# --------------------------------------------------------------------------- bad input


def test_a_lane_the_table_does_not_map_names_the_file_and_its_first_line(tmp_path: Path) -> None:
    path = tmp_path / "three.castor"
    records = [record(1.0, 1, 20.0, (50, 90), (4.5,)), record(2.0, 1, 20.0, (50, 90), (4.5,), local_lane=2),
               record(3.0, 2, 20.0, (50, 90), (4.5,)), record(4.0, 1, 20.0, (50, 90), (4.5,), local_lane=2)]
    write_records(path, "castor", records)
    with pytest.raises(ConfigError) as caught:
        check_records(path, "castor", LANES, L, key="traffic.records.lanes")
    message = str(caught.value)
    # two lanes in direction 1, one in direction 2: BTLS's lane 2 is direction 1's lane 2, direction 2's is 3
    assert message.startswith(f"{path}: line 3: direction 2 / lane 1 is lane 3 as BTLS numbers them "
                              "(2 lane(s) in direction 1, 1 in direction 2), which traffic.records.lanes does not "
                              "map (it maps lane(s) 1, 2); add {lane = 3, y = ..., direction = ...} to it"), message
    assert "\n" not in message
    # outside the window the lane is not driven: no error
    assert check_records(path, "castor", LANES, L, end=3.0).count == 2


def test_times_going_backwards_name_the_file_and_line(tmp_path: Path, castor: Path) -> None:
    lines = castor.read_text().splitlines()
    lines[2], lines[3] = lines[3], lines[2]  # 30 s, then 9.27 s
    path = tmp_path / "swapped.castor"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ConfigError, match=rf"^{path}: line 4: its time is 20.73 s before the previous record's "
                                          r"\(line 3\); the records must be in time order"):
        check_records(path, "castor", LANES, L)


def test_lanes_table_is_checked() -> None:
    with pytest.raises(ConfigError, match="lane 1 is given twice"):
        RecordTraffic("x.castor", "castor", (LANES[0], LANES[0]), L)
    with pytest.raises(ConfigError, match="direction"):
        RecordLane(1, 0.0, 2)


# --------------------------------------------------------------------------- against scripted moving forces


def _as_scripted(records: list[VehicleRecord], begin: float = 0.0) -> ScriptedTraffic:
    """Each axle a scripted moving force entering its spacing behind the front one, later."""
    vehicles = []
    for n, rec in enumerate(records):
        lane = LANES[rec.direction - 1]
        behind = np.concatenate([[0.0], np.cumsum(rec.axle_spacings)])
        for k, (w, b) in enumerate(zip(rec.axle_loads, behind)):
            vehicles.append(ScriptedVehicle(f"v{n}.{k}", MovingForce(w / G), lane.y, rec.speed,
                                            rec.time - begin + b / rec.speed, lane.direction))
    return ScriptedTraffic(tuple(vehicles), L)


class _NoQuiet(TrafficSource):
    """A source without quiet stretches: every block asked for."""

    def __init__(self, inner: RecordTraffic) -> None:
        self.inner = inner

    def start(self) -> _NoQuiet:
        self.inner.start()
        return self

    def block(self, times):  # noqa: ANN001, ANN201
        return self.inner.block(times)

    @property
    def length(self) -> float:
        return self.inner.length


@pytest.mark.parametrize("method", ["quasi-static", "dynamic"])
def test_records_load_the_deck_as_the_same_axles_scripted_do(castor: Path, method: str) -> None:
    sc = scenario(bridge=bridge_table(L, elements_per_span=10), vehicles=[moving_force("x", 1000.0, 0.0, 10.0)])
    model = sc.build_bridge()
    sensors = [Sensor("mid", 20.0, 1.875), Sensor("m", 20.0, 0.0, "bending_moment")]
    settings = SolverSettings(dt=0.01, method=method)
    duration = 110.0
    runs = []
    for traffic in (RecordTraffic(castor, "castor", LANES, L), _NoQuiet(RecordTraffic(castor, "castor", LANES, L)),
                    _as_scripted(RECORDS)):
        with traffic:
            runs.append(simulate(model, traffic, duration, settings, sensors=sensors, output_every=7))
    records, every_block, scripted = runs
    for name in ("mid", "m"):
        peak = np.abs(scripted.sensors[name]).max()
        assert np.array_equal(records.sensors[name], every_block.sensors[name])  # quiet stretches skipped: the same
        assert np.abs(records.sensors[name] - scripted.sensors[name]).max() <= 1e-9 * peak
    assert records.weights["truck-5"].count == 1 and records.weights["car"].count == 1


def test_the_static_kernel_is_the_influence_superposition() -> None:
    sc = scenario(bridge=bridge_table(L, elements_per_span=7), vehicles=[moving_force("x", 1000.0, 0.0, 10.0)])
    model = sc.build_bridge()
    sensors = [Sensor("mid", 17.3, 2.0), Sensor("m", 20.0, 0.0, "bending_moment"), Sensor("edge", 3.0, -5.0)]
    g = np.nan_to_num(influence_vectors(model, sensors))
    rng = np.random.default_rng(4)
    x = rng.uniform(-5.0, 45.0, (30, 6))
    x[3, 2], x[4, 2], x[5, 2] = 0.0, L, L / 7 * 3  # the ends, a node
    y = rng.uniform(-5.0, 5.0, 6)
    block = TrafficBlock(tuple(f"c{j}" for j in range(6)), tuple(MovingForce(1000.0 + j) for j in range(6)),
                         x, np.zeros_like(x), np.zeros_like(x), y)
    values, on, _, _ = static_block(model, g, block, G, (-5.0, 5.0), influence_polynomials(model, g))
    for k in range(30):
        loads = [PointLoad(x[k, j], y[j], -(1000.0 + j) * G) for j in range(6) if 0 <= x[k, j] <= L]
        direct = influence(model, g, [p.x for p in loads], [p.y for p in loads]) @ [p.Fz for p in loads] \
            if loads else np.zeros(3)
        assert values[k] == pytest.approx(direct, rel=1e-12, abs=1e-12 * np.abs(values).max())
    system = QuasiStaticSystem(model, tuple(sensors), G)
    assert np.array_equal(system.advance(block).sensors, values)
