"""Issue items 6, 7, 8 and 9: one clear line instead of a traceback, exit 2 with nothing written for
bad input (SUMO's included, checked before the log exists), exit 1 with a finished log naming the
likely cause for a diverging run, and nothing silently accepted."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from _craft import edit_protobuf, rewrite
from _robust import PROFILED, ROAD_CSV, SUMO_SCENARIO, assert_one_line, cosim_cli, sumo_folder, write

from cosim.log import TOPIC_SENSORS, TOPIC_TRAFFIC, TOPIC_VEHICLES, open_log

DAMPING = '[bridge.damping]\nratios = [0.02, 0.02]\nmodes = ["vertical-1", "torsion-1"]\n'


def profiled(folder: Path, road: str = ROAD_CSV, **replace: str) -> Path:
    text = PROFILED
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    write(folder, "data/road.csv", road)
    return write(folder, "s.toml", text)


# --------------------------------------------------------------------------- item 6: tracebacks


@pytest.mark.parametrize("case, cause", [
    ("road", "likely cause: road: the profile's elevations reach 1e+306 m"),
    ("mass", "likely cause: vehicles[0] (truck): m_v = 1e+300 is outside any road vehicle's range"),
])
def test_a_diverging_run_names_its_likely_cause_and_finishes_its_log(tmp_path: Path, case: str, cause: str) -> None:
    if case == "road":
        scenario = profiled(tmp_path, ROAD_CSV.replace("\n9.0,", "\n9.0,1e306\n9.05,"))
    else:
        scenario = profiled(tmp_path, **{"m_v = 1000.0": "m_v = 1e300"})
    result = cosim_cli("run", str(scenario), "--out", "o.mcap", "--quiet", cwd=tmp_path)
    assert_one_line(result, 1, "the solution diverged", cause, 'its log o.mcap is finished, status "error"')
    status = open_log(tmp_path / "o.mcap").final_status
    assert status["state"] == "error" and cause in status["message"]


def test_a_mass_density_of_1e_minus_300_is_assert_one_line(tmp_path: Path) -> None:
    scenario = profiled(tmp_path, **{"rho = 2500": "rho = 1e-300"})
    assert_one_line(cosim_cli("modes", str(scenario), cwd=tmp_path), 2, "the modal analysis found 0 of",
                    "rho = 1e-300 kg/m^3")
    modal = profiled(tmp_path, **{"rho = 2500": "rho = 1e-300", DAMPING: "",
                                  "dt = 0.002": 'dt = 0.002\nbasis = "modal"'})
    assert_one_line(cosim_cli("run", str(modal), "--out", "o.mcap", cwd=tmp_path), 2, "the modal analysis found 0 of")
    assert not (tmp_path / "o.mcap").exists()


def test_an_output_folder_that_cannot_be_written_is_assert_one_line(profiled_log: Path, tmp_path: Path) -> None:
    folder = Path("/sys/kernel")  # no file can be created there, not even by root
    scenario = profiled(tmp_path)
    assert_one_line(cosim_cli("run", str(scenario), "--out", str(folder / "o.mcap"), cwd=tmp_path), 2,
                    f"{folder / 'o.mcap'}: cannot create the log")
    assert_one_line(cosim_cli("export", str(profiled_log), "--csv", str(folder / "o.csv"), cwd=tmp_path), 2,
                    f"{folder / 'o.csv'}: cannot write the CSV")
    assert_one_line(cosim_cli("plot", str(profiled_log), "-o", str(folder / "o.png"), cwd=tmp_path), 2,
                    f"{folder / 'o.png'}: cannot write the plot")


def _spoil(topic_wanted: str, change):  # noqa: ANN001, ANN202
    seen = {"n": 0}

    def message(topic: str, msg: dict) -> dict:
        if topic == topic_wanted:
            seen["n"] += 1
            if seen["n"] == 5:
                return change(msg)
        return msg

    return message


#: Logs written by earlier versions, in JSON (tests/regression/logs): crafted JSON messages are crafted from them.
OLD_LOGS = Path(__file__).resolve().parents[1] / "regression" / "logs"


def test_crafted_json_messages_are_one_line_for_every_reader(tmp_path: Path) -> None:
    """Logs of earlier versions are JSON: a message that parses but lies is one line, for every reader."""
    scripted, sumo = OLD_LOGS / "paper-double-tee.mcap", OLD_LOGS / "paper-bridge-traffic-fixed-weights.mcap"
    sensors = rewrite(scripted, tmp_path / "sensors.mcap",
                      message=_spoil(TOPIC_SENSORS, lambda m: {**m, "node1": "0.001"}))
    for args in (("export", str(sensors), "--csv", "o.csv"), ("plot", str(sensors), "-o", "o.png"),
                 ("replay", str(sensors), "--out", "r.mcap")):
        assert_one_line(cosim_cli(*args, cwd=tmp_path), 2, "a message on /cosim/sensors", "does not match its schema",
                        "node1: expected a finite number, got '0.001'")
    vehicles = rewrite(scripted, tmp_path / "vehicles.mcap",
                       message=_spoil(TOPIC_VEHICLES, lambda m: {**m, "vehicles": 5}))
    assert_one_line(cosim_cli("export", str(vehicles), "--topic", TOPIC_VEHICLES, "--csv", "v.csv", cwd=tmp_path), 2,
                    "vehicles: expected an array, got 5")
    frames = rewrite(sumo, tmp_path / "frames.mcap", message=_spoil(TOPIC_TRAFFIC, lambda m: {**m, "x": ["a"]}))
    assert_one_line(cosim_cli("replay", str(frames), "--out", "r.mcap", cwd=tmp_path), 2, "a message on /cosim/traffic",
                    "x[0]: expected a finite number")
    garbage = rewrite(scripted, tmp_path / "garbage.mcap",
                      raw=lambda _s, topic, data: data[:-3] if topic == TOPIC_SENSORS else data)
    assert_one_line(cosim_cli("export", str(garbage), "--csv", "o.csv", cwd=tmp_path), 2,
                    "a message on /cosim/sensors is not valid JSON")
    assert not any((tmp_path / n).exists() for n in ("o.csv", "o.png", "r.mcap", "v.csv", "runs"))


def _spoil_bytes(topic_wanted: str, change):  # noqa: ANN001, ANN202
    """The fifth message of a topic through ``change(schema, data)``, the others as they are."""
    seen = {"n": 0}

    def raw(schema, topic: str, data: bytes) -> bytes:  # noqa: ANN001
        if topic == topic_wanted:
            seen["n"] += 1
            if seen["n"] == 5:
                return change(schema, data)
        return data

    return raw


def test_crafted_protobuf_messages_are_one_line_for_every_reader(profiled_log: Path, sumo_log: Path,
                                                                  tmp_path: Path) -> None:
    """Logs of this version are protobuf: bytes that do not parse, and a valid message whose values lie (crafted
    with the protobuf runtime from the log's own schema), are each one line, for every reader."""
    cut = rewrite(profiled_log, tmp_path / "cut.mcap", raw=_spoil_bytes(TOPIC_SENSORS, lambda _s, d: d[: len(d) // 2]))
    for args in (("export", str(cut), "--csv", "o.csv"), ("plot", str(cut), "-o", "o.png"),
                 ("replay", str(cut), "--out", "r.mcap")):
        assert_one_line(cosim_cli(*args, cwd=tmp_path), 2, "a message on /cosim/sensors",
                        "is not a valid cosim.SensorSample message")
    nan = rewrite(profiled_log, tmp_path / "nan.mcap", raw=_spoil_bytes(
        TOPIC_SENSORS, lambda s, d: edit_protobuf(s, d, lambda m: setattr(m, "mid", float("nan")))))
    for args in (("export", str(nan), "--csv", "o.csv"), ("plot", str(nan), "-o", "o.png")):
        assert_one_line(cosim_cli(*args, cwd=tmp_path), 2, "a message on /cosim/sensors", "does not match its schema",
                        "mid: expected a finite number, got nan")
    garbage = rewrite(profiled_log, tmp_path / "garbage.mcap",
                      raw=_spoil_bytes(TOPIC_VEHICLES, lambda _s, _d: b"\xff\xff\xff\xff"))
    assert_one_line(cosim_cli("export", str(garbage), "--topic", TOPIC_VEHICLES, "--csv", "v.csv", cwd=tmp_path), 2,
                    "a message on /cosim/vehicles is not a valid cosim.VehiclesOnDeck message")
    short = rewrite(sumo_log, tmp_path / "short.mcap", raw=_spoil_bytes(
        TOPIC_TRAFFIC, lambda s, d: edit_protobuf(s, d, lambda m: m.ClearField("x"))))
    assert_one_line(cosim_cli("replay", str(short), "--out", "r.mcap", "--quiet", cwd=tmp_path), 2, "ids but 0 x")
    meta = rewrite(profiled_log, tmp_path / "meta.mcap", metadata={"cosim": {"rate_hz": "fast", "sensors": "[1]"}})
    assert_one_line(cosim_cli("info", str(meta), cwd=tmp_path), 2, "malformed cosim metadata: rate_hz")
    assert not any((tmp_path / n).exists() for n in ("o.csv", "o.png", "r.mcap", "v.csv", "runs"))


# --------------------------------------------------------------------------- item 7: exit 2, nothing written


SUMO_CASES = {
    "broken network": ("bridge.net.xml", lambda t: t[:3000], "bridge.net.xml: not a readable SUMO network"),
    "unknown vType": ("light.rou.xml", lambda t: t.replace('type="mix"', 'type="nosuchtype"', 1),
                      "SUMO could not load it"),
    "impossible cosim values": ("vtypes.add.xml", lambda t: t.replace('key="cosim.m_w" value="150"',
                                                                     'key="cosim.m_w" value="150000"', 1),
                                "vType car: `cosim.m_w` = 150000 kg leaves no body mass"),
}


@pytest.mark.parametrize("case", [*SUMO_CASES, "missing bridge edges"])
def test_sumo_start_up_errors_write_nothing(tmp_path: Path, case: str) -> None:
    folder = sumo_folder(tmp_path)
    text = SUMO_SCENARIO.format(end=20.0)
    if case == "missing bridge edges":
        text = text.replace("seed = 3\n", 'seed = 3\nedges = ["bridge_e", "nowhere"]\n')
        fragment = "traffic.edges: the network bridge.net.xml has no edge 'nowhere'"
    else:
        name, change, fragment = SUMO_CASES[case]
        (folder / name).write_text(change((folder / name).read_text()))
    scenario = write(tmp_path, "s.toml", text)
    for _ in range(2):  # and again: the same --out is not refused, since nothing was written
        result = cosim_cli("run", str(scenario), "--out", "o.mcap", "--quiet", cwd=tmp_path)
        line = assert_one_line(result, 2, fragment)
        assert "already exists" not in line and "Error:" not in result.stderr.replace("cosim: error:", "")
        assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "sumo"]


def test_a_basis_that_cannot_be_built_writes_nothing(tmp_path: Path) -> None:
    scenario = profiled(tmp_path, **{"dt = 0.002": 'dt = 0.002\nbasis = "modal"\ncutoff_hz = 1e-6'})
    assert_one_line(cosim_cli("run", str(scenario), "--out", "o.mcap", cwd=tmp_path), 2,
                    "solver.cutoff_hz: no mode below")
    scenario = profiled(tmp_path, **{"elements_per_span = 8": "elements_per_span = 900", DAMPING: ""})
    assert_one_line(cosim_cli("run", str(scenario), "--out", "o.mcap", cwd=tmp_path), 2,
                    "solver.basis: the direct basis keeps a dense", 'above 6000 free DOFs use basis = "modal"')
    assert not (tmp_path / "o.mcap").exists()


# --------------------------------------------------------------------------- item 8: studies


def test_a_study_refuses_the_folder_of_another_study(tmp_path: Path) -> None:
    sumo_folder(tmp_path)
    write(tmp_path, "base.toml", SUMO_SCENARIO.format(end=600.0))
    other = write(tmp_path, "out/study.toml", '[study]\nname = "volumes"\nbase = "base.toml"\n')
    write(tmp_path, "out/results.csv", "run_id,status\nx,ok\n")
    mine = write(tmp_path, "mine.toml", '[study]\nname = "mine"\nbase = "base.toml"\nduration = 10.0\n')
    assert_one_line(cosim_cli("study", str(mine), "--out", "out", "--workers", "0", cwd=tmp_path), 2,
                    "holds the results of study 'volumes', not 'mine'", "give another --out")
    assert other.read_text().startswith('[study]\nname = "volumes"')
    assert (tmp_path / "out/results.csv").read_text() == "run_id,status\nx,ok\n"
    write(tmp_path, "out2/study.json", json.dumps({"name": "volumes", "source": "/elsewhere/volumes.toml"}))
    assert_one_line(cosim_cli("study", str(mine), "--out", "out2", "--workers", "0", cwd=tmp_path), 2,
                    "holds the results of study 'volumes'")


# --------------------------------------------------------------------------- item 9: nothing silently accepted


@pytest.mark.parametrize("old, new, fragment", [
    ('key="cosim.k_v"', 'key="cosim.kv"', "vType car: unknown param `cosim.kv` (did you mean `cosim.k_v`?"),
    ('key="cosim.model"', 'key="cosim.modle"', "vType car: unknown param `cosim.modle` (did you mean `cosim.model`?"),
    ('<param key="cosim.m_w" value="150"/>', '<param key="cosim.m_w" value="150"/><param key="cosim.k_t" value="1e6"/>',
     "vType car: param `cosim.k_t` is not used by model quarter-car"),
])
def test_misspelled_and_unused_vtype_params_are_errors(tmp_path: Path, old: str, new: str, fragment: str) -> None:
    folder = sumo_folder(tmp_path)
    text = (folder / "vtypes.add.xml").read_text()
    assert old in text
    (folder / "vtypes.add.xml").write_text(text.replace(old, new, 1))
    scenario = write(tmp_path, "s.toml", SUMO_SCENARIO.format(end=20.0))
    assert_one_line(cosim_cli("run", str(scenario), "--out", "o.mcap", cwd=tmp_path), 2, "vtypes.add.xml", fragment)
    assert not (tmp_path / "o.mcap").exists()


@pytest.mark.parametrize("content, fragment", [
    ("x,r,z\n-1.0,0.0,0\n21.0,0.0,0\n", "line 2: expected two columns 'x, r', got 3"),
    ("x,r\n-1.0,0.0\n5.0,nan\n21.0,0.0\n", "line 3: r must be a finite number"),
    ("x,r\n-1.0,0.0\ninf,0.0\n", "line 3: x must be a finite number"),
])
def test_a_road_profile_is_read_strictly(tmp_path: Path, content: str, fragment: str) -> None:
    scenario = profiled(tmp_path, content)
    assert_one_line(cosim_cli("run", str(scenario), cwd=tmp_path), 2, "s.toml: road.profile:", fragment)


def test_a_binary_road_profile_is_reported_at_its_key(tmp_path: Path) -> None:
    scenario = profiled(tmp_path)
    (tmp_path / "data/road.csv").write_bytes(bytes(range(256)) * 4)
    assert_one_line(cosim_cli("run", str(scenario), cwd=tmp_path), 2, "s.toml: road.profile:", "not a text file")


# --------------------------------------------------------------------------- issue 27, item 6: a log cut short


def test_a_log_that_cannot_be_finished_says_up_to_when_it_can_be_read(tmp_path: Path) -> None:
    """The disk fills during a run: here a real limit on the file size (RLIMIT_FSIZE: a write past it fails with
    EFBIG, File too large, Python ignoring SIGXFSZ), which fails the log's writes as a full disk (ENOSPC) does,
    in the same place. The run exits 1 with one line that names the error and the simulated time up to which the
    file can be read: what a reader of the file finds."""
    import resource
    import subprocess
    import sys

    from _robust import cli_env

    from cosim.log import read_log

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))

    result = subprocess.run([sys.executable, "-m", "cosim", "run", "paper-double-tee", "--out", "cut.mcap",
                             "--quiet"], capture_output=True, text=True, cwd=tmp_path, env=cli_env(), timeout=600,
                            preexec_fn=limit)
    line = assert_one_line(result, 1, "cut.mcap: writing the log failed", "File too large",
                           "the log cut.mcap is cut short: it can be read up to t = ",
                           "of the 20 s simulated (and has no final status)")
    assert "finished" not in line and "status \"error\"" not in line
    stated = float(line.split("read up to t = ")[1].split(" s")[0])
    log = read_log(tmp_path / "cut.mcap")
    assert log.truncated and log.final_status["state"] != "finished"
    assert 0 < stated < 20 and max(t for t, _ in log.messages["/cosim/sensors"]) / 1e9 == stated
    assert (tmp_path / "cut.mcap").stat().st_size <= 200_000


THREAD_WRITER_CUT = r"""
import resource, signal, sys
from pathlib import Path
from cosim.run.logged import LogCutShort, run_logged
from cosim.run.scenario import load_scenario
scenario = load_scenario("paper-double-tee")
run_logged(scenario, Path("warm.mcap"), writer="thread")  # kernels compiled and cached before the limit
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))
try:
    run_logged(scenario, Path("cut.mcap"), writer="thread")
except LogCutShort as exc:
    print(str(exc))
    sys.exit(1)
"""


def test_a_log_written_by_a_thread_that_cannot_be_finished_says_so_too(tmp_path: Path) -> None:
    """The same full disk where no log writer process can be forked (the log encoded by a thread of the run,
    ``writer="thread"``): the run ends with the same LogCutShort and its readable time, not a raw OSError."""
    import subprocess
    import sys

    from _robust import cli_env

    from cosim.log import read_log

    result = subprocess.run([sys.executable, "-c", THREAD_WRITER_CUT], capture_output=True, text=True, cwd=tmp_path,
                            env=cli_env(), timeout=600)
    assert result.returncode == 1, result.stderr[-2000:]
    line = result.stdout.strip()
    assert "\n" not in line and "cut.mcap: writing the log failed" in line and "File too large" in line, line
    stated = float(line.split("read up to t = ")[1].split(" s")[0])
    log = read_log(tmp_path / "cut.mcap")
    assert log.truncated and log.final_status["state"] != "finished"
    assert 0 < stated < 20 and max(t for t, _ in log.messages["/cosim/sensors"]) / 1e9 == stated
