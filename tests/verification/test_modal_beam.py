"""The beam's own modes through the modal route (cosim.bridges.from_beam, docs/modal-decks.md): the deck they
make gives, at any contact point, exactly the beam's contact rows projected on its modes (docs/theory.md §13.3),
the frequencies and damping of the beam's modal basis, and survives a modes file bit for bit. This is the
exactness the modal deck's run needs to reproduce the beam's modal-basis run to 1e-9."""
from __future__ import annotations

import numpy as np
import pytest

from cosim.bridges import from_beam, read_modes, write_modes
from cosim.core.bases import ModalBasis
from cosim.core.bridge import RayleighDamping, build_bridge
from cosim.core.element import BeamTheory
from cosim.core.schemes import Scheme
from cosim.core.section import Material, section_from_constants
from cosim.core.sensors import Sensor, sensor_row
from cosim.run.scenario import parse_scenario

#: What "exact" means here: the largest difference over the points, relative to the largest |row| of that mode
#: and derivative (measured: 3e-15, 3e-15, 4e-14 for w, w_x, w_xx; the same numbers summed in another order).
EXACT = 1e-9

THEORIES = {
    "timoshenko-vlasov": BeamTheory(),
    "euler-bernoulli-vlasov": BeamTheory(bending="euler-bernoulli"),
    "euler-bernoulli-benscoter": BeamTheory(torsion="benscoter", bending="euler-bernoulli"),
}


def two_span_bridge(theory: BeamTheory):
    """A continuous two-span deck (18 m + 24 m) whose shear centre is off the deck's middle and below it
    (bending and twist couple at every contact), with shear areas (Timoshenko slopes jump between elements)
    and warping."""
    section = section_from_constants(A=5.0, I_y=2.5, I_z=40.0, J=1.2, I_w=0.8, I_ws=0.4, y_s=0.4, z_s=-0.9,
                                     z_c=-0.5, A_sy=2.0, A_sz=1.1, deck_y=(-5.5, 4.5))
    return build_bridge([18.0, 24.0], [9, 12], Material(E=35e9, G=35e9 / 2.4, rho=2500.0), section,
                        ["fork", "pinned", "fork"], damping=RayleighDamping((0.02, 0.03), (1, 4)), theory=theory)


def beam_rows(bridge, modes, x, y):
    """The beam's contact rows (w, w_x, w_xx) of every mode at (x, y): docs/theory.md (5.1)-(5.2) on the modes."""
    dofs, values = bridge.deck_rows(x, y)
    return np.einsum("qok,qkm->qom", values, modes[dofs])


@pytest.mark.parametrize("name", list(THEORIES), ids=list(THEORIES))
def test_the_beams_modes_give_the_beams_contact_rows_anywhere_on_the_deck(name):
    bridge = two_span_bridge(THEORIES[name])
    deck = from_beam(bridge, n_modes=25, lateral=4)
    basis = ModalBasis(bridge, 0.005, Scheme.newmark(), n_modes=25)
    rng = np.random.default_rng(5)
    x = np.concatenate([bridge.nodes_x, rng.uniform(0, bridge.length, 400), [bridge.length]])
    y = np.concatenate([np.full(len(bridge.nodes_x), 4.5), rng.uniform(-5.5, 4.5, 401)])
    got = deck.rows(x, y)
    expected = beam_rows(bridge, basis.phi_full, x, y)
    scale = np.max(np.abs(expected), axis=0)  # (3, m)
    error = np.max(np.abs(got - expected), axis=0) / scale
    assert np.all(error <= EXACT), error.max(axis=1)
    # the same modes, frequencies and damping as the beam's modal basis
    assert np.allclose(deck.omega, basis.omega, rtol=1e-14, atol=0)
    assert deck.zeta is not None and np.allclose(2 * deck.zeta * deck.omega, basis.c_diag, rtol=1e-12, atol=0)
    assert deck.modal_mass is not None and np.all(deck.modal_mass == 1.0)
    # the slopes jump between elements where a shear strain does (Timoshenko bending, Benscoter torsion's
    # twist), not where the slope is a field's derivative (Euler-Bernoulli bending with Vlasov torsion)
    theory = THEORIES[name]
    assert (deck.phi_x_minus is not None) == (theory.bending == "timoshenko" or theory.torsion == "benscoter")
    assert deck.covers([0.0, bridge.length, 10.0, 10.0], [-5.5, 4.5, 4.5 + 1e-6, -5.6]).tolist() == [
        True, True, False, False]


def test_the_beam_round_trips_through_a_modes_file_bit_for_bit(tmp_path):
    bridge = two_span_bridge(BeamTheory())
    deck = from_beam(bridge, n_modes=8)
    x, y = np.linspace(0, bridge.length, 97), np.linspace(-5.5, 4.5, 97)
    for path in (tmp_path / "beam.npz", tmp_path / "beam_csv"):
        back = read_modes(write_modes(path, deck))
        assert np.array_equal(back.rows(x, y), deck.rows(x, y)), path.name


SCENARIO = """\
name = "modal beam"
[bridge]
spans = [30.0]
elements_per_span = 15
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
x = 15.0
quantity = "bending_moment"
[[sensors]]
name = "edge"
x = 15.0
y = 5.0
[solver]
dt = 0.01
duration = 1.0
basis = "modal"
{truncation}
"""


