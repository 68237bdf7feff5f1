"""The scenario keys of the element's theories: [bridge] torsion, bending; [bridge.section.constants] I_ws,
mass_per_length, rotary_inertia (docs/scenario.md). Defaults keep the seed's element; bad values get one line
naming the file and the key."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cosim.core.element import BeamTheory
from cosim.errors import ConfigError
from cosim.run.scenario import load_scenario

BASE = """\
name = "theories"
[bridge]
spans = [20.0]
elements_per_span = 10
supports = ["pinned", "fork"]
{bridge}
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
{constants}
"""


def _write(tmp_path: Path, bridge: str = "", constants: str = "") -> Path:
    path = tmp_path / "theories.toml"
    path.write_text(BASE.format(bridge=bridge, constants=constants), encoding="utf-8")
    return path


def test_defaults_are_the_seeds_element(tmp_path: Path) -> None:
    scenario = load_scenario(_write(tmp_path))
    assert (scenario.bridge.torsion, scenario.bridge.bending) == ("vlasov", "timoshenko")
    bridge = scenario.build_bridge()
    assert bridge.theory == BeamTheory()
    section = bridge.section
    assert (section.I_ws, section.mass_per_length, section.rotary_inertia) == (None, None, True)


def test_the_keys_reach_the_model(tmp_path: Path) -> None:
    path = _write(tmp_path, 'torsion = "benscoter"\nbending = "euler-bernoulli"',
                  "I_ws = 0.05\nmass_per_length = 6000.0\nrotary_inertia = false")
    bridge = load_scenario(path).build_bridge()
    assert bridge.theory == BeamTheory(torsion="benscoter", bending="euler-bernoulli")
    assert (bridge.section.I_ws, bridge.section.mass_per_length, bridge.section.rotary_inertia) == (0.05, 6000.0, False)
    # The translational mass is the given mass per length over the span: r^T M r for a unit vertical translation.
    r = np.zeros(bridge.ndof)
    r[2::7] = 1.0
    assert r @ (bridge.M @ r) == pytest.approx(6000.0 * 20.0, rel=1e-12)


@pytest.mark.parametrize(("bridge", "constants", "key", "fragments"), [
    ('torsion = "timoshenko"', "", "bridge.torsion", ['unknown torsion theory "timoshenko"', "vlasov, benscoter"]),
    ('torsion = "benscotter"', "", "bridge.torsion", ['did you mean "benscoter"?']),
    ('bending = "euler"', "", "bridge.bending", ["unknown bending theory", "timoshenko, euler-bernoulli"]),
    ('torsion = "benscoter"', "", "bridge.section.constants.I_ws",
     ['required by torsion = "benscoter" when I_w > 0', "m^4"]),
    ("", "I_ws = 0.0", "bridge.section.constants.I_ws", ["must be > 0"]),
    ("", "mass_per_length = -5.0", "bridge.section.constants.mass_per_length", ["must be > 0"]),
    ("", "rotary_inertia = 0", "bridge.section.constants.rotary_inertia", ["expected", "bool"]),
], ids=["unknown-torsion", "misspelled-torsion", "unknown-bending", "benscoter-needs-iws", "iws-zero",
        "negative-mass", "rotary-not-bool"])
def test_bad_values_get_one_line_naming_the_key(tmp_path: Path, bridge: str, constants: str, key: str,
                                                fragments: list[str]) -> None:
    path = _write(tmp_path, bridge, constants)
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    first = str(info.value).splitlines()[0]
    assert first.startswith(f"{path}: {key}: "), first
    for fragment in fragments:
        assert fragment in first, (fragment, first)


def test_benscoter_without_warping_needs_no_i_ws(tmp_path: Path) -> None:
    """I_w = 0: nothing warps, so Benscoter is the Vlasov element and needs no I_ws."""
    def without_warping(bridge: str, name: str) -> Path:
        path = tmp_path / name
        path.write_text(BASE.format(bridge=bridge, constants="").replace("I_w = 0.1\n", ""), encoding="utf-8")
        return path

    benscoter = load_scenario(without_warping('torsion = "benscoter"', "b.toml")).build_bridge()
    vlasov = load_scenario(without_warping("", "v.toml")).build_bridge()
    assert benscoter.theory.torsion == "benscoter"
    assert (benscoter.K != vlasov.K).nnz == 0 and (benscoter.M != vlasov.M).nnz == 0
