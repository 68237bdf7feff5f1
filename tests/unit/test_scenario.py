"""Scenario files: bundled scenarios load; malformed ones fail with the file and key named."""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest
from pydantic import ValidationError

from cosim.errors import ConfigError
from cosim.run.scenario import (
    Scenario,
    list_bundled_scenarios,
    load_scenario,
    parse_scenario,
)
from cosim.run.simulate import simulate_scenario

REPO = Path(__file__).resolve().parents[2]
BUNDLED = REPO / "cosim" / "scenarios"
PAPER_TEXT = (BUNDLED / "paper-double-tee.toml").read_text(encoding="utf-8")

# A small scenario with explicit section constants (no FE section solve).
CONSTANTS_TEXT = """\
name = "small"
[bridge]
spans = [10.0, 12.0]
elements_per_span = [4, 6]
supports = ["fork", "pinned", ["v", "w", "theta_x"]]
[bridge.material]
E = 30e9
nu = 0.2
rho = 2500
[bridge.section.constants]
A = 2.0
I_y = 0.5
I_z = 8.0
J = 0.2
I_w = 0.1
deck_y = [-3.0, 3.0]
[[sensors]]
name = "mid"
x = 5
y = -3
"""


def write(tmp_path: Path, text: str, name: str = "bad.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def replaced(old: str, new: str, text: str = PAPER_TEXT) -> str:
    assert old in text, f"test setup: {old!r} not in the base scenario"
    return text.replace(old, new, 1)


def config_error(path: Path | str) -> str:
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    return str(info.value)


# --------------------------------------------------------------------------- bundled


def test_bundled_scenarios_are_listed() -> None:
    names = list_bundled_scenarios()
    assert "paper-double-tee" in names
    assert "paper-double-tee-asymmetric" in names


@pytest.mark.parametrize("name", ["paper-double-tee", "paper-double-tee-asymmetric"])
def test_bundled_scenario_loads(name: str) -> None:
    scenario = load_scenario(name)
    assert scenario.name == name
    assert scenario.source == name
    assert "[bridge]" in scenario.text
    bridge = scenario.bridge
    assert bridge.spans == (40.0,)
    assert bridge.elements_per_span == 40
    assert bridge.supports == ("rigid-end", "rigid-end")
    assert (bridge.material.E, bridge.material.G, bridge.material.rho) == (33.0e9, 13.75e9, 2500.0)
    assert bridge.material.poisson == pytest.approx(0.2)
    assert bridge.section.deck_y == pytest.approx((-6.655, 6.655))
    assert bridge.damping is not None
    assert bridge.damping.ratios == (0.02, 0.02)
    assert bridge.damping.modes == ("vertical-1", "torsion-1")
    sensors = {s.name: s for s in scenario.sensors}
    assert (sensors["node1"].x, sensors["node1"].y) == (20.0, 0.0)
    assert (sensors["node2"].x, sensors["node2"].y) == (20.0, 6.655)
    assert (sensors["node3"].x, sensors["node3"].y) == (20.0, 3.325)
    assert sensors["node3_acc"].quantity == "acceleration"
    assert (scenario.solver.dt, scenario.solver.scheme, scenario.solver.basis) == (0.005, "newmark", "direct")
    assert scenario.solver.duration == 20.0
    # The paper's vehicles (docs/validation.md): QC-2 enters 7.5 s (30 m) after QC-1.
    qc1, qc2 = scenario.vehicles
    assert (qc1.id, qc1.model, qc2.id, qc2.model) == ("QC-1", "quarter-car", "QC-2", "quarter-car")
    assert qc1.parameters == {"m_v": 1000.0, "m_w": 100.0, "k_v": 39478.40, "c_v": 5026.55}
    assert qc2.parameters == {"m_v": 2000.0, "m_w": 200.0, "k_v": 78956.80, "c_v": 10053.10}
    for qc in (qc1, qc2):
        assert (qc.y, qc.speed, qc.direction, qc.profile) == (3.325, 4.0, "+x", None)
    assert (qc1.entry_time, qc2.entry_time) == (0.0, 7.5)
    assert scenario.road.smooth
    assert scenario.leave_time == pytest.approx(17.5)
    assert scenario.duration == 20.0


def test_paper_sections_differ_only_in_the_right_web() -> None:
    webs = {}
    for name in ("paper-double-tee", "paper-double-tee-asymmetric"):
        plates = load_scenario(name).bridge.section.plates
        assert plates is not None and len(plates) == 3
        webs[name] = {p.start[0]: p.thickness for p in plates if p.start[0] == p.end[0]}
        deck = [p for p in plates if p.start[1] == p.end[1]]
        assert [(d.start, d.end, d.thickness) for d in deck] == [((-6.655, 0.0), (6.655, 0.0), 0.25)]
    assert webs["paper-double-tee"] == {3.325: 0.40, -3.325: 0.40}
    assert webs["paper-double-tee-asymmetric"] == {3.325: 0.40, -3.325: 0.25}


def test_load_by_path_object_and_string(tmp_path: Path) -> None:
    path = write(tmp_path, PAPER_TEXT, "copy.toml")
    assert load_scenario(path) == load_scenario(str(path))
    assert load_scenario(path).source == str(path)


def test_constants_scenario_with_nu_and_explicit_supports(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, CONSTANTS_TEXT, "small.toml"))
    assert scenario.bridge.elements_per_span == (4, 6)
    assert scenario.bridge.supports == ("fork", "pinned", ("v", "w", "theta_x"))
    assert scenario.bridge.material.shear_modulus == pytest.approx(30e9 / 2.4)
    assert scenario.bridge.section.deck_y == (-3.0, 3.0)
    assert scenario.bridge.length == 22.0
    assert scenario.bridge.damping is None
    assert scenario.solver.dt == 0.005  # default
    assert scenario.sensors[0].quantity == "displacement"  # default
    assert scenario.sensors[0].x == 5.0 and isinstance(scenario.sensors[0].x, float)


