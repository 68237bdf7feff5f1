"""A vehicle model added by its own code alone: defined and registered here, run from a scenario's
``[[vehicles]]`` table and from a SUMO vType (issue 24, item 1; docs/architecture.md, "Adding a vehicle model").

The model: a moving force on two wheels side by side, ``track`` metres apart (half the weight on each), on
the compiled loop's MOVING_FORCE kind. Nothing outside this file knows it: the scenario table, the vType's
``cosim.*`` params, the logs and the traffic sources find it in the registry. Stopped on the deck it gives
the beam's static deflection under its two wheel loads, its contact forces are its static axle loads, and
its wheels run ``track / 2`` to either side of its path.
"""
from __future__ import annotations

import shutil
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

from cosim.core.bridge import PointLoad
from cosim.core.vehicles import (
    MOVING_FORCE,
    ContactPoint,
    ModelSpec,
    Parameter,
    VehicleModel,
    VTypeInputs,
    VTypeRecipe,
    check_positive,
    model_from_dict,
    model_to_dict,
    registered,
)
from cosim.run.scenario import parse_scenario
from cosim.run.simulate import simulate_scenario
from cosim.sumo import bundled_networks

G = 9.81


@dataclass(frozen=True)
class TwinForce(VehicleModel):
    """A constant force ``mass * g`` on two wheels side by side, ``track`` m apart (half on each)."""

    mass: float
    track: float = 1.8
    kind: ClassVar[str] = "twin-force"
    KIND: ClassVar[int] = MOVING_FORCE

    def __post_init__(self) -> None:
        check_positive("twin force", mass=self.mass, track=self.track)

    @property
    def total_mass(self) -> float:
        return float(self.mass)

    def pack(self) -> tuple[float, ...]:
        return ()

    @property
    def contact_points(self) -> tuple[ContactPoint, ...]:
        return (ContactPoint(0.0, self.track / 2), ContactPoint(0.0, -self.track / 2))

    def static_axle_loads(self, gravity: float) -> np.ndarray:
        return np.full(2, self.mass * gravity / 2)

    def scaled(self, share: float) -> TwinForce:
        return replace(self, mass=self.mass * share)  # the track is a length: not shared


def _from_table(values: Mapping[str, Any], unilateral: bool) -> TwinForce:
    return TwinForce(values["mass"], values["track"])


def _from_vtype(vtype: VTypeInputs) -> TwinForce:
    return TwinForce(vtype.mass, vtype.values["track"])


TRACK = Parameter("track", "m", "wheel spacing", 1.8, above=0.0)
SPEC = ModelSpec(
    name=TwinForce.kind, cls=TwinForce, doc="a moving force on two wheels side by side",
    parameters=(Parameter("mass", "kg", "the vehicle's mass", above=0.0), TRACK),
    build=_from_table, example=TwinForce(20000.0),
    vtype=VTypeRecipe(parameters=(TRACK,), build=_from_vtype),
)


@pytest.fixture
def twin() -> Iterator[ModelSpec]:
    with registered(SPEC) as spec:  # registered for this test only (a forked SUMO child sees it too)
        yield spec


BRIDGE = """
[bridge]
spans = [40.0]
elements_per_span = 10
supports = ["rigid-end", "rigid-end"]
[bridge.material]
E = 33.0e9
G = 13.75e9
rho = 2500.0
[bridge.section.constants]
A = 4.8
I_y = 1.6
I_z = 60.0
J = 0.15
I_w = 19.0
deck_y = [-6.655, 6.655]
[bridge.damping]
ratios = [0.05, 0.05]
modes = ["vertical-1", "torsion-1"]

[[sensors]]
name = "edge"
x = 20.0
y = -6.0
"""


def _static(scenario: Any, result: Any, ids: tuple[str, ...], mass: float) -> float:
    """The beam's own static solution at the sensor under the wheels where they stopped (half the weight each)."""
    loads = [PointLoad(float(result.vehicle(i)["x"][-1]), float(result.vehicle(i)["y"][-1]), -mass * G / 2)
             for i in ids]
    return scenario.build_bridge().static(loads).deck_displacement(20.0, -6.0)


