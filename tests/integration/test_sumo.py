"""SUMO co-simulation with real SUMO through libsumo (no mocks)."""
from __future__ import annotations

import gzip
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import broken_sumo_configs, bundled_scenario

from cosim.core.bridge import PointLoad
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.vehicles import QuarterCar, TyreQuarterCar
from cosim.errors import ConfigError, SumoError
from cosim.run.scenario import load_scenario
from cosim.run.simulate import build_traffic
from cosim.sumo import (
    BridgeAxis,
    SumoTraffic,
    bundled_networks,
    distribution_ids,
    model_from_parameters,
    read_config,
    read_input,
    read_sumo_set,
    split_file_list,
    sumo_input_files,
)
from cosim.sumo import files as sumo_files
from cosim.sumo.files import MAX_CONFIG_BYTES

AXIS = BridgeAxis((0.0, 0.0), (40.0, 0.0))
G = 9.81


@pytest.fixture(scope="module")
def paper_bridge():
    return load_scenario("paper-double-tee").build_bridge()


def _config(tmp_path: Path, routes: str, end: float = 200.0) -> Path:
    """A SUMO config in tmp_path on the bundled network with the given route file body."""
    net = bundled_networks()
    for name in ("bridge.net.xml", "vtypes.add.xml"):
        shutil.copy(net / name, tmp_path / name)
    (tmp_path / "test.rou.xml").write_text(f'<?xml version="1.0"?>\n<routes>\n{routes}\n</routes>\n')
    cfg = tmp_path / "test.sumocfg"
    cfg.write_text(
        '<?xml version="1.0"?><configuration><input><net-file value="bridge.net.xml"/>'
        '<route-files value="vtypes.add.xml,test.rou.xml"/></input>'
        f'<time><begin value="0"/><end value="{end}"/></time></configuration>'
    )
    return cfg


TRUCK = (
    '<vType id="t40" vClass="truck" length="10" mass="40000" sigma="0" maxSpeed="20" accel="1" decel="4">'
    '<param key="cosim.m_w" value="4000"/><param key="cosim.k_v" value="4.0e6"/>'
    '<param key="cosim.c_v" value="1.6e5"/></vType>'
)


def test_vehicles_on_the_deck_match_sumos_own_view(tmp_path):
    """Subscription path vs libsumo's per-vehicle getters, step by step (one point per axle)."""
    import libsumo

    cfg = bundled_networks() / "heavy.sumocfg"
    compared = 0
    with SumoTraffic(cfg, AXIS, step=0.1, end=200.0, half_width=6.655) as traffic:
        for _ in range(1200):
            frame = traffic.advance()
            ours = {vid for vid, x in zip(frame.ids, frame.x) if 0.0 <= x <= 40.0}
            theirs = set()
            for vid in libsumo.vehicle.getIDList():
                px, py = libsumo.vehicle.getPosition(vid)
                heading = np.radians(libsumo.vehicle.getAngle(vid))
                vtype = libsumo.vehicle.getTypeID(vid)
                axles = traffic._axles.get(vtype)
                if axles is None:  # a type the adapter has not needed yet: one point at mid-length
                    axles = ((libsumo.vehicle.getLength(vid) / 2, 1.0),)
                for k, (behind, _) in enumerate(axles):
                    cx, cy = px - behind * np.sin(heading), py - behind * np.cos(heading)
                    if 0.0 <= cx <= 40.0 and abs(cy) <= 6.655:
                        theirs.add(vid if len(axles) == 1 else f"{vid}#{k}")
            assert ours == theirs, f"t = {frame.t}"
            compared += len(theirs)
    assert compared > 500, "the check must see a good number of vehicles on the deck"


def _twist(paper_bridge, cfg, duration=60.0):
    with SumoTraffic(cfg, AXIS, step=0.05, end=200.0, half_width=6.655) as traffic:
        res = simulate(paper_bridge, traffic, duration, SolverSettings(dt=0.005),
                       [Sensor("left", 20.0, 6.0), Sensor("right", 20.0, -6.0), Sensor("mid", 20.0, 0.0)])
    return (res.sensors["left"] - res.sensors["right"]) / 12.0, res


