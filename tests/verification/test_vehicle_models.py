"""Axle groups (the half-car on several axles) and unilateral tyre contact, against independent solutions.

- A half-car parked on the deck: the compiled step against a monolithic Newmark/HHT integration of
  [modes, body bounce and pitch, wheels] with constant matrices (round-off, 1e-9 of the peak).
- A half-car on one axle without pitch is the tyre quarter-car: the generic path against the dedicated one.
- On a rigid road (the approach, off the deck) over a bump: the half-car and the unilateral tyre
  quarter-car against scipy's solve_ivp (DOP853, tight tolerances; events at every contact change).
- Parked on the deck, the half-car's settled deflection is the static solution under its axle loads.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cosim.core.bases import make_basis
from cosim.core.bridge import ExplicitDamping, build_bridge
from cosim.core.coupling import CoupledSystem
from cosim.core.roughness import RoadProfile
from cosim.core.schemes import Scheme
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle, TrafficBlock
from cosim.core.vehicles import Axle, HalfCar, TyreQuarterCar

MAT = Material(E=33e9, G=13.75e9, rho=2500.0)
SEC = SectionProperties(A=4.8, y_c=0.0, z_c=0.0, I_y=1.6, I_z=60.0, I_yz=0.0, y_s=0.0, z_s=-0.4,
                        J=0.15, I_w=19.0, A_sy=2.5, A_sz=0.9, deck_y=(-6.6, 6.6))
G = 9.81
TRUCK = HalfCar(m_b=16000.0, i_b=6e4, cg=2.2, axles=(Axle(0.0, 700.0, 6e5, 3e4, 2.5e6, 2e3),
                                                   Axle(4.0, 1100.0, 9e5, 5e4, 4e6, 3e3),
                                                   Axle(5.3, 1100.0, 9e5, 5e4, 4e6, 3e3)))
TOL_MONOLITHIC = 1e-9  # of the peak: one linear system solved two ways (round-off)
TOL_ODE = 2e-3  # of the peak: Newmark at dt = 1 ms against DOP853 (second order; tyre modes ~10 Hz)
TOL_FLIGHT = 2e-3  # of the peak: contact states switch at step ends (first order at the switches; dt = 0.2 ms)


def _bridge():
    return build_bridge(spans=[30.0], elements_per_span=12, material=MAT, section=SEC,
                        supports=["pinned", "fork"], damping=ExplicitDamping(alpha=0.3, beta=1e-3))


def _rigid_deck():
    """A 60 m deck a million times stiffer than concrete: a rigid road whose contact forces are recorded."""
    stiff = Material(E=33e15, G=13.75e15, rho=2500.0)
    return build_bridge(spans=[60.0], elements_per_span=12, material=stiff, section=SEC, supports=["pinned", "fork"])


def _parked_block(model, x_front: float, y: float, steps: int) -> TrafficBlock:
    offsets = model.contact_offsets
    ids = tuple(f"t#{k}" for k in range(len(offsets)))
    xs = np.array([[x_front - d for d in offsets]] * steps)
    return TrafficBlock(ids, (model,) * len(offsets), xs, np.zeros_like(xs), np.zeros_like(xs),
                        np.full(len(offsets), y))


@pytest.mark.parametrize("scheme", [Scheme.newmark(), Scheme.hht(-0.2)], ids=["newmark", "hht-0.2"])
def test_a_parked_half_car_matches_a_monolithic_integration(scheme):
    """[modes, vehicle DOFs] with the tyres between wheels and deck points: constant matrices, integrated whole
    (Hilber, Hughes & Taylor 1977); the vehicle arrives at rest at t = 0+, as in the block loop."""
    bridge = _bridge()
    dt, steps, x_front, y = 2e-3, 500, 18.0, 2.0
    basis = make_basis(bridge, dt, scheme, "modal", n_modes=12)
    sensor = Sensor("deck", 12.0, y)
    system = CoupledSystem(bridge, basis, scheme, dt, gravity=G, sensors=(sensor,))
    report = system.advance(_parked_block(TRUCK, x_front, y, steps))
    lin = TRUCK.linear_system(G)
    m, nz = basis.n, lin["mv"].shape[0]
    rows = np.array([basis.reduce_rows(r.dofs[None, :], r.values[:1])[0] for r in
                     (bridge.deck_point_row(x_front - d, y) for d in TRUCK.contact_offsets)])
    sens_row = basis.reduce_rows(*(lambda r: (r.dofs[None, :], r.values[:1]))(bridge.deck_point_row(12.0, y)))[0]
    size = m + nz
    M, C, K = np.zeros((size, size)), np.zeros((size, size)), np.zeros((size, size))
    M[:m, :m], C[:m, :m], K[:m, :m] = np.eye(m), np.diag(basis.c_diag), np.diag(basis.k_diag)
    M[m:, m:], C[m:, m:], K[m:, m:] = lin["mv"], lin["cv"], lin["kv"]
    for k in range(len(rows)):
        coupling = np.concatenate([-rows[k], lin["b"][k]])  # tyre stretch: wheel minus deck point
        K += lin["k_t"][k] * np.outer(coupling, coupling)
        C += lin["c_t"][k] * np.outer(coupling, coupling)
    f = np.zeros(size)
    f[:m] = -(lin["loads"] @ rows)  # the axle loads on the deck; the vehicle is in equilibrium on a rigid road
    al, be, ga = scheme.alpha, scheme.beta, scheme.gamma
    d, v, a, f_prev = np.zeros(size), np.zeros(size), np.zeros(size), np.zeros(size)
    A = M + (1 + al) * (ga * dt * C + be * dt * dt * K)
    deck, force = [], []
    for _ in range(steps):
        d_star, v_star = d + dt * v + (0.5 - be) * dt * dt * a, v + (1 - ga) * dt * a
        a = np.linalg.solve(A, (1 + al) * f - al * f_prev - (1 + al) * (C @ v_star + K @ d_star) + al * (C @ v + K @ d))
        f_prev = f
        d, v = d_star + be * dt * dt * a, v_star + ga * dt * a
        deck.append(sens_row @ d[:m])
        stretch = lin["b"] @ d[m:] - rows @ d[:m]
        stretch_rate = lin["b"] @ v[m:] - rows @ v[:m]
        force.append(lin["loads"] - (lin["k_t"] * stretch + lin["c_t"] * stretch_rate))
    deck, force = np.array(deck), np.array(force)
    assert np.max(np.abs(report.sensors[:, 0] - deck)) <= TOL_MONOLITHIC * np.max(np.abs(deck))
    assert np.max(np.abs(report.contact_force - force)) <= TOL_MONOLITHIC * np.max(np.abs(force))


def test_a_half_car_on_one_axle_without_pitch_is_the_tyre_quarter_car():
    """The generic linear-vehicle path against the tyre quarter-car's own compiled physics (same equations)."""
    bridge = _bridge()
    x = np.arange(1201) * 0.05 - 20.0
    bumps = 0.01 * np.sin(2 * np.pi * x / 3.0)
    slope = 0.01 * 2 * np.pi / 3.0 * np.cos(2 * np.pi * x / 3.0)
    road = RoadProfile((0.0,), -20.0, 0.05, bumps[None, :], slope[None, :], "sine")
    tyre_qc = TyreQuarterCar(m_v=9000.0, m_w=900.0, k_v=4e5, c_v=3e4, k_t=3e6, c_t=2e3)
    as_half_car = HalfCar(m_b=9000.0, i_b=0.0, cg=0.0, axles=(Axle(0.0, 900.0, 4e5, 3e4, 3e6, 2e3),), pitch=False)
    sensors = [Sensor("mid", 15.0, 1.0)]
    runs = [simulate(bridge, ScriptedTraffic((ScriptedVehicle("v", model, 1.0, 20.0),), 30.0), 2.0,
                     SolverSettings(dt=1e-3), sensors, road=road) for model in (tyre_qc, as_half_car)]
    ref, got = runs[0].sensors["mid"], runs[1].sensors["mid"]
    # Independent arithmetic, same mathematics: agreement to round-off accumulated over 2000 steps.
    assert np.max(np.abs(got - ref)) <= 1e-9 * np.max(np.abs(ref))
    np.testing.assert_allclose(runs[1].vehicle("v")["contact_force"], runs[0].vehicle("v")["contact_force"],
                               rtol=0, atol=1e-9 * runs[0].contact_force_range["v"][1])


