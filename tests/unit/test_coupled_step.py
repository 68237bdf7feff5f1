"""The compiled coupled step against an independent monolithic solution, the vehicle registry, and the
Python API's input checks.

Reference for the step: a vehicle standing still on the deck makes a linear
system with constant matrices (the bridge's modes plus the vehicle's own
DOFs), which any Newmark/HHT implementation integrates directly. The one
below assembles it whole and solves it monolithically, step by step, with
numpy: nothing of cosim's condensation or Woodbury update is shared.
"""
from __future__ import annotations

import numpy as np
import pytest

from cosim.core import kernels
from cosim.core.bases import DirectBasis, make_basis
from cosim.core.bridge import ExplicitDamping, build_bridge
from cosim.core.coupling import CoupledSystem
from cosim.core.roughness import RoadProfile
from cosim.core.schemes import Scheme
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle, TrafficBlock
from cosim.core.vehicles import MODELS, MovingForce, QuarterCar, TyreQuarterCar
from cosim.errors import ConfigError

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=-0.4,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))
GRAVITY = 9.81
TOL_MONOLITHIC = 1e-9  # of the peak: the same linear system solved two ways, round-off only


def _bridge():
    return build_bridge(spans=[30.0], elements_per_span=12, material=MAT, section=SEC,
                        supports=["pinned", "fork"], damping=ExplicitDamping(alpha=0.3, beta=1e-3))


def _monolithic(bridge, basis, model: TyreQuarterCar, x: float, y: float, scheme: Scheme, dt: float, steps: int):
    """Deck deflection under the wheel and tyre force of a tyre quarter-car parked at (x, y), by a monolithic
    HHT/Newmark integration of [modal coordinates, body, wheel] (Hilber, Hughes & Taylor 1977)."""
    m = basis.n
    row = bridge.deck_point_row(x, y)
    n0 = basis.reduce_rows(row.dofs[None, :], row.values[:1])[0]  # deck w at the wheel, per mode
    size = m + 2
    M = np.zeros((size, size))
    C = np.zeros((size, size))
    K = np.zeros((size, size))
    M[:m, :m] = np.eye(m)
    C[:m, :m] = np.diag(basis.c_diag)
    K[:m, :m] = np.diag(basis.k_diag)
    b, w = m, m + 1
    M[b, b], M[w, w] = model.m_v, model.m_w
    for mat, k_v, k_t in ((K, model.k_v, model.k_t), (C, model.c_v, model.c_t)):
        # Suspension between body and wheel; tyre between wheel and deck point (stretch u_w - n0 q).
        mat[b, b] += k_v
        mat[b, w] -= k_v
        mat[w, b] -= k_v
        mat[w, w] += k_v + k_t
        mat[w, :m] -= k_t * n0
        mat[:m, w] -= k_t * n0
        mat[:m, :m] += k_t * np.outer(n0, n0)
    f = np.zeros(size)
    f[:m] = -model.total_mass * GRAVITY * n0  # displacements from the vehicle's equilibrium on a rigid road
    al, be, ga = scheme.alpha, scheme.beta, scheme.gamma
    # The vehicle arrives at t = 0+: at rest, no load before (f_0 = 0), no acceleration yet.
    d, v, a, f_prev = np.zeros(size), np.zeros(size), np.zeros(size), np.zeros(size)
    A = M + (1 + al) * (ga * dt * C + be * dt * dt * K)
    deflection, tyre = [], []
    for _ in range(steps):
        d_star = d + dt * v + (0.5 - be) * dt * dt * a
        v_star = v + (1 - ga) * dt * a
        rhs = (1 + al) * f - al * f_prev - (1 + al) * (C @ v_star + K @ d_star) + al * (C @ v + K @ d)
        f_prev = f
        a = np.linalg.solve(A, rhs)
        d, v = d_star + be * dt * dt * a, v_star + ga * dt * a
        deflection.append(n0 @ d[:m])
        tyre.append(model.total_mass * GRAVITY - (model.k_t * (d[w] - n0 @ d[:m]) + model.c_t * (v[w] - n0 @ v[:m])))
    return np.array(deflection), np.array(tyre)