def test_mirrored_traffic_does_not_twist_and_one_direction_does(paper_bridge, tmp_path):
    both = TRUCK + (
        '<vehicle id="e" type="t40" depart="0" departSpeed="15" departPos="0">'
        '<route edges="in_e pre_e bridge_e post_e out_e"/></vehicle>'
        '<vehicle id="w" type="t40" depart="0" departSpeed="15" departPos="0">'
        '<route edges="in_w pre_w bridge_w post_w out_w"/></vehicle>'
    )
    (tmp_path / "a").mkdir()
    mirrored, res = _twist(paper_bridge, _config(tmp_path / "a", both))
    assert np.max(np.abs(res.sensors["mid"])) > 1e-3  # two 40 t trucks: millimetres of deflection
    # Point-symmetric loads: the mid-span twist vanishes (to round-off of the SUMO positions).
    assert np.max(np.abs(mirrored)) < 1e-3 * np.max(np.abs(res.sensors["mid"])) / 6.0
    east = TRUCK + (
        '<vehicle id="e" type="t40" depart="0" departSpeed="15" departPos="0">'
        '<route edges="in_e pre_e bridge_e post_e out_e"/></vehicle>'
    )
    (tmp_path / "b").mkdir()
    twist, _ = _twist(paper_bridge, _config(tmp_path / "b", east))
    # Eastbound lane is right of the axis (y < 0): a load on the right lifts the left side, positive twist.
    assert twist.max() > 1e-5 and twist.min() > -0.05 * twist.max()


def test_a_queue_stopped_on_the_deck_gives_the_static_deflection(paper_bridge, tmp_path):
    stops = TRUCK + "".join(
        f'<vehicle id="q{i}" type="t40" depart="{2 * i}" departSpeed="10">'
        f'<route edges="in_e pre_e bridge_e post_e out_e"/>'
        f'<stop lane="bridge_e_0" endPos="{32 - 12 * i}" duration="1000"/></vehicle>'
        for i in range(3)
    )
    cfg = _config(tmp_path, stops, end=300.0)
    with SumoTraffic(cfg, AXIS, step=0.05, end=300.0, half_width=6.655) as traffic:
        res = simulate(paper_bridge, traffic, 150.0, SolverSettings(dt=0.01), [Sensor("mid", 20.0, -1.875)])
        last = traffic.frames.frames[-1]
    on = [(x, y, traffic.models[t]) for x, y, t in zip(last.x, last.y, last.types) if 0 <= x <= 40]
    assert len(on) == 3 and all(abs(v) < 1e-9 for v in last.v)
    static = paper_bridge.static([PointLoad(x, y, -m.total_mass * G) for x, y, m in on]).deck_displacement(20.0, -1.875)
    assert res.sensors["mid"][-1] == pytest.approx(static, rel=0.01)


def test_sumo_errors_are_reported_clearly(tmp_path):
    with pytest.raises(SumoError, match="SUMO config not found"):
        SumoTraffic(tmp_path / "missing.sumocfg", AXIS)
    broken, unknown = broken_sumo_configs(tmp_path)
    with pytest.raises(ConfigError, match=r"broken\.sumocfg: net-file: cannot read .*nope\.net\.xml"):
        SumoTraffic(broken, AXIS).start()
    # A config cosim can read but SUMO cannot load: SUMO's own first error line, not libsumo's "Process Error".
    with pytest.raises(SumoError, match=r"SUMO could not load it: .*nowhere"):
        SumoTraffic(unknown, AXIS).start()
    with pytest.raises(SumoError, match="has no edge 'no_such_edge'"):
        SumoTraffic(bundled_networks() / "light.sumocfg", AXIS, edges=("no_such_edge",)).start()
    with pytest.raises(SumoError, match="no lane of the network lies on the bridge"):
        SumoTraffic(bundled_networks() / "light.sumocfg", BridgeAxis((0.0, 500.0), (40.0, 500.0)), half_width=6).start()


