"""A bridge given by its modes through the scenario file and the command line (issue 26, items 1, 3 and 8):
``[bridge] modes = "FILE"`` runs SUMO traffic and scripted vehicles, logs, replays from its log alone, and
refuses bad input in one line (exit 2, nothing written)."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli

from cosim import testing
from cosim.bridges import from_beam, write_modes
from cosim.run.bundled import bundled_folder
from cosim.run.scenario import load_scenario, parse_scenario

#: The deck of from_beam gives the beam's contact rows to round-off (tests/verification/test_modal_beam.py), so a
#: whole SUMO run on it is the beam's modal-basis run; measured: 2e-15 of the peak.
SAME_RUN = 1e-9
N_MODES = 20


def _beam_and_modal_texts(folder: Path) -> tuple[str, str]:
    """The default scenario, 50 s of its SUMO traffic on the beam's 20-mode basis, and the same with the bridge
    replaced by the beam's modes (its moment sensor's modal values in the file)."""
    text = (bundled_folder() / "paper-bridge-traffic.toml").read_text()
    text = text.replace("end = 600.0", "end = 50.0").replace('basis = "direct"', f'basis = "modal"\nmodes = {N_MODES}')
    beam = parse_scenario(text, "beam.toml", base_dir=folder)
    write_modes(folder / "beam-modes.npz", from_beam(beam, lateral=3))
    start, end = text.index("[bridge]"), text.index("[[sensors]]")
    modal = (text[:start] + '[bridge]\nmodes = "beam-modes.npz"\n[bridge.damping]\nratios = [0.02, 0.02]\n'
             "modes = [1, 2]\n\n" + text[end:])
    return text, modal.replace(f'basis = "modal"\nmodes = {N_MODES}', "")


def test_sumo_traffic_on_the_beams_imported_modes_is_the_beams_modal_run(tmp_path: Path) -> None:
    beam_text, modal_text = _beam_and_modal_texts(tmp_path)
    beam = testing.run(parse_scenario(beam_text, "beam.toml", base_dir=tmp_path))
    modal_scenario = parse_scenario(modal_text, "modal.toml", base_dir=tmp_path)
    # Rayleigh at modes 1 and 2 of the file: the beam's vertical-1 and torsion-1 are its first two modes.
    assert load_scenario("paper-double-tee").build_beam().modes(2).kinds == ["vertical", "torsion"]
    modal = testing.run(modal_scenario)
    assert len(beam.vehicle_ids) > 3 and modal.vehicle_ids == beam.vehicle_ids
    for vid in beam.vehicle_ids:
        ref = beam.vehicle(vid)["contact_force"]
        assert np.max(np.abs(modal.vehicle(vid)["contact_force"] - ref)) <= SAME_RUN * np.max(np.abs(ref)), vid
    for name in beam.names:  # displacements, acceleration and the moment (the file's modal values)
        ref = beam[name]
        assert np.max(np.abs(modal[name] - ref)) <= SAME_RUN * np.max(np.abs(ref)), name


SCRIPTED = """\
name = "modal deck"
[bridge]
modes = "{modes}"
[bridge.damping]
ratio = 0.02
[[sensors]]
name = "mid"
x = 15.0
y = 2.0
[[sensors]]
name = "mid_acc"
x = 15.0
y = -3.0
quantity = "acceleration"
[[vehicles]]
id = "car"
model = "quarter-car"
m_v = 1500.0
m_w = 150.0
k_v = 6e4
c_v = 4e3
y = 2.0
speed = 15.0
[[vehicles]]
id = "truck"
model = "moving-force"
mass = 20000.0
y = -3.0
speed = 12.0
direction = "-x"
entry_time = 0.5
[solver]
dt = 0.005
"""


def _beam_deck() -> object:
    """A 30 m beam's 12 modes (any deck would do: these tests are about the file and the command line)."""
    beam = testing.scenario({"bridge": testing.bridge(30.0, elements_per_span=15), "solver": {"duration": 1.0}})
    return from_beam(beam.build_beam(), n_modes=12, lateral=3)


@pytest.fixture(scope="module")
def csv_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("modal")
    write_modes(folder / "deck_csv", _beam_deck())
    (folder / "deck.toml").write_text(SCRIPTED.format(modes="deck_csv"))
    result = cosim_cli("run", "deck.toml", "--out", "run.mcap", cwd=folder)
    assert result.returncode == 0, result.stderr
    assert "Bridge: a deck given by its modes, " in result.stdout and "12 modes" in result.stdout
    return folder


