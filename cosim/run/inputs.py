"""The input files a scenario refers to (road profile, WIM record file, SUMO config and the files it names).

A log carries them as attachments, so that it can be replayed without the
originals (:mod:`cosim.run.logged`, :mod:`cosim.run.replay`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from cosim.sumo import sumo_input_files

from .scenario import Scenario


@dataclass(frozen=True)
class InputFile:
    """A file the scenario refers to: its dotted key, the path as written, the file, and its attachment name."""

    key: str
    written: str
    path: Path
    attachment: str


def input_files(scenario: Scenario) -> list[InputFile]:
    """The scenario's input files (the road profile, the record file, the SUMO config and the files it names),
    with the names they get in a log.

    A relative path inside the scenario's folder keeps its name (``data/road.csv``);
    any other path is stored as ``inputs/<file name>``.
    """
    found = []
    profile = scenario.road_profile_path
    if profile is not None and scenario.road.profile is not None:
        found.append(_own_file("road.profile", scenario.road.profile, profile))
    records = scenario.records_path
    if records is not None and scenario.records is not None:
        found.append(_own_file("traffic.records.file", scenario.records.file, records))
    sumo_cfg = scenario.sumo_config_path
    if sumo_cfg is not None:
        for path in sumo_input_files(sumo_cfg):
            rel = path.relative_to(sumo_cfg.parent) if path.is_relative_to(sumo_cfg.parent) else Path(path.name)
            # Only the config is a scenario key; the files it names travel along as plain attachments.
            key = "traffic.sumo_config" if path == sumo_cfg else ""
            found.append(InputFile(key, str(path), path, f"sumo/{rel.as_posix()}"))
    return found


def _own_file(key: str, written: str, path: Path) -> InputFile:
    """A file a scenario key names: a relative path inside the scenario's folder keeps its name in a log, any
    other is ``inputs/<file name>``."""
    pure = PurePosixPath(written.replace("\\", "/"))
    safe = not pure.is_absolute() and ".." not in pure.parts and not re.match(r"^[A-Za-z]:", written)
    return InputFile(key, written, path, str(pure) if safe else f"inputs/{pure.name}")


def scenario_files(scenario: Scenario) -> list[tuple[str, Path]]:
    """Every file a run of ``scenario`` reads, as (what it is, path): the scenario file and its input files.

    For :func:`cosim.run.outputs.check_not_input`: no output of a command may be one of these.
    """
    found: list[tuple[str, Path]] = []
    source = Path(scenario.source)
    if source.is_file():
        found.append(("the scenario", source))
    for item in input_files(scenario):
        found.append((f"an input file of the scenario ({item.key or 'SUMO'})", item.path))
    return found
