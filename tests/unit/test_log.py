"""MCAP logs: real files written and read back (no mocks)."""
from __future__ import annotations

import json
from typing import Any

import jsonschema
import numpy as np
import pytest

from cosim.core.bridge import build_bridge
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import QuarterCar
from cosim.errors import LogError
from cosim.log import (
    TOPIC_EVENTS,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_VEHICLES,
    BlockLogger,
    LogRecorder,
    file_is_complete,
    read_log,
)

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))
SENSORS = [Sensor("mid", 15.0, 0.0), Sensor("edge_acc", 15.0, 6.0, "acceleration")]


def schema_validator(text: bytes, cache: dict[bytes, Any]) -> Any:
    """A JSON Schema validator for a schema record's text, checked and built once per schema."""
    if text not in cache:
        schema = json.loads(text)
        cls = jsonschema.validators.validator_for(schema)
        cls.check_schema(schema)
        cache[text] = cls(schema)
    return cache[text]


def _logged_run(path, duration=2.0, **kwargs):
    bridge = build_bridge([30.0], 10, MAT, SEC, ["rigid-end", "rigid-end"])
    cars = (ScriptedVehicle("a", QuarterCar(1e4, 1e3, 4e5, 2e4), 3.0, 20.0),
            ScriptedVehicle("b", QuarterCar(2e4, 2e3, 8e5, 4e4), -3.0, 15.0, entry_time=0.3, direction=-1))
    names = [s.name for s in SENSORS]
    with LogRecorder(path, names, **kwargs) as rec, BlockLogger(rec, names, duration) as logger:
        rec.attach("scenario.toml", "# test\n")
        rec.status(0.0, "started")
        result = simulate(bridge, ScriptedTraffic(cars, 30.0), duration, SolverSettings(dt=0.005), SENSORS,
                          output_every=2, observers=[logger])
    return result


def test_round_trip_is_exact(tmp_path):
    path = tmp_path / "run.mcap"
    result = _logged_run(path)
    log = read_log(path)
    assert not log.truncated and file_is_complete(path)
    samples = log.topic(TOPIC_SENSORS)
    t = np.array([m["t"] for m in samples])
    np.testing.assert_array_equal(t, result.t[1:])  # the initial rest state is not logged
    for name in result.sensors:
        np.testing.assert_array_equal(np.array([m[name] for m in samples]), result.sensors[name][1:])
    assert log.final_status["state"] == "finished"
    assert log.attachments["scenario.toml"] == b"# test\n"
    events = log.topic(TOPIC_EVENTS)
    assert [e["event"] for e in events if e["vehicle"] == "a"][:1] == ["entered"]
    assert {"entered", "left"} <= {e["event"] for e in events}
    # Log times are integer nanoseconds of simulated time.
    assert [ns for ns, _ in log.messages[TOPIC_SENSORS]][:2] == [10_000_000, 20_000_000]


def test_every_message_validates_against_its_schema(tmp_path):
    from mcap.reader import make_reader

    path = tmp_path / "run.mcap"
    _logged_run(path)
    with open(path, "rb") as fh:
        reader = make_reader(fh, validate_crcs=True)
        validators: dict[bytes, Any] = {}
        count = 0
        for schema, channel, message in reader.iter_messages():
            assert schema.encoding == "jsonschema" and channel.message_encoding == "json"
            schema_validator(schema.data, validators).validate(json.loads(message.data))
            count += 1
    assert count > 100


def test_an_exception_leaves_a_finished_log_that_says_why(tmp_path):
    path = tmp_path / "boom.mcap"
    with pytest.raises(RuntimeError):
        with LogRecorder(path, ["s"]) as rec:
            rec.write(TOPIC_SENSORS, 0.01, {"t": 0.01, "s": 1.0})
            raise RuntimeError("solver blew up")
    log = read_log(path)
    assert not log.truncated
    assert log.final_status["state"] == "error" and "solver blew up" in log.final_status["message"]
    with pytest.raises(KeyboardInterrupt):
        with LogRecorder(tmp_path / "int.mcap", ["s"]):
            raise KeyboardInterrupt
    assert read_log(tmp_path / "int.mcap").final_status["state"] == "interrupted"


