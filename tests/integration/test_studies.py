"""``cosim study``: traffic-volume studies on Dask, with real SUMO and real MCAP logs.

A small study (2 volumes x 2 seeds of 60 s on a coarse 40 m girder) runs on a
local cluster of 2 worker processes; its rows are checked against the same
runs one after another in this process and against a scheduler and workers
started as separate processes. Then: a study interrupted with Ctrl-C (on a
local cluster of 1 worker) resumes, a run with a broken SUMO file is reported
while the others finish, and gzipped SUMO files sweep like plain ones.
"""
from __future__ import annotations

import contextlib
import gzip
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import cosim
from cosim.errors import ConfigError
from cosim.log import file_is_complete
from cosim.run.logged import run_logged
from cosim.run.replay import compare_sensors
from cosim.run.scenario import load_scenario
from cosim.study import load_study, parse_study, run_study, summary_text
from cosim.sumo import bundled_networks

REPO = Path(cosim.__file__).resolve().parents[1]

# The bundled network's 40 m bridge as a coarse girder: 10 elements, dt = 25 ms
# (two sub-steps per SUMO step), logged at 40 Hz.
BASE = """\
name = "small"
[bridge]
spans = [40.0]
elements_per_span = 10
supports = ["pinned", "fork"]
[bridge.material]
E = 35e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
z_c = -0.8
deck_y = [-5.0, 5.0]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = 20.0
y = -1.875
[[sensors]]
name = "mid_moment"
x = 20.0
quantity = "bending_moment"
[[sensors]]
name = "mid_acc"
x = 20.0
quantity = "acceleration"
[traffic]
sumo_config = "medium"
step = 0.05
end = 600.0
seed = 42
axis = [[0.0, 0.0], [40.0, 0.0]]
[solver]
dt = 0.025
[output]
rate_hz = 40.0
"""

#: The same with its first sensor only: fewer plots, where a test is not about them.
BASE_ONE_SENSOR = BASE[:BASE.index('[[sensors]]\nname = "mid_moment"')] + BASE[BASE.index("[traffic]"):]

STUDY = """\
[study]
name = "small"
base = "base.toml"
duration = 60.0
[sweep]
vehicles_per_hour = [300.0, 900.0]
seeds = [1, 2]
"""

WALL = ("wall_time", "wall_time_total")


def _write_study(folder: Path, study: str = STUDY, base: str = BASE) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "base.toml").write_text(base)
    path = folder / "study.toml"
    path.write_text(study)
    return path


def _numbers(frame: pd.DataFrame) -> pd.DataFrame:
    """The table without wall times: what must not depend on how the runs were executed."""
    return frame[[c for c in frame.columns if c not in WALL]].reset_index(drop=True)


@pytest.fixture(scope="module")
def small_study(tmp_path_factory):
    """The small study, one run after another in this process: the reference the other executions must match."""
    folder = tmp_path_factory.mktemp("study")
    study = load_study(_write_study(folder), output=folder / "out")
    seen = []
    outcome = run_study(study, workers=0, progress=lambda done, total, row: seen.append((done, total)))
    return study, outcome, seen


def test_two_volumes_two_seeds_give_four_rows_a_table_and_plots(small_study):
    study, outcome, seen = small_study
    assert outcome.workers == 0
    assert "Runs: 4: 4 run now in this process, 0 reused from earlier, 0 failed" in summary_text(outcome)
    assert [r["run_id"] for r in outcome.rows] == [
        "vph-300_seed-1", "vph-300_seed-2", "vph-900_seed-1", "vph-900_seed-2"]
    assert outcome.failed == [] and len(outcome.ran) == 4 and outcome.skipped == []
    assert seen[0] == (0, 4) and seen[-1] == (4, 4) and len(seen) == 5
    csv = pd.read_csv(outcome.table_csv, dtype={"error": str})
    csv["error"] = csv["error"].fillna("")  # an empty CSV cell reads as NaN
    parquet = pd.read_parquet(outcome.table_parquet)
    assert len(csv) == len(parquet) == 4
    pd.testing.assert_frame_equal(csv, parquet, check_dtype=False)
    for column in ("vehicles_per_hour", "seed", "sumo_seed", "mid.peak", "mid.p95", "mid.rms", "mid.daf",
                   "mid_moment.daf", "mid_acc.rms", "vehicles", "max_on_deck", "heaviest_kg", "liftoff_events",
                   "wall_time", "status"):
        assert column in csv.columns, column
    assert (csv["status"] == "ok").all()
    assert csv["mid_acc.daf"].isna().all()  # no quasi-static counterpart for accelerations
    # More traffic, more vehicles (same seed).
    by = csv.set_index("run_id")
    for seed in (1, 2):
        assert by.loc[f"vph-900_seed-{seed}", "vehicles"] > by.loc[f"vph-300_seed-{seed}", "vehicles"]
    assert (csv["vehicles"] > 0).all()
    assert ((csv["mid.daf"] > 0.95) & (csv["mid.daf"] < 1.5)).all()
    for name in ("mid.peak.png", "mid.daf.png", "mid_acc.rms.png", "vehicles.png"):
        assert (outcome.study.output / "plots" / name).stat().st_size > 1000, name
    run = outcome.study.output / "runs" / "vph-900_seed-2"
    assert {p.name for p in run.iterdir()} >= {"scenario.toml", "run.mcap", "result.json", "sumo"}
    assert 'vehsPerHour="900"' in (run / "sumo" / "medium.rou.xml").read_text()