def test_scheme_defaults_fill_in() -> None:
    hht = parse_scenario(replaced('scheme = "newmark"', 'scheme = "hht"'), "hht.toml")
    assert hht.solver.hht_alpha == -0.05
    assert hht.solver_settings().hht_alpha == -0.05
    modal = parse_scenario(replaced('basis = "direct"', 'basis = "modal"'), "modal.toml")
    assert modal.solver.modes == 30
    settings = modal.solver_settings()
    assert (settings.scheme, settings.basis, settings.modes, settings.cutoff_hz) == ("newmark", "modal", 30, None)


def test_scenario_name_defaults_to_the_file_stem(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, CONSTANTS_TEXT.replace('name = "small"\n', ""), "my-bridge.toml"))
    assert scenario.name is None
    assert scenario.title == "my-bridge"


def _toml_blocks(markdown: str) -> list[str]:
    return re.findall(r"```toml\n(.*?)```", markdown, flags=re.S)


def test_documented_examples_are_valid() -> None:
    """docs/scenario.md's complete examples load, and its copy of the bundled file is current."""
    blocks = [b for b in _toml_blocks((REPO / "docs" / "scenario.md").read_text(encoding="utf-8")) if "[bridge]" in b]
    assert len(blocks) >= 2
    scenarios = [parse_scenario(block, f"docs/scenario.md example {i}") for i, block in enumerate(blocks)]

    assert scenarios[0].model_dump() == load_scenario("paper-double-tee").model_dump()


# --------------------------------------------------------------------------- frozen


def test_objects_are_frozen() -> None:
    scenario = load_scenario("paper-double-tee")
    with pytest.raises(ValidationError):
        scenario.name = "other"  # type: ignore[misc]
    with pytest.raises(ValidationError):
        scenario.bridge.material.E = 1.0  # type: ignore[misc]
    with pytest.raises(ValidationError):
        scenario.sensors[0].x = 1.0  # type: ignore[misc]
    with pytest.raises(ValidationError):
        scenario.solver.dt = 1.0  # type: ignore[misc]
    # Sequences are tuples, so nothing can be appended or replaced in place.
    assert isinstance(scenario.bridge.spans, tuple)
    assert isinstance(scenario.sensors, tuple)
    assert isinstance(scenario.bridge.section.plates, tuple)
    assert isinstance(scenario.bridge.section.plates[0].start, tuple)
    # "Changing" a scenario makes a new one.
    other = scenario.model_copy(update={"name": "other"})
    assert other.name == "other" and scenario.name == "paper-double-tee"


# --------------------------------------------------------------------------- malformed