def _bump(h: float, x0: float, length: float):
    def r(x):
        inside = (x >= x0) & (x <= x0 + length)
        return np.where(inside, 0.5 * h * (1 - np.cos(2 * np.pi * (x - x0) / length)), 0.0)

    def r_x(x):
        inside = (x >= x0) & (x <= x0 + length)
        return np.where(inside, 0.5 * h * 2 * np.pi / length * np.sin(2 * np.pi * (x - x0) / length), 0.0)
    return r, r_x


def _road(r, r_x, x0=-10.0, x1=70.0, dx=0.002):
    x = np.arange(x0, x1 + dx / 2, dx)
    return RoadProfile((0.0,), x0, dx, r(x)[None, :], r_x(x)[None, :], "bump")


def test_a_half_car_over_a_bump_on_a_rigid_road_matches_an_ode_solution():
    """Off the deck the road is rigid: the half-car's own ODE, solved by DOP853 (rtol 1e-10)."""
    r, r_x = _bump(0.03, 20.0, 2.0)
    speed, t_end, dt = 15.0, 2.0, 1e-3
    x_front0 = 8.0  # on the rigid deck for the whole run
    bridge = _rigid_deck()
    traffic_x = lambda t: x_front0 + speed * t  # noqa: E731
    steps = int(round(t_end / dt))
    times = dt * np.arange(1, steps + 1)
    offsets = TRUCK.contact_offsets
    xs = np.array([[traffic_x(t) - d for d in offsets] for t in times])
    block = TrafficBlock(tuple(f"t#{k}" for k in range(3)), (TRUCK,) * 3, xs, np.full_like(xs, speed),
                         np.zeros_like(xs), np.zeros(3))
    system = CoupledSystem(bridge, make_basis(bridge, dt, Scheme.newmark()), Scheme.newmark(), dt, road=_road(r, r_x),
                           gravity=G)
    report = system.advance(block)
    lin = TRUCK.linear_system(G)
    nz = lin["mv"].shape[0]
    minv = np.linalg.inv(lin["mv"])

    def rhs(t, s):
        z, zd = s[:nz], s[nz:]
        xk = traffic_x(t) - np.array(offsets)
        tyre = lin["k_t"] * (lin["b"] @ z - r(xk)) + lin["c_t"] * (lin["b"] @ zd - speed * r_x(xk))
        return np.concatenate([zd, -minv @ (lin["cv"] @ zd + lin["kv"] @ z + lin["b"].T @ tyre)])

    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(2 * nz), method="DOP853", rtol=1e-10, atol=1e-12, t_eval=times,
                    max_step=1e-3)
    z = sol.y[:nz].T
    body_ref = z @ lin["obs"].T  # body above each axle
    xk = traffic_x(times)[:, None] - np.array(offsets)[None, :]
    tyre_ref = lin["k_t"] * (z @ lin["b"].T - r(xk)) + lin["c_t"] * (sol.y[nz:].T @ lin["b"].T - speed * r_x(xk))
    force_ref = lin["loads"] - tyre_ref
    assert np.max(np.abs(report.body_displacement - body_ref)) <= TOL_ODE * np.max(np.abs(body_ref))
    dyn = force_ref - lin["loads"]
    assert np.max(np.abs(report.contact_force - force_ref)) <= TOL_ODE * np.max(np.abs(dyn))
    assert report.on_deck.all()


