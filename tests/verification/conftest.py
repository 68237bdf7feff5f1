"""Fixtures for the verification tests: the paper's validation case (shared/cases/paper-double-tee.md)."""
from __future__ import annotations

import pytest

from cosim.bridge import RayleighDamping, build_bridge
from cosim.section import Material, Plate, section_from_plates
from cosim.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.vehicles import QuarterCar

PAPER_MATERIAL = Material(E=33.0e9, G=13.75e9, rho=2500.0)
PAPER_PLATES = (
    Plate((-6.655, 0.0), (6.655, 0.0), 0.25),
    Plate((3.325, 0.0), (3.325, -2.0), 0.40),
    Plate((-3.325, 0.0), (-3.325, -2.0), 0.40),
)
QC1 = QuarterCar(m_v=1000.0, m_w=100.0, k_v=39478.40, c_v=5026.55)
QC2 = QuarterCar(m_v=2000.0, m_w=200.0, k_v=78956.80, c_v=10053.10)


@pytest.fixture(scope="session")
def paper_bridge():
    section = section_from_plates(PAPER_PLATES, nu=0.2)
    damping = RayleighDamping(ratios=(0.02, 0.02), modes=("vertical-1", "torsion-1"))
    return build_bridge([40.0], 40, PAPER_MATERIAL, section, ["rigid-end", "rigid-end"], damping)


@pytest.fixture(scope="session")
def paper_traffic():
    return ScriptedTraffic(
        (ScriptedVehicle("QC-1", QC1, 3.325, 4.0, 0.0), ScriptedVehicle("QC-2", QC2, 3.325, 4.0, 7.5)), 40.0
    )
