"""[[vehicles]] with axle groups (half-car) and unilateral contact: keys, errors, and a run."""
from __future__ import annotations

import pytest

from cosim.core.vehicles import HalfCar, TyreQuarterCar
from cosim.errors import ConfigError
from cosim.run.scenario import parse_scenario

BRIDGE = """
[bridge]
spans = [30.0]
elements_per_span = 12
supports = ["pinned", "fork"]
[bridge.material]
E = 33e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 4.8
I_y = 1.6
I_z = 60.0
J = 0.15
I_w = 19.0
deck_y = [-6.6, 6.6]
"""
TRUCK = """
[[vehicles]]
id = "truck"
model = "half-car"
m_b = 16000.0
i_b = 6e4
cg = 2.2
y = 1.5
speed = 20.0
axles = [
  {distance = 0.0, m_w = 700.0, k_s = 6e5, c_s = 3e4, k_t = 2.5e6, c_t = 2e3},
  {distance = 4.0, m_w = 1100.0, k_s = 9e5, c_s = 5e4, k_t = 4e6},
]
"""


def test_a_half_car_table_becomes_the_model():
    sc = parse_scenario(BRIDGE + TRUCK, "t.toml")
    model = sc.vehicles[0].to_model()
    assert isinstance(model, HalfCar) and model.pitch and not model.unilateral
    assert model.contact_offsets == (0.0, 4.0) and model.axles[1].c_t == 0.0
    # The run lasts until the last axle leaves: (30 + 4) m at 20 m/s, + 2 s.
    assert sc.duration == pytest.approx(34.0 / 20.0 + 2.0)


def test_unilateral_contact_is_a_key_of_tyre_models_only():
    unilateral = TRUCK.replace('speed = 20.0', 'speed = 20.0\ncontact = "unilateral"')
    assert parse_scenario(BRIDGE + unilateral, "t.toml").vehicles[0].to_model().unilateral
    golden = '[[vehicles]]\nmodel = "golden-car"\nm_v = 300.0\ny = 0.0\nspeed = 10.0\ncontact = "unilateral"\n'
    model = parse_scenario(BRIDGE + golden, "t.toml").vehicles[0].to_model()
    assert isinstance(model, TyreQuarterCar) and model.unilateral
    rigid = '[[vehicles]]\nmodel = "quarter-car"\nm_v = 1e3\nm_w = 100.0\nk_v = 4e4\nc_v = 1e3\ny = 0.0\n' \
            'speed = 10.0\ncontact = "unilateral"\n'
    with pytest.raises(ConfigError, match=r"^t.toml: vehicles\[0\].contact: unilateral contact needs a tyre"):
        parse_scenario(BRIDGE + rigid, "t.toml")
    with pytest.raises(ConfigError, match=r'vehicles\[0\].contact: unknown contact "sliding"'):
        parse_scenario(BRIDGE + rigid.replace('"unilateral"', '"sliding"'), "t.toml")


@pytest.mark.parametrize("change, where, message", [
    ("i_b = 6e4\n", "vehicles[0].i_b", "must be > 0 kg m^2 for a pitching body (or set pitch = false)"),
    ("distance = 4.0", "vehicles[0]", "axle distances must start at 0 (the front axle) and increase"),
    ("distance = 0.0", "vehicles[0].axles[0].distance", "must be >= 0"),
    ("k_t = 4e6}", "vehicles[0].axles[1].k_t", "must be > 0"),
    ("m_w = 700.0, ", "vehicles[0].axles[0].m_w", "required key is missing"),
])
def test_half_car_mistakes_are_one_line_naming_the_key(change, where, message):
    replacement = {"i_b = 6e4\n": "", "distance = 4.0": "distance = 0.0", "distance = 0.0": "distance = -1.0",
                   "k_t = 4e6}": "k_t = -4e6}", "m_w = 700.0, ": ""}[change]
    with pytest.raises(ConfigError) as err:
        parse_scenario(BRIDGE + TRUCK.replace(change, replacement), "t.toml")
    first = str(err.value).splitlines()[0]
    assert first.startswith(f"t.toml: {where}") and message in first
