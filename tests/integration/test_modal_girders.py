"""The worked example of docs/modal-decks.md, "Worked example: a slab on five girders" (issue 26, item 6):
examples/modal/girders.py's OpenSeesPy model, the modes it committed (girders-modes.npz) and a short run of
examples/modal/girders.toml under real SUMO traffic (libsumo) in both directions.

OpenSeesPy is a test oracle here (the ``test`` extra installs it); cosim imports it only inside from_opensees.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

import numpy as np
import openseespy.opensees as ops
import pytest

from cosim import testing
from cosim.bridges import read_modes
from cosim.core.modal_deck import ModalDeck

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "modal"


def _example() -> Any:
    spec = importlib.util.spec_from_file_location("girders", EXAMPLES / "girders.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


girders = _example()
MID = girders.SPAN / 2
AT_GIRDERS = [(MID, y) for y in girders.GIRDERS_Y]


@pytest.fixture(scope="module")
def built() -> tuple[Any, ModalDeck]:
    """The example's OpenSees model, built in this process, and the modes it gives now (about 15 s)."""
    model = girders.build(ops)
    return model, girders.import_modes(ops, model)


def _flexibility(deck: ModalDeck, points: list[tuple[float, float]], x: float, y: float) -> np.ndarray:
    """The deck's static displacement at ``points`` per unit upward force at (x, y): sum over the file's modes
    of phi_j(point) phi_j(x, y) / omega_j^2, through cosim's contact rows (exact at the grid's nodes)."""
    load = deck.rows(np.array([x]), np.array([y]))[0, 0]
    at = np.stack([deck.rows(np.array([px]), np.array([py]))[0, 0] for px, py in points])
    return np.asarray(at @ (load / deck.omega**2))


#: The committed file against the model's modes computed now: the same model, the same eigen solver
#: (ARPACK): measured bit for bit here (0); the tolerance allows another BLAS. Shapes up to a sign.
SAME_MODES = 1e-8
#: The first frequency against the whole cross-section as one simply supported Euler-Bernoulli beam, (pi/2L^2)
#: sqrt(EI/m), I and m of the slab and the five girders together (the plates by cosim's section solver): the
#: shell model adds shear lag, shear deformation and the end diaphragms' mass. Measured 2.504 vs 2.513 Hz
#: (0.36 %); tolerance 2 %.
F1_BEAM = 0.02


def test_the_committed_modes_are_the_models_and_its_first_frequency_the_composite_beams(built):
    model, live = built
    committed = read_modes(EXAMPLES / "girders-modes.npz")
    assert committed.n_modes == live.n_modes == girders.N_MODES
    assert np.allclose(committed.points, live.points, rtol=0, atol=1e-12)
    assert np.allclose(committed.f_hz, live.f_hz, rtol=SAME_MODES, atol=0)
    sign = np.sign(np.einsum("jn,jn->j", committed.phi, live.phi))
    scale = np.abs(live.phi).max()
    assert np.max(np.abs(committed.phi - sign[:, None] * live.phi)) <= SAME_MODES * scale
    assert committed.f_hz[0] == pytest.approx(girders.composite_f1(girders.whole_section()), rel=F1_BEAM)
    assert len(model.deck_nodes) == committed.points.shape[0] == 825


#: The modes file's static response against OpenSees' own linear static analysis of the model, a 100 kN
#: point load at mid-span on the eastbound lane's centre, on the axis and on the deck's edge, the vertical
#: displacement at mid-span over each of the five girders. The difference is the 50 modes' truncation (the
#: contact rows are exact at the nodes): measured at most 0.51 % of the largest of the five (10 modes: 5.0 %,
#: 20 modes: 1.8 %) and 0.13 % in their sum. Tolerances: 1 % and 0.3 %.
STATIC_PEAK, STATIC_SUM = 1e-2, 3e-3


@pytest.mark.parametrize("y_load", [-1.875, 0.0, -6.5], ids=["lane", "axis", "edge"])
def test_the_modes_static_response_is_opensees_static_analysis(built, y_load):
    model, _ = built
    deck = read_modes(EXAMPLES / "girders-modes.npz")
    force = -100e3
    reference = girders.static_deflections(ops, model, MID, y_load, force, AT_GIRDERS)
    modal = force * _flexibility(deck, AT_GIRDERS, MID, y_load)
    assert np.max(np.abs(modal - reference)) <= STATIC_PEAK * np.max(np.abs(reference)), (modal, reference)
    assert abs(modal.sum() - reference.sum()) <= STATIC_SUM * abs(reference.sum())
    # the girder nearest the load deflects most, and the share falls away from it
    nearest = int(np.argmin(np.abs(np.array(girders.GIRDERS_Y) - y_load)))
    assert int(np.argmin(reference)) == nearest


#: 60 s of the example's SUMO traffic (about a dozen vehicles, both directions). Reference: the quasi-static
#: response to the same axles, each at its logged position with its logged contact force, through the static
#: flexibility the test above checks against OpenSees (0.5 %). What remains is the deck's own dynamics
#: (inertia and damping: a 2.5 Hz deck under vehicles at up to 22 m/s, speed parameter v / (2 f1 L) = 0.11,
#: and a class A road), measured: each girder's peak 0.98 to 1.013 of the quasi-static one, the largest
#: difference at any logged time 9 to 13 % of the girder's peak. Tolerances: 0.9 to 1.15 and 20 %. An axle on
#: the wrong side of the axis (a lane's y with the wrong sign) gives differences of about 55 % of the peak.
PEAK_RATIO, HISTORY = (0.9, 1.15), 0.2


def test_two_way_sumo_traffic_on_the_girders_is_its_quasi_static_response_plus_dynamics(tmp_path):
    result = testing.run(EXAMPLES / "girders.toml", traffic={"end": 60.0}, log=tmp_path / "run.mcap")
    deck = read_modes(EXAMPLES / "girders-modes.npz")
    names = ["g1", "g2", "g3", "g4", "g5"]
    at = np.stack([deck.rows(np.array([MID]), np.array([y]))[0, 0] for y in girders.GIRDERS_Y])  # (5, m)
    index = {round(t * 1000): k for k, t in enumerate(result.t)}  # logged times, ms
    static = np.zeros((len(result.t), len(names)))
    lanes = set()
    for vid in result.vehicle_ids:
        v = result.vehicle(vid)
        on = (v["x"] >= 0.0) & (v["x"] <= girders.SPAN)
        rows = deck.rows(v["x"][on], v["y"][on])[:, 0, :]
        steps = [index[round(t * 1000)] for t in v["t"][on]]
        static[steps] -= v["contact_force"][on, None] * ((rows / deck.omega**2) @ at.T)  # compression down
        lanes.add(float(np.sign(np.median(v["y"]))))
    assert lanes == {-1.0, 1.0}  # both directions crossed
    for k, name in enumerate(names):
        dynamic = result[name]
        assert PEAK_RATIO[0] <= dynamic.min() / static[:, k].min() <= PEAK_RATIO[1], name
        assert np.max(np.abs(dynamic - static[:, k])) <= HISTORY * np.max(np.abs(dynamic)), name
