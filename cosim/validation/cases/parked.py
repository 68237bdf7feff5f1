"""A quarter-car braking to a stop on a damped deck must settle on the statics."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import ExplicitDamping, PointLoad, build_bridge
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings, simulate
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import QuarterCar

from ..references import STEEL, rectangle_section
from ..results import CaseResult, FigureData, StudyResult
from .common import GRAVITY, TOL_PARKED

__all__ = [
    "ParkedFigure",
    "parked_vehicle",
]


@dataclass(frozen=True)
class ParkedFigure(FigureData):
    """Deflection under the wheel (m) while the vehicle brakes to a stop, and the static deflection."""

    title: str
    t: npt.NDArray[np.float64]
    w: npt.NDArray[np.float64]
    w_static: float
    stop_time: float


def parked_vehicle() -> StudyResult:
    """A quarter-car brakes to a stop at mid-span on a heavily damped deck: it must settle on the statics."""
    bridge = build_bridge([20.0], 20, STEEL, rectangle_section(1.0, 1.0), ["rigid-end", "rigid-end"],
                          ExplicitDamping(5.0, 1e-3))
    car = QuarterCar(m_v=1.5e4, m_w=1.5e3, k_v=5e5, c_v=4e4)
    v0 = 10.0
    stop_time = 2 * 10.0 / v0  # uniform deceleration over 10 m: stops at mid-span
    traffic = ScriptedTraffic((ScriptedVehicle("P", car, 0.3, v0, profile=((0.0, v0), (stop_time, 0.0))),), 20.0)
    res = simulate(bridge, traffic, 30.0, SolverSettings(dt=0.01, gravity=GRAVITY), [Sensor("load", 10.0, 0.3)])
    static = bridge.static([PointLoad(10.0, 0.3, -car.total_mass * GRAVITY)]).deck_displacement(10.0, 0.3)
    veh = res.vehicle("P")
    weight = car.total_mass * GRAVITY
    w_end, p_end, x_end = float(res.sensors["load"][-1]), float(veh["contact_force"][-1]), float(veh["x"][-1])
    error = max(abs(w_end / static - 1.0), abs(p_end / weight - 1.0))
    file = "parked_vehicle.png"
    figure = ParkedFigure(file=file, title="Quarter-car braking to a stop at mid-span, heavily damped 20 m deck",
                          t=res.t, w=res.sensors["load"], w_static=float(static), stop_time=stop_time)
    return StudyResult((CaseResult(
        name="Parked vehicle: settled deflection and contact force",
        reference="static solution of the same FE model under the vehicle's weight (m_v + m_w) g",
        metric="max of abs(w_end / w_static - 1) and abs(P_end / (m g) - 1) after 30 s",
        error=error, tolerance=TOL_PARKED, figures=(file,),
        details=(f"Deflection at 30 s {1e3 * w_end:.6f} mm, static {1e3 * static:.6f} mm; contact force "
                 f"{p_end:.2f} N, weight {weight:.2f} N; final position "
                 f"x = {x_end:.6f} m (exercises the a != 0 contact kinematics).",),
        values={"w_end": w_end, "w_static": static, "contact_force_end": p_end, "weight": weight, "x_end": x_end},
    ),), (figure,))
