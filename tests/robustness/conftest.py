"""Fixtures of the robustness tests: real runs and real logs to craft hostile and careless inputs from."""
from __future__ import annotations

from pathlib import Path

import pytest
from _robust import PROFILED, ROAD_CSV, SUMO_SCENARIO, cosim_cli, sumo_folder, write


@pytest.fixture(scope="session")
def profiled_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished log of PROFILED (scripted cars over a road profile file), 401 sensor samples."""
    folder = tmp_path_factory.mktemp("profiled")
    scenario = write(folder, "profiled.toml", PROFILED)
    write(folder, "data/road.csv", ROAD_CSV)
    result = cosim_cli("run", str(scenario), "--out", str(folder / "run.mcap"), "--quiet", cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder / "run.mcap"


@pytest.fixture(scope="session")
def sumo_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished log of 80 s of SUMO traffic over the bundled bridge (its SUMO files embedded); the first
    vehicles reach the deck after about 40 s."""
    folder = tmp_path_factory.mktemp("sumo")
    sumo_folder(folder)
    scenario = write(folder, "sumo.toml", SUMO_SCENARIO.format(end=80.0))
    result = cosim_cli("run", str(scenario), "--out", str(folder / "run.mcap"), "--quiet", cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder / "run.mcap"