def test_a_scenario_brings_its_modal_basis_and_its_moment_sensors():
    """from_beam(scenario): the modes its modal-basis run uses (``modes`` or ``cutoff_hz``), and the modal
    values of its bending-moment sensor (which the shapes alone cannot give)."""
    scenario = parse_scenario(SCENARIO.format(truncation="modes = 12"), "modal-beam.toml")
    deck = from_beam(scenario)
    bridge = scenario.build_bridge()
    assert deck.n_modes == 12 and deck.source == "from_beam(modal-beam.toml)"
    sensor = Sensor("mid", 15.0, 0.0, "bending_moment")
    row = sensor_row(bridge, sensor)
    expected = row.values[0] @ bridge.modes(12).shapes[row.dofs]
    assert np.array_equal(deck.quantities["bending_moment:mid"], expected)
    assert list(deck.quantities) == ["bending_moment:mid"]  # the displacement sensor reads the shapes
    assert np.array_equal(deck.sensor_row(sensor), expected)
    cut = from_beam(parse_scenario(SCENARIO.format(truncation="cutoff_hz = 20.0"), "cut.toml"))
    basis = ModalBasis(bridge, 0.01, Scheme.newmark(), cutoff_hz=20.0)
    assert cut.n_modes == basis.n and np.allclose(cut.omega, basis.omega, rtol=1e-14, atol=0)


# ------------------------------------------------------------------------------------------ whole runs
#: The deck's rows equal the beam's to round-off (above), so whole runs do too; measured: 3e-15 of the peak.
RUN_EXACT = 1e-9


def _fleet():
    """Every kind of vehicle on both directions, off-centre (bending and twist), one of them unilateral on a
    rough road (it leaves the deck and lands again)."""
    from cosim.core.traffic import ScriptedVehicle
    from cosim.core.vehicles import Axle, HalfCar, MovingForce, QuarterCar, TyreQuarterCar
    half = HalfCar(m_b=16000.0, i_b=6e4, cg=2.2, axles=(Axle(0.0, 700.0, 6e5, 3e4, 2.5e6, 2e3),
                                                       Axle(4.0, 1100.0, 9e5, 5e4, 4e6, 3e3)))
    return (
        ScriptedVehicle("qc", QuarterCar(m_v=12000.0, m_w=800.0, k_v=5e5, c_v=1e4), 2.0, 18.0),
        ScriptedVehicle("tyre", TyreQuarterCar(m_v=9000.0, m_w=900.0, k_v=4e5, c_v=8e3, k_t=3e6, c_t=2e3),
                        -1.0, 25.0, entry_time=0.3),
        ScriptedVehicle("bouncer", TyreQuarterCar(m_v=400.0, m_w=60.0, k_v=3e4, c_v=1e3, k_t=4e5,
                                                  unilateral=True), -3.0, 30.0),
        ScriptedVehicle("half", half, 3.5, 15.0, entry_time=0.5, direction=-1),
        ScriptedVehicle("force", MovingForce(mass=20000.0), 2.0, 22.0, entry_time=1.0, direction=-1),
    )


@pytest.mark.parametrize("name", ["timoshenko-vlasov", "euler-bernoulli-benscoter"])
def test_the_beams_modes_imported_reproduce_the_beams_modal_run(name):
    """A deck given by the beam's own modes (from_beam) runs the same vehicles to the same numbers as the beam
    on its modal basis (issue 26, item 5): every sensor, contact force and body motion to 1e-9 of the peak."""
    from cosim.core.modal_bridge import ModalBridge
    from cosim.core.roughness import iso8608_profile
    from cosim.core.simulation import SolverSettings, simulate
    from cosim.core.traffic import ScriptedTraffic

    bridge = two_span_bridge(THEORIES[name])
    n_modes = 20
    sensors = [Sensor("mid-1", 9.0, 4.5), Sensor("mid-2", 30.0, -5.5, "acceleration"),
               Sensor("mid-2v", 30.0, 0.0, "velocity")]
    road = iso8608_profile("E", 7, 0.0, bridge.length, path_y=(-3.0, -1.0, 2.0, 3.5))
    settings = SolverSettings(dt=0.002, basis="modal", modes=n_modes)
    traffic = ScriptedTraffic(_fleet(), bridge.length)
    beam = simulate(bridge, traffic, 3.5, settings, sensors, road=road)
    deck = ModalBridge(from_beam(bridge, n_modes=n_modes, lateral=3))
    modal = simulate(deck, ScriptedTraffic(_fleet(), deck.length), 3.5, settings, sensors, road=road)
    for s in sensors:
        ref = beam.sensors[s.name]
        assert np.max(np.abs(modal.sensors[s.name] - ref)) <= RUN_EXACT * np.max(np.abs(ref)), s.name
    assert modal.vehicle_ids == beam.vehicle_ids
    for vid in beam.vehicle_ids:
        for column in ("contact_force", "body_displacement", "body_acceleration"):
            ref = beam.vehicle(vid)[column]
            got = modal.vehicle(vid)[column]
            assert got.shape == ref.shape and np.max(np.abs(got - ref)) <= RUN_EXACT * np.max(np.abs(ref)), (vid,
                                                                                                            column)
    assert beam.liftoff_events > 0 and modal.liftoff_events == beam.liftoff_events
