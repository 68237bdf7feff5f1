"""Vehicle-bridge interaction against closed forms, symmetry and counters (docs/theory.md §8).

Fryba's moving force (direct basis), the sprung mass, the paper case, time-step
convergence, energy conservation and the parked vehicle are validation cases
(``cosim validate``), judged in ``test_cases.py``. Each test here names its
reference and states its tolerance.
"""
from __future__ import annotations

import numpy as np
from _beams import STEEL, rectangle

from cosim.core.bases import DirectBasis
from cosim.core.bridge import build_bridge
from cosim.core.coupling import CoupledSystem
from cosim.core.schemes import Scheme
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import QuarterCar, TyreQuarterCar
from cosim.validation.cases import TOL_FRYBA, fryba_moving_force

NO_TWIST_ABS = 1e-15  # m: symmetric vehicles on a symmetric deck (round-off)
MIRROR_REL = 1e-12  # of the peak: a mirrored crossing (round-off)
STIFF_TYRE_DEFLECTION = 0.01  # of the peak: k_t = 1e10 N/m against rigid contact
STIFF_TYRE_ACCELERATION = 0.02  # of the peak


def _euler_bernoulli_bridge(L=20.0, n_el=40):
    sec = rectangle(0.5, 1.0, shear_factor=1e6)  # no shear flexibility: the Euler-Bernoulli references apply
    return build_bridge([L], n_el, STEEL, sec, ["pinned", "fork"]), sec


def test_moving_force_in_the_modal_basis_matches_frybas_series():
    """The validation case "Moving force (Fryba)" uses the direct basis; the same case in a 20-mode basis."""
    result = fryba_moving_force(steps=2000, basis="modal", modes=20)
    for case in result.cases:
        # Fryba (1972) modal series, 80 terms; tolerance 1 % of the peak (TOL_FRYBA), as the direct basis.
        assert case.error <= case.tolerance == TOL_FRYBA, (case.name, case.error)


def _twist_history(vehicles):
    bridge = build_bridge([20.0], 10, STEEL, rectangle(6.0, 1.0), ["rigid-end", "rigid-end"])
    sensors = [Sensor("left", 10.0, 2.5), Sensor("right", 10.0, -2.5)]
    res = simulate(bridge, ScriptedTraffic(tuple(vehicles), 20.0), 1.5, SolverSettings(dt=0.005), sensors)
    return res.sensors["left"] - res.sensors["right"]  # 5 m x twist


def test_symmetric_vehicles_do_not_twist_and_one_eccentric_vehicle_twists_negatively():
    car = QuarterCar(m_v=1e4, m_w=1e3, k_v=4e5, c_v=2e4)
    pair = [ScriptedVehicle("L", car, 2.0, 15.0), ScriptedVehicle("R", car, -2.0, 15.0)]
    # Symmetry of deck and loads (docs/theory.md §1.4 sign convention): no twist, to round-off (1e-15 m).
    assert np.max(np.abs(_twist_history(pair))) < NO_TWIST_ABS
    alone = _twist_history([ScriptedVehicle("L", car, 2.0, 15.0)])
    # Left side goes down: negative twist (after it leaves, the deck rings with tiny amplitude).
    assert alone.min() < -1e-6 and alone.max() < 1e-3 * abs(alone.min())


def test_opposite_directions_mirror_each_other():
    car = QuarterCar(m_v=1e4, m_w=1e3, k_v=4e5, c_v=2e4)
    # 15 m/s: contact points land on nodes (x = 6, 12, 18 m), where the curvature of the cubic elements
    # jumps; a point on a node takes the element ahead of it, so both directions see mirrored rows.
    forward = _twist_history([ScriptedVehicle("A", car, 2.0, 15.0, direction=1)])
    backward = _twist_history([ScriptedVehicle("A", car, 2.0, 15.0, direction=-1)])
    # A rigid-end, uniform beam is symmetric about mid-span: the mid-span twist histories coincide (1e-12 of the peak).
    np.testing.assert_allclose(backward, forward, rtol=0, atol=MIRROR_REL * np.max(np.abs(forward)))


def test_stiff_tyre_quarter_car_approaches_the_rigid_contact_model():
    bridge, _ = _euler_bernoulli_bridge()
    rigid = QuarterCar(m_v=1e4, m_w=1e3, k_v=4e5, c_v=2e4)
    tyre = TyreQuarterCar(m_v=1e4, m_w=1e3, k_v=4e5, c_v=2e4, k_t=1e10, c_t=0.0)
    out = []
    for model in (rigid, tyre):
        tr = ScriptedTraffic((ScriptedVehicle("V", model, 0.0, 20.0),), 20.0)
        res = simulate(bridge, tr, 1.0, SolverSettings(dt=0.001), [Sensor("mid", 10.0)])
        out.append((res.sensors["mid"], res.vehicle("V")["body_acceleration"]))
    # A tyre of 1e10 N/m is rigid contact in the limit (docs/theory.md §5.6); 1 % / 2 % of the peaks.
    np.testing.assert_allclose(out[1][0], out[0][0], atol=STIFF_TYRE_DEFLECTION * np.max(np.abs(out[0][0])))
    np.testing.assert_allclose(out[1][1], out[0][1], atol=STIFF_TYRE_ACCELERATION * np.max(np.abs(out[0][1])))


def test_effective_matrix_is_factorised_once_and_solved_twice_per_step():
    bridge, _ = _euler_bernoulli_bridge()
    cars = tuple(ScriptedVehicle(f"C{i}", QuarterCar(1e4, 1e3, 4e5, 2e4), 0.0, 20.0, entry_time=0.1 * i)
                 for i in range(5))
    basis = DirectBasis(bridge, 0.002, Scheme.newmark(), complete_modal=False)  # the banded engine's counts
    system = CoupledSystem(bridge, basis, Scheme.newmark(), 0.002)
    traffic = ScriptedTraffic(cars, 20.0)
    for k in range(1, 501):
        system.step(traffic.frame(k * 0.002))
    # The Woodbury step of cosim.core.coupling: exact counts (scipy OdeSolver-style counters).
    assert basis.n_factorizations == 1
    # Two banded solves per step (the loads, the Woodbury correction), whatever the vehicle count.
    assert basis.n_solves == 2 * 500