def test_a_model_registered_by_a_test_runs_from_a_vehicles_table(twin):
    text = BRIDGE + """
[[vehicles]]
id = "twin"
model = "twin-force"
mass = 20000.0
y = 1.0
profile = [[0.0, 10.0], [4.0, 0.0]]   # stops 20 m in: at mid-span

[solver]
dt = 0.01
duration = 30.0
"""
    scenario = parse_scenario(text, "twin.toml")
    model = scenario.vehicles[0].to_model()
    assert model == TwinForce(20000.0, 1.8)  # track: its registered default
    assert model_from_dict(model_to_dict(model)) == model  # the log's vehicle types
    result = simulate_scenario(scenario)
    ids = ("twin#0", "twin#1")
    assert set(ids) <= set(result.vehicle_ids)
    wheels = [result.vehicle(i) for i in ids]
    # The wheels beside the path: its left one (+y driving along +x) 0.9 m to the left, the other to the right.
    assert [w["y"][-1] for w in wheels] == [pytest.approx(1.9, abs=1e-12), pytest.approx(0.1, abs=1e-12)]
    assert [w["x"][-1] for w in wheels] == [pytest.approx(20.0, abs=1e-9)] * 2
    # Contact forces: its static axle loads, half the weight each; the deck settles to their static deflection.
    np.testing.assert_allclose([w["contact_force"][-1] for w in wheels], [20000.0 * G / 2] * 2, rtol=1e-12)
    static = _static(scenario, result, ids, 20000.0)
    assert static < -1e-4
    assert result.sensors["edge"][-1] == pytest.approx(static, rel=1e-3)


def test_a_model_registered_by_a_test_runs_from_a_sumo_vtype(twin, tmp_path: Path):
    shutil.copy(bundled_networks() / "bridge.net.xml", tmp_path / "bridge.net.xml")
    vtype = ('<vType id="twin" vClass="passenger" length="4.5" mass="20000" sigma="0" maxSpeed="20" accel="1" '
             'decel="4"><param key="cosim.model" value="twin-force"/><param key="cosim.track" value="2.0"/></vType>')
    stop = ('<vehicle id="q" type="twin" depart="0" departSpeed="10"><route edges="in_e pre_e bridge_e post_e out_e"/>'
            '<stop lane="bridge_e_0" endPos="26" duration="1000"/></vehicle>')
    (tmp_path / "twin.rou.xml").write_text(f'<?xml version="1.0"?>\n<routes>\n{vtype}{stop}\n</routes>\n')
    (tmp_path / "twin.sumocfg").write_text(
        '<?xml version="1.0"?><configuration><input><net-file value="bridge.net.xml"/>'
        '<route-files value="twin.rou.xml"/></input><time><begin value="0"/><end value="300"/></time>'
        '</configuration>')
    text = BRIDGE + f"""
[traffic]
sumo_config = "{(tmp_path / 'twin.sumocfg').as_posix()}"
step = 0.05
end = 300.0

[solver]
dt = 0.01
duration = 90.0
"""
    scenario = parse_scenario(text, "twin-sumo.toml")
    result = simulate_scenario(scenario)  # SUMO in a forked child where it can be: it knows the model too
    ids = ("q#0", "q#1")
    assert set(ids) <= set(result.vehicle_ids)
    wheels = [result.vehicle(i) for i in ids]
    assert all(abs(w["speed"][-1]) < 1e-9 for w in wheels)  # stopped on the deck
    # One axle at mid-length (no cosim.axles), its wheels cosim.track = 2.0 m apart across the path.
    assert wheels[0]["x"][-1] == pytest.approx(wheels[1]["x"][-1], abs=1e-12)
    assert wheels[0]["y"][-1] - wheels[1]["y"][-1] == pytest.approx(2.0, abs=1e-9)
    np.testing.assert_allclose([w["contact_force"][-1] for w in wheels], [20000.0 * G / 2] * 2, rtol=1e-12)
    static = _static(scenario, result, ids, 20000.0)
    assert static < -1e-4
    assert result.sensors["edge"][-1] == pytest.approx(static, rel=1e-3)
