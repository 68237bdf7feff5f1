"""``cosim static`` (point loads anywhere on the deck) and the mode shapes of ``cosim modes --json``, in process.

References: the simply supported Euler-Bernoulli beam's deflection under a
point load (Gere & Timoshenko, Mechanics of Materials) and its first mode
``sqrt(2 / (m L)) sin(pi x / L)`` mass-normalised (Clough & Penzien).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli

L, EI, MASS = 20.0, 30e9 * 0.8, 6000.0
BEAM = f"""\
name = "eb-beam"
[bridge]
spans = [{L}]
elements_per_span = 10
supports = ["pinned", "fork"]
bending = "euler-bernoulli"
[bridge.material]
E = 30e9
nu = 0.2
rho = 2500
[bridge.section.constants]
A = 2.0
I_y = 0.8
I_z = 5.0
J = 1.0
mass_per_length = {MASS}
rotary_inertia = false
deck_y = [-2.0, 2.0]
[[sensors]]
name = "quarter"
x = 5.0
y = 0.0
[[sensors]]
name = "mid_moment"
x = 10.0
y = 0.0
quantity = "bending_moment"
"""
NODAL_EXACT = 1e-9  # Hermite cubics: exact at the nodes (and so at sensors on nodes) for point loads


@pytest.fixture()
def beam(tmp_path: Path) -> Path:
    path = tmp_path / "eb-beam.toml"
    path.write_text(BEAM, encoding="utf-8")
    return path


def _w_simply_supported(x: float, a: float, P: float) -> float:
    """Deflection at x under P at a (Gere & Timoshenko, Mechanics of Materials, table of beam deflections)."""
    b = L - a
    if x <= a:
        return P * b * x * (L**2 - b**2 - x**2) / (6 * EI * L)
    return _w_simply_supported(L - x, L - a, P)


def test_static_loads_anywhere_act_together(beam: Path) -> None:
    result = cosim_cli("static", str(beam), "--load", "6", "0", "-1e5", "--load", "14", "0", "-5e4", "--json")
    assert result.returncode == 0, result.stderr
    payload = json.loads(result.stdout)  # nothing but JSON on stdout
    assert payload["theory"] == {"torsion": "vlasov", "bending": "euler-bernoulli"}
    loads = [(6.0, -1e5), (14.0, -5e4)]
    # Superposition of the closed forms; the loads are over S (S = C = the axis): no twist.
    for entry, (a, _) in zip(payload["loads"], loads):
        ref = sum(_w_simply_supported(a, a_k, P) for a_k, P in loads)
        assert entry["w"] == pytest.approx(ref, rel=NODAL_EXACT)
    sensors = {s["name"]: s for s in payload["sensors"]}
    assert sensors["quarter"]["w"] == pytest.approx(sum(_w_simply_supported(5.0, a, P) for a, P in loads),
                                                    rel=NODAL_EXACT)
    # Sagging moment at mid-span from statics: sum of P b x / L (left of each load) ...
    moment = -sum(P * (L - a) * 10.0 / L if 10.0 <= a else P * a * (L - 10.0) / L for a, P in loads)
    assert sensors["mid_moment"]["bending_moment"] == pytest.approx(moment, rel=1e-6)
    assert payload["units"]["w"] == "m (positive up)"


def test_static_table(beam: Path) -> None:
    result = cosim_cli("static", str(beam), "--load", "10", "0", "-100e3")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("Scenario: eb-beam")
    load_row = next(line for line in lines if line.strip().startswith("load 1"))
    assert "-100 kN" in load_row
    assert float(load_row.split()[-1]) == pytest.approx(1e3 * _w_simply_supported(10.0, 10.0, -1e5), rel=1e-4)
    assert any(line.strip().startswith("mid_moment") for line in lines)


@pytest.mark.parametrize(("load", "message"), [
    (("25", "0", "-1e5"),
     "load 1 (x = 25 m, y = 0 m, Fz = -100000 N) is off the bridge: x must lie in 0 <= x <= 20 m"),
    (("10", "2.5", "-1e5"),
     "load 1 (x = 10 m, y = 2.5 m, Fz = -100000 N) is off the deck: y must lie in -2 <= y <= 2 m"),
])
def test_a_load_off_the_deck_is_one_line_and_exit_2(beam: Path, load: tuple[str, ...], message: str) -> None:
    result = cosim_cli("static", str(beam), "--load", "5", "0", "-1e3", "--load", *load)
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr == f"cosim: error: {message.replace('load 1', 'load 2')}\n"


def test_a_load_that_is_not_a_finite_number_is_a_usage_error(beam: Path) -> None:
    result = cosim_cli("static", str(beam), "--load", "5", "inf", "-1e3")
    assert result.returncode == 2
    assert "expected a finite number, got 'inf'" in result.stderr
    assert cosim_cli("static", str(beam)).returncode == 2  # --load is required


def test_modes_json_has_the_mass_normalised_nodal_shapes(beam: Path) -> None:
    result = cosim_cli("modes", str(beam), "--json", "--count", "4")
    assert result.returncode == 0, result.stderr
    payload = json.loads(result.stdout)
    x = np.array(payload["nodes_x"])
    assert len(x) == 11 and x[-1] == pytest.approx(L)
    vertical = next(m for m in payload["modes"] if m["kind"] == "vertical")
    shape = vertical["shape"]
    assert set(shape) == {"w", "theta_x", "v"} and all(len(values) == len(x) for values in shape.values())
    # First bending mode of the simply supported beam, mass-normalised: sqrt(2 / (m L)) sin(pi x / L).
    ref = np.sqrt(2 / (MASS * L)) * np.sin(np.pi * x / L)
    np.testing.assert_allclose(shape["w"], ref, atol=1e-4 * ref.max())
    assert np.max(np.abs(shape["theta_x"])) < 1e-9 * ref.max() and np.max(np.abs(shape["v"])) < 1e-9 * ref.max()
    lateral = next(m for m in payload["modes"] if m["kind"] == "lateral")
    assert np.max(np.abs(lateral["shape"]["w"])) < 1e-9 * np.max(np.abs(lateral["shape"]["v"]))


def test_modes_shapes_of_a_twisting_mode_put_the_axis_off_the_shear_centre() -> None:
    """The asymmetric paper section: S is off the axis, so w on the axis carries the twist, w = w_S - y_S theta_x."""
    result = cosim_cli("modes", "paper-double-tee-asymmetric", "--json", "--count", "3")
    payload = json.loads(result.stdout)
    torsion = next(m for m in payload["modes"] if m["kind"] == "torsion")
    y_s = payload["section"]["y_s"]
    assert abs(y_s) > 0.05
    from cosim.run.scenario import load_scenario

    bridge = load_scenario("paper-double-tee-asymmetric").build_bridge()
    modal = bridge.modes(3)
    j = [m["n"] for m in payload["modes"]].index(torsion["n"])
    w_axis = modal.field(j, "w_deck", bridge.nodes_x, y=0.0)
    np.testing.assert_allclose(torsion["shape"]["w"], w_axis, atol=1e-12 * np.max(np.abs(w_axis)))


def test_static_help_describes_the_loads() -> None:
    result = cosim_cli("static", "--help")
    assert result.returncode == 0
    for word in ("--load X Y FZ", "positive up", "--json", "examples:", "off the deck"):
        assert word in result.stdout, word
    assert "static" in cosim_cli("--help").stdout