@pytest.mark.parametrize("scheme", [Scheme.newmark(), Scheme.hht(-0.3)], ids=["newmark", "hht-0.3"])
def test_a_parked_tyre_quarter_car_matches_a_monolithic_integration(scheme):
    bridge = _bridge()
    dt, steps = 2e-3, 600
    basis = make_basis(bridge, dt, scheme, "modal", n_modes=12)
    car = TyreQuarterCar(m_v=8000.0, m_w=800.0, k_v=4e5, c_v=2e4, k_t=3e6, c_t=3e3)
    x, y = 11.0, 2.5  # eccentric: bending and twist
    sensor = Sensor("wheel", x, y)
    system = CoupledSystem(bridge, basis, scheme, dt, gravity=GRAVITY, sensors=(sensor,))
    block = TrafficBlock(("car",), (car,), np.full((steps, 1), x), np.zeros((steps, 1)), np.zeros((steps, 1)),
                         np.array([y]))
    report = system.advance(block)
    ref_w, ref_tyre = _monolithic(bridge, basis, car, x, y, scheme, dt, steps)
    assert np.max(np.abs(report.sensors[:, 0] - ref_w)) <= TOL_MONOLITHIC * np.max(np.abs(ref_w))
    assert np.max(np.abs(report.contact_force[:, 0] - ref_tyre)) <= TOL_MONOLITHIC * np.max(np.abs(ref_tyre))


# ------------------------------------------------------------------ registry


def _parked(model, x: float, steps: int, ids: str = "v") -> TrafficBlock:
    """A vehicle standing with its front contact at x (m): one column per axle, the axles behind it."""
    offsets = model.contact_offsets
    names = tuple(f"{ids}#{k}" for k in range(len(offsets))) if len(offsets) > 1 else (ids,)
    xs = np.array([[x - off for off in offsets]] * steps)
    return TrafficBlock(names, (model,) * len(offsets), xs, np.zeros_like(xs), np.zeros_like(xs),
                        np.zeros(len(offsets)))


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_registered_model_runs_through_the_compiled_step(name):
    """A vehicle parked on the deck settles to its static loads as contact forces (statics), whatever its model."""
    model = MODELS[name].example
    bridge = _bridge()
    dt, steps = 5e-3, 4000
    scheme = Scheme.newmark()
    system = CoupledSystem(bridge, make_basis(bridge, dt, scheme), scheme, dt, gravity=GRAVITY)
    report = system.advance(_parked(model, 15.0, steps))
    loads = model.static_axle_loads(GRAVITY)
    # Statics: the settled contact forces are the static axle loads (damped transients decay within 20 s);
    # they add up to the weight.
    np.testing.assert_allclose(report.contact_force[-1], loads, rtol=1e-6)
    assert loads.sum() == pytest.approx(model.total_mass * GRAVITY, rel=1e-12)
    assert report.on_deck.all() and not report.lifted.any()


def test_a_vehicle_off_the_deck_loads_nothing():
    bridge = _bridge()
    dt = 5e-3
    scheme = Scheme.newmark()
    system = CoupledSystem(bridge, make_basis(bridge, dt, scheme), scheme, dt, sensors=(Sensor("mid", 15.0),))
    x = np.array([[-0.5], [bridge.length + 0.5]])  # before and after the deck
    block = TrafficBlock(("v",), (MovingForce(9000.0),), x, np.full((2, 1), 10.0), np.zeros((2, 1)), np.zeros(1))
    report = system.advance(block)
    assert not report.on_deck.any()
    assert np.all(report.contact_force == 0.0) and np.all(report.sensors == 0.0)


def test_a_wheel_beside_the_deck_surface_loads_nothing_and_is_counted_once_per_excursion():
    # Deck surface y = -6.6 to 6.6 m. A moving force on the deck's length beside it (y = 7 m) for steps 3-5 of 8,
    # on it otherwise: it loads nothing while beside (no contact force, no response at that step's start), and
    # the excursion is one event of three wheel-steps; a wheel beside it before the deck's start is not counted.
    bridge = _bridge()
    dt = 5e-3
    scheme = Scheme.newmark()
    system = CoupledSystem(bridge, make_basis(bridge, dt, scheme), scheme, dt, sensors=(Sensor("mid", 15.0),))
    force = MovingForce(9000.0)
    x = np.full((1, 2), 10.0)
    on, beside, before = (TrafficBlock(("w", "u"), (force, force), x + np.array([[0.0, -15.0]]), np.zeros((1, 2)),
                                       np.zeros((1, 2)), np.array([y, 7.0])) for y in (0.0, 7.0, 7.0))
    reports = [system.advance(b) for b in (on, on, beside, beside, beside, on, on)]
    assert [bool(r.on_deck[0, 0]) for r in reports] == [True, True, False, False, False, True, True]
    assert [bool(r.off_surface[0, 0]) for r in reports] == [False, False, True, True, True, False, False]
    assert all(r.contact_force[0, 0] == 0.0 for r in reports[2:5]) and reports[1].contact_force[0, 0] > 0.0
    assert not any(r.off_surface[0, 1] for r in reports)  # "u" is before the deck (x = -5 m): rigid ground
    assert (system.offdeck_events, system.offdeck_steps) == (1, 3)
    quiet = CoupledSystem(bridge, make_basis(bridge, dt, scheme), scheme, dt, sensors=(Sensor("mid", 15.0),))
    assert np.all(quiet.advance(before).sensors == 0.0)  # beside from the start: the bridge stays at rest