def test_the_rows_are_the_runs_one_by_one(small_study, tmp_path):
    """A run's scenario runs by itself (``cosim run runs/<id>/scenario.toml``) and gives its row's numbers exactly."""
    study, outcome, _ = small_study
    row = outcome.rows[-1]
    folder = study.output / "runs" / row["run_id"]
    alone = run_logged(load_scenario(folder / "scenario.toml"), tmp_path / "alone.mcap")
    for name in ("mid", "mid_moment", "mid_acc"):
        assert row[f"{name}.min"] == alone.result.sensor_min[name]
        assert row[f"{name}.max"] == alone.result.sensor_max[name]
    # vehicles, not contact points: a lorry of the bundled mix is "id#0", "id#1", ... in vehicle_ids
    assert row["vehicles"] == len({contact.split("#")[0] for contact in alone.result.vehicle_ids})
    assert row["max_on_deck"] == alone.result.max_on_deck
    assert row["liftoff_events"] == alone.result.liftoff_events
    assert compare_sensors(folder / "run.mcap", alone.log_path).identical


def _same_runs(outcome, reference) -> None:
    """Rows (wall times aside) and sensor logs identical, bit for bit, to the reference's."""
    pd.testing.assert_frame_equal(_numbers(outcome.table()), _numbers(reference.table()))
    for row in reference.rows:
        ours, theirs = (o.study.output / "runs" / row["run_id"] for o in (outcome, reference))
        assert compare_sensors(ours / "run.mcap", theirs / "run.mcap").identical, row["run_id"]


