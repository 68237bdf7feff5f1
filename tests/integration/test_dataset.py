"""``cosim dataset``: instruments' noise statistics as specified, and the frequency shift of a damaged case
against a modal analysis of the damaged bridge (real logged runs, real MCAP files)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cosim import testing as ct
from cosim.dataset import measure, parse_dataset, write_dataset
from cosim.errors import ConfigError

BASE = """\
name = "girder"
[bridge]
spans = [40.0]
elements_per_span = 16
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
ratios = [0.005, 0.005]
modes = ["vertical-1", "torsion-1"]
[[vehicles]]                  # three axles, one vehicle (the table counts vehicles, not axles)
id = "truck"
model = "half-car"
m_b = 16000.0
i_b = 6.0e4
cg = 2.2
y = 0.0
speed = 25.0
axles = [
  {distance = 0.0, m_w = 700.0, k_s = 6.0e5, c_s = 3.0e4, k_t = 2.5e6, c_t = 2.0e3},
  {distance = 4.0, m_w = 1100.0, k_s = 9.0e5, c_s = 5.0e4, k_t = 4.0e6, c_t = 3.0e3},
  {distance = 5.3, m_w = 1100.0, k_s = 9.0e5, c_s = 5.0e4, k_t = 4.0e6, c_t = 3.0e3},
]
[solver]
dt = 0.005
[output]
rate_hz = 100.0
"""

DATASET = """\
[dataset]
name = "pair"
base = "base.toml"
window = 25.0
windows = 2
spacing = 21600.0
seed = 3
[temperature]
mean = 10.0
amplitude = 10.0
peak_hour = 6.0
reference = 10.0
e_per_kelvin = -0.004
[[damage]]
name = "healthy"
[[damage]]
name = "cracked"
x = [14.0, 26.0]
stiffness = 0.5
[[sensors]]
name = "acc"
type = "accelerometer"
x = 20.0
rate_hz = 50.0
[[sensors]]
name = "gauge"
type = "displacement"
x = 10.0
rate_hz = 20.0
noise = 1e-5
resolution = 2e-6
"""


def test_instrument_noise_quantisation_and_anti_aliasing_are_as_specified():
    rng = np.random.default_rng(5)
    n = 40000
    noisy = measure(np.zeros(n), 100.0, 50.0, noise=0.01, resolution=0.0, rng=rng)
    assert len(noisy) == n // 2
    # White noise of RMS 0.01 on 20000 samples: the sample standard deviation within 3 % (its standard error
    # is 0.5 %), the mean within 4 standard errors of 0.
    assert noisy.std() == pytest.approx(0.01, rel=0.03)
    assert abs(noisy.mean()) < 4 * 0.01 / np.sqrt(len(noisy))
    quantised = measure(np.linspace(0, 1, 1000), 100.0, 100.0, noise=0.0, resolution=0.05, rng=rng)
    assert np.allclose(quantised / 0.05, np.round(quantised / 0.05))
    assert np.max(np.abs(quantised - np.linspace(0, 1, 1000))) <= 0.025 + 1e-12
    t = np.arange(0, 20, 0.01)
    passed = measure(np.sin(2 * np.pi * 5 * t), 100.0, 50.0, 0.0, 0.0, rng)
    aliased = measure(np.sin(2 * np.pi * 40 * t), 100.0, 50.0, 0.0, 0.0, rng)  # above the new Nyquist (25 Hz)
    middle = slice(100, -100)  # away from the filter's end effects
    t_out = np.arange(len(passed)) / 50.0
    assert np.max(np.abs(passed - np.sin(2 * np.pi * 5 * t_out))[middle]) < 0.01  # passes within 1 %
    assert np.max(np.abs(aliased[middle])) < 0.01  # the anti-aliasing filter removed it (> 40 dB)
    with pytest.raises(ConfigError, match="rate_hz"):
        measure(np.zeros(10), 100.0, 200.0, 0.0, 0.0, rng)


def test_a_damaged_case_shifts_the_frequency_as_the_damaged_bridges_modes_say(tmp_path):
    (tmp_path / "base.toml").write_text(BASE)
    dataset = parse_dataset(DATASET, str(tmp_path / "pair.toml"), base_dir=tmp_path, output=tmp_path / "out")
    outcome = write_dataset(dataset)
    table = pd.read_parquet(outcome.table)
    assert list(table["case"]) == ["healthy", "healthy", "cracked", "cracked"]
    assert list(table["vehicles"]) == [1, 1, 1, 1]  # the one truck of the scenario, its three axles one vehicle
    assert all(p.is_file() for p in outcome.logs)
    # The temperature cycle: 10 deg C at 00:00, 20 deg C at its peak at 06:00; f1 ~ sqrt(E) exactly (only K scales).
    healthy = table[table["case"] == "healthy"]
    assert list(healthy["temperature"]) == pytest.approx([10.0, 20.0])
    ratio = healthy["f1_hz"].iloc[0] / healthy["f1_hz"].iloc[1]
    assert ratio == pytest.approx(np.sqrt(healthy["e_factor"].iloc[0] / healthy["e_factor"].iloc[1]), rel=1e-9)
    # The signal's dominant frequency after the truck left (1.8 s) against each bridge's modal analysis.
    for _, row in table[table["window"] == 1].iterrows():
        acc = np.asarray(row["acc"])
        t = np.arange(len(acc)) / row["acc.rate_hz"]
        free = t > 3.0
        f_signal = ct.dominant_frequency(t[free], acc[free], band=(0.5 * row["f1_hz"], 1.5 * row["f1_hz"]))
        assert f_signal == pytest.approx(row["f1_hz"], rel=5e-3)  # 22 s of free vibration, interpolated peak
    shift = table[table["window"] == 1].set_index("case")["f1_hz"]
    assert shift["cracked"] < 0.95 * shift["healthy"]
    # The displacement gauge: the noise as specified on the quiet end of the record, quantised to 2 um.
    gauge = np.asarray(table["gauge"].iloc[1])
    assert np.allclose(gauge / 2e-6, np.round(gauge / 2e-6))
    with pytest.raises(Exception, match="already exists"):
        write_dataset(dataset)