def test_the_basis_counts_its_factorisations_and_the_loop_its_solves():
    bridge = _bridge()
    dt, scheme = 5e-3, Scheme.newmark()
    basis = DirectBasis(bridge, dt, scheme, complete_modal=False)  # the banded engine only
    system = CoupledSystem(bridge, basis, scheme, dt)
    car = QuarterCar(m_v=8000.0, m_w=1000.0, k_v=4e5, c_v=4e4)
    for k in range(5):  # five blocks, vehicles on the deck in the last three
        q = 1 if k >= 2 else 0
        x = np.full((100, q), 10.0)
        system.advance(TrafficBlock(("c",) * q, (car,) * q, x, 0 * x, 0 * x, np.zeros(q)))
    assert basis.n_factorizations == 1
    # Direct basis: one banded solve per step, a second for the Woodbury correction with vehicles on the deck.
    assert basis.n_solves == 200 * 1 + 300 * 2
    assert make_basis(bridge, dt, scheme, "modal", n_modes=5).n_factorizations == 1


# ------------------------------------------------------- the API's checks


def _traffic(length: float, y: float = 0.0) -> ScriptedTraffic:
    return ScriptedTraffic((ScriptedVehicle("truck", MovingForce(3e4), y, 20.0),), length)


def test_simulate_rejects_traffic_made_for_another_bridge():
    with pytest.raises(ConfigError, match=r"traffic was made for a bridge 40 m long, this one is 30 m"):
        simulate(_bridge(), _traffic(40.0), 1.0)


def test_simulate_rejects_a_wheel_path_off_the_deck_naming_the_vehicle():
    with pytest.raises(ConfigError, match=r"vehicle truck: its wheel path y = 9 m lies off the deck"):
        simulate(_bridge(), _traffic(30.0, y=9.0), 1.0)


def test_simulate_rejects_sensors_off_the_deck_and_duplicate_names():
    with pytest.raises(ConfigError, match=r"sensor far: `x` must lie on the bridge"):
        simulate(_bridge(), _traffic(30.0), 1.0, sensors=[Sensor("far", 31.0)])
    with pytest.raises(ConfigError, match=r"sensor edge: `y` must lie on the deck"):
        simulate(_bridge(), _traffic(30.0), 1.0, sensors=[Sensor("edge", 10.0, 7.0)])
    with pytest.raises(ConfigError, match="sensor names must be unique"):
        simulate(_bridge(), _traffic(30.0), 1.0, sensors=[Sensor("a", 10.0), Sensor("a", 12.0)])


def test_simulate_rejects_a_road_that_does_not_cover_the_deck():
    flat = np.zeros((1, 41))
    road = RoadProfile(path_y=(0.0,), x0=0.0, dx=0.5, r=flat, r_x=flat, description="a 20 m survey")
    with pytest.raises(ConfigError, match=r"must cover the deck, 0 <= x <= 30 m"):
        simulate(_bridge(), _traffic(30.0), 1.0, road=road)


@pytest.mark.parametrize("kwargs, key", [
    ({"dt": float("nan")}, "dt"), ({"dt": -1.0}, "dt"), ({"gravity": float("inf")}, "gravity"),
    ({"scheme": "euler"}, "scheme"), ({"basis": "fourier"}, "basis"), ({"modes": 0}, "modes"),
])
def test_solver_settings_reject_non_physical_values_naming_the_key(kwargs, key):
    with pytest.raises(ConfigError, match=f"`{key}`"):
        SolverSettings(**kwargs)


@pytest.mark.parametrize("field, value", [("y", float("nan")), ("speed", float("inf")), ("entry_time", "0")])
def test_scripted_vehicles_reject_non_finite_values_naming_the_key(field, value):
    args = {"id": "car", "model": MovingForce(1e3), "y": 0.0, "speed": 10.0, field: value}
    with pytest.raises(ConfigError, match=f"vehicle car: `{field}`"):
        ScriptedVehicle(**args)