def test_a_second_run_of_the_same_study_redoes_nothing(small_study):
    study, outcome, _ = small_study
    logs = {r: (study.output / "runs" / r / "run.mcap").stat().st_mtime_ns for r in outcome.ran}
    again = run_study(load_study(study.source, output=study.output), workers=2, plots=False)
    assert again.ran == [] and again.skipped == outcome.ran and again.workers == 0
    assert again.rows == outcome.rows
    assert logs == {r: (study.output / "runs" / r / "run.mcap").stat().st_mtime_ns for r in outcome.ran}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(["dask", *args], cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def test_a_study_on_a_separately_started_scheduler_gives_the_same_runs(small_study, tmp_path):
    """``dask scheduler`` and ``dask worker --nworkers 2`` processes started apart, in a folder of their own."""
    from dask.distributed import Client

    if shutil.which("dask") is None:
        pytest.fail("the `dask` command (dask[distributed]) is not on PATH")
    study, outcome, _ = small_study
    elsewhere = tmp_path / "elsewhere"  # the workers' working folder: not the caller's
    elsewhere.mkdir()
    address = f"tcp://127.0.0.1:{_free_port()}"
    port = address.rsplit(":", 1)[1]
    scheduler = _dask("scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard", cwd=elsewhere)
    worker = None
    try:
        worker = _dask("worker", address, "--nworkers", "2", "--nthreads", "1", "--no-dashboard", cwd=elsewhere)
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
        remote = run_study(load_study(study.source, output=tmp_path / "remote"), scheduler=address, plots=False)
    finally:
        for proc in (worker, scheduler):
            if proc is not None:
                os.killpg(proc.pid, signal.SIGTERM)
        for proc in (worker, scheduler):
            if proc is not None:
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
    assert remote.workers == 2 and remote.failed == []
    assert "Runs: 4: 4 run now on 2 workers, 0 reused from earlier, 0 failed" in summary_text(remote)
    _same_runs(remote, outcome)
    assert not any(elsewhere.glob("**/*.mcap"))  # every log went to the output folder


RUN_STUDY = """\
import sys
from cosim.study import load_study, run_study
if __name__ == "__main__":
    try:
        run_study(load_study(sys.argv[1], output=sys.argv[2]), workers=1, plots=False)
    except KeyboardInterrupt as exc:  # the API's contract: Ctrl-C is a KeyboardInterrupt, its table written
        sys.exit(f"stopped: {type(exc).__name__} ({exc})")
"""


def _ok_runs(out: Path) -> dict[str, int]:
    found = {}
    for path in out.glob("runs/*/result.json"):
        try:
            if json.loads(path.read_text())["row"]["status"] == "ok":
                found[path.parent.name] = (path.parent / "run.mcap").stat().st_mtime_ns
        except (OSError, ValueError, KeyError):
            pass
    return found


def test_an_interrupted_study_resumes_without_redoing_finished_runs(small_study, tmp_path):
    """On a local cluster of 1 worker, Ctrl-C after the first finished run; the same study again runs only the rest.

    The finished runs, from the cluster, and the rest, from this process, make the same rows as the reference.
    """
    study_path = _write_study(tmp_path)
    out = tmp_path / "out"
    script = tmp_path / "go.py"
    script.write_text(RUN_STUDY)
    with contextlib.ExitStack() as taken:
        with contextlib.suppress(OSError):  # Dask's default dashboard port, taken (as by a second study): no warning
            taken.enter_context(socket.create_server(("127.0.0.1", 8787)))
        proc = subprocess.Popen([sys.executable, str(script), str(study_path), str(out)], cwd=tmp_path,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        started = time.monotonic()
        while not _ok_runs(out) and time.monotonic() - started < 120 and proc.poll() is None:
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    assert proc.returncode != 0, f"the study finished before it was interrupted:\n{err[-2000:]}"
    assert err.strip() == "stopped: Interrupted (SIGINT)", err  # cosim.errors.Interrupted; no traceback from Dask
    finished = _ok_runs(out)
    assert 1 <= len(finished) < 4
    # The table of the finished runs is written on the way out.
    assert set(pd.read_csv(out / "results.csv")["run_id"]) == set(finished)
    # A run cut short (its log truncated, no result) must run again, whatever state it was left in.
    cut = sorted(finished)[-1]
    if len(finished) >= 2:
        log = out / "runs" / cut / "run.mcap"
        log.write_bytes(log.read_bytes()[: log.stat().st_size // 2])
        assert not file_is_complete(log)
        del finished[cut]
    resumed = run_study(load_study(study_path, output=out), workers=0, plots=False)
    assert sorted(resumed.skipped) == sorted(finished)
    assert sorted(resumed.ran) == sorted(set(small_study[1].ran) - set(finished))
    assert resumed.failed == []
    assert {k: v for k, v in _ok_runs(out).items() if k in finished} == finished  # logs not rewritten
    assert len(pd.read_csv(out / "results.csv")) == 4
    _same_runs(resumed, small_study[1])


def _broken_sumo(folder: Path) -> Path:
    """A SUMO config on the bundled network whose route names an edge the network does not have."""
    folder.mkdir(parents=True)
    for name in ("bridge.net.xml", "vtypes.add.xml"):
        shutil.copy(bundled_networks() / name, folder / name)
    (folder / "broken.rou.xml").write_text(
        '<routes>\n  <flow id="east" type="mix" begin="0" end="3600" vehsPerHour="300" from="in_e" to="nowhere"/>\n'
        '</routes>\n')
    cfg = folder / "broken.sumocfg"
    cfg.write_text('<configuration><input><net-file value="bridge.net.xml"/>'
                   '<route-files value="vtypes.add.xml,broken.rou.xml"/></input></configuration>')
    return cfg


def test_a_failing_run_is_reported_and_the_others_finish(tmp_path):
    _broken_sumo(tmp_path / "mine")
    study_path = _write_study(tmp_path, STUDY.replace(
        "vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]",
        'sumo_config = ["light", "mine/broken.sumocfg"]\nseeds = [1]'), BASE_ONE_SENSOR)
    outcome = run_study(load_study(study_path, output=tmp_path / "out"), workers=0)
    table = pd.read_csv(outcome.table_csv).set_index("run_id")
    assert list(table.index) == ["cfg-light_seed-1", "cfg-broken_seed-1"]
    assert outcome.failed == ["cfg-broken_seed-1"]
    assert table.loc["cfg-light_seed-1", "status"] == "ok" and table.loc["cfg-light_seed-1", "vehicles"] > 0
    assert table.loc["cfg-broken_seed-1", "status"] == "error"
    assert "nowhere" in table.loc["cfg-broken_seed-1", "error"]
    assert np.isnan(table.loc["cfg-broken_seed-1", "mid.peak"])
    assert (tmp_path / "out" / "plots" / "mid.peak.png").is_file()  # from the runs that worked
    summary = summary_text(outcome)
    assert "Runs: 2: 2 run now in this process, 0 reused from earlier, 1 failed" in summary
    assert "  cfg-broken_seed-1: " in summary and "nowhere" in summary
    # Re-running retries the failed run only.
    again = run_study(load_study(study_path, output=tmp_path / "out"), workers=0, plots=False)
    assert again.ran == ["cfg-broken_seed-1"] and again.skipped == ["cfg-light_seed-1"]


def test_a_broken_demand_file_fails_its_runs_only(tmp_path):
    """A route file that is not XML cannot take the sweep's rate: those runs fail, before SUMO starts."""
    cfg = _broken_sumo(tmp_path / "mine")
    (cfg.parent / "broken.rou.xml").write_text("<routes><flow id='east'")
    study_path = _write_study(tmp_path, STUDY.replace(
        "seeds = [1, 2]", 'sumo_config = ["light", "mine/broken.sumocfg"]'))
    outcome = run_study(load_study(study_path, output=tmp_path / "out"), workers=0, plots=False)
    status = {r["run_id"]: (r["status"], r.get("error", "")) for r in outcome.rows}
    assert [k for k, (s, _) in status.items() if s == "ok"] == ["cfg-light_vph-300", "cfg-light_vph-900"]
    for run_id in ("cfg-broken_vph-300", "cfg-broken_vph-900"):
        assert status[run_id][0] == "error" and "broken.rou.xml: not well-formed XML" in status[run_id][1]


def test_sweeping_the_speed_limit_slows_the_traffic(tmp_path):
    from cosim.log import TOPIC_TRAFFIC, read_log

    study_path = _write_study(tmp_path, STUDY.replace(
        "vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]", "speed_limit = [10.0, 25.0]\nseeds = [3]"))
    outcome = run_study(load_study(study_path, output=tmp_path / "out"), workers=0, plots=False)
    assert outcome.failed == []
    speeds = {}
    for row in outcome.rows:
        frames = read_log(outcome.study.output / row["log"], topics=[TOPIC_TRAFFIC]).topic(TOPIC_TRAFFIC)
        on_deck = [abs(v) for f in frames for v, x in zip(f["speed"], f["x"]) if 0.0 <= x <= 40.0]
        speeds[row["speed_limit"]] = np.mean(on_deck)
    assert 7.0 < speeds[10.0] < 11.5 < 18.0 < speeds[25.0]


def _gzipped_medium(folder: Path) -> Path:
    """The bundled medium demand with every file gzipped: network, vehicle types and routes."""
    folder.mkdir(parents=True)
    for name in ("bridge.net.xml", "vtypes.add.xml", "medium.rou.xml"):
        (folder / f"{name}.gz").write_bytes(gzip.compress((bundled_networks() / name).read_bytes()))
    cfg = folder / "medium-gz.sumocfg"
    cfg.write_text('<configuration><input><net-file value="bridge.net.xml.gz"/>'
                   '<route-files value="vtypes.add.xml.gz, medium.rou.xml.gz"/></input></configuration>')
    return cfg


def test_gzipped_sumo_files_sweep_like_plain_ones_and_truck_share_changes_the_mix(tmp_path):
    """The bundled medium demand, plain and gzipped: every edit applies to both, and the runs are identical.

    All trucks vs no trucks: the heaviest vehicle on the deck tells which.
    """
    _gzipped_medium(tmp_path / "gz")
    study_path = _write_study(tmp_path, STUDY.replace(
        "vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]",
        'sumo_config = ["medium", "gz/medium-gz.sumocfg"]\ntruck_share = [0.0, 1.0]\nvehicles_per_hour = [900.0]\n'
        "speed_limit = [16.0]"))
    outcome = run_study(load_study(study_path, output=tmp_path / "out"), workers=0, plots=False)
    assert outcome.failed == []
    rows = {(r["sumo_config"], r["truck_share"]): r for r in outcome.rows}
    for cfg in ("medium", "gz/medium-gz.sumocfg"):
        assert rows[cfg, 0.0]["heaviest_kg"] <= 3000.0  # cars (1.5 t) and vans (3 t) only
        assert rows[cfg, 1.0]["heaviest_kg"] >= 11000.0
        assert rows[cfg, 1.0]["mid.peak"] > rows[cfg, 0.0]["mid.peak"]
    table = _numbers(outcome.table()).drop(columns=["run_id", "sumo_config", "log"])
    pd.testing.assert_frame_equal(table.iloc[2:].reset_index(drop=True), table.iloc[:2].reset_index(drop=True))
    # The gzipped run's inputs stay gzipped, with the edits inside.
    sumo = outcome.study.output / "runs" / "cfg-medium-gz_vph-900_trucks-1_vmax-16" / "sumo"
    edited = {name: gzip.decompress((sumo / name).read_bytes()).decode()
              for name in ("medium.rou.xml.gz", "vtypes.add.xml.gz", "bridge.net.xml.gz")}
    assert 'vehsPerHour="900"' in edited["medium.rou.xml.gz"]
    assert "truck share 1 (cosim study)" in edited["vtypes.add.xml.gz"]
    assert 'speed="16"' in edited["bridge.net.xml.gz"]
    assert "vtypes.add.xml.gz,medium.rou.xml.gz" in (sumo / "medium-gz.sumocfg").read_text()


def test_study_file_errors_name_the_file_and_the_key(tmp_path):
    base = tmp_path / "base.toml"
    base.write_text(BASE)
    cases = {
        '[study]\nbase = "base.toml"\nduraton = 60.0\n': 'study.duraton: unknown key; did you mean "duration"?',
        '[study]\nbase = "base.toml"\n[sweep]\nvehicles_per_hour = [300, -5]\n':
            "sweep.vehicles_per_hour[1]: must be > 0",
        '[study]\nbase = "base.toml"\n[sweep]\ntruck_share = [1.5]\n': "sweep.truck_share[0]: must be <= 1",
        '[study]\nbase = "base.toml"\n[sweep]\nroad_class = ["b"]\n': 'did you mean "B"?',
        '[study]\nbase = "base.toml"\n[sweep]\nseeds = [1, 1]\n': "sweep.seeds: value 1 is listed twice",
        '[study]\nbase = "nope.toml"\n': "nope.toml: no such scenario file",
        '[study]\nbase = "base.toml"\n[sweep]\nsumo_config = ["nothere.sumocfg"]\n':
            "sweep.sumo_config[0]: file not found",
        '[study]\nbase = "paper-double-tee"\n[sweep]\nvehicles_per_hour = [300]\n':
            "sweep.vehicles_per_hour: needs SUMO traffic",
        '[study]\nbase = "base.toml"\n[sweep]\nloads = ["fixed", "Auxere"]\n':
            'sweep.loads[1]: \'Auxere\' is neither "fixed" (the vTypes\' own weights), a bundled site',
        '[study]\nbase = "base.toml"\n[sweep]\nloads = ["fixed", "Auxerre"]\n':
            "sweep.loads[1]: 'Auxerre' draws each vehicle's loads, which needs the base scenario's [traffic.loads]",
        '[study]\nbase = "paper-double-tee"\n[sweep]\nloads = ["fixed"]\n': "sweep.loads: needs SUMO traffic",
    }
    for text, expected in cases.items():
        path = tmp_path / "s.toml"
        path.write_text(text)
        with pytest.raises(ConfigError) as info:
            load_study(path)
        message = str(info.value)
        assert message.startswith(str(path)) and expected in message, message


def test_run_ids_follow_the_values_not_the_order_of_execution(tmp_path):
    study = parse_study(STUDY.replace('base = "base.toml"', 'base = "paper-double-tee"').replace(
        "vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]", 'road_class = ["smooth", "C"]\nseeds = 2'),
        "s.toml", base_dir=tmp_path, output=tmp_path / "o")
    tasks = study.tasks()
    assert [t.run_id for t in tasks] == ["road-smooth_seed-1", "road-smooth_seed-2", "road-C_seed-1",
                                         "road-C_seed-2"]
    assert [t.fingerprint for t in tasks] == [t.fingerprint for t in study.tasks()]
    assert tasks[2].parameters == {"road_class": "C", "seed": 1, "road_seed": 1}
    assert 'class = "C"\nseed = 1' in tasks[2].scenario_text
    assert "duration = 60.0" in tasks[0].scenario_text  # a scripted base: the study's duration is the run's


def test_a_loads_axis_runs_the_base_with_and_without_its_traffic_loads(tmp_path):
    """``loads = ["fixed", <site>, <folder>]``: no [traffic.loads], or the base's with that model (a folder's
    files travel with the run); the run's seed is the loads' seed too (the same ids draw anew in every seed)."""
    from cosim.core.loads import bundled_sites

    site = tmp_path / "my site"
    site.mkdir()
    auxerre = Path(cosim.__file__).parent / "core" / "loads" / "sites" / "Auxerre"
    for name in ("GVWpdf.csv", "ASall.csv", "AW2&3.csv", "AW4&5.csv", "CLASS%.csv"):
        shutil.copyfile(auxerre / name, site / name)
    (site / "notes.txt").write_text("not a parameter file")
    base = BASE.replace("[solver]", '[traffic.loads]\nmodel = "Auxerre"\nseed = 7\nwander = "none"\n'
                                    'vtype_classes = { artic_loaded = [5] }\n[solver]')
    path = _write_study(tmp_path, STUDY.replace("vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]",
                                                'loads = ["fixed", "angers", "my site"]\nseeds = [3, 4]'), base)
    study = load_study(path, output=tmp_path / "out")
    tasks = study.tasks()
    assert [t.run_id for t in tasks] == ["loads-fixed_seed-3", "loads-fixed_seed-4", "loads-angers_seed-3",
                                         "loads-angers_seed-4", "loads-my_site_seed-3", "loads-my_site_seed-4"]
    assert tasks[0].parameters == {"loads": "fixed", "seed": 3, "sumo_seed": 3}
    assert "[traffic.loads]" not in tasks[0].scenario_text
    assert tasks[3].parameters == {"loads": "angers", "seed": 4, "loads_seed": 4, "sumo_seed": 4}
    assert '[traffic.loads]\nmodel = "angers"\nseed = 4\nwander = "none"' in tasks[3].scenario_text
    assert "artic_loaded = [5]" in tasks[3].scenario_text
    assert not [name for name in tasks[3].files if name.startswith("inputs/")]
    assert 'model = "inputs/loads/my_site"\nseed = 3' in tasks[4].scenario_text
    copied = sorted(name for name in tasks[4].files if name.startswith("inputs/"))
    assert copied == sorted(f"inputs/loads/my_site/{name}" for name in ("GVWpdf.csv", "ASall.csv", "AW2&3.csv",
                                                                       "AW4&5.csv", "CLASS%.csv"))
    assert tasks[4].files["inputs/loads/my_site/GVWpdf.csv"] == (site / "GVWpdf.csv").read_bytes()
    # Without a seeds axis the base's loads seed stays; a site's name in any case is a site.
    one = load_study(_write_study(tmp_path / "one", STUDY.replace(
        "vehicles_per_hour = [300.0, 900.0]\nseeds = [1, 2]", 'loads = ["AUXERRE"]'), base), output=tmp_path / "o1")
    (task,) = one.tasks()
    assert task.run_id == "loads-AUXERRE" and task.parameters["loads_seed"] == 7
    assert "auxerre" in {s.lower() for s in bundled_sites()}


def test_the_study_command(tmp_path):
    """``cosim study`` as users run it: the table, the plots, exit 0; a bad study file: one line, exit 2."""
    from _cli import cosim_cli

    study_path = _write_study(tmp_path, STUDY.replace("vehicles_per_hour = [300.0, 900.0]",
                                                      "vehicles_per_hour = [300.0]").replace("seeds = [1, 2]",
                                                                                             "seeds = [1]"),
                              BASE_ONE_SENSOR)
    done = cosim_cli("study", str(study_path), "--workers", "0", "--quiet", "--out", "out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(tmp_path / "out" / "results.csv")
    assert len(table) == 1 and table["status"].tolist() == ["ok"]
    assert any((tmp_path / "out" / "plots").glob("*.png"))
    bad = tmp_path / "bad.toml"
    bad.write_text(STUDY.replace("[sweep]", "[sweep]\nvehicle_per_hour = [1.0]"))
    failed = cosim_cli("study", str(bad), "--quiet", cwd=tmp_path)
    assert failed.returncode == 2 and "vehicle_per_hour" in failed.stderr and "Traceback" not in failed.stderr
