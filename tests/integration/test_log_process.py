"""The log written by a child process (cosim.log.process): real forks, real pipes, real MCAP files."""
from __future__ import annotations

import datetime
import os
import threading
from multiprocessing import active_children
from pathlib import Path

import numpy as np
import pytest
from _cli import bundled_scenario
from mcap.reader import make_reader

from cosim.core.traffic import Frame, pack_frames, unpack_frames
from cosim.errors import ConfigError, LogError
from cosim.log import TOPIC_SENSORS, TOPIC_STATUS, read_log
from cosim.log.process import WRITER_NICENESS, LogProcess, fork_possible
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario

STARTED = datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc)
#: SUMO's messages name its scratch folder (a new one per run): not compared.
SCRATCH_NAMED = {"sumo-messages.log"}

pytestmark = pytest.mark.skipif(not fork_possible(), reason="the log writer process needs Linux and fork")


def log_records(path: Path) -> tuple[list, list, list]:
    """Every message but the status (whose wall times differ), every attachment, every metadata record."""
    with open(path, "rb") as fh:
        reader = make_reader(fh)
        messages = sorted((channel.topic, m.log_time, m.data) for _, channel, m in reader.iter_messages()
                          if channel.topic != TOPIC_STATUS)
        attachments = sorted((a.name, a.data) for a in reader.iter_attachments() if a.name not in SCRATCH_NAMED)
        metadata = sorted((m.name, sorted(m.metadata.items())) for m in reader.iter_metadata())
    return messages, attachments, metadata


@pytest.mark.parametrize("name, end, scene", [("paper-double-tee", None, None), ("paper-bridge-traffic", 20.0, None),
                                              ("paper-bridge-traffic", 20.0, False)])
def test_the_process_writes_the_same_log_as_the_thread(tmp_path: Path, name: str, end: float | None,
                                                       scene: bool | None) -> None:
    """SUMO: 20 s of traffic, the 3D scene and SUMO's frames included; without the scene, the run beside the
    writer process steps SUMO in a process of its own (cosim.run.sumo_process), and the log is still the same."""
    scenario = bundled_scenario(name, end=end, scene=scene)
    bridge = scenario.build_bridge()
    logs = {}
    children: dict[str, set[str]] = {"thread": set(), "process": set()}
    for writer in ("thread", "process"):
        logs[writer] = tmp_path / f"{writer}.mcap"
        run_logged(scenario, logs[writer], bridge=bridge, writer=writer, started=STARTED,
                   progress=lambda _, seen=children[writer]: seen.update(p.name for p in active_children()))
    thread, process = log_records(logs["thread"]), log_records(logs["process"])
    assert len(thread[0]) > 100  # a run's worth of messages, not an empty comparison
    assert process == thread  # same objects encode the same messages: byte for byte
    assert read_log(logs["process"]).final_status["state"] == "finished"
    assert children["process"] == {"cosim-log-writer"} | ({"cosim-sumo"} if scene is False else set())
    assert children["thread"] == set()


def test_an_error_in_the_writer_process_is_raised_in_the_run_and_the_log_still_ends(tmp_path: Path) -> None:
    log = LogProcess(tmp_path / "run.mcap", ["mid"])
    log.write(TOPIC_SENSORS, 0.0, {"t": 0.0, "mid": 0.0})
    log.write("/no/such/topic", 0.1, {"t": 0.1})  # the child's recorder has no channel for it: KeyError there
    with pytest.raises(LogError, match=r"run\.mcap: writing the log failed: KeyError: '/no/such/topic'"):
        for _ in range(200):  # the child reports asynchronously: the run hears of it at a later message
            log.flush()
            threading.Event().wait(0.01)
    with pytest.raises(LogError, match="writing the log failed: KeyError"):
        log.close("error", "stopped")
    contents = read_log(tmp_path / "run.mcap")
    assert not contents.truncated and contents.final_status["message"] == "stopped"
    assert len(contents.topic(TOPIC_SENSORS)) == 1


def test_a_log_the_process_cannot_create_is_the_recorders_error(tmp_path: Path) -> None:
    taken = tmp_path / "taken.mcap"
    taken.write_bytes(b"someone's file")
    with pytest.raises(LogError, match=r"taken\.mcap: exists; refusing to overwrite a log \(use --force\)"):
        LogProcess(taken, ["mid"])
    assert taken.read_bytes() == b"someone's file"


