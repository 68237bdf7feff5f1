"""Issue items 4, 8 and 10: SIGINT, SIGTERM and SIGHUP stop real processes the same way.

Real ``python -m cosim`` processes get real signals: a run and a replay finish
their logs with status "interrupted" and the signal's name and exit with
128 + the signal's number; a replay's scratch folder and an export's
temporary file are removed; a signal during start-up prints one line, never a
traceback; a study writes the table of the runs it completed.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from _robust import PROFILED, ROAD_CSV, SUMO_SCENARIO, cli_env, sumo_folder, write

from cosim.errors import Interrupted
from cosim.log import LogRecorder, open_log
from cosim.run.signals import stop_signals
from cosim.study.execute import _stop_runs

# One slow car for 10 000 s, every step logged: a run long enough to be stopped from outside.
LONG = (PROFILED.replace('name = "profiled"', 'name = "long"').replace("speed = 25.0", "speed = 0.05")
        .replace("[solver]\ndt = 0.002", "[solver]\ndt = 0.002\nduration = 10000.0\n[output]\nevery = 1"))


def start(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    """``python -m cosim ARGS`` as a real process with the default signal dispositions (a child of a
    non-interactive shell may inherit SIGINT ignored), in a session of its own."""
    def defaults() -> None:
        for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(signum, signal.SIG_DFL)

    return subprocess.Popen([sys.executable, "-m", "cosim", *args], cwd=cwd, env=env or cli_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=defaults,
                            start_new_session=True)


def wait_for(condition, timeout: float = 60.0, every: float = 0.01) -> None:  # noqa: ANN001
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError("timed out")
        time.sleep(every)


def finish(proc: subprocess.Popen[str]) -> tuple[int, str]:
    _, err = proc.communicate(timeout=60)
    assert "Traceback" not in err, err
    return proc.returncode, err


@pytest.fixture(scope="module")
def long_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("long")
    write(folder, "long.toml", LONG)
    write(folder, "data/road.csv", ROAD_CSV)
    return folder


def test_each_signal_finishes_the_log_and_exits_128_plus_its_number(long_folder: Path) -> None:
    signals = {signal.SIGINT: "interrupted by the user (SIGINT)", signal.SIGTERM: "interrupted by SIGTERM",
               signal.SIGHUP: "interrupted by SIGHUP"}
    procs = {}
    for signum in signals:  # all three at once: the machine has cores to spare while they start
        log = long_folder / f"{signum.name}.mcap"
        procs[signum] = (start("run", "long.toml", "--out", log.name, "--quiet", cwd=long_folder), log)
    for signum, (proc, log) in procs.items():
        wait_for(lambda log=log: log.exists())  # the log takes its name when the time stepping starts
        time.sleep(0.3)
        proc.send_signal(signum)
    for signum, (proc, log) in procs.items():
        status, err = finish(proc)
        assert status == 128 + signum, (signum, status, err)
        assert err.strip().splitlines()[-1].startswith(f"cosim: interrupted by {signum.name} at about t = ")
        assert f'the log up to there is in {log.name} (finished, status "interrupted")' in err
        overview = open_log(log)
        assert overview.complete and overview.final_status["state"] == "interrupted"
        assert overview.final_status["message"] == signals[signum]
        assert not [p for p in long_folder.iterdir() if ".part" in p.name]


def test_ctrl_c_finishes_the_log_of_a_run_whose_sumo_has_a_process_of_its_own(tmp_path: Path) -> None:
    """Without the 3D scene, a logged run steps SUMO in a child process (cosim.run.sumo_process) beside the log
    writer's. Ctrl-C reaches all three (the terminal signals the process group): the log is finished, one
    line is printed, and SUMO's scratch folder is removed."""
    sumo_folder(tmp_path)
    write(tmp_path, "run.toml", SUMO_SCENARIO.format(end=3000.0).replace("[output]\n", "[output]\nscene = false\n"))
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    proc = start("run", "run.toml", "--out", "run.mcap", "--quiet", cwd=tmp_path,
                 env={**cli_env(), "TMPDIR": str(scratch)})
    wait_for(lambda: (tmp_path / "run.mcap").exists())
    time.sleep(0.5)
    children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
    assert len(children) == 2, children  # the log writer's process and SUMO's
    os.killpg(proc.pid, signal.SIGINT)
    status, err = finish(proc)
    assert status == 130, err
    assert err.strip().splitlines()[-1].startswith("cosim: interrupted by SIGINT at about t = "), err
    overview = open_log(tmp_path / "run.mcap")
    assert overview.complete and overview.final_status["state"] == "interrupted"
    wait_for(lambda: not list(scratch.glob("cosim-sumo-*")), 10)  # SUMO's child closed SUMO and cleaned up


