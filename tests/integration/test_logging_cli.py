"""MCAP logs through the command line, as users run it: real files, the commands in this process,
and real processes for Ctrl-C (SIGINT) and SIGKILL in the middle of a run.

``cosim run`` -> log -> ``info`` / ``export`` / ``plot``; ``replay`` bit for bit
and onto another bridge; stopped runs; damaged and foreign files; overwrite
refusal; every message of a real run against its JSON Schema.
"""
from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomllib
from _cli import TWO_CARS, cli_env, cosim_cli

import cosim
from cosim.log import TOPIC_EVENTS, TOPIC_SENSORS, TOPIC_STATUS, TOPIC_VEHICLES, read_log
from cosim.log.process import ORPHANED
from cosim.run.scenario import load_scenario
from cosim.run.simulate import simulate_scenario
from cosim.run.toml_writer import toml_dumps

# A 20 m span with explicit constants (fast to build): a quarter-car along +x
# and a golden car along -x on a class H road (the light wheels lift off),
# logged at 100 Hz (every 5th step of 2 ms).
CARS = TWO_CARS.replace('name = "two-cars"', 'name = "cars"')

# The same bridge with a measured road profile next to the scenario (an input
# file the log must carry) and a different name.
PROFILED = CARS.replace('name = "cars"', 'name = "profiled"').replace(
    '[road]\nclass = "H"\nseed = 7', '[road]\nprofile = "data/road.csv"')

# Another bridge for the same traffic: 24 m, stiffer, other damping.
OTHER = (CARS.replace('name = "cars"', 'name = "other"').replace("spans = [20.0]", "spans = [24.0]")
         .replace("I_y = 0.5", "I_y = 0.9").replace("ratios = [0.02, 0.02]", "ratios = [0.05, 0.05]"))

# A run long enough to be stopped from outside: one slow car, 10 000 s, every step logged.
LONG = (CARS.replace('name = "cars"', 'name = "long"').replace("speed = 25.0", "speed = 0.05")
        .replace("[solver]\ndt = 0.002", "[solver]\ndt = 0.002\nduration = 10000.0\n[output]\nevery = 1"))


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



def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def sensors_of(path: Path) -> list[dict]:
    return read_log(path, [TOPIC_SENSORS]).topic(TOPIC_SENSORS)


def one_line_error(result: subprocess.CompletedProcess[str], *fragments: str) -> None:
    assert result.returncode == 2, (result.stdout, result.stderr)
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: "), result.stderr
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


