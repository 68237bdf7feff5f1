"""A vType's vehicle model: cosim's library for what the vType does not say, every number with its source."""
from __future__ import annotations

import math

import pytest

from cosim.core.vehicles import QuarterCar, TyreQuarterCar
from cosim.errors import SumoError
from cosim.sumo.library import ENTRIES, GOLDEN_CAR, LORRY_3
from cosim.sumo.vtypes import SOURCE_MASS, SOURCE_PARAMS, vehicle_type


def test_a_vtype_without_mass_or_params_is_its_vclass_library_vehicle():
    car = vehicle_type("p", "passenger", 5.0, None, {})
    # IRI golden car (Sayers, Gillespie & Queiroz 1986): k_s/m_s = 63.3, c_s/m_s = 6.0, k_t/m_s = 653, m_u/m_s = 0.15.
    m = car.model
    assert isinstance(m, TyreQuarterCar) and m.total_mass == pytest.approx(1500.0)
    assert (m.k_v / m.m_v, m.c_v / m.m_v, m.k_t / m.m_v, m.m_w / m.m_v) == pytest.approx((63.3, 6.0, 653.0, 0.15))
    assert car.sources == {"mass": "cosim default: car", "suspension": "cosim default: IRI golden car",
                           "axles": "cosim default: car"}
    lorry = vehicle_type("l", "trailer", 16.5, None, {})
    # EN 1991-2 Table 4.7, lorry 3: spacings 3.2, 5.2, 1.3, 1.3 m; axle loads 70, 150, 90, 90, 90 kN.
    assert [d for d, _ in lorry.axles] == pytest.approx([1.4, 4.6, 9.8, 11.1, 12.4])
    assert [s for _, s in lorry.axles] == pytest.approx([70 / 490, 150 / 490, 90 / 490, 90 / 490, 90 / 490])
    assert lorry.mass == pytest.approx(490e3 / 9.81)
    # Each axle carries its share of the whole vehicle's masses, springs and dampers.
    per_axle = dict(lorry.axle_models())
    assert sum(v.total_mass for v in per_axle.values()) == pytest.approx(lorry.mass)
    assert per_axle["l#1"].k_t == pytest.approx(lorry.model.k_t * 150 / 490)


def test_a_vtype_with_only_its_mass_is_the_library_vehicle_at_that_mass():
    t = vehicle_type("t", "truck", 7.1, 26000.0, {})
    assert t.mass == pytest.approx(26000.0) and t.sources["mass"] == SOURCE_MASS
    assert len(t.axles) == 2 and t.sources["axles"] == "cosim default: EN 1991-2 FLM4 lorry 1"
    # The heavy-axle set keeps its frequencies at any mass: 2.0 Hz body bounce on a rigid tyre.
    assert math.sqrt(t.model.k_v / t.model.m_v) / (2 * math.pi) == pytest.approx(2.0)


def test_params_given_in_part_take_the_rest_from_the_library_and_say_so():
    t = vehicle_type("b", "bus", 12.0, 18000.0, {"cosim.model": "tyre-quarter-car", "cosim.k_v": "2e6"})
    assert t.model.k_v == 2e6 and t.model.m_w == pytest.approx(1800.0)  # 10 % unsprung: the library's
    assert t.sources["suspension"] == f"{SOURCE_PARAMS} + cosim default"
    assert "m_w, c_v, k_t, c_t from road-friendly heavy axle" in t.details["suspension"]
    assert t.axles == ((6.0, 1.0),) and t.sources["axles"] == SOURCE_PARAMS  # one quarter-car at mid-length
    plain = vehicle_type("c", "passenger", 4.5, 1500.0, {"cosim.m_w": "150", "cosim.k_v": "76750",
                                                        "cosim.c_v": "6110"})
    assert isinstance(plain.model, QuarterCar) and plain.model.m_v == 1350.0  # as before: a quarter-car


def test_unknown_or_impossible_params_are_errors_naming_the_vtype():
    with pytest.raises(SumoError, match=r"vType x: unknown param `cosim.axle_load` \(did you mean `cosim.axle_loads`"):
        vehicle_type("x", "passenger", 5.0, None, {"cosim.axle_load": "1"})
    with pytest.raises(SumoError, match=r"`cosim.model` must be .* \(got 'quartercar'; did you mean quarter-car\?\)"):
        vehicle_type("x", "passenger", 5.0, None, {"cosim.model": "quartercar"})
    with pytest.raises(SumoError, match="must lie on the vehicle, 0 to 5 m"):
        vehicle_type("x", "passenger", 5.0, None, {"cosim.axles": "1 6", "cosim.axle_loads": "0.5 0.5"})
    # Before SUMO says a vType's length (none in its file), axles are checked against the vehicle later.
    assert len(vehicle_type("x", "passenger", None, None, {"cosim.axles": "1 6",
                                                            "cosim.axle_loads": "0.5 0.5"}).axles) == 2
    assert vehicle_type("p", "param-only", 5.0, None, {"other.key": "1"}).note  # other params are not cosim's


def test_every_library_vehicle_is_physical_and_a_vclass_without_one_says_so():
    for vclass, entry in ENTRIES.items():
        t = vehicle_type(vclass, vclass, entry.length, None, {})
        assert sum(s for _, s in t.axles) == pytest.approx(1.0) and t.note == ""
        assert all(0 < d < entry.length for d, _ in t.axles), vclass
    tram = vehicle_type("tram", "tram", 22.0, None, {})
    assert "vClass 'tram' has no vehicle of its own in cosim's library: the car stands in" == tram.note
    assert GOLDEN_CAR.unsprung_share() == pytest.approx(0.15 / 1.15) and LORRY_3.length == 16.5
