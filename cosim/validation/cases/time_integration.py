"""Time integration: energy conservation of Newmark and the time-step convergence of Newmark and HHT-alpha."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import scipy.sparse.linalg as spla

from cosim.core.bases import make_basis
from cosim.core.bridge import PointLoad
from cosim.core.coupling import CoupledSystem
from cosim.core.schemes import Scheme
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle, TrafficFrame
from cosim.core.vehicles import QuarterCar, TyreQuarterCar, VehicleModel

from ..results import CaseResult, FigureData, StudyResult, Table
from .common import GRAVITY, TOL_ENERGY, TOL_ORDER_TIME, euler_bernoulli_bridge, observed_orders

__all__ = [
    "EnergyFigure",
    "TimeStepFigure",
    "energy_conservation",
    "time_step_convergence",
]


@dataclass(frozen=True)
class EnergyFigure(FigureData):
    """Kinetic and strain energy (J) and the relative drift of their sum."""

    title: str
    tolerance: float
    t: npt.NDArray[np.float64]
    kinetic: npt.NDArray[np.float64]
    strain: npt.NDArray[np.float64]
    drift: npt.NDArray[np.float64]


def energy_conservation(steps: int) -> StudyResult:
    """Undamped free vibration of a 20 m beam, Newmark's average acceleration: the energy must stay."""
    bridge, _ = euler_bernoulli_bridge()
    dt = 1e-3
    scheme = Scheme.newmark()
    basis = make_basis(bridge, dt, scheme)
    system = CoupledSystem(bridge, basis, scheme, dt)
    K, M = bridge.K_ff, bridge.M_ff
    d0 = bridge.static([PointLoad(7.0, 0.0, -1e6)]).d[bridge.free]
    system.set_state(d0, np.zeros_like(d0), spla.spsolve(M.tocsc(), -(K @ d0)))  # consistent a0: M a0 = -K d0

    def energies() -> tuple[float, float]:
        return float(0.5 * system.v @ (M @ system.v)), float(0.5 * system.d @ (K @ system.d))

    kinetic, strain = np.empty(steps + 1), np.empty(steps + 1)
    kinetic[0], strain[0] = energies()
    e0 = kinetic[0] + strain[0]
    empty = TrafficFrame((), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), ())
    for k in range(1, steps + 1):
        system.step(empty)
        kinetic[k], strain[k] = energies()
    drift = (kinetic[1:] + strain[1:]) / e0 - 1.0
    file = "energy_drift.png"
    figure = EnergyFigure(
        file=file, title="Undamped free vibration of a 20 m beam (40 elements, direct basis, Newmark, dt = 1 ms)",
        tolerance=TOL_ENERGY, t=dt * np.arange(0, steps + 1, dtype=np.float64), kinetic=kinetic, strain=strain,
        drift=np.concatenate([[0.0], drift]),
    )
    return StudyResult((CaseResult(
        name="Energy conservation, undamped free vibration",
        reference="average acceleration conserves the energy of a linear undamped system exactly "
                  "(Hughes, The FEM, 9.3)",
        metric=f"max abs(E(t) / E0 - 1) over {steps} steps, E = kinetic + strain energy",
        error=float(np.max(np.abs(drift))), tolerance=TOL_ENERGY, figures=(file,),
        details=(f"Initial state: static deflection under 1 MN at x = 7 m, released from rest; E0 = {e0:.6g} J.",),
        values={"e0": e0, "steps": steps},
    ),), (figure,))


@dataclass(frozen=True)
class TimeStepFigure(FigureData):
    """Errors (m) of the end deflection against the time step, per model and scheme."""

    title: str
    dt: npt.NDArray[np.float64]
    labels: tuple[str, ...]
    errors: tuple[npt.NDArray[np.float64], ...]


def time_step_convergence() -> StudyResult:
    """Second-order accuracy of Newmark and HHT-α with quarter-cars (modal basis, 6 modes)."""
    bridge, _ = euler_bernoulli_bridge(L=10.0, n_el=10)
    duration, ref_steps = 0.4, 12800
    steps = np.array([100, 200, 400, 800, 1600])
    asymptotic = steps >= 400  # the orders judged: 400 -> 800 -> 1600 steps
    combos: list[tuple[str, VehicleModel, Scheme]] = [
        ("quarter-car", QuarterCar(2e4, 2e3, 2e6, 5e4), Scheme.newmark()),
        ("quarter-car", QuarterCar(2e4, 2e3, 2e6, 5e4), Scheme.hht(-0.1)),
        ("tyre quarter-car", TyreQuarterCar(2e4, 2e3, 2e6, 5e4, 2e7, 0.0), Scheme.newmark()),
        ("tyre quarter-car", TyreQuarterCar(2e4, 2e3, 2e6, 5e4, 2e7, 0.0), Scheme.hht(-0.1)),
    ]

    def midspan_at_end(n: int, model: VehicleModel, scheme: Scheme) -> float:
        traffic = ScriptedTraffic((ScriptedVehicle("Q", model, 0.0, 20.0),), 10.0)
        # Six modes: each retained mode is resolved by every step used, so the error is asymptotic.
        settings = SolverSettings(dt=duration / n, scheme=scheme.name, hht_alpha=scheme.alpha, basis="modal",
                                  modes=6, gravity=GRAVITY)
        return float(simulate(bridge, traffic, duration, settings, [Sensor("mid", 5.0)]).sensors["mid"][-1])

    dts = duration / steps
    rows, worst, labels, all_errors, values = [], 0.0, [], [], {}
    for label, model, scheme in combos:
        ref = midspan_at_end(ref_steps, model, scheme)
        errors = np.array([abs(midspan_at_end(int(n), model, scheme) - ref) for n in steps])
        orders = observed_orders(dts[asymptotic], errors[asymptotic])
        worst = max(worst, max(0.0, 2.0 - float(np.min(orders))))
        name = f"{label}, {scheme.name}" + (f" (α = {scheme.alpha:g})" if scheme.name == "hht" else "")
        rows.append((name, ", ".join(f"{e:.3g}" for e in errors), ", ".join(f"{p:.2f}" for p in orders)))
        labels.append(name)
        all_errors.append(errors)
        values[f"min_order: {name}"] = float(np.min(orders))
    file = "time_step_convergence.png"
    figure = TimeStepFigure(file=file, title=f"Time-step convergence (reference: dt = {duration / ref_steps:.3g} s)",
                            dt=dts, labels=tuple(labels), errors=tuple(all_errors))
    return StudyResult((CaseResult(
        name="Time-step convergence (Newmark, HHT)",
        reference="second-order accuracy of Newmark average acceleration and HHT-α (Hilber, Hughes & Taylor 1977)",
        metric="order shortfall max(0, 2 - min observed order) over 400 -> 800 -> 1600 steps",
        error=worst, tolerance=TOL_ORDER_TIME, figures=(file,),
        details=(
            f"Vehicle at 20 m/s on a 10 m beam (10 elements, modal basis with 6 modes); error against dt = "
            f"{duration / ref_steps:.3g} s; steps per 0.4 s: {', '.join(str(n) for n in steps)}.",
            Table(("model, scheme", "errors [m]", "observed orders 400→800, 800→1600"), rows),
        ),
        values=values,
    ),), (figure,))
