"""The one vehicle-model registry and the one interface (issue 24, item 1): every list of models, every table of
their parameters and every check of them derives from it; contact points beside the path reach the columns."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, is_dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from cosim.core.traffic import Frame, FrameTraffic, ScriptedTraffic, ScriptedVehicle
from cosim.core.vehicles import (
    MODELS,
    MOVING_FORCE,
    ContactPoint,
    HalfCar,
    ModelSpec,
    MovingForce,
    Parameter,
    VehicleModel,
    VTypeRecipe,
    check_positive,
    markdown_tables,
    model_from_dict,
    model_to_dict,
    register,
    registered,
)
from cosim.core.vehicles.registry import DOCS_BEGIN, DOCS_END
from cosim.errors import ConfigError, SumoError
from cosim.run import tables
from cosim.run.scenario import parse_scenario
from cosim.sumo import vtypes

DOCS = Path(cosim.__file__).resolve().parents[1] / "docs"


@dataclass(frozen=True)
class Pair(VehicleModel):
    """A moving force on two wheels side by side, 1.8 m apart: what a model with roll would put on the deck."""

    mass: float
    kind: ClassVar[str] = "pair"
    KIND: ClassVar[int] = MOVING_FORCE

    def __post_init__(self) -> None:
        check_positive("pair", mass=self.mass)

    @property
    def total_mass(self) -> float:
        return float(self.mass)

    def pack(self) -> tuple[float, ...]:
        return ()

    @property
    def contact_points(self) -> tuple[ContactPoint, ...]:
        return (ContactPoint(0.0, 0.9), ContactPoint(0.0, -0.9))

    def static_axle_loads(self, gravity: float) -> np.ndarray:
        return np.full(2, self.mass * gravity / 2)


def _pair(values: Mapping[str, Any], unilateral: bool) -> Pair:
    return Pair(values["mass"])


PAIR = ModelSpec(name="pair", cls=Pair, doc="two wheels side by side",
                 parameters=(Parameter("mass", "kg", "mass", above=0.0),), build=_pair, example=Pair(2000.0),
                 vtype=VTypeRecipe(parameters=(), build=lambda v: Pair(v.mass)))


def _generated(page: Path) -> list[str]:
    """The generated tables of a docs page (between the markers)."""
    text = page.read_text(encoding="utf-8")
    return [part.split(DOCS_END)[0].strip("\n") for part in text.split(DOCS_BEGIN)[1:]]


def test_one_registry_under_every_name():
    assert cosim.VEHICLE_MODELS is MODELS and tables.VEHICLE_MODELS is MODELS
    assert list(MODELS) == ["moving-force", "quarter-car", "tyre-quarter-car", "golden-car", "half-car"]
    assert tables.tyre_models() == ("tyre-quarter-car", "golden-car", "half-car")
    assert list(vtypes.vtype_models()) == ["moving-force", "quarter-car", "tyre-quarter-car", "half-car"]
    assert vtypes.param_keys() == ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads", "contact",
                                   "pitch", "i_b")


def test_the_docs_tables_are_the_registrys():
    assert _generated(DOCS / "scenario.md") == [markdown_tables()], \
        "docs/scenario.md: paste cosim.core.vehicles.markdown_tables() between its markers"
    assert _generated(DOCS / "own-network.md") == [vtypes.markdown_table()], \
        "docs/own-network.md: paste cosim.sumo.vtypes.markdown_table() between its markers"


def _values(spec: ModelSpec) -> dict[str, Any]:
    """The example's values of the spec's parameters (an array of tables as dicts)."""
    values = {}
    for p in spec.parameters:
        value = getattr(spec.example, p.name)
        values[p.name] = tuple(asdict(t) for t in value) if p.kind == "tables" else value
    return values


@pytest.mark.parametrize("name", list(MODELS))
def test_every_model_builds_its_example_and_its_class_checks_the_documented_constraints(name):
    spec = MODELS[name]
    assert spec.build(_values(spec), False) == spec.example
    assert is_dataclass(spec.example) and spec.example.__dataclass_params__.frozen
    for p in spec.parameters:
        for f, outside in [(p, None)] + [(f, p.name) for f in p.fields]:
            if f.kind != "number" or (f.above is None and f.at_least is None):
                continue
            bad = f.above if f.above is not None else f.at_least - 1.0
            values = _values(spec)
            if outside is None:
                values[f.name] = bad
            else:
                values[outside] = tuple({**t, f.name: bad} for t in values[outside])
            with pytest.raises(ConfigError, match=f"`{f.name}` must be"):
                spec.build(values, False)


@pytest.mark.parametrize("name", list(MODELS))
def test_every_model_is_logged_and_read_back(name):
    model = MODELS[name].example
    record = model_to_dict(model)
    assert record["model"] == type(model).kind and all(isinstance(v, float | int) for k, v in record.items()
                                                         if k != "model")
    assert model_from_dict(record) == model
    assert sum(model.static_axle_loads(9.81)) == pytest.approx(model.total_mass * 9.81, rel=1e-12)
    assert len(model.static_axle_loads(9.81)) == model.contacts == len(model.contact_points)


def test_registration_is_checked_and_undone():
    with pytest.raises(ConfigError, match="registered already"):
        register(MODELS["quarter-car"])
    with pytest.raises(ConfigError, match="derive from VehicleModel"):
        register(ModelSpec(name="x", cls=dict, doc="", parameters=(), build=_pair,  # type: ignore[arg-type]
                           example=Pair(1.0)))
    with registered(PAIR):
        assert MODELS["pair"] is PAIR and "pair" in vtypes.vtype_models()
    assert "pair" not in MODELS


def test_a_registered_model_is_a_vehicles_table_with_the_same_messages():
    base = ('[bridge]\nspans = [30.0]\nelements_per_span = 6\nsupports = ["pinned", "fork"]\n[bridge.material]\n'
            'E = 33e9\nnu = 0.2\nrho = 2500.0\n[bridge.section.constants]\nA = 4.8\nI_y = 1.6\nI_z = 60.0\nJ = 0.15\n'
            'I_w = 19.0\ndeck_y = [-6.6, 6.6]\n[[vehicles]]\ny = 1.0\nspeed = 10.0\n')
    with pytest.raises(ConfigError, match='unknown vehicle model "pair"'):
        parse_scenario(base + 'model = "pair"\nmass = 2000.0\n', "t.toml")
    with registered(PAIR):
        scenario = parse_scenario(base + 'model = "pair"\nmass = 2000.0\n', "t.toml")
        assert scenario.vehicles[0].to_model() == Pair(2000.0)
        with pytest.raises(ConfigError, match=r'^t.toml: vehicles\[0\].m_v: not a parameter of model "pair" '
                                              r"\(its parameters: mass\)"):
            parse_scenario(base + 'model = "pair"\nmass = 2000.0\nm_v = 3.0\n', "t.toml")
        with pytest.raises(ConfigError, match=r"vehicles\[0\].mass: must be a finite number > 0 \(got -1.0\)"):
            parse_scenario(base + 'model = "pair"\nmass = -1.0\n', "t.toml")
        with pytest.raises(ConfigError, match=r"vehicles\[0\].contact: unilateral contact needs a tyre"):
            parse_scenario(base + 'model = "pair"\nmass = 2000.0\ncontact = "unilateral"\n', "t.toml")
        with pytest.raises(ConfigError, match=r'vehicles\[0\].mas: unknown key; did you mean "mass"\?'):
            parse_scenario(base + 'model = "pair"\nmas = 2000.0\n', "t.toml")


def test_contact_points_beside_the_path_are_columns_beside_it():
    """Each contact point is a column whose y is the path's plus its offset to the vehicle's left: +y driving
    along +x, -y driving along -x."""
    traffic = ScriptedTraffic((ScriptedVehicle("e", Pair(2000.0), 1.0, 10.0),
                               ScriptedVehicle("w", Pair(2000.0), -2.0, 10.0, direction=-1),
                               ScriptedVehicle("m", MovingForce(1000.0), 3.0, 10.0)), 30.0)
    block = traffic.block(np.array([1.0, 1.5]))
    assert block.ids == ("e#0", "e#1", "w#0", "w#1", "m")
    np.testing.assert_allclose(block.y, [1.9, 0.1, -2.9, -1.1, 3.0], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(block.x[:, 0], block.x[:, 1])
    frames = FrameTraffic(0.5, 30.0, {"p#0": Pair(2000.0), "p#1": Pair(2000.0)})
    frames.add_frame(Frame(0.5, ("p#0", "p#1"), np.array([-0.1, -0.1]), np.array([1.9, 0.1]), np.ones(2),
                           np.zeros(2), ("p#0", "p#1")))
    frames.add_frame(Frame(1.0, ("p#0", "p#1"), np.array([0.4, 0.4]), np.array([1.9, 0.1]), np.ones(2),
                           np.zeros(2), ("p#0", "p#1")))
    assert frames.block(np.array([0.75, 1.0])).ids == ("p#0", "p#1")  # one body: its columns together


def test_a_vtype_places_each_contact_point_of_its_model():
    with registered(PAIR):
        typ = vtypes.vehicle_type("p", "passenger", 4.0, 2000.0, {"cosim.model": "pair"})
        assert typ.contact_columns() == [("p#0", Pair(2000.0), 2.0, 0.9), ("p#1", Pair(2000.0), 2.0, -0.9)]
        with pytest.raises(SumoError, match=r"param `cosim.k_v` is not used by model pair \(its params: "
                                            r"cosim.model, cosim.axles, cosim.axle_loads\)"):
            vtypes.vehicle_type("p", "passenger", 4.0, 2000.0, {"cosim.model": "pair", "cosim.k_v": "1"})
    # A body on its axles: each contact at its axle, as the vType gives it (no round-off of front + offset).
    truck = vtypes.vehicle_type("b", "bus", 10.8, None, {"cosim.model": "half-car"})
    assert isinstance(truck.model, HalfCar)
    assert [back for _, _, back, _ in truck.contact_columns()] == [d for d, _ in truck.axles]
    with pytest.raises(SumoError, match=r"`cosim.model` must be moving-force, quarter-car, tyre-quarter-car, "
                                        r"half-car \(got 'golden-car'"):
        vtypes.vehicle_type("g", "passenger", 4.0, 1000.0, {"cosim.model": "golden-car"})
