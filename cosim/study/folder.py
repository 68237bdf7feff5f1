"""A study's output folder: the names of its files, and a writer that never leaves half a file.

::

    <output>/
      study.toml                 the study file, as given
      results.csv, results.parquet
      plots/<column>.png
      runs/<run id>/
        scenario.toml            the run's scenario
        sumo/                    its SUMO config, network, routes and additional files
        inputs/                  a road profile file of the base, if any
        run.mcap                 its log
        result.json              its row and the fingerprint of its inputs
"""
from __future__ import annotations

import os
from pathlib import Path

__all__ = [
    "LOG_FILE",
    "PLOTS_FOLDER",
    "RESULT_FILE",
    "RUNS_FOLDER",
    "SCENARIO_FILE",
    "STUDY_FILE",
    "SUMO_FOLDER",
    "TABLE_CSV",
    "TABLE_PARQUET",
    "write_file",
]

STUDY_FILE = "study.toml"
RUNS_FOLDER = "runs"
SUMO_FOLDER = "sumo"
SCENARIO_FILE = "scenario.toml"
LOG_FILE = "run.mcap"
RESULT_FILE = "result.json"
TABLE_CSV = "results.csv"
TABLE_PARQUET = "results.parquet"
PLOTS_FOLDER = "plots"


def write_file(path: Path, data: bytes | str) -> None:
    """Write through a temporary file, so a reader never sees half a file (text as UTF-8)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".part")
    if isinstance(data, str):
        data = data.encode("utf-8")
    partial.write_bytes(data)
    os.replace(partial, path)