def test_a_modes_run_replays_from_its_log_alone(csv_run: Path, tmp_path: Path) -> None:
    """The CSV folder travels in the log as the .npz it reads as: the replay needs nothing else."""
    shutil.copy(csv_run / "run.mcap", tmp_path / "run.mcap")
    result = cosim_cli("replay", "run.mcap", "--out", "again.mcap", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "identical, bit for bit" in result.stdout


def test_the_solver_keeps_the_first_modes_it_is_asked_for(tmp_path: Path) -> None:
    write_modes(tmp_path / "deck.npz", _beam_deck())
    text = SCRIPTED.format(modes="deck.npz").replace("dt = 0.005", "dt = 0.005\nmodes = 5")
    scenario = parse_scenario(text, "deck.toml", base_dir=tmp_path)
    bridge = scenario.build_bridge()
    assert bridge.n_modes == 5 and scenario.bridge.length == pytest.approx(30.0)  # type: ignore[union-attr]
    cut = parse_scenario(SCRIPTED.format(modes="deck.npz").replace("dt = 0.005", "dt = 0.005\ncutoff_hz = 20.0"),
                         "deck.toml", base_dir=tmp_path).build_bridge()
    assert 0 < cut.n_modes < 12 and float(cut.f_hz[-1]) <= 20.0  # type: ignore[union-attr]


BAD = [
    ("missing", lambda t: t.replace("deck.npz", "nowhere.npz"), "deck.toml: bridge.modes: file not found: "),
    ("spans", lambda t: t.replace('[bridge]\n', '[bridge]\nspans = [30.0]\n'),
     "deck.toml: bridge.spans: not used with modes"),
    ("direct", lambda t: t.replace("dt = 0.005", 'dt = 0.005\nbasis = "direct"'),
     "deck.toml: solver.basis: a deck given by its modes is solved on its modes"),
    ("quasi-static", lambda t: t.replace("dt = 0.005", 'dt = 0.005\nmethod = "quasi-static"'),
     'deck.toml: solver.method: a deck given by its modes runs with method = "dynamic"'),
    ("mode name", lambda t: t.replace("ratio = 0.02", 'ratios = [0.02, 0.02]\nmodes = ["vertical-1", 3]'),
     "deck.toml: bridge.modes: deck.npz: damping `modes`: 'vertical-1': a deck given by its modes knows its "
     "modes by number only"),
    ("sensor off", lambda t: t.replace("y = -3.0\nquantity", "y = -9.0\nquantity"),
     "deck.toml: sensors[1]: sensor mid_acc: (15, -9) m is not on the deck's surface"),
    ("vehicle off", lambda t: t.replace("y = -3.0\nspeed", "y = -9.0\nspeed"),
     "deck.toml: vehicles[1].y: must lie on the deck"),
    ("network", lambda t: t.replace("[bridge]\n", '[bridge]\nframe = "network"\n'),
     'deck.toml: bridge.frame: frame = "network" places the deck by a SUMO network'),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path: Path, case) -> None:
    _, change, starts = case
    write_modes(tmp_path / "deck.npz", _beam_deck())
    (tmp_path / "deck.toml").write_text(change(SCRIPTED.format(modes="deck.npz")))
    before = sorted(p.name for p in tmp_path.iterdir())
    result = cosim_cli("run", "deck.toml", "--out", "run.mcap", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: " + starts), result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_a_damaged_modes_file_is_one_line_naming_the_file_and_the_array(tmp_path: Path) -> None:
    deck = _beam_deck()
    arrays = dict(np.load(write_modes(tmp_path / "good.npz", deck)))
    arrays["f_hz"] = arrays["f_hz"][::-1].copy()  # not ascending
    np.savez(tmp_path / "deck.npz", **arrays)
    (tmp_path / "deck.toml").write_text(SCRIPTED.format(modes="deck.npz"))
    result = cosim_cli("run", "deck.toml", "--out", "run.mcap", cwd=tmp_path)
    assert result.returncode == 2
    line = result.stderr.strip()
    assert "\n" not in line and line.startswith("cosim: error: deck.toml: bridge.modes: ") and "f_hz" in line, line
    assert not (tmp_path / "run.mcap").exists()


# ------------------------------------------------------------------------------- frame = "network"
ANGLE = np.radians(30.0)  # the bridge runs 30 degrees north of east: nothing lines up with the network's axes
DIRECTION = np.array([np.cos(ANGLE), np.sin(ANGLE)])


def _at(s: float) -> str:
    x, y = s * DIRECTION + np.array([500.0, 300.0])
    return f'x="{x:.6f}" y="{y:.6f}"'


ROTATED_NODES = f"""<nodes>
    <node id="W" {_at(-150.0)}/>
    <node id="A" {_at(0.0)} type="priority"/>
    <node id="B" {_at(40.0)} type="priority"/>
    <node id="E" {_at(190.0)}/>
</nodes>
"""
_ROAD = 'numLanes="1" speed="16.0" width="3.5"'
ROTATED_EDGES = "<edges>\n" + "\n".join(
    f'    <edge id="{e}" from="{a}" to="{b}" {_ROAD}/>'
    for e, a, b in (("in", "W", "A"), ("deck", "A", "B"), ("out", "B", "E"),
                    ("-out", "E", "B"), ("-deck", "B", "A"), ("-in", "A", "W"))) + "\n</edges>\n"
ROTATED_ROUTES = """<routes>
    <vType id="lorry" vClass="truck" maxSpeed="16" sigma="0"/>
    <vType id="car" vClass="passenger" maxSpeed="16" sigma="0"/>
    <vehicle id="east" type="lorry" depart="0" departSpeed="max"><route edges="in deck out"/></vehicle>
    <vehicle id="west" type="lorry" depart="2" departSpeed="max"><route edges="-out -deck -in"/></vehicle>
    <vehicle id="car" type="car" depart="4" departSpeed="max"><route edges="in deck out"/></vehicle>
</routes>
"""
ROTATED_CONFIG = """<configuration>
    <input><net-file value="rot.net.xml"/><route-files value="rot.rou.xml"/></input>
</configuration>
"""
ROTATED_TRAFFIC = """
[traffic]
sumo_config = "rot.sumocfg"
edges = ["deck", "-deck"]
step = 0.05
end = 25.0
[solver]
dt = 0.005
"""


def _rotated_network(folder: Path):  # noqa: ANN202 - a BridgeAxis
    """The turned two-way road built with SUMO's netconvert, its routes and config; the deck edges' axis."""
    import subprocess

    import sumo

    from cosim.sumo.network import locate_bridge

    (folder / "rot.nod.xml").write_text(ROTATED_NODES)
    (folder / "rot.edg.xml").write_text(ROTATED_EDGES)
    subprocess.run([str(Path(sumo.SUMO_HOME) / "bin" / "netconvert"), "--node-files", "rot.nod.xml",
                    "--edge-files", "rot.edg.xml", "-o", "rot.net.xml", "--offset.disable-normalization", "true",
                    "--no-turnarounds", "true", "--no-warnings", "true"], cwd=folder, check=True,
                   capture_output=True, timeout=60)
    (folder / "rot.rou.xml").write_text(ROTATED_ROUTES)
    (folder / "rot.sumocfg").write_text(ROTATED_CONFIG)
    return locate_bridge(folder / "rot.net.xml", ["deck", "-deck"]).axis


def test_points_that_leave_a_lane_uncovered_are_one_line_naming_the_lane(tmp_path: Path) -> None:
    """A network-frame deck 2 m wide under lanes 3.5 m wide on each side of the axis (issue 26, item 8)."""
    axis = _rotated_network(tmp_path)
    beam = testing.scenario({"bridge": testing.bridge(axis.length, elements_per_span=12, deck_y=(-1.0, 1.0)),
                             "solver": {"duration": 1.0}}).build_beam()
    deck = from_beam(beam, n_modes=6, lateral=3)
    e, n = axis.unit()
    network = deck.points[:, :1] * e + deck.points[:, 1:] * n + np.asarray(axis.start)
    np.savez(tmp_path / "narrow.npz", x=network[:, 0], y=network[:, 1], f_hz=deck.f_hz, phi=deck.phi)
    (tmp_path / "narrow.toml").write_text('name = "narrow"\n[bridge]\nmodes = "narrow.npz"\nframe = "network"\n'
                                          + ROTATED_TRAFFIC)
    before = sorted(p.name for p in tmp_path.iterdir())
    result = cosim_cli("run", "narrow.toml", "--out", "run.mcap", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    line = result.stderr.strip()
    assert "\n" not in line and line.startswith("cosim: error: narrow.toml: traffic.edges: lane "), line
    assert "leaves the deck's surface" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_a_network_frame_deck_is_placed_where_its_points_are(tmp_path: Path) -> None:
    """frame = "network": the beam's modes, their points moved to where the bridge lies in a network turned by
    30 degrees, give the run of the same modes in the bridge frame (placement: a rotation and a shift, exact
    to round-off; 1e-9 of the peak), with real SUMO traffic both ways."""
    axis = _rotated_network(tmp_path)
    length = axis.length
    beam = testing.scenario({"bridge": testing.bridge(length, elements_per_span=12, deck_y=(-4.0, 4.0)),
                             "solver": {"duration": 1.0}}).build_beam()
    deck = from_beam(beam, n_modes=12, lateral=3)
    write_modes(tmp_path / "beam.npz", deck)
    # Values only in both files: a network-frame deck takes no slopes (they would be along the bridge's x).
    arrays = {k: v for k, v in np.load(tmp_path / "beam.npz").items() if k not in ("frame", "phi_x", "phi_x_minus")}
    np.savez(tmp_path / "bridge.npz", **arrays)
    e, n = axis.unit()
    network = deck.points[:, :1] * e + deck.points[:, 1:] * n + np.asarray(axis.start)
    arrays["x"], arrays["y"] = network[:, 0], network[:, 1]
    np.savez(tmp_path / "network.npz", **arrays)
    sensors = '[[sensors]]\nname = "mid"\nx = {x}\ny = 1.6\n[[sensors]]\nname = "edge_acc"\nx = {x}\ny = -4.0\n' \
              'quantity = "acceleration"\n'.format(x=round(length / 2, 6))
    runs = {}
    for frame, file in (("bridge", "bridge.npz"), ("network", "network.npz")):
        text = (f'name = "{frame}"\n[bridge]\nmodes = "{file}"\nframe = "{frame}"\n[bridge.damping]\nratio = 0.02\n'
                + sensors + ROTATED_TRAFFIC)
        if frame == "bridge":
            text = text.replace('edges = ["deck", "-deck"]',
                                f"axis = [[{axis.start[0]!r}, {axis.start[1]!r}], [{axis.end[0]!r}, {axis.end[1]!r}]]")
        scenario = parse_scenario(text, f"{frame}.toml", base_dir=tmp_path)
        assert scenario.bridge.length == pytest.approx(length, rel=1e-12)
        runs[frame] = testing.run(scenario)
    bridge_run, network_run = runs["bridge"], runs["network"]
    assert sorted({v.split("#")[0] for v in bridge_run.vehicle_ids}) == ["car", "east", "west"]
    assert network_run.vehicle_ids == bridge_run.vehicle_ids
    for name in ("mid", "edge_acc"):
        ref = bridge_run[name]
        assert np.max(np.abs(network_run[name] - ref)) <= 1e-9 * np.max(np.abs(ref)), name


def test_a_study_runs_on_a_deck_given_by_its_modes(tmp_path: Path) -> None:
    """``cosim study`` on a modes file: the rows are the beam's own modal-basis study's (from_beam: the same
    numbers, 1e-9 of the peak, tests above), without a static peak or DAF (no influence lines)."""
    from cosim.study import load_study, run_study

    beam_text = (bundled_folder() / "paper-bridge-traffic.toml").read_text()
    beam_text = beam_text.replace('basis = "direct"', f'basis = "modal"\nmodes = {N_MODES}')
    start, end = beam_text.index("[bridge]"), beam_text.index("[[sensors]]")
    beam = parse_scenario(beam_text, "beam.toml", base_dir=tmp_path)
    write_modes(tmp_path / "deck.npz", from_beam(beam, lateral=3))
    modal_text = (beam_text[:start] + '[bridge]\nmodes = "deck.npz"\n[bridge.damping]\nratios = [0.02, 0.02]\n'
                  "modes = [1, 2]\n\n" + beam_text[end:]).replace(f'basis = "modal"\nmodes = {N_MODES}', "")
    rows = {}
    for name, text in (("beam", beam_text), ("deck", modal_text)):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "base.toml").write_text(text.replace('"deck.npz"', '"../deck.npz"'))
        (folder / "study.toml").write_text('[study]\nname = "s"\nbase = "base.toml"\nduration = 40.0\n[sweep]\n'
                                           "vehicles_per_hour = [900.0]\nseeds = [3]\n")
        outcome = run_study(load_study(folder / "study.toml", output=folder / "out"), workers=0, plots=False)
        (rows[name],) = outcome.rows
    assert rows["deck"]["vehicles"] == rows["beam"]["vehicles"] > 0
    for key in ("node1.peak", "node3_acc.peak", "moment_mid.peak", "edge_right.rms"):
        assert rows["deck"][key] == pytest.approx(rows["beam"][key], rel=SAME_RUN), key
    assert rows["deck"]["node1.daf"] is None and rows["beam"]["node1.daf"] > 0