def test_a_signal_before_the_run_starts_leaves_no_log(long_folder: Path) -> None:
    """SIGTERM once the log's temporary file exists but the time stepping has not started (the direct
    basis of a 4207-DOF model is being factorised): nothing is left, and the exit status is 143."""
    heavy = LONG.replace("elements_per_span = 8", "elements_per_span = 600").replace(
        "[bridge.damping]\nratios = [0.02, 0.02]\nmodes = [\"vertical-1\", \"torsion-1\"]\n", "")
    write(long_folder, "heavy.toml", heavy)
    proc = start("run", "heavy.toml", "--out", "heavy.mcap", cwd=long_folder)
    wait_for(lambda: any(p.name.startswith(".heavy.mcap.") for p in long_folder.iterdir()), 60, 0.0005)
    proc.send_signal(signal.SIGTERM)
    status, err = finish(proc)
    assert status == 143, err
    assert "the run had not started: no log was written" in err
    assert not (long_folder / "heavy.mcap").exists()
    assert not [p for p in long_folder.iterdir() if ".part" in p.name]


@pytest.mark.parametrize("delay", [0.3, 1.0])
def test_ctrl_c_during_start_up_prints_one_line(long_folder: Path, delay: float) -> None:
    """Ctrl-C while cosim imports numpy and numba, reads the scenario, builds the bridge: one line, 130.

    (Earlier than about 0.1 s the Python interpreter itself is starting, before any of cosim runs:
    ``python -m cosim`` blocks the signals from its first line on, until its handlers are in place.)
    """
    proc = start("run", "long.toml", "--out", f"startup-{delay}.mcap", cwd=long_folder)
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    status, err = finish(proc)
    assert status == 130, (status, err)
    assert err.strip().splitlines()[-1].startswith("cosim: interrupted"), err
    assert len(err.strip().splitlines()) <= 2, err  # at most a progress line and the one message


def test_a_killed_replay_leaves_no_scratch_folder(long_folder: Path, tmp_path: Path) -> None:
    log = long_folder / "SIGTERM.mcap"
    if not log.exists():
        pytest.skip("needs the SIGTERM run of the test above")
    env = {**cli_env(), "TMPDIR": str(tmp_path)}
    proc = start("replay", str(log), "--scenario", "long.toml", "--out", str(tmp_path / "replay.mcap"), "--quiet",
                 cwd=long_folder, env=env)
    wait_for(lambda: (tmp_path / "replay.mcap").exists())
    assert list(tmp_path.glob("cosim-replay-*"))
    time.sleep(0.3)
    proc.send_signal(signal.SIGTERM)
    status, err = finish(proc)
    assert status == 143, err
    assert not list(tmp_path.glob("cosim-replay-*"))
    assert open_log(tmp_path / "replay.mcap").final_status["message"] == "interrupted by SIGTERM"


