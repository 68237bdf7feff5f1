"""Scenario files: bundled scenarios load; malformed ones fail with the file and key named."""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest
from pydantic import ValidationError

from cosim.errors import ConfigError
from cosim.scenario import (
    Scenario,
    list_bundled_scenarios,
    load_scenario,
    parse_scenario,
)

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
    galpha = parse_scenario(replaced('scheme = "newmark"', 'scheme = "generalized-alpha"'), "ga.toml")
    assert galpha.solver.rho_inf == 0.8
    modal = parse_scenario(replaced('basis = "direct"', 'basis = "modal"'), "modal.toml")
    assert modal.solver.modes == 30


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
        PAPER_TEXT + '\n[traffic]\nsumocfg = "net.sumocfg"\n',
        "traffic",
        ["not supported yet", "expected one of: name, description, bridge, sensors, solver"],
        id="future-section-traffic",
    ),
    pytest.param(
        PAPER_TEXT + '\n[[vehicles]]\nmodel = "quarter-car"\n',
        "vehicles",
        ["not supported yet"],
        id="future-section-vehicles",
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