MALFORMED = [
    pytest.param(
        replaced("spans = [40.0]", "spanz = [40.0]"),
        "bridge.spanz",
        ['unknown key', 'did you mean "spans"', "expected one of: name, spans, elements_per_span"],
        id="misspelled-key",
    ),
    pytest.param(
        replaced("dt = 0.005", 'dt = "0.005"'),
        "solver.dt",
        ['expected a number, got string "0.005"'],
        id="string-for-number",
    ),
    pytest.param(
        replaced("E = 33.0e9", "E = true"),
        "bridge.material.E",
        ["expected a number, got boolean true"],
        id="boolean-for-number",
    ),
    pytest.param(
        replaced("elements_per_span = 40", "elements_per_span = 40.5"),
        "bridge.elements_per_span",
        ["expected an integer", "40.5"],
        id="float-for-integer",
    ),
    pytest.param(
        replaced("thickness = 0.25", "thickness = -0.25"),
        "bridge.section.plates[0].thickness",
        ["must be > 0 (got -0.25)"],
        id="negative-thickness",
    ),
    pytest.param(
        replaced("spans = [40.0]", "spans = [0.0]"),
        "bridge.spans[0]",
        ["must be > 0 (got 0.0)"],
        id="zero-span",
    ),
    pytest.param(
        replaced("x = 20.0\ny = 6.655", "x = 40.5\ny = 6.655"),
        "sensors[1].x",
        ["0 <= x <= 40", "got 40.5"],
        id="sensor-beyond-the-bridge",
    ),
    pytest.param(
        replaced("x = 20.0\ny = 0.0", "x = -1.0\ny = 0.0"),
        "sensors[0].x",
        ["0 <= x <= 40", "got -1.0"],
        id="sensor-before-the-bridge",
    ),
    pytest.param(
        replaced("y = 6.655", "y = 6.8"),
        "sensors[1].y",
        ["-6.655 <= y <= 6.655", "got 6.8"],
        id="sensor-off-the-deck",
    ),
    pytest.param(
        replaced('supports = ["rigid-end", "rigid-end"]', 'supports = ["rigid-end", "hinged"]'),
        "bridge.supports[1]",
        ['unknown support preset "hinged"', "free, fork, warping-restrained, pinned, rigid-end, fixed"],
        id="unknown-support-preset",
    ),
    pytest.param(
        replaced('supports = ["rigid-end", "rigid-end"]', 'supports = ["rigid-end", ["v", "w", "phi"]]'),
        "bridge.supports[1][2]",
        ['unknown DOF name "phi"', "u, v, w, theta_x, theta_y, theta_z, psi"],
        id="unknown-dof-name",
    ),
    pytest.param(
        replaced('supports = ["rigid-end", "rigid-end"]', 'supports = ["rigid-end"]'),
        "bridge.supports",
        ["expected 2 entries", "got 1"],
        id="wrong-number-of-supports",
    ),
    pytest.param(
        replaced("rho = 2500.0", "rho = 2500.0\nnu = 0.2"),
        "bridge.material",
        ["exactly one of G or nu", "got both"],
        id="both-G-and-nu",
    ),
    pytest.param(
        replaced("G = 13.75e9", "nu = 0.5"),
        "bridge.material.nu",
        ["must be < 0.5 (got 0.5)"],
        id="nu-out-of-range",
    ),
    pytest.param(
        replaced("rho = 2500.0", "rho = 0"),
        "bridge.material.rho",
        ["must be > 0 (got 0)"],
        id="zero-density",
    ),
    pytest.param(
        replaced('modes = ["vertical-1", "torsion-1"]', 'modes = ["torsion-1", "torsion-1"]'),
        "bridge.damping.modes",
        ["must differ", '"torsion-1"'],
        id="damping-modes-equal",
    ),
    pytest.param(
        replaced("ratios = [0.02, 0.02]", "ratios = [0.02, 1.2]"),
        "bridge.damping.ratios[1]",
        ["must be < 1 (got 1.2)"],
        id="damping-ratio-out-of-range",
    ),
    pytest.param(
        replaced('modes = ["vertical-1", "torsion-1"]', 'modes = ["vertical-1", "twist-1"]'),
        "bridge.damping.modes[1]",
        ['unknown mode reference "twist-1"', "axial, lateral, vertical, torsion"],
        id="unknown-mode-kind",
    ),
    pytest.param(
        replaced('quantity = "acceleration"', 'quantity = "jerk"'),
        "sensors[3].quantity",
        ['unknown quantity "jerk"', "displacement, velocity, acceleration, bending_moment"],
        id="unknown-quantity",
    ),
    pytest.param(
        replaced('name = "node2"', 'name = "node1"'),
        "sensors[1].name",
        ['duplicate sensor name "node1"'],
        id="duplicate-sensor-name",
    ),
    pytest.param(
        replaced("dt = 0.005", "dt = 0"),
        "solver.dt",
        ["must be > 0 (got 0)"],
        id="zero-dt",
    ),
    pytest.param(
        replaced('scheme = "newmark"', 'scheme = "newmark"\nhht_alpha = -0.1'),
        "solver.hht_alpha",
        ['only used with scheme = "hht"'],
        id="parameter-of-another-scheme",
    ),
    pytest.param(
        "name = 'no bridge'\n",
        "bridge",
        ["required key is missing"],
        id="missing-bridge",
    ),
    pytest.param(
        replaced("rho = 2500.0", ""),
        "bridge.material.rho",
        ["required key is missing"],
        id="missing-required-key",
    ),
    pytest.param(
        PAPER_TEXT.split("[[vehicles]]")[0] + '\n[traffic]\nsumocfg = "net.sumocfg"\n',
        "traffic.sumocfg",
        ['did you mean "sumo_config"'],
        id="traffic-misspelled-key",
    ),
    pytest.param(
        PAPER_TEXT + '\n[traffic]\nsumo_config = "medium"\n',
        "traffic",
        ["either [traffic] (SUMO) or [[vehicles]] (scripted), not both"],
        id="traffic-and-vehicles",
    ),
    pytest.param(
        PAPER_TEXT.split("[[vehicles]]")[0] + '\n[traffic]\nsumo_config = "nowhere.sumocfg"\n',
        "traffic.sumo_config",
        ["file not found", "light, medium, heavy, congested"],
        id="traffic-config-missing",
    ),
    pytest.param(
        PAPER_TEXT.split("[[vehicles]]")[0].replace("duration = 20.0", "")
        + '\n[traffic]\nsumo_config = "medium"\nstep = 0.0123\n',
        "traffic.step",
        ["whole number of solver steps"],
        id="traffic-step-not-multiple-of-dt",
    ),
    pytest.param(
        PAPER_TEXT.split("[[vehicles]]")[0] + '\n[traffic]\nsumo_config = "medium"\naxis = [[0, 0], [30, 0]]\n',
        "traffic.axis",
        ["must be the bridge's length, 40 m"],
        id="traffic-axis-length",
    ),
    pytest.param(
        replaced('scheme = "newmark"', 'scheme = "generalized-alpha"'),
        "solver.scheme",
        ['unknown scheme "generalized-alpha"', "expected one of: newmark, hht"],
        id="generalized-alpha-not-implemented",
    ),
    pytest.param(
        replaced("dt = 0.005", "dt = 0.005\nrho_inf = 0.8"),
        "solver.rho_inf",
        ["unknown key", "expected one of: method, dt, scheme, hht_alpha, basis, modes, cutoff_hz, duration, gravity"],
        id="rho-inf-not-implemented",
    ),
    pytest.param(
        replaced("duration = 20.0", "duration = 0.001"),
        "solver.duration",
        ["must be >= dt = 0.005 s (got 0.001)"],
        id="duration-shorter-than-dt",
    ),
    # [[vehicles]]
    pytest.param(
        replaced("speed = 4.0", "sped = 4.0"),
        "vehicles[0].sped",
        ['unknown key; did you mean "speed"?', "expected one of: id, model, mass, m_v"],
        id="misspelled-vehicle-key",
    ),
    pytest.param(
        replaced("m_w = 200.0", "m_w = '200'"),
        "vehicles[1].m_w",
        ['expected a number, got string "200"'],
        id="vehicle-string-for-number",
    ),
    pytest.param(
        replaced("m_v = 1000.0", "m_v = -1000.0"),
        "vehicles[0].m_v",
        ["must be a finite number > 0 (got -1000.0)"],
        id="negative-vehicle-mass",
    ),
    pytest.param(
        replaced("c_v = 10053.10", "c_v = -1.0"),
        "vehicles[1].c_v",
        ["must be a finite number >= 0 (got -1.0)"],
        id="negative-suspension-damping",
    ),
    pytest.param(
        replaced("y = 3.325                                   # m\nspeed", "y = 6.7\nspeed"),
        "vehicles[0].y",
        ["must lie on the deck, -6.655 <= y <= 6.655 m (got 6.7)"],
        id="vehicle-off-the-deck",
    ),
    pytest.param(
        replaced('model = "quarter-car"', 'model = "quater-car"'),
        "vehicles[0].model",
        ['unknown vehicle model "quater-car"; did you mean "quarter-car"?',
         "expected one of: moving-force, quarter-car, tyre-quarter-car, golden-car"],
        id="unknown-vehicle-model",
    ),
    pytest.param(
        replaced("c_v = 10053.10", "c_v = 10053.10\nk_t = 1e6"),
        "vehicles[1].k_t",
        ['not a parameter of model "quarter-car" (its parameters: m_v, m_w, k_v, c_v)'],
        id="parameter-of-another-model",
    ),
    pytest.param(
        replaced("k_v = 39478.40", ""),
        "vehicles[0].k_v",
        ['required key is missing (model "quarter-car" needs m_v, m_w, k_v, c_v)'],
        id="missing-vehicle-parameter",
    ),
    pytest.param(
        replaced("speed = 4.0", "speed = 0.0"),
        "vehicles[0].speed",
        ["must be > 0 (got 0.0)"],
        id="zero-speed",
    ),
    pytest.param(
        replaced("speed = 4.0", ""),
        "vehicles[0].speed",
        ["required key is missing", "speed profile"],
        id="missing-speed",
    ),
    pytest.param(
        replaced("speed = 4.0", "speed = 4.0\nprofile = [[0, 4.0]]"),
        "vehicles[0].speed",
        ["give either speed or profile, not both"],
        id="speed-and-profile",
    ),
    pytest.param(
        replaced("speed = 4.0", "profile = [[0, 4.0], [5.0, 3.0], [4.0, 3.0]]"),
        "vehicles[0].profile[2][0]",
        ["times must increase (got 4.0 after 5.0)"],
        id="profile-decreasing-times",
    ),
    pytest.param(
        replaced("speed = 4.0", "profile = [[1.0, 4.0]]"),
        "vehicles[0].profile[0][0]",
        ["the first time must be 0"],
        id="profile-not-starting-at-zero",
    ),
    pytest.param(
        replaced("speed = 4.0", "profile = [[0, 4.0], [2.0, -1.0]]"),
        "vehicles[0].profile[1][1]",
        ["speed must be >= 0 m/s (got -1.0)"],
        id="profile-negative-speed",
    ),
    pytest.param(
        replaced("speed = 4.0", "profile = [[0, 4.0, 1.0]]"),
        "vehicles[0].profile[0]",
        ["expected a pair [t, v]"],
        id="profile-not-pairs",
    ),
    pytest.param(
        replaced("entry_time = 7.5", "entry_time = -7.5"),
        "vehicles[1].entry_time",
        ["must be >= 0 (got -7.5)"],
        id="negative-entry-time",
    ),
    pytest.param(
        replaced('direction = "+x"', 'direction = "backwards"'),
        "vehicles[0].direction",
        ['unknown direction "backwards"', "expected one of: +x, -x"],
        id="unknown-direction",
    ),
    pytest.param(
        replaced('id = "QC-2"', 'id = "QC-1"'),
        "vehicles[1].id",
        ['duplicate vehicle id "QC-1" (also vehicles[0]'],
        id="duplicate-vehicle-id",
    ),
    pytest.param(
        replaced('id = "QC-2"', 'id = "QC 2"'),
        "vehicles[1].id",
        ["may contain only letters, digits"],
        id="vehicle-id-with-space",
    ),
    pytest.param(
        replaced("speed = 4.0", "profile = [[0, 4.0], [5.0, 0.0]]").replace("duration = 20.0", "", 1),
        "solver.duration",
        ["required key is missing", "vehicles[0] (QC-1) stops on the deck at x = 10 m"],
        id="vehicle-stops-without-duration",
    ),
    pytest.param(
        PAPER_TEXT + '\n[[vehicles]]\nmodel = "quarter-car"\n',
        "vehicles[2].y",
        ["required key is missing"],
        id="incomplete-vehicle",
    ),
    # [road]
    pytest.param(
        replaced('class = "smooth"', 'class = "C"'),
        "road.seed",
        ["required key is missing", "needs a seed"],
        id="road-class-without-seed",
    ),
    pytest.param(
        replaced('class = "smooth"', 'class = "c"\nseed = 1'),
        "road.class",
        ['unknown road class "c"; did you mean "C"?', "expected one of: A, B, C, D, E, F, G, H, smooth"],
        id="unknown-road-class",
    ),
    pytest.param(
        replaced('class = "smooth"', 'class = "smooth"\nseed = 1'),
        "road.seed",
        ['only used with a random road'],
        id="seed-with-smooth-road",
    ),
    pytest.param(
        replaced('class = "smooth"', 'class = "B"\nseed = -1'),
        "road.seed",
        ["must be >= 0 (got -1)"],
        id="negative-seed",
    ),
    pytest.param(
        replaced('class = "smooth"', 'class = "B"\nseed = 1.5'),
        "road.seed",
        ["expected an integer", "1.5"],
        id="float-seed",
    ),
    pytest.param(
        replaced('class = "smooth"', 'profile = "no-such-road.csv"'),
        "road.profile",
        ["file not found", "no-such-road.csv", "relative to the scenario file's folder"],
        id="road-profile-file-missing",
    ),
    pytest.param(
        replaced('class = "smooth"', 'class = "A"\nseed = 1\nprofile = "road.csv"'),
        "road",
        ["give either class or profile, not both"],
        id="road-class-and-profile",
    ),
    pytest.param(
        replaced('class = "smooth"', 'klass = "smooth"'),
        "road.klass",
        ['did you mean "class"?', "expected one of: class, seed, profile"],
        id="misspelled-road-key",
    ),
    # [output]
    pytest.param(
        replaced("every = 1 ", "every = 0 "),
        "output.every",
        ["must be >= 1 (got 0)"],
        id="output-every-zero",
    ),
    pytest.param(
        replaced("every = 1 ", 'mcap = "run.mcap"\nevery = 1 '),
        "output.mcap",
        ["unknown key", "expected one of: log, rate_hz, every, csv"],
        id="output-unknown-key",
    ),
    pytest.param(
        replaced("every = 1 ", "rate_hz = 50.0\nevery = 1 "),
        "output.every",
        ["give either rate_hz", "or every", "not both"],
        id="output-rate-and-every",
    ),
    pytest.param(
        replaced("every = 1 ", "rate_hz = 400.0 "),
        "output.rate_hz",
        ["must be <= 1 / solver.dt = 200 Hz", "got 400.0"],
        id="output-rate-above-steps",
    ),
    pytest.param(
        replaced("every = 1 ", 'log = "run.csv" '),
        "output.log",
        ["expected a path ending in .mcap"],
        id="output-log-not-mcap",
    ),
    pytest.param(
        replaced('start = [-6.655, 0.0]', 'start = [-6.655]'),
        "bridge.section.plates[0].start",
        ["expected an array of 2 numbers [y, z]"],
        id="point-with-one-coordinate",
    ),
    pytest.param(
        replaced("[bridge.damping]", "[bridge.section.constants]\nA = 1\nI_y = 1\nI_z = 1\nJ = 1\n"
                 "deck_y = [-1, 1]\n\n[bridge.damping]"),
        "bridge.section",
        ["exactly one of", "got both"],
        id="plates-and-constants",
    ),
]