def test_a_unilateral_wheel_flies_over_a_bump_as_the_ode_with_contact_events_says():
    """A tyre quarter-car whose tyre carries no tension, over a bump fast enough to throw the wheel:
    solve_ivp with an event at every take-off and landing (independent of cosim's step-wise contact states)."""
    m_v, m_w, k_v, c_v, k_t, c_t = 4000.0, 500.0, 2e5, 1e4, 2e6, 0.0
    car = TyreQuarterCar(m_v=m_v, m_w=m_w, k_v=k_v, c_v=c_v, k_t=k_t, c_t=c_t, unilateral=True)
    weight = (m_v + m_w) * G
    r, r_x = _bump(0.05, 20.0, 0.8)
    speed, t_end, dt = 20.0, 1.2, 2e-4
    x0 = 10.0
    steps = int(round(t_end / dt))
    times = dt * np.arange(1, steps + 1)
    xs = (x0 + speed * times)[:, None]
    bridge = _rigid_deck()
    system = CoupledSystem(bridge, make_basis(bridge, dt, Scheme.newmark()), Scheme.newmark(), dt, road=_road(r, r_x),
                           gravity=G)
    report = system.advance(TrafficBlock(("car",), (car,), xs, np.full_like(xs, speed), np.zeros_like(xs),
                                         np.zeros(1)))

    def tyre_lin(t, s):
        x = x0 + speed * t
        return k_t * (s[1] - r(x)) + c_t * (s[3] - speed * r_x(x))

    def make_rhs(flying):
        def rhs(t, s):
            u_v, u_w, v_v, v_w = s
            susp = k_v * (u_v - u_w) + c_v * (v_v - v_w)
            tyre = weight if flying else tyre_lin(t, s)
            return [v_v, v_w, -susp / m_v, (susp - tyre) / m_w]
        return rhs

    def take_off(t, s):
        return weight - tyre_lin(t, s)  # contact force; < 0 would pull
    take_off.terminal, take_off.direction = True, -1

    def landing(t, s):
        return weight - tyre_lin(t, s)  # > 0: the tyre would be compressed again
    landing.terminal, landing.direction = True, 1

    t, s, flying = 0.0, np.zeros(4), False
    ts, ys, flights = [], [], []
    while t < t_end:
        event = landing if flying else take_off
        sol = solve_ivp(make_rhs(flying), (t, t_end), s, method="DOP853", rtol=1e-10, atol=1e-12,
                        events=event, dense_output=True, max_step=2e-4)
        ts.append(sol.t)
        ys.append(sol.y)
        if sol.status == 1:
            t, s = sol.t_events[0][0], sol.y_events[0][0]
            flights.append(t)
            flying = not flying
            t += 1e-12
        else:
            break
    t_ref = np.concatenate(ts)
    u_w_ref = np.interp(times, t_ref, np.concatenate([y[1] for y in ys]))
    u_v_ref = np.interp(times, t_ref, np.concatenate([y[0] for y in ys]))
    assert len(flights) >= 2, "the reference wheel must take off and land"
    assert np.max(np.abs(report.body_displacement[:, 0] - u_v_ref)) <= TOL_FLIGHT * np.max(np.abs(u_v_ref))
    # The flight: cosim flags the wheel lifted while the reference flies (within a few steps at each switch).
    flying_ref = np.zeros(steps, dtype=bool)
    for start, end in zip(flights[0::2], flights[1::2] + [t_end]):
        flying_ref |= (times >= start) & (times <= end)
    mismatch = np.count_nonzero(report.lifted[:, 0] != flying_ref)
    assert report.lifted[:, 0].any() and mismatch <= 2  # steps: take-off and landing within a step each
    # No tension is ever transmitted; in flight the contact force is zero, on the ground the reference's.
    assert report.contact_force.min() >= -1e-6 * weight
    force_ref = np.where(flying_ref, 0.0, weight - k_t * (u_w_ref - r(x0 + speed * times)))
    assert np.max(np.abs(report.contact_force[:, 0] - force_ref)[~(report.lifted[:, 0] ^ flying_ref)]) <= \
        TOL_FLIGHT * weight