def test_vtype_parameters_become_quarter_cars():
    car = model_from_parameters("car", 1500.0, "passenger",
                                {"cosim.m_w": "150", "cosim.k_v": "76750", "cosim.c_v": "6110"})
    assert isinstance(car, QuarterCar) and car.m_v == 1350.0 and car.total_mass == 1500.0
    lorry = model_from_parameters("lorry", 20000.0, "truck", {})
    # A truck's library suspension at the vType's mass: the limits of a "road-friendly" suspension,
    # Council Directive 96/53/EC Annex III: body bounce 2.0 Hz (on a rigid tyre), 20 % damping; 10 % unsprung.
    assert isinstance(lorry, TyreQuarterCar) and lorry.total_mass == pytest.approx(20000.0)
    assert np.sqrt(lorry.k_v / lorry.m_v) / (2 * np.pi) == pytest.approx(2.0, rel=1e-12)
    assert lorry.c_v / (2 * np.sqrt(lorry.k_v * lorry.m_v)) == pytest.approx(0.20, rel=1e-12)
    assert lorry.m_w == pytest.approx(2000.0) and np.sqrt((lorry.k_v + lorry.k_t) / lorry.m_w) / (2 * np.pi) == \
        pytest.approx(10.0, rel=1e-12)
    with pytest.raises(SumoError, match="vType bad: param `cosim.k_v` must be a number"):
        model_from_parameters("bad", 1500.0, "passenger", {"cosim.k_v": "stiff"})
    with pytest.raises(SumoError, match="leaves no body mass"):
        model_from_parameters("bad", 1500.0, "passenger", {"cosim.m_w": "2000"})


def test_importing_the_sumo_package_does_not_load_libsumo():
    code = "import sys, cosim.sumo; print('libsumo' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


# ------------------------------------------------------------------ SUMO's files, read by one reader