@pytest.mark.parametrize(("text", "key", "fragments"), MALFORMED)
def test_malformed_scenario_names_file_and_key(tmp_path: Path, text: str, key: str, fragments: list[str]) -> None:
    path = write(tmp_path, text)
    message = config_error(path)
    first = message.splitlines()[0]
    assert first.startswith(f"{path}: {key}: "), first
    for fragment in fragments:
        assert fragment in first, (fragment, first)


def test_misspelled_key_does_not_also_report_the_missing_one(tmp_path: Path) -> None:
    message = config_error(write(tmp_path, replaced("spans = [40.0]", "spanz = [40.0]")))
    assert len(message.splitlines()) == 1
    assert "missing" not in message


def test_several_problems_first_line_self_contained(tmp_path: Path) -> None:
    text = replaced("dt = 0.005", "dt = -1", replaced("E = 33.0e9", 'E = "33e9"'))
    path = write(tmp_path, text)
    lines = config_error(path).splitlines()
    assert lines[0] == f'{path}: bridge.material.E: expected a number, got string "33e9"'
    assert any(line == f"{path}: solver.dt: must be > 0 (got -1)" for line in lines[1:])


def test_toml_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    path = write(tmp_path, replaced("dt = 0.005", "dt = "))
    message = config_error(path)
    line = next(i for i, text in enumerate(PAPER_TEXT.splitlines(), 1) if text.startswith("dt = "))
    assert message.startswith(f"{path}: TOML syntax error: ")
    assert f"line {line}" in message


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nowhere.toml"
    message = config_error(path)
    assert message.startswith(f"{path}: no such scenario file")
    assert "paper-double-tee" in message  # lists the bundled scenarios