def test_a_killed_export_leaves_neither_csv_nor_temporary_file(tmp_path: Path) -> None:
    log = tmp_path / "big.mcap"
    with LogRecorder(log, ["a", "b"]) as rec:
        times = [k * 0.01 for k in range(60_000)]
        for t in times:
            rec.write("/cosim/sensors", t, {"t": t, "a": 1e-3 * t, "b": 0.5})
    proc = start("export", str(log), "--csv", "out.csv", cwd=tmp_path)
    wait_for(lambda: any(".part" in p.name for p in tmp_path.iterdir()), 30, 0.0005)
    proc.send_signal(signal.SIGTERM)
    status, err = finish(proc)
    assert status == 143 and err.strip() == "cosim: interrupted (SIGTERM)", (status, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.mcap"]


STUDY = """\
[study]
name = "stopped"
base = "base.toml"
duration = 20.0
[sweep]
seeds = [1, 2, 3, 4, 5, 6]
"""


@pytest.mark.parametrize("workers, signum", [("0", signal.SIGTERM), ("1", signal.SIGINT)])
def test_a_stopped_study_writes_the_table_of_its_completed_runs(tmp_path: Path, workers: str,
                                                               signum: signal.Signals) -> None:
    """In this process (``--workers 0``) with SIGTERM, and on a Dask worker with Ctrl-C (SIGINT to the
    whole process group, as a terminal sends it): the runs completed are in the table, the one in
    progress stopped with a finished log, no traceback from any process."""
    sumo_folder(tmp_path)
    write(tmp_path, "base.toml", SUMO_SCENARIO.format(end=600.0))
    write(tmp_path, "study.toml", STUDY)
    proc = start("study", "study.toml", "--out", "out", "--workers", workers, "--no-plots", "--quiet",
                 cwd=tmp_path)
    results = tmp_path / "out" / "runs"
    wait_for(lambda: len(list(results.glob("*/result.json"))) >= 1, 120)
    if signum == signal.SIGINT:
        os.killpg(proc.pid, signum)
    else:
        proc.send_signal(signum)
    status, err = finish(proc)
    assert status == 128 + signum, err
    assert err.strip().splitlines()[-1].startswith(f"cosim: interrupted by {signum.name}; the runs completed so far")
    table = pd.read_csv(tmp_path / "out" / "results.csv")
    done = {p.parent.name for p in results.glob("*/result.json")
            if '"status": "ok"' in p.read_text()}
    assert set(table["run_id"]) == done and 1 <= len(done) < 6
    assert (table["status"] == "ok").all()
    stopped = [open_log(p) for p in results.glob("*/run.mcap") if p.parent.name not in done]
    for overview in stopped:
        assert overview.complete and overview.final_status["state"] == "interrupted", overview.final_status
    assert not (tmp_path / "out" / ".stop").exists()


def _a_run_that_stops_when_told(stop: Path, release: Path) -> dict[str, str]:
    """Stands in for a study's run on a worker: it stops once the stop file appears (as runs do) and, for
    a run that does not stop in time, the file ``release`` too (made by the test, at most 60 s)."""
    deadline = time.monotonic() + 60.0
    while not (stop.exists() and release.exists()) and time.monotonic() < deadline:
        time.sleep(0.01)
    return {"run_id": "a", "status": "ok"}


@pytest.mark.parametrize("signals", [1, 2])
def test_a_second_signal_stops_the_wait_for_the_runs_in_progress(tmp_path: Path, signals: int) -> None:
    """A study stopped on Dask (real signals to this process, a real in-process cluster): with one signal it
    waits for the run in progress and keeps its row; a second signal ends the wait at once, leaving none."""
    from dask.distributed import Client, LocalCluster

    stop, release, rows = tmp_path / ".stop", tmp_path / "release", []
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address="127.0.0.1:0") as cluster, \
            Client(cluster) as client:
        future = client.submit(_a_run_that_stops_when_told, stop, release, key="cosim-run-a", pure=False)
        wait_for(lambda: any(client.processing().values()), 30)
        if signals == 1:
            release.touch()  # the run stops as soon as it sees the stop file
        started = time.monotonic()
        with pytest.raises(Interrupted) as held, stop_signals(hold=True) as guard:
            for _ in range(signals):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.01)
            _stop_runs(client, [future], stop, guard, rows.append)
        waited = time.monotonic() - started
        assert not stop.exists()  # removed on the way out, for the next run of the same study
        release.touch()
        stop.touch()  # lets the run end so that the cluster closes at once
    assert held.value.name == "SIGINT" and guard.received == signals
    if signals == 1:
        assert rows == [{"run_id": "a", "status": "ok"}]
    else:
        assert rows == [] and waited < 5.0  # STOP_WAIT is 30 s; the run would have held it to 60 s