def test_the_writer_argument_is_checked(tmp_path: Path) -> None:
    scenario = load_scenario("paper-double-tee")
    with pytest.raises(ConfigError, match=r"`writer` must be one of auto, process, thread \(got 'fork'\)"):
        run_logged(scenario, tmp_path / "a.mcap", writer="fork")
    errors: list[BaseException] = []

    def in_a_thread() -> None:
        try:
            run_logged(scenario, tmp_path / "b.mcap", writer="process")
        except BaseException as exc:  # noqa: BLE001 - checked below, in the test's thread
            errors.append(exc)

    worker = threading.Thread(target=in_a_thread)
    worker.start()
    worker.join()
    assert len(errors) == 1 and isinstance(errors[0], ConfigError)
    assert "needs Linux and the main thread" in str(errors[0])
    assert not (tmp_path / "a.mcap").exists() and not (tmp_path / "b.mcap").exists()


@pytest.mark.parametrize("dt", [0.005, 0.002])
def test_joined_blocks_are_logged_in_pieces_exactly_as_block_by_block(tmp_path: Path, dt: float) -> None:
    """The solver hands over blocks of one fleet joined (simulate(join_blocks=True)); the logger writes them in
    pieces of the traffic's blocks, with SUMO's frames among them as they came: the reference is the same run
    handed over block by block. Real SUMO, real MCAP files: same messages, same bytes, same order."""
    from cosim.core.simulation import simulate
    from cosim.log.writer import BlockLogger, LogRecorder
    from cosim.run.logged import FrameRelay
    from cosim.run.simulate import build_traffic

    scenario = bundled_scenario("paper-bridge-traffic", end=40.0, dt=dt)
    bridge = scenario.build_bridge()
    names = [s.name for s in scenario.sensors_core()]
    orders = []
    for join in (True, False):
        path = tmp_path / f"join-{join}.mcap"
        relay = FrameRelay()  # the frame sink the source is built with, connected once the log is open
        with LogRecorder(path, names) as rec, build_traffic(scenario, frame_sink=relay) as traffic:
            with BlockLogger(rec, names, 40.0, threaded=False, piece_steps=200 if join else None) as logger:
                relay.connect(logger.traffic_sink())
                simulate(bridge, traffic, 40.0, scenario.solver_settings(), scenario.sensors_core(),
                         road=scenario.build_road(), output_every=scenario.output_every, observers=[logger],
                         collect=False, join_blocks=join)
        with open(path, "rb") as fh:
            orders.append([(channel.topic, m.log_time, m.data) for _, channel, m in
                           make_reader(fh).iter_messages(log_time_order=False) if channel.topic != TOPIC_STATUS])
    joined, separate = orders
    assert sum(topic == "/cosim/traffic" for topic, _, _ in separate) > 100  # SUMO's frames are among them
    assert joined == separate


def test_frames_packed_for_the_pipe_come_back_equal_bit_for_bit() -> None:
    rng = np.random.default_rng(7)
    frames = []
    for k, n in enumerate((0, 2, 0, 3, 1)):  # empty frames too: they carry time for the log's pieces
        ids = tuple(f"v{k}.{i}" for i in range(n))
        frames.append(Frame(0.05 * (k + 1), ids, *(rng.normal(size=n) for _ in range(4)), tuple("car" for _ in ids)))
    back = unpack_frames(pack_frames(frames))
    assert len(back) == len(frames)
    for got, sent in zip(back, frames):
        assert (got.t, got.ids, got.types) == (sent.t, sent.ids, sent.types)
        for column in ("x", "y", "v", "a"):
            assert getattr(got, column).tobytes() == getattr(sent, column).tobytes()  # the same doubles
    assert unpack_frames(pack_frames([])) == []


def test_the_writer_process_runs_nicer_than_the_run(tmp_path: Path) -> None:
    log = LogProcess(tmp_path / "run.mcap", ["mid"])
    try:
        ours = os.getpriority(os.PRIO_PROCESS, 0)
        # The child lowered its priority before it said it was ready (Linux caps niceness at 19).
        assert os.getpriority(os.PRIO_PROCESS, log._process.pid) == min(ours + WRITER_NICENESS, 19)
    finally:
        log.close()