def test_misspelled_bundled_name_gets_a_suggestion() -> None:
    message = config_error("paper-double-te")
    assert 'did you mean "paper-double-tee"' in message


def test_sensor_y_checked_against_constants_deck_y(tmp_path: Path) -> None:
    path = write(tmp_path, CONSTANTS_TEXT.replace("y = -3\n", "y = -3.5\n"))
    message = config_error(path)
    assert message.startswith(f"{path}: sensors[0].y: must lie on the deck, -3 <= y <= 3 m (got -3.5)")


def test_elements_per_span_list_must_match_spans(tmp_path: Path) -> None:
    path = write(tmp_path, CONSTANTS_TEXT.replace("elements_per_span = [4, 6]", "elements_per_span = [4]"))
    assert config_error(path).startswith(f"{path}: bridge.elements_per_span: expected one entry per span (2), got 1")


def test_parse_scenario_names_its_source() -> None:
    with pytest.raises(ConfigError, match=r"^inline: bridge: required key is missing"):
        parse_scenario("", "inline")


def test_scenario_is_not_built_from_unvalidated_data() -> None:
    with pytest.raises(ValidationError):
        Scenario.model_validate({"bridge": {"spans": ["40"]}})


# --------------------------------------------------------------------------- model


def test_build_bridge_from_constants(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, CONSTANTS_TEXT, "small.toml"))
    bridge = scenario.build_bridge()
    assert bridge.length == pytest.approx(22.0)
    assert len(bridge.nodes_x) == 11
    assert bridge.modes(count=3).f_hz[0] > 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        bridge.alpha = 1.0  # type: ignore[misc]


