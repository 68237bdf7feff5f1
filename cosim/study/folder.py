"""A study's output folder: the names of its files, and a writer that never leaves half a file.

::

    <output>/
      study.toml                 the study file, as given
      study.json                 whose folder this is: the study's name and file
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

import contextlib
import os
import secrets
from pathlib import Path

__all__ = [
    "LOG_FILE",
    "PLOTS_FOLDER",
    "RESULT_FILE",
    "RUNS_FOLDER",
    "SCENARIO_FILE",
    "STOP_FILE",
    "STUDY_FILE",
    "STUDY_ID_FILE",
    "SUMO_FOLDER",
    "TABLE_CSV",
    "TABLE_PARQUET",
    "write_file",
]

STUDY_FILE = "study.toml"
#: Which study the folder belongs to (a study's folder holds one study: --out into another's is refused).
STUDY_ID_FILE = "study.json"
#: Present while a stopped study asks its runs on the workers to stop (holds the signal's name).
STOP_FILE = ".stop"
RUNS_FOLDER = "runs"
SUMO_FOLDER = "sumo"
SCENARIO_FILE = "scenario.toml"
LOG_FILE = "run.mcap"
RESULT_FILE = "result.json"
TABLE_CSV = "results.csv"
TABLE_PARQUET = "results.parquet"
PLOTS_FOLDER = "plots"


def write_file(path: Path, data: bytes | str) -> None:
    """Write through a temporary file in the same folder, flushed to disk and renamed over ``path``:
    a reader never sees half a file, and a failure (or a signal) leaves ``path`` as it was."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.{secrets.token_hex(4)}.part")
    if isinstance(data, str):
        data = data.encode("utf-8")
    try:
        with open(partial, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(partial, path)
    finally:
        with contextlib.suppress(OSError):
            partial.unlink(missing_ok=True)