@pytest.fixture(scope="module")
def cars_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One real run of CARS, shared by the read-only tests."""
    folder = tmp_path_factory.mktemp("cars")
    scenario = write(folder, "cars.toml", CARS)
    result = cosim_cli("run", str(scenario), "--out", "cars.mcap", "--quiet", cwd=folder)
    assert result.returncode == 0, result.stderr
    assert "Wrote the log cars.mcap (" in result.stdout
    return folder / "cars.mcap"


# --------------------------------------------------------------------------- run -> log


def test_the_log_holds_the_run_exactly_and_is_self_contained(cars_log: Path) -> None:
    log = read_log(cars_log)
    assert not log.truncated and log.final_status["state"] == "finished"
    # The sensor channels are the simulation's own samples, float for float (t = 0 at rest included).
    expected = simulate_scenario(load_scenario(cars_log.parent / "cars.toml"))
    samples = log.topic(TOPIC_SENSORS)
    np.testing.assert_array_equal([m["t"] for m in samples], expected.t)
    for name, values in expected.sensors.items():
        np.testing.assert_array_equal([m[name] for m in samples], values)
    assert [ns for ns, _ in log.messages[TOPIC_SENSORS]][:3] == [0, 10_000_000, 20_000_000]  # integer ns
    # What a re-run needs: the scenario text exactly, resolved parameters, section, modes, metadata.
    assert log.attachments["scenario.toml"] == CARS.encode()
    resolved = json.loads(log.attachments["resolved.json"])
    assert resolved["scenario"]["solver"]["scheme"] == "newmark" and resolved["derived"]["output_every"] == 5
    assert json.loads(log.attachments["section.json"])["A"] == 2.0
    modes = json.loads(log.attachments["modes.json"])["modes"]
    assert modes[0]["kind"] == "vertical" and len(modes) == 20
    meta = log.metadata["cosim"]
    assert (meta["version"], meta["scenario"], meta["dt"], meta["rate_hz"]) == (cosim.__version__, "cars", "0.002",
                                                                                repr(100.0))
    assert json.loads(meta["sensors"]) == ["mid", "mid_left_acc"]
    states = [m["state"] for m in log.topic(TOPIC_STATUS)]
    assert states[0] == "started" and states[-1] == "finished"
    events = {(e["vehicle"], e["event"]) for e in log.topic(TOPIC_EVENTS)}
    assert {("truck", "entered"), ("truck", "left"), ("car", "entered"), ("car", "left")} <= events
    assert any(kind == "liftoff" for _, kind in events)  # class H road


def test_every_message_validates_against_its_schema(cars_log: Path) -> None:
    from mcap.reader import make_reader

    counts: dict[str, int] = {}
    with open(cars_log, "rb") as fh:
        reader = make_reader(fh, validate_crcs=True)
        validators: dict[bytes, Any] = {}
        for schema, channel, message in reader.iter_messages():
            assert schema.encoding == "protobuf" and channel.message_encoding == "protobuf"
            assert isinstance(stored_schema_decoder(schema, validators)(message.data), dict)
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
        summary = reader.get_summary()
    assert counts[TOPIC_SENSORS] == 401 and counts[TOPIC_VEHICLES] > 100 and counts[TOPIC_EVENTS] >= 4
    assert summary.statistics.message_count == sum(counts.values())
    assert all(index.compression == "zstd" for index in summary.chunk_indexes)


def test_info_export_and_plot(cars_log: Path, tmp_path: Path) -> None:
    info = cosim_cli("info", str(cars_log), cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    out = info.stdout
    for text in ("Scenario: cars", f"cosim {cosim.__version__}", "Simulated: 4 s of 4 s",
                 "Sensors (2): mid (displacement), mid_left_acc (acceleration)", "Vehicles (2): truck, car",
                 "/cosim/sensors", "401 messages", "Status: finished", "Truncated: no", "scenario.toml"):
        assert text in out, (text, out)

    table = tmp_path / "cars.csv"
    result = cosim_cli("export", str(cars_log), "--csv", str(table), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    with open(table, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", "mid", "mid_left_acc"] and len(rows) == 402
    samples = sensors_of(cars_log)
    assert [[float(v) for v in row] for row in rows[1:]] == [[m["t"], m["mid"], m["mid_left_acc"]] for m in samples]

    vehicles = tmp_path / "vehicles.csv"
    assert cosim_cli("export", str(cars_log), "--topic", TOPIC_VEHICLES, "--csv", str(vehicles),
                     cwd=tmp_path).returncode == 0
    with open(vehicles, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["id"] for r in rows} == {"truck", "car"} and {r["model"] for r in rows} == {"quarter-car",
                                                                                          "tyre-quarter-car"}
    assert float(rows[0]["contact_force"]) > 0

    figure = tmp_path / "cars.png"
    result = cosim_cli("plot", str(cars_log), "--sensor", "mid", "-o", str(figure), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    one_line_error(cosim_cli("plot", str(cars_log), "--sensor", "nope", "-o", str(tmp_path / "x.png"), cwd=tmp_path),
                   "no sensor nope in this log (sensors: mid, mid_left_acc)")


def test_outputs_are_never_overwritten_silently(cars_log: Path, tmp_path: Path) -> None:
    keep = write(tmp_path, "keep.csv", "mine\n")
    figure = write(tmp_path, "keep.png", "mine\n")
    for args in (("export", str(cars_log), "--csv", str(keep)), ("plot", str(cars_log), "-o", str(figure)),
                 ("replay", str(cars_log), "--out", str(cars_log))):
        one_line_error(cosim_cli(*args, cwd=tmp_path), "already exists")
    assert keep.read_text() == "mine\n" and figure.read_text() == "mine\n"
    assert cosim_cli("export", str(cars_log), "--csv", str(keep), "--force", cwd=tmp_path).returncode == 0
    assert keep.read_text().startswith("t,mid,mid_left_acc")


# --------------------------------------------------------------------------- replay


def test_replay_reproduces_the_sensors_bit_for_bit_from_the_log_alone(tmp_path: Path) -> None:
    run_dir = tmp_path / "run"
    scenario = write(run_dir, "profiled.toml", PROFILED)
    x = np.linspace(-1.0, 21.0, 221).tolist()
    write(run_dir, "data/road.csv", "x,r\n" + "".join(f"{a!r},{0.004 * np.sin(1.3 * a):.6f}\n" for a in x))
    result = cosim_cli("run", str(scenario), "--out", "first.mcap", "--quiet", cwd=run_dir)
    assert result.returncode == 0, result.stderr
    first = run_dir / "first.mcap"
    assert read_log(first).attachments["data/road.csv"].startswith(b"x,r\n")
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    os.replace(first, moved / "first.mcap")
    (run_dir / "data" / "road.csv").unlink()  # the log alone must be enough
    scenario.unlink()

    result = cosim_cli("replay", "first.mcap", "--out", "again.mcap", "--quiet", cwd=moved)
    assert result.returncode == 0, result.stderr
    assert "the 2 sensor channel(s) are identical, bit for bit (401 samples)" in result.stdout
    a, b = sensors_of(moved / "first.mcap"), sensors_of(moved / "again.mcap")
    assert a == b and len(a) == 401
    again = read_log(moved / "again.mcap")
    assert again.attachments["scenario.toml"] == PROFILED.encode()
    assert again.metadata["replay"]["log"] == "first.mcap" and again.metadata["cosim"]["kind"] == "replay"


def test_replay_onto_another_bridge(cars_log: Path, tmp_path: Path) -> None:
    other = write(tmp_path, "other.toml", OTHER)
    result = cosim_cli("replay", str(cars_log), "--scenario", str(other), "--out", "other.mcap", "--quiet",
                       cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Sensors of the same name, the logged run vs this bridge" in result.stdout
    new = read_log(tmp_path / "other.mcap")
    assert new.final_status["state"] == "finished"
    merged = tomllib.loads(new.attachments["scenario.toml"].decode())
    assert merged["bridge"]["spans"] == [24.0] and [v["id"] for v in merged["vehicles"]] == ["truck", "car"]
    assert new.attachments["replay/bridge-scenario.toml"] == OTHER.encode()
    # Same traffic, another bridge: a longer crossing, other deflections.
    old_mid = np.array([m["mid"] for m in sensors_of(cars_log)])
    new_mid = np.array([m["mid"] for m in new.topic(TOPIC_SENSORS)])
    assert len(new_mid) > len(old_mid) and abs(new_mid.min() - old_mid.min()) > 0.05 * abs(old_mid.min())
    # The replay's log replays by itself, bit for bit.
    again = cosim_cli("replay", "other.mcap", "--out", "other-again.mcap", "--quiet", cwd=tmp_path)
    assert again.returncode == 0 and "identical, bit for bit" in again.stdout, again.stderr

    bridge_only = OTHER[:OTHER.index("[[vehicles]]")] + "[solver]\ndt = 0.002\nduration = 1.0\n"
    narrow = write(tmp_path, "narrow.toml", bridge_only.replace("deck_y = [-3.0, 3.0]", "deck_y = [-1.0, 1.0]")
                   .replace("y = 2.0", "y = 0.5"))
    result = cosim_cli("replay", str(cars_log), "--scenario", str(narrow), cwd=tmp_path)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.startswith(f"cosim: error: {narrow} with the traffic of {cars_log}: vehicles[0].y: "
                                    "must lie on the deck, -1 <= y <= 1 m (got 1.5)"), result.stderr


# --------------------------------------------------------------------------- stopped runs


def start_long_run(folder: Path) -> tuple[subprocess.Popen[str], Path]:
    scenario = write(folder, "long.toml", LONG)
    log = folder / "long.mcap"

    def default_sigint() -> None:  # a child of a non-interactive shell may inherit SIGINT ignored
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    proc = subprocess.Popen([sys.executable, "-m", "cosim", "run", str(scenario), "--out", str(log)],
                            cwd=folder, env=cli_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_sigint, start_new_session=True)  # its group: the run, its log writer
    deadline = time.monotonic() + 60
    while not (log.exists() and log.stat().st_size > 600_000):  # a few chunks are on disk
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run did not write its log"
        time.sleep(0.05)
    return proc, log


def test_ctrl_c_leaves_a_finished_log_with_status_interrupted(tmp_path: Path) -> None:
    proc, log = start_long_run(tmp_path)
    os.killpg(proc.pid, signal.SIGINT)  # as a terminal does: to the run and its log writer process
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, (out, err)
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].endswith(f'the log up to there is in {log} (finished, status "interrupted")')
    contents = read_log(log)
    assert not contents.truncated and contents.final_status["state"] == "interrupted"
    assert 0 < len(contents.topic(TOPIC_SENSORS)) < 5_000_000
    info = cosim_cli("info", str(log), cwd=tmp_path)
    assert info.returncode == 0 and "Status: interrupted" in info.stdout and "Truncated: no" in info.stdout


def test_sigkill_of_the_run_leaves_a_log_its_writer_process_finishes(tmp_path: Path) -> None:
    proc, log = start_long_run(tmp_path)
    proc.kill()  # the run only (the out-of-memory killer's way): its log writer process finishes the file
    proc.communicate(timeout=60)  # returns when the writer, which shares the run's output pipes, has ended too
    assert proc.returncode == -signal.SIGKILL
    contents = read_log(log)
    assert not contents.truncated and contents.final_status["state"] == "error"
    assert contents.final_status["message"] == ORPHANED
    info = cosim_cli("info", str(log), cwd=tmp_path)
    assert info.returncode == 0 and "Truncated: no" in info.stdout and ORPHANED in info.stdout, info.stdout


def test_sigkill_of_the_whole_group_leaves_a_truncated_log_that_can_still_be_read(tmp_path: Path) -> None:
    proc, log = start_long_run(tmp_path)
    os.killpg(proc.pid, signal.SIGKILL)  # the run and its log writer: nothing finishes the file
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    info = cosim_cli("info", str(log), cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    assert "TRUNCATED" in info.stdout and "Truncated: yes" in info.stdout and "Scenario: long" in info.stdout
    result = cosim_cli("export", str(log), "--csv", "part.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "was cut short (truncated)" in result.stderr
    with open(tmp_path / "part.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", "mid", "mid_left_acc"] and len(rows) > 1000
    times = [float(r[0]) for r in rows[1:]]
    assert times == sorted(times) and times[0] == 0.0


# --------------------------------------------------------------------------- bad files


def test_foreign_damaged_and_missing_files_exit_2_with_one_line(cars_log: Path, tmp_path: Path) -> None:
    text = write(tmp_path, "notes.mcap", "not a log at all\n")
    raw = bytearray(cars_log.read_bytes())
    from mcap.reader import make_reader

    with open(cars_log, "rb") as fh:
        chunk = make_reader(fh).get_summary().chunk_indexes[0]
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    raw[middle:middle + 64] = bytes(64)  # inside the first chunk's compressed data
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(raw))
    from mcap.writer import Writer

    foreign = tmp_path / "foreign.mcap"
    with open(foreign, "wb") as fh:
        writer = Writer(fh)
        writer.start(profile="ros2", library="test")
        writer.finish()
    cases = [(text, "not an MCAP file"), (damaged, "corrupt MCAP file"),
             (foreign, "an MCAP file, but not a cosim log (profile 'ros2')"),
             (tmp_path / "missing.mcap", "cannot read")]
    for path, fragment in cases:
        for args in (("info", str(path)), ("export", str(path), "--csv", str(tmp_path / "o.csv")),
                     ("plot", str(path), "-o", str(tmp_path / "o.png")), ("replay", str(path))):
            one_line_error(cosim_cli(*args, cwd=tmp_path), str(path), fragment)
    assert not (tmp_path / "o.csv").exists() and not (tmp_path / "runs").exists()


# --------------------------------------------------------------------------- pieces


def test_scenarios_survive_the_toml_writer() -> None:
    for text in (CARS, PROFILED, LONG, load_scenario("paper-double-tee").text):
        data = tomllib.loads(text)
        assert tomllib.loads(toml_dumps(data)) == data
    odd = {"a b": "quote \" and \\ and \x7f", "x": [1, 2.5e-300, -0.0], "t": {"inner": [{"k": True}, {"k": False}]}}
    assert tomllib.loads(toml_dumps(odd)) == odd


def test_outputs_are_written_whole_or_not_at_all(tmp_path: Path) -> None:
    from cosim.errors import CosimError
    from cosim.run.outputs import atomic_write

    target = write(tmp_path, "out.csv", "old\n")
    with pytest.raises(RuntimeError):
        with atomic_write(target, "CSV") as partial:
            partial.write_text("half")
            raise RuntimeError("interrupted while writing")
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]
    with atomic_write(tmp_path / "new" / "out.csv", "CSV") as partial:
        assert partial.parent == tmp_path / "new" and partial.suffix == ".csv"  # same folder, same format
        partial.write_text("whole\n")
    assert (tmp_path / "new" / "out.csv").read_text() == "whole\n" and len(list((tmp_path / "new").iterdir())) == 1
    blocked = tmp_path / "new" / "folder.csv"
    write(blocked, "inside.txt", "")  # a folder where the file should go: the final rename fails
    with pytest.raises(CosimError, match="folder.csv: cannot write the CSV"):
        with atomic_write(blocked, "CSV") as partial:
            partial.write_text("whole\n")
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == ["folder.csv", "out.csv"]


def test_the_bulk_message_path_writes_the_same_bytes_as_mcap() -> None:
    import io
    import random

    from mcap.writer import CompressionType

    from cosim.log.writer import _BulkWriter

    rng = random.Random(1)
    datas = [bytes(rng.randrange(256) for _ in range(rng.randrange(1, 2000))) for _ in range(1200)]
    times = sorted(rng.randrange(10**12) for _ in datas)
    for chunk_size in (1000, 16 * 1024, 1024 * 1024):
        files = []
        for bulk in (False, True):
            out = io.BytesIO()
            writer = _BulkWriter(out, chunk_size=chunk_size, compression=CompressionType.ZSTD)
            writer.start(profile="cosim", library="test")
            schema = writer.register_schema("s", "jsonschema", b"{}")
            channels = [writer.register_channel(topic, "json", schema) for topic in ("/a", "/b")]
            sequence = 0
            for k in range(0, len(datas), 100):
                for channel in channels:
                    if bulk:
                        sequence = writer.add_encoded(channel, times[k:k + 100], datas[k:k + 100], sequence)
                    else:
                        for t, data in zip(times[k:k + 100], datas[k:k + 100]):
                            sequence += 1
                            writer.add_message(channel, t, data, t, sequence)
            writer.finish()
            files.append(out.getvalue())
        assert files[0] == files[1], chunk_size