def _files(folder: Path, files: dict[str, bytes], routes: str) -> Path:
    """The bundled network and ``files`` in ``folder``, and a config naming ``routes`` as its route files."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, content in files.items():
        (folder / name).write_bytes(content)
    net = "bridge.net.xml.gz" if "bridge.net.xml.gz" in files else "bridge.net.xml"
    if net not in files:
        shutil.copy(bundled_networks() / net, folder / net)
    cfg = folder / "test.sumocfg"
    cfg.write_text(f'<configuration><input><net-file value="{net}"/><route-files value="{routes}"/></input>'
                   '</configuration>')
    return cfg


OTHER = (b'<routes><vTypeDistribution id="other"><vType id="other_car" vClass="passenger" mass="1500" '
         b'probability="1"/></vTypeDistribution><flow id="f" type="other" begin="0" end="100" vehsPerHour="600" '
         b'from="in_e" to="out_e"/></routes>')


def test_every_caller_splits_a_file_list_as_sumo_does(tmp_path):
    """``"a.xml, b.xml c.xml"``: commas separate, white space around a name goes; SUMO reads the same two files."""
    mix = (bundled_networks() / "vtypes.add.xml").read_bytes()
    cfg = _files(tmp_path, {"a.xml": mix, "b.xml c.xml": OTHER}, "a.xml, b.xml c.xml")
    assert split_file_list("a.xml, b.xml c.xml") == ["a.xml", "b.xml c.xml"]
    assert sumo_input_files(cfg) == [cfg, tmp_path / "bridge.net.xml", tmp_path / "a.xml", tmp_path / "b.xml c.xml"]
    assert distribution_ids(cfg) == {"mix", "other"}
    flat = read_sumo_set(cfg, "test")
    assert flat.routes == ("a.xml", "b.xml c.xml") and flat.files["b.xml c.xml"] == OTHER
    assert b'<route-files value="a.xml,b.xml c.xml" />' in flat.files["test.sumocfg"]
    with SumoTraffic(cfg, AXIS, end=100.0, half_width=6.655) as traffic:
        for _ in range(400):
            traffic.advance()
        import libsumo

        assert {"mix", "other", "other_car"} <= set(libsumo.vehicletype.getIDList())
        running = libsumo.vehicle.getIDList()  # the flow of "b.xml c.xml", drawing from its distribution
        assert running and {libsumo.vehicle.getTypeID(v) for v in running} == {"other_car"}
    assert "other_car" in traffic.models and not {"mix", "other"} & set(traffic.models)


def test_gzipped_files_are_read_like_plain_ones(tmp_path, monkeypatch):
    """Distribution ids are found in gzipped files, so SUMO runs on them with every vType a vehicle model."""
    gz = {f"{name}.gz": gzip.compress((bundled_networks() / name).read_bytes())
          for name in ("bridge.net.xml", "vtypes.add.xml", "medium.rou.xml")}
    cfg = _files(tmp_path, gz, "vtypes.add.xml.gz,medium.rou.xml.gz")
    assert [p.name for p in sumo_input_files(cfg)] == ["test.sumocfg", *gz]
    assert distribution_ids(cfg) == {"mix"}
    assert read_input(tmp_path / "medium.rou.xml.gz") == (bundled_networks() / "medium.rou.xml").read_bytes()
    with SumoTraffic(cfg, AXIS, end=100.0, half_width=6.655) as traffic:
        for _ in range(600):
            traffic.advance()
    assert "mix" not in traffic.models and {"car", "artic_loaded"} <= set(traffic.models)
    # A cut gzip stream: one line, naming the file.
    cut = tmp_path / "cut.rou.xml.gz"
    cut.write_bytes(gz["medium.rou.xml.gz"][:40])
    with pytest.raises(ConfigError, match=r"^.*cut\.rou\.xml\.gz: not a readable gzip file \(it ends early\)$"):
        read_input(cut)
    # Decompression stops at the bound (a gzip bomb), here lowered to 1 kB.
    monkeypatch.setattr(sumo_files, "MAX_XML_BYTES", 1000)
    with pytest.raises(ConfigError, match=r"vtypes\.add\.xml\.gz: more than 1000 bytes once decompressed; not read$"):
        read_input(tmp_path / "vtypes.add.xml.gz")


def test_sumo_config_errors_are_one_line_naming_the_file(tmp_path):
    with pytest.raises(ConfigError, match=r"missing\.sumocfg: cannot read the SUMO config \(No such file"):
        read_config(tmp_path / "missing.sumocfg")
    bad = tmp_path / "bad.sumocfg"
    bad.write_text("<configuration><input>")
    with pytest.raises(ConfigError, match=r"bad\.sumocfg: not well-formed XML \(no element found: line 1"):
        sumo_input_files(bad)
    assert distribution_ids(bad) == set()  # lenient: SUMO itself judges a config it runs
    huge = tmp_path / "huge.sumocfg"
    huge.write_bytes(b"<configuration>" + b" " * MAX_CONFIG_BYTES + b"</configuration>")
    with pytest.raises(ConfigError, match="huge.sumocfg: more than 1048576 bytes; not a SUMO config"):
        read_config(huge)
    for problem in ("missing", "bad", "huge"):
        with pytest.raises(ConfigError) as info:
            read_config(tmp_path / f"{problem}.sumocfg")
        assert "\n" not in str(info.value)


def test_replaying_a_sumo_log_reproduces_the_sensors_bit_for_bit(paper_bridge, tmp_path):
    from cosim.log import TOPIC_SENSORS, BlockLogger, LogRecorder, TrafficLogger, read_log, traffic_from_log

    sensors = [Sensor("mid", 20.0, 0.0), Sensor("acc", 20.0, 3.0, "acceleration")]
    names = [s.name for s in sensors]
    path = tmp_path / "sumo.mcap"
    with LogRecorder(path, names) as rec, BlockLogger(rec, names, 40.0) as logger:
        traffic = SumoTraffic(bundled_networks() / "heavy.sumocfg", AXIS, step=0.05, end=100.0, half_width=6.655,
                              frame_sink=TrafficLogger(rec))
        with traffic:
            simulate(paper_bridge, traffic, 40.0, SolverSettings(dt=0.005), sensors, output_every=2,
                     observers=[logger], collect=False)
    log = read_log(path)
    replayed = simulate(paper_bridge, traffic_from_log(log, 40.0, 0.05), 40.0, SolverSettings(dt=0.005), sensors,
                        output_every=2)
    logged = log.topic(TOPIC_SENSORS)
    assert len(logged) == len(replayed.t) - 1 and np.max(np.abs(replayed.sensors["mid"])) > 1e-4
    for name in names:
        np.testing.assert_array_equal(np.array([m[name] for m in logged]), replayed.sensors[name][1:])


# ------------------------------------------------------------------ command line
from cosim.run.scenario import SUMO_LEVELS  # noqa: E402

SCENARIO = """
name = "sumo-cli"
[bridge]
spans = [40.0]
elements_per_span = 10
supports = ["rigid-end", "rigid-end"]
[bridge.material]
E = 33.0e9
G = 13.75e9
rho = 2500.0
[bridge.section.constants]
A = 4.8
I_y = 1.6
I_z = 65.0
J = 0.15
I_w = 19.0
z_s = 0.59
A_sy = 2.5
A_sz = 0.9
deck_y = [-6.655, 6.655]
[bridge.damping]
ratios = [0.02, 0.02]
modes = ["vertical-1", "torsion-1"]
[[sensors]]
name = "mid"
x = 20.0
[[sensors]]
name = "left"
x = 20.0
y = 6.0
quantity = "acceleration"
[traffic]
sumo_config = "{config}"
end = {end}
seed = 3
[road]
class = "B"
seed = 2
"""


def cosim(*args, cwd):
    return subprocess.run([sys.executable, "-m", "cosim", *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_cli_runs_sumo_traffic_and_replays_it_bit_for_bit(tmp_path):
    assert "heavy" in SUMO_LEVELS
    (tmp_path / "s.toml").write_text(SCENARIO.format(config="heavy", end=60.0))
    run = cosim("run", "s.toml", "--out", "a.mcap", "--quiet", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "Traffic: SUMO" in run.stdout
    replay = cosim("replay", "a.mcap", "--out", "b.mcap", "--quiet", cwd=tmp_path)
    assert replay.returncode == 0, replay.stderr
    assert "identical, bit for bit" in replay.stdout and "SUMO is not run again" in replay.stdout
    # The same traffic on another bridge: finer and stiffer than the logged one.
    (tmp_path / "other.toml").write_text(SCENARIO.format(config="heavy", end=60.0).replace(
        "elements_per_span = 10", "elements_per_span = 16").replace("I_y = 1.6", "I_y = 2.4"))
    other = cosim("replay", "a.mcap", "--scenario", "other.toml", "--out", "c.mcap", "--quiet", cwd=tmp_path)
    assert other.returncode == 0, other.stderr
    assert "its SUMO traffic" in other.stdout and "Bridge: 40 m, 16 elements" in other.stdout
    # The inputs travel with the log (``cosim info`` lists them; tested with the logging commands).
    from cosim.log import read_log

    attached = read_log(tmp_path / "a.mcap").attachments
    for name in ("heavy.sumocfg", "bridge.net.xml", "vtypes.add.xml", "heavy.rou.xml"):
        assert attached[f"sumo/{name}"] == (bundled_networks() / name).read_bytes(), name


def test_cli_reports_a_broken_sumo_config_before_writing_anything(tmp_path, capsys, monkeypatch):
    from cosim.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "broken.sumocfg").write_text("<configuration><input><net-file value='missing.net.xml'/>"
                                             "</input></configuration>")
    (tmp_path / "s.toml").write_text(SCENARIO.format(config="broken.sumocfg", end=30.0))
    assert main(["run", "s.toml", "--out", "a.mcap", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "missing.net.xml: cannot read the network" in err
    assert not (tmp_path / "a.mcap").exists()


def test_cli_reports_a_config_sumo_cannot_load_before_writing_anything(tmp_path, capsys, monkeypatch):
    """cosim reads the files, SUMO rejects them (a route over an edge the network lacks): SUMO's own reason in
    one line, exit 2, and no log: SUMO is started before the log is created (issue 10)."""
    from cosim.cli import main

    monkeypatch.chdir(tmp_path)
    shutil.copy(bundled_networks() / "bridge.net.xml", tmp_path / "bridge.net.xml")
    (tmp_path / "bad.rou.xml").write_text('<routes><vehicle id="v" depart="0"><route edges="nowhere"/></vehicle>'
                                         '</routes>')
    (tmp_path / "bad.sumocfg").write_text('<configuration><input><net-file value="bridge.net.xml"/>'
                                          '<route-files value="bad.rou.xml"/></input></configuration>')
    (tmp_path / "s.toml").write_text(SCENARIO.format(config="bad.sumocfg", end=30.0))
    assert main(["run", "s.toml", "--out", "a.mcap", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "SUMO could not load it" in err and "nowhere" in err
    assert not (tmp_path / "a.mcap").exists()


def test_cli_rejects_a_vtype_with_impossible_parameters_before_the_run(tmp_path, capsys, monkeypatch):
    from cosim.cli import main

    monkeypatch.chdir(tmp_path)
    shutil.copy(bundled_networks() / "bridge.net.xml", tmp_path / "bridge.net.xml")
    (tmp_path / "bad.rou.xml").write_text(
        '<routes><vType id="lorry" vClass="truck" mass="20000"><param key="cosim.k_v" value="stiff"/></vType>'
        '<flow id="f" type="lorry" begin="0" end="100" vehsPerHour="100" from="in_e" to="out_e"/></routes>')
    (tmp_path / "bad.sumocfg").write_text(
        '<configuration><input><net-file value="bridge.net.xml"/><route-files value="bad.rou.xml"/></input>'
        '</configuration>')
    (tmp_path / "s.toml").write_text(SCENARIO.format(config="bad.sumocfg", end=30.0))
    assert main(["run", "s.toml", "--out", "a.mcap", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "bad.rou.xml: vType lorry: param `cosim.k_v` must be a number" in err and err.count("\n") == 1
    assert not (tmp_path / "a.mcap").exists()  # read from the demand files before anything is written


@pytest.mark.parametrize("dt", [0.005, 0.001])
def test_blocks_of_one_fleet_joined_give_the_same_numbers_to_the_bit(dt):
    """simulate(join_blocks=True) advances consecutive blocks with the same vehicles in one call; real SUMO
    traffic on the bundled bridge (vehicles entering and leaving, quiet gaps): the reference is the same run
    block by block."""
    scenario = bundled_scenario("paper-bridge-traffic", end=40.0, dt=dt)
    bridge = scenario.build_bridge()
    runs, calls = [], []
    for join in (True, False):
        handed: list[float] = []  # progress is reported once per call of the solver
        with build_traffic(scenario) as traffic:
            runs.append(simulate(bridge, traffic, 40.0, scenario.solver_settings(), scenario.sensors_core(),
                                 road=scenario.build_road(), output_every=scenario.output_every, join_blocks=join,
                                 progress=handed.append))
        calls.append(len(handed))
    joined, separate = runs
    assert len(separate.vehicle_ids) >= 10  # traffic came and went
    assert calls[1] == round(40.0 / dt) // 200 and calls[0] < 0.8 * calls[1], calls  # blocks were joined
    for name in separate.sensors:
        np.testing.assert_array_equal(joined.sensors[name], separate.sensors[name])
    for key in ("contact_force", "body_acceleration"):
        np.testing.assert_array_equal(joined.vehicle_table[key], separate.vehicle_table[key])


def test_the_adapter_reads_through_libsumos_extension_and_falls_back_to_its_public_getters():
    import types

    import libsumo

    from cosim.sumo.reads import SumoReads

    # libsumo's wrappers are one-line calls of the SWIG functions of the same names (libsumo/__init__.py).
    direct = SumoReads.of(libsumo)
    assert direct.position is libsumo._libsumo.vehicle_getPosition
    assert direct.lane_vehicles is libsumo._libsumo.lane_getLastStepVehicleIDs
    without = types.SimpleNamespace(lane=libsumo.lane, vehicle=libsumo.vehicle)  # a build without _libsumo
    public = SumoReads.of(without)
    assert public == (libsumo.lane.getLastStepVehicleIDs, libsumo.vehicle.getPosition, libsumo.vehicle.getAngle,
                      libsumo.vehicle.getSpeed, libsumo.vehicle.getAcceleration)