def test_a_cut_off_file_is_read_up_to_its_last_chunk(tmp_path):
    path = tmp_path / "run.mcap"
    _logged_run(path, duration=6.0, chunk_size=16 * 1024)
    raw = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(raw[: len(raw) * 2 // 3])
    log = read_log(cut)
    assert log.truncated and not file_is_complete(cut)
    n_full = len(read_log(path).topic(TOPIC_SENSORS))
    assert 0 < len(log.topic(TOPIC_SENSORS)) < n_full


def test_refuses_to_overwrite_and_rejects_foreign_files(tmp_path):
    path = tmp_path / "run.mcap"
    _logged_run(path, duration=0.5)
    with pytest.raises(LogError, match="refusing to overwrite"):
        LogRecorder(path, ["s"])
    LogRecorder(path, ["s"], force=True).close()
    (tmp_path / "text.mcap").write_text("not a log")
    with pytest.raises(LogError, match="not an MCAP file"):
        read_log(tmp_path / "text.mcap")
    with pytest.raises(LogError, match="cannot read"):
        read_log(tmp_path / "missing.mcap")


def test_vehicle_messages_carry_the_contact_forces(tmp_path):
    path = tmp_path / "run.mcap"
    result = _logged_run(path)
    frames = read_log(path).topic(TOPIC_VEHICLES)
    forces = [v["contact_force"] for f in frames for v in f["vehicles"] if v["id"] == "a"]
    expected = result.vehicle("a")["contact_force"]
    logged = np.isin(result.vehicle("a")["t"], [f["t"] for f in frames])
    np.testing.assert_array_equal(np.array(forces), expected[logged])
    assert len(read_log(path).topic(TOPIC_STATUS)) >= 2


def test_the_vehicle_schema_follows_the_recorded_fields():
    """The /cosim/vehicles item is derived from VEHICLE_FIELDS and keeps the layout logs have always had."""
    from cosim.core.fields import VEHICLE_FIELDS
    from cosim.log.schemas import VEHICLE_ITEM

    names = ["id", "model", "x", "y", "speed", "acceleration", "body_displacement", "body_acceleration",
             "contact_force"]
    assert list(VEHICLE_ITEM["properties"]) == names == [f.name for f in VEHICLE_FIELDS]
    assert VEHICLE_ITEM["required"] == names and VEHICLE_ITEM["additionalProperties"] is False
    types = {name: prop["type"] for name, prop in VEHICLE_ITEM["properties"].items()}
    assert types == {name: "string" if name in ("id", "model") else "number" for name in names}
    assert VEHICLE_ITEM["properties"]["contact_force"]["description"] == "wheel on deck, compression positive, N"


def test_one_reader_whole_streamed_and_overview_agree_on_finished_and_cut_files(tmp_path):
    from cosim.log import iter_messages, open_log

    path = tmp_path / "run.mcap"
    _logged_run(path, duration=6.0, chunk_size=16 * 1024)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size * 2 // 3])
    for log_path, complete in ((path, True), (cut, False)):
        whole = read_log(log_path)
        overview = open_log(log_path)
        assert overview.complete is complete and whole.truncated is (not complete)
        assert overview.counts == {topic: len(msgs) for topic, msgs in whole.messages.items()}
        assert overview.final_status == whole.final_status and overview.attachments == whole.attachments
        assert overview.end_time == max(ns for msgs in whole.messages.values() for ns, _ in msgs) / 1e9
        streamed = [msg for _, msg in iter_messages(log_path, [TOPIC_SENSORS])]
        assert streamed == whole.topic(TOPIC_SENSORS)
    assert overview.status_word == "started (truncated)"  # cut before its first "running" status (every 10 s)


def test_damage_in_a_finished_log_is_an_error_for_every_reader(tmp_path):
    from mcap.reader import make_reader

    from cosim.log import iter_messages, open_log

    path = tmp_path / "run.mcap"
    _logged_run(path, duration=2.0)
    with open(path, "rb") as fh:
        chunk = make_reader(fh).get_summary().chunk_indexes[0]
    raw = bytearray(path.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    raw[middle:middle + 64] = bytes(64)
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(raw))
    for read in (read_log, open_log, lambda p: list(iter_messages(p, [TOPIC_SENSORS]))):
        with pytest.raises(LogError, match="corrupt MCAP file"):
            read(damaged)