# --------------------------------------------------------------------------- vehicles, road, output

# CONSTANTS_TEXT (22 m, deck -3 <= y <= 3) with one vehicle of every model.
VEHICLES_TEXT = CONSTANTS_TEXT + """\
[[vehicles]]
model = "moving-force"
mass = 5000
y = 1.0
speed = 11.0
[[vehicles]]
id = "qc"
model = "quarter-car"
m_v = 1000
m_w = 100
k_v = 39478.4
c_v = 5026.55
y = -1.0
speed = 5.5
entry_time = 1.0
direction = "-x"
[[vehicles]]
model = "tyre-quarter-car"
m_v = 400
m_w = 40
k_v = 2.5e4
c_v = 2.4e3
k_t = 2.6e5
y = 1.0
profile = [[0, 2.0], [2.0, 4.0]]
[[vehicles]]
model = "golden-car"
m_v = 300
y = 2.5
speed = 22.0
"""


def test_every_vehicle_model_loads_and_builds(tmp_path: Path) -> None:
    from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar

    scenario = load_scenario(write(tmp_path, VEHICLES_TEXT, "cars.toml"))
    assert [v.id for v in scenario.vehicles] == ["V1", "qc", "V3", "V4"]  # default ids by position
    models = [v.to_model() for v in scenario.vehicles]
    assert models[0] == MovingForce(mass=5000.0)
    assert models[1] == QuarterCar(m_v=1000.0, m_w=100.0, k_v=39478.4, c_v=5026.55)
    assert models[2] == TyreQuarterCar(m_v=400.0, m_w=40.0, k_v=2.5e4, c_v=2.4e3, k_t=2.6e5, c_t=0.0)  # c_t default
    assert models[3] == TyreQuarterCar.golden_car(300.0)
    assert scenario.vehicles[2].parameters["c_t"] == 0.0
    assert scenario.vehicles[0].direction == "+x" and scenario.vehicles[0].entry_time == 0.0  # defaults
    assert scenario.vehicles[2].profile == ((0.0, 2.0), (2.0, 4.0))


