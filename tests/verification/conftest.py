"""Fixtures for the verification tests: the paper's validation case (shared/cases/paper-double-tee.md)."""
from __future__ import annotations

import pytest

from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.run.scenario import load_scenario
from cosim.validation.cases import PAPER_LANE_Y, PAPER_QC1, PAPER_QC2, PAPER_QC2_ENTRY, PAPER_SPEED


@pytest.fixture(scope="session")
def paper_bridge():
    # The bundled scenario is the case file's bridge: 40 elements, rigid ends, Rayleigh 2 % at vertical-1/torsion-1.
    return load_scenario("paper-double-tee").build_bridge()


@pytest.fixture(scope="session")
def paper_traffic():
    return ScriptedTraffic(
        (
            ScriptedVehicle("QC-1", PAPER_QC1, PAPER_LANE_Y, PAPER_SPEED, 0.0),
            ScriptedVehicle("QC-2", PAPER_QC2, PAPER_LANE_Y, PAPER_SPEED, PAPER_QC2_ENTRY),
        ),
        40.0,
    )
