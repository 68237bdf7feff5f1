"""MCAP logs: real files written and read back (no mocks)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

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
from cosim.log.proto import TOPIC_MESSAGES
from cosim.log.scene import SceneWriter, plan_scene, scene_sensors
from cosim.log.schemas import TOPIC_SCENE, TOPIC_SCENE_STATIC, TOPIC_SCENE_TRANSFORM

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=0.0,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))
SENSORS = [Sensor("mid", 15.0, 0.0), Sensor("edge_acc", 15.0, 6.0, "acceleration")]


def stored_schema_decoder(schema: Any, cache: dict[tuple[str, bytes], Any]) -> Any:
    """A decoder of a channel's messages built from its schema record alone (the ``FileDescriptorSet`` in the file),
    with the protobuf runtime, as Foxglove and the ``mcap`` CLI read them: an independent check of the encoding."""
    if (schema.name, schema.data) not in cache:
        from google.protobuf import descriptor_pb2, json_format, message_factory

        files = descriptor_pb2.FileDescriptorSet.FromString(schema.data).file
        cls = message_factory.GetMessages(list(files))[schema.name]

        def decode(data: bytes) -> dict:
            message = cls.FromString(data)
            return json_format.MessageToDict(message, preserving_proto_field_name=True)

        cache[(schema.name, schema.data)] = decode
    return cache[(schema.name, schema.data)]



def _logged_run(path, duration=2.0, scene=False, **kwargs):
    """Two quarter-cars over a 30 m span, logged (with the 3D scene and its hidden sensors if ``scene``)."""
    bridge = build_bridge([30.0], 10, MAT, SEC, ["rigid-end", "rigid-end"])
    cars = (ScriptedVehicle("a", QuarterCar(1e4, 1e3, 4e5, 2e4), 3.0, 20.0),
            ScriptedVehicle("b", QuarterCar(2e4, 2e3, 8e5, 4e4), -3.0, 15.0, entry_time=0.3, direction=-1))
    names = [s.name for s in SENSORS]
    plan = plan_scene(bridge, SENSORS, 0.005, paths=[3.0, -3.0], taken=names) if scene else None
    with LogRecorder(path, names, scene=scene, **kwargs) as rec:
        writer = SceneWriter(rec, plan, len(names)) if plan is not None else None
        if writer is not None:
            writer.start()
        with BlockLogger(rec, names, duration, scene=writer) as logger:
            rec.attach("scenario.toml", "# test\n")
            rec.status(0.0, "started")
            result = simulate(bridge, ScriptedTraffic(cars, 30.0), duration, SolverSettings(dt=0.005),
                              [*SENSORS, *(scene_sensors(plan) if plan is not None else [])],
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
    _logged_run(path, scene=True)
    with open(path, "rb") as fh:
        reader = make_reader(fh, validate_crcs=True)
        validators: dict[bytes, Any] = {}
        counts: dict[str, int] = {}
        for schema, channel, message in reader.iter_messages():
            assert schema.encoding == "protobuf" and channel.message_encoding == "protobuf"
            assert schema.name == TOPIC_MESSAGES[channel.topic], channel.topic
            assert isinstance(stored_schema_decoder(schema, validators)(message.data), dict)
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    assert counts[TOPIC_SENSORS] > 100
    # the scene: at t = 0 and every 0.1 s; the static part and the transform once
    assert counts[TOPIC_SCENE] == 21 and counts[TOPIC_SCENE_STATIC] == counts[TOPIC_SCENE_TRANSFORM] == 1
    assert read_log(path).topic(TOPIC_SCENE)  # and cosim's reader checks them against its own schemas


# --------------------------------------------------------------------------- Foxglove

#: The JSON types Foxglove's JSON-Schema parser turns into fields (studio-base 1.48's parseJsonSchema, the same
#: code in Lichtblick): a property without one (an ``enum`` alone) drops the whole channel with
#: "Unsupported type undefined for <field>", and arrays of arrays are not supported.
FOXGLOVE_TYPES = {"boolean", "string", "number", "integer", "object", "array"}


def foxglove_problems(schema: dict[str, Any], where: str = "") -> list[str]:
    """What Foxglove would reject in a message schema: every property needs a type it knows, objects are
    walked, an array's items need a type too (not another array)."""
    if schema.get("type") != "object":
        return [f"{where or 'the message'}: expected type object, got {schema.get('type')!r}"]
    problems = []
    for name, prop in schema.get("properties", {}).items():
        here = f"{where}.{name}" if where else name
        kind = prop.get("type")
        if kind not in FOXGLOVE_TYPES:
            problems.append(f"{here}: type {kind!r}")
        elif kind == "object":
            problems += foxglove_problems(prop, here)
        elif kind == "array":
            item = prop.get("items", {})
            if item.get("type") not in FOXGLOVE_TYPES - {"array"}:
                problems.append(f"{here}[]: item type {item.get('type')!r}")
            elif item["type"] == "object":
                problems += foxglove_problems(item, here + "[]")
    return problems