def test_build_vehicles_places_them_on_the_bridge(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, VEHICLES_TEXT, "cars.toml"))
    traffic = scenario.build_vehicles()
    assert traffic.length == 22.0
    assert [v.id for v in traffic.vehicles] == ["V1", "qc", "V3", "V4"]
    assert [v.direction for v in traffic.vehicles] == [1, -1, 1, 1]
    frame = traffic.frame(1.5)
    on_deck = dict(zip(frame.ids, frame.x))
    assert on_deck["V1"] == pytest.approx(16.5)
    assert on_deck["qc"] == pytest.approx(22.0 - 5.5 * 0.5)  # "-x" enters at x = L
    assert frame.v[frame.ids.index("qc")] == pytest.approx(-5.5)
    assert on_deck["V3"] == pytest.approx(2.0 * 1.5 + 0.5 * 1.0 * 1.5**2)  # speed 2 m/s rising by 1 m/s^2


def test_default_duration_is_the_last_exit_plus_two_seconds(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, VEHICLES_TEXT, "cars.toml"))
    assert scenario.solver.duration is None
    # qc: enters at 1 s, 22 m at 5.5 m/s -> leaves at 5 s; V3: 6 m in the first 2 s, then 16 m at 4 m/s -> 6 s.
    assert scenario.leave_time == pytest.approx(6.0)
    assert scenario.leave_time == pytest.approx(scenario.build_vehicles().end_time())
    assert scenario.duration == pytest.approx(8.0)
    given = parse_scenario(VEHICLES_TEXT + "[solver]\nduration = 3.0\n")
    assert given.duration == 3.0


def test_a_vehicle_stopping_after_the_deck_needs_no_duration(tmp_path: Path) -> None:
    text = CONSTANTS_TEXT + (
        '[[vehicles]]\nmodel = "moving-force"\nmass = 1e3\ny = 0\nprofile = [[0, 4.0], [20.0, 0.0]]\n'
    )
    scenario = parse_scenario(text)
    # distance 4 t - 0.1 t^2 reaches 22 m at t = (4 - sqrt(16 - 8.8)) / 0.2, before it stops at 40 m.
    leave = (4.0 - (16.0 - 8.8) ** 0.5) / 0.2
    assert scenario.leave_time == pytest.approx(leave, abs=1e-6)
    assert scenario.duration == pytest.approx(leave + 2.0, abs=1e-6)


def test_duration_without_vehicles_must_be_given() -> None:
    scenario = parse_scenario(CONSTANTS_TEXT, "static.toml")
    assert scenario.vehicles == () and scenario.leave_time is None
    with pytest.raises(ConfigError, match=r"^static.toml: solver.duration: required key is missing"):
        _ = scenario.duration


def test_random_road_has_one_seeded_profile_per_wheel_path(tmp_path: Path) -> None:
    text = VEHICLES_TEXT + '[road]\nclass = "C"\nseed = 42\n'
    scenario = load_scenario(write(tmp_path, text, "rough.toml"))
    assert (scenario.road.road_class, scenario.road.seed) == ("C", 42)
    road = scenario.build_road()
    assert road.path_y == (-1.0, 1.0, 2.5) == scenario.wheel_paths()
    assert road.x0 == -10.0
    assert road.x0 + road.dx * (road.r.shape[1] - 1) >= 22.0 + 10.0
    assert "class C" in road.description and "seed 42" in road.description
    again = scenario.build_road()
    assert (road.r == again.r).all()  # reproducible from the recorded seed
    assert not (road.r[0] == road.r[1]).all()  # independent paths


def test_smooth_road_by_default_and_by_name() -> None:
    for text in (CONSTANTS_TEXT, CONSTANTS_TEXT + '[road]\nclass = "smooth"\n'):
        scenario = parse_scenario(text)
        assert scenario.road.smooth and not scenario.road.random
        assert scenario.build_road().description == "smooth"