def test_a_unilateral_tyre_that_never_leaves_behaves_as_the_bilateral_one():
    bridge = _bridge()
    sensors = [Sensor("mid", 15.0, 0.0)]
    runs = []
    for unilateral in (False, True):
        car = TyreQuarterCar(m_v=9000.0, m_w=900.0, k_v=4e5, c_v=3e4, k_t=3e6, c_t=2e3, unilateral=unilateral)
        runs.append(simulate(bridge, ScriptedTraffic((ScriptedVehicle("v", car, 0.0, 20.0),), 30.0), 2.0,
                             SolverSettings(dt=1e-3), sensors))
    assert runs[1].liftoff_events == 0
    ref = runs[0].sensors["mid"]
    assert np.max(np.abs(runs[1].sensors["mid"] - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_a_parked_half_car_settles_at_the_static_equilibrium_of_bridge_and_vehicle():
    """Statics of the coupled system: [K_ff + tyres, -tyres; -tyres, Kv + tyres] [d; z] = [-sum W_k n_k; 0]
    (the vehicle's equilibrium on a rigid road is its reference). Three axles on one body are statically
    indeterminate: on the flexible deck the axle loads differ from the rigid-road ones, by 2.6e-4 here."""
    bridge = _bridge()
    dt, steps, x_front, y = 5e-3, 6000, 20.0, 1.5
    sensor = Sensor("deck", 14.0, -1.0)
    scheme = Scheme.newmark()
    system = CoupledSystem(bridge, make_basis(bridge, dt, scheme), scheme, dt, gravity=G, sensors=(sensor,))
    report = system.advance(_parked_block(TRUCK, x_front, y, steps))
    lin = TRUCK.linear_system(G)
    free = bridge.free
    rows = np.array([bridge.deck_point_row(x_front - d, y).dense(bridge.ndof)[free] for d in TRUCK.contact_offsets])
    n, nz = len(free), lin["mv"].shape[0]
    K = np.zeros((n + nz, n + nz))
    K[:n, :n] = bridge.K_ff.toarray()
    K[n:, n:] = lin["kv"]
    for k in range(len(rows)):
        coupling = np.concatenate([-rows[k], lin["b"][k]])
        K += lin["k_t"][k] * np.outer(coupling, coupling)
    f = np.zeros(n + nz)
    f[:n] = -(lin["loads"] @ rows)
    sol = np.linalg.solve(K, f)
    expected = bridge.deck_point_row(14.0, -1.0).dense(bridge.ndof)[free] @ sol[:n]
    forces = lin["loads"] - lin["k_t"] * (lin["b"] @ sol[n:] - rows @ sol[:n])
    assert report.sensors[-1, 0] == pytest.approx(expected, rel=1e-6)
    np.testing.assert_allclose(report.contact_force[-1], forces, rtol=1e-6)
    assert forces.sum() == pytest.approx(TRUCK.total_mass * G, rel=1e-12)


def test_a_scripted_half_car_crosses_axle_after_axle():
    """Scripted traffic gives one column per axle, the axles following the front one: each axle is on the
    deck for one contiguous interval of L / v, starting d_k / v after the front axle (exact kinematics)."""
    bridge = _bridge()
    speed, dt = 20.0, 1e-3
    traffic = ScriptedTraffic((ScriptedVehicle("truck", TRUCK, 1.0, speed, entry_time=0.1),), 30.0)
    assert traffic.end_time() == pytest.approx(0.1 + (30.0 + TRUCK.contact_offsets[-1]) / speed, rel=1e-12)
    res = simulate(bridge, traffic, traffic.end_time() + 0.2, SolverSettings(dt=dt), [Sensor("mid", 15.0, 1.0)])
    for k, d in enumerate(TRUCK.contact_offsets):
        samples = res.vehicle(f"truck#{k}")
        t_on = samples["t"]
        assert np.all(np.diff(t_on) == pytest.approx(dt, rel=1e-9)), "one contiguous interval on the deck"
        assert t_on[0] == pytest.approx(0.1 + d / speed, abs=dt)
        assert t_on[-1] - t_on[0] == pytest.approx(30.0 / speed, abs=dt)
    assert res.liftoff_events == 0 and res.max_on_deck == 1