def test_every_schema_is_one_foxglove_accepts():
    from cosim.log.schemas import topic_schemas

    schemas = topic_schemas(["node1", "node.2", "t_2"], scene=True)
    assert {topic for topic, _ in schemas} >= {TOPIC_EVENTS, TOPIC_STATUS, TOPIC_SCENE, TOPIC_SCENE_TRANSFORM}
    for topic, schema in schemas:
        assert foxglove_problems(schema) == [], topic
    # The check fails where Foxglove failed: the schemas of logs written before this version (enum alone).
    old_events = {"type": "object", "properties": {"t": {"type": "number"}, "event": {"enum": ["entered"]}}}
    assert foxglove_problems(old_events) == ["event: type None"]
    nested = {"type": "object", "properties": {"a": {"type": "array", "items": {"type": "array"}}}}
    assert foxglove_problems(nested) == ["a[]: item type 'array'"]
    # The 3D panel recognises the scene by its schema's name.
    titles = {topic: schema["title"] for topic, schema in schemas}
    assert titles[TOPIC_SCENE] == titles[TOPIC_SCENE_STATIC] == "foxglove.SceneUpdate"
    assert titles[TOPIC_SCENE_TRANSFORM] == "foxglove.FrameTransform"


@pytest.mark.parametrize("name", ["paper-double-tee", "paper-bridge-traffic-fixed-weights"])
def test_logs_written_before_the_schemas_had_types_still_read(name):
    """A scripted and a SUMO log written by an earlier version: every message checked against today's schemas."""
    from mcap.reader import make_reader

    from cosim.log import open_log

    path = Path(__file__).resolve().parents[1] / "regression" / "logs" / f"{name}.mcap"
    with open(path, "rb") as fh:
        summary = make_reader(fh).get_summary()
    stored = {c.topic: json.loads(summary.schemas[c.schema_id].data) for c in summary.channels.values()}
    assert "type" not in stored[TOPIC_EVENTS]["properties"]["event"]  # written before this change
    whole = read_log(path)
    assert not whole.truncated and whole.final_status["state"] == "finished"
    assert {topic: len(m) for topic, m in whole.messages.items()} == open_log(path).counts
    assert {e["event"] for e in whole.topic(TOPIC_EVENTS)} >= {"entered", "left"}


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


def test_sumo_frames_handed_to_the_writer_thread_are_all_written_in_order(tmp_path):
    # The traffic sink only queues frames; the writer thread writes them with the next block, and close()
    # writes those still waiting (a run stopped between two blocks must still replay to its last frame).
    from cosim.core.coupling import BlockReport
    from cosim.core.traffic import Frame
    from cosim.log.reader import iter_messages
    from cosim.log.schemas import TOPIC_TRAFFIC

    model = QuarterCar(1e4, 1e3, 4e5, 2e4)
    frames = [Frame(t=0.05 * k, ids=("car",), x=np.array([1.0 + k]), y=np.array([3.0]), v=np.array([20.0]),
                    a=np.array([0.0]), types=("car",)) for k in range(1, 8)]
    times = np.array([0.005, 0.01])
    none = np.zeros((2, 0))
    report = BlockReport((), (), none, np.zeros(0), none, none, none.astype(bool), none, none, none,
                         np.zeros((2, 1)), none.astype(bool))
    path = tmp_path / "frames.mcap"
    with LogRecorder(path, ["s"]) as rec, BlockLogger(rec, ["s"], 1.0) as logger:
        sink = logger.traffic_sink()
        for frame in frames[:4]:  # handed over with the block below
            sink(frame, {"car": model})
        logger.on_block(times, np.array([True, True]), report)
        for frame in frames[4:]:  # after the last block: written by close()
            sink(frame, {"car": model})
    got = [m for _, m in iter_messages(path, [TOPIC_TRAFFIC])]
    assert [m["t"] for m in got] == [f.t for f in frames]
    assert [m["x"] for m in got] == [[f.x[0]] for f in frames]


def test_the_bulk_writer_reaches_mcaps_chunk_state_and_writes_the_bytes_of_its_public_api(monkeypatch):
    """The one read of mcap's private state (``cosim.log.writer._mcap_chunk_state``) still finds it, and the bulk
    path built on it writes the bytes mcap's public ``add_message`` writes: if mcap's internals change, this
    fails, rather than logging silently falling back to the slow path (or writing other bytes)."""
    import io

    from mcap.writer import CompressionType, Writer

    from cosim.log.writer import _BulkWriter, _mcap_chunk_state

    assert _mcap_chunk_state(Writer(io.BytesIO(), chunk_size=4096)) is not None, (
        "mcap's Writer no longer keeps its chunk state where cosim.log.writer._mcap_chunk_state reads it")
    rng = np.random.default_rng(7)
    datas = [bytes(rng.integers(0, 256, int(rng.integers(1, 600)), dtype=np.uint8)) for _ in range(600)]
    times = sorted(int(t) for t in rng.integers(0, 10**12, len(datas)))
    files = []
    for bulk in (False, True):
        out = io.BytesIO()
        writer = (_BulkWriter if bulk else Writer)(out, chunk_size=4096, compression=CompressionType.ZSTD,
                                                   enable_data_crcs=True)
        if bulk:  # the bulk path must not need add_message
            monkeypatch.setattr(writer, "add_message", lambda *args, **kwargs: pytest.fail("fell back"))
        writer.start(profile="cosim", library="test")
        schema = writer.register_schema("s", "jsonschema", b"{}")
        channels = [writer.register_channel(topic, "json", schema) for topic in ("/a", "/b")]
        sequence = 0
        for k in range(0, len(datas), 50):
            for channel in channels:
                if bulk:
                    sequence = writer.add_encoded(channel, times[k:k + 50], datas[k:k + 50], sequence)
                else:
                    for t, data in zip(times[k:k + 50], datas[k:k + 50]):
                        sequence += 1
                        writer.add_message(channel, t, data, t, sequence)
        writer.finish()
        files.append(out.getvalue())
    assert files[0] == files[1]