def test_road_profile_file_is_relative_to_the_scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "site"
    folder.mkdir()
    rows = "".join(f"{x},{1e-4 * x}\n" for x in range(-1, 24))  # r = 1e-4 x for -1 <= x <= 23 m
    (folder / "road.csv").write_text("x,r\n" + rows, encoding="utf-8")
    path = write(folder, VEHICLES_TEXT + '[road]\nprofile = "road.csv"\n', "bridge.toml")
    monkeypatch.chdir(tmp_path)  # not the scenario's folder
    scenario = load_scenario(path)
    assert scenario.road_profile_path == folder / "road.csv"
    road = scenario.build_road()
    assert road.path_y == (-1.0, 1.0, 2.5)
    r, _ = road.evaluate([-1.0, 1.0, 2.5], [10.0, 10.0, 10.0])
    assert r == pytest.approx([1e-3, 1e-3, 1e-3])  # the same profile on every path


@pytest.mark.parametrize(
    ("content", "fragments"),
    [
        ("x,r\n0.0,0.0\n10.0,0.001\n", ["the profile covers 0 <= x <= 10 m", "must cover the deck, 0 <= x <= 22 m"]),
        ("x,r\n0.0,0.0\n__import__('os').system('true'),0\n30,0\n", ["line 3: expected two numbers"]),
        ("x,r\n0.0,0.0\n30,0\n20,0\n", ["line 4: x must increase strictly"]),
    ],
    ids=["too-short", "not-a-number", "x-decreasing"],
)
def test_bad_road_profile_file(tmp_path: Path, content: str, fragments: list[str]) -> None:
    (tmp_path / "road.csv").write_text(content, encoding="utf-8")
    path = write(tmp_path, CONSTANTS_TEXT + '[road]\nprofile = "road.csv"\n')
    first = config_error(path).splitlines()[0]
    assert first.startswith(f"{path}: road.profile: "), first
    for fragment in fragments:
        assert fragment in first, (fragment, first)


def test_output_defaults_log_path_and_rate(tmp_path: Path) -> None:
    import datetime

    scenario = parse_scenario(CONSTANTS_TEXT)  # dt = 0.005 s by default
    assert (scenario.output.log, scenario.output.csv, scenario.output.every, scenario.output.rate_hz) == (
        None, None, None, None)
    assert scenario.csv_path is None and scenario.log_path is None
    assert (scenario.output_every, scenario.output_rate_hz) == (2, 100.0)  # the default 100 Hz
    when = datetime.datetime(2025, 1, 2, 3, 4, 5)
    assert scenario.default_log_path(when) == Path("runs") / "small-20250102-030405.mcap"
    unnamed = load_scenario(write(tmp_path, CONSTANTS_TEXT.replace('name = "small"', 'name = "my bridge/2"')))
    assert unnamed.default_log_path(when, "-replay") == Path("runs") / "my_bridge_2-replay-20250102-030405.mcap"
    given = parse_scenario(CONSTANTS_TEXT + '[output]\nlog = "out/run1.mcap"\ncsv = "out/run1.csv"\nevery = 4\n')
    assert (given.log_path, given.csv_path, given.output_every) == (Path("out/run1.mcap"), Path("out/run1.csv"), 4)
    # round(1 / (rate dt)) steps per sample; the rate actually used follows from it.
    rated = parse_scenario(CONSTANTS_TEXT + "[solver]\ndt = 0.002\n[output]\nrate_hz = 30.0\n")
    assert (rated.output_every, rated.output_rate_hz) == (17, pytest.approx(1 / 0.034))
    coarse = parse_scenario(CONSTANTS_TEXT + "[solver]\ndt = 0.02\n")  # 100 Hz > 1/dt: every step
    assert coarse.output_every == 1
    exact = parse_scenario(CONSTANTS_TEXT + "[output]\nrate_hz = 200.0\n")  # = 1/dt: allowed
    assert exact.output_every == 1


def test_sensors_core_and_solver_settings() -> None:
    from cosim.core.sensors import Sensor
    from cosim.core.simulation import SolverSettings

    scenario = parse_scenario(CONSTANTS_TEXT + '[solver]\ndt = 0.01\nscheme = "hht"\nhht_alpha = -0.1\ngravity = 9.8\n')
    assert scenario.sensors_core() == [Sensor(name="mid", x=5.0, y=-3.0, quantity="displacement")]
    assert scenario.solver_settings() == SolverSettings(
        dt=0.01, scheme="hht", hht_alpha=-0.1, basis="direct", modes=None, cutoff_hz=None, gravity=9.8
    )


def test_simulate_runs_the_scenario(tmp_path: Path) -> None:
    text = VEHICLES_TEXT + '[road]\nclass = "B"\nseed = 1\n[solver]\ndt = 0.01\nduration = 2.0\n[output]\nevery = 2\n'
    scenario = load_scenario(write(tmp_path, text, "cars.toml"))
    seen: list[float] = []
    result = simulate_scenario(scenario, progress=seen.append)
    assert result.steps == 200
    assert len(result.t) == 101 and result.t[-1] == pytest.approx(2.0)  # every 2nd step and t = 0
    assert list(result.sensors) == ["mid"]
    assert set(result.vehicle_ids) == {"V1", "qc", "V3", "V4"}
    assert seen and seen[-1] == 1.0
    assert result.factorizations == 1