def test_scripted_traffic_rejects_a_bad_length_and_a_non_model():
    with pytest.raises(ConfigError, match="`length` must be the bridge's length"):
        ScriptedTraffic((), float("nan"))
    with pytest.raises(ConfigError, match="vehicle car: `model` must be one of the vehicle models"):
        ScriptedVehicle("car", "quarter-car", 0.0, 10.0)


def test_a_basis_built_for_another_bridge_or_step_is_refused():
    bridge, other = _bridge(), _bridge()
    scheme = Scheme.newmark()
    with pytest.raises(ConfigError, match="another bridge model"):
        CoupledSystem(bridge, make_basis(other, 5e-3, scheme), scheme, 5e-3)
    with pytest.raises(ConfigError, match="built for dt = 0.005 s"):
        CoupledSystem(bridge, make_basis(bridge, 5e-3, scheme), scheme, 1e-3)


def test_the_direct_basis_engines_agree_and_switch_with_the_number_of_vehicles():
    """The complete modal engine and the banded one solve the same full FE problem (Rayleigh damping makes the
    Newmark/HHT operator diagonal in the modes): round-off agreement, 1e-9 of the peak (issue 12's bound)."""
    bridge = _bridge()
    dt, scheme = 2e-3, Scheme.hht(-0.1)
    car = QuarterCar(m_v=8000.0, m_w=1000.0, k_v=4e5, c_v=4e4)
    few = DirectBasis.COMPLETE_MODAL_MAX_VEHICLES
    sensors = (Sensor("mid", 15.0, 2.0), Sensor("acc", 9.0, -1.0, "acceleration"))
    outputs = {}
    for allowed in (True, False):
        basis = DirectBasis(bridge, dt, scheme, complete_modal=allowed)
        system = CoupledSystem(bridge, basis, scheme, dt, sensors=sensors)
        engines, records = [], []
        for q in (0, 2, few + 3, 1, 0):  # free vibration, few vehicles, many, few, none
            x = np.linspace(2.0, 28.0, q)[None, :] + 0.4 * np.arange(1, 301)[:, None] * dt * 10
            block = TrafficBlock(tuple(f"c{k}" for k in range(q)), (car,) * q, x, np.full_like(x, 4.0),
                                 np.zeros_like(x), np.linspace(-3.0, 3.0, q))
            records.append(system.advance(block).sensors)
            engines.append(system.engine)
        outputs[allowed] = np.concatenate(records)
        if allowed:
            assert engines == ["complete-modal", "complete-modal", "basis", "complete-modal", "complete-modal"]
        else:
            assert set(engines) == {"basis"}
    for k in range(len(sensors)):
        ref = outputs[False][:, k]
        assert np.max(np.abs(outputs[True][:, k] - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_overlapping_traffic_and_solver_gives_the_same_numbers():
    """simulate(overlap=True) computes the next traffic block while a worker advances the bridge: the blocks are
    still advanced in order, so the results are identical to the bit."""
    bridge = _bridge()
    cars = tuple(ScriptedVehicle(f"c{k}", QuarterCar(m_v=8000.0, m_w=900.0, k_v=4e5, c_v=3e4), 1.5 * (-1) ** k,
                                 15.0 + k, entry_time=0.3 * k) for k in range(4))
    traffic = ScriptedTraffic(cars, 30.0)
    sensors = [Sensor("mid", 15.0, 1.0), Sensor("acc", 10.0, -1.0, "acceleration")]
    runs = [simulate(bridge, traffic, 4.0, SolverSettings(dt=2e-3), sensors, block_steps=50, overlap=flag)
            for flag in (True, False)]
    for name in ("mid", "acc"):
        np.testing.assert_array_equal(runs[0].sensors[name], runs[1].sensors[name])
    np.testing.assert_array_equal(runs[0].vehicle_table["contact_force"], runs[1].vehicle_table["contact_force"])


@pytest.mark.parametrize("basis", ["direct", "modal"])
def test_a_sensor_read_every_nth_step_is_the_same_numbers_at_those_steps(basis):
    """Sensor(every=N) is read at the steps whose index is a multiple of N (NaN at the others), in both engines
    and across blocks; its values there are the dense sensor's bit for bit (the same row, the same state)."""
    bridge = _bridge()
    cars = tuple(ScriptedVehicle(f"c{k}", QuarterCar(m_v=8000.0, m_w=900.0, k_v=4e5, c_v=3e4), 1.5 * (-1) ** k,
                                 15.0 + k, entry_time=0.3 * k) for k in range(3))
    dense, sparse = Sensor("mid", 15.0, 1.0), Sensor("mid_every_7", 15.0, 1.0, every=7)
    acc = Sensor("acc_every_7", 10.0, -1.0, "acceleration", every=7)
    solver = SolverSettings(dt=2e-3, basis=basis, modes=20 if basis == "modal" else None)
    run = simulate(bridge, ScriptedTraffic(cars, 30.0), 3.0, solver,
                   [dense, sparse, acc, Sensor("acc", 10.0, -1.0, "acceleration")], block_steps=50)
    steps = np.rint(run.t / 2e-3).astype(int)
    read = steps % 7 == 0
    assert read.sum() == 1500 // 7 + 1 and np.all(np.isnan(run.sensors["mid_every_7"][~read]))
    np.testing.assert_array_equal(run.sensors["mid_every_7"][read], run.sensors["mid"][read])
    np.testing.assert_array_equal(run.sensors["acc_every_7"][read], run.sensors["acc"][read])
    # The extremes count only the steps read: those of the dense sensor at the same steps.
    assert run.sensor_min["mid_every_7"] == np.min(run.sensors["mid"][read])
    assert run.sensor_max["acc_every_7"] == max(np.max(run.sensors["acc"][read]), 0.0)
    with pytest.raises(ConfigError, match="sensor s: `every` must be an integer >= 1"):
        Sensor("s", 1.0, every=0)


@pytest.mark.parametrize("basis_name", ["modal", "complete"])
def test_modal_contact_rows_from_the_element_cubics_equal_the_projection_of_the_deck_dofs(basis_name):
    """kernels.project_contacts evaluates each mode's cubics on the element (modal_polynomials); the reference
    is the definition: the physical row's values at the element's deck DOFs times the mode shapes there."""
    bridge = _bridge()
    basis = make_basis(bridge, 2e-3, Scheme.newmark(), "modal" if basis_name == "modal" else "direct",
                       20 if basis_name == "modal" else None, None)
    system = CoupledSystem(bridge, basis, Scheme.newmark(), 2e-3)
    arrays = system._engines["basis" if basis_name == "modal" else "complete-modal"][0]
    deck = system._deck
    rng = np.random.default_rng(7)
    x = np.concatenate([rng.uniform(0.0, 30.0, 9), bridge.nodes_x[[0, 5, 12]], [-1.0]])  # nodes, and off the deck
    y = rng.uniform(-2.0, 2.0, len(x))
    q, n = len(x), arrays.n
    elems, vals, geo = np.zeros(q, dtype=np.int64), np.zeros((q, 3, 14)), np.zeros((q, 3))
    kernels.contact_rows(x, y, np.ones(q), deck, elems, vals, geo)
    idx, rv = np.zeros((q, n), dtype=np.int64), np.zeros((q, 3, n))
    nd = len(deck.dofs)
    pidx, prv = np.zeros((q, nd), dtype=np.int64), np.zeros((q, 3, nd))
    kernels.project_contacts(arrays, deck, elems, vals, geo, idx, rv, pidx, prv)
    for i in range(q):
        expected = np.zeros((3, n))
        if elems[i] >= 0:
            dofs = deck.node_dofs * elems[i] + deck.dofs
            expected = vals[i][:, deck.dofs] @ arrays.phi[dofs]
        scale = np.max(np.abs(expected)) or 1.0
        assert np.max(np.abs(rv[i] - expected)) <= 1e-12 * scale, i  # round-off of a reordered sum
    assert elems[-1] == -1 and not rv[-1].any()


def test_the_capacitance_solve_matches_lapack():
    """kernels.solve_small (Gaussian elimination, partial pivoting) against numpy.linalg.solve (LAPACK gesv)."""
    rng = np.random.default_rng(11)
    for q in (1, 2, 3, 8, 17):
        for _ in range(20):
            S = np.eye(q) + rng.normal(size=(q, q)) * rng.choice([0.1, 1.0, 10.0])
            S[rng.integers(q), :] *= 1e-3 if q > 1 else 1.0  # a small row: pivoting matters
            b = rng.normal(size=q)
            expected = np.linalg.solve(S, b)
            got = b.copy()
            kernels.solve_small(S.copy(), got)
            cond = np.linalg.cond(S)
            assert np.max(np.abs(got - expected)) <= 1e-13 * cond * np.max(np.abs(expected)), (q, cond)
