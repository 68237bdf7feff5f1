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
