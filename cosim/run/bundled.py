"""The scenarios shipped with cosim (``cosim/scenarios/*.toml``): where they are and their names.

Importing this loads nothing but the standard library: the command line's
help lists the bundled scenarios without loading the scenario machinery
(:mod:`.scenario` loads them).
"""
from __future__ import annotations

from importlib import resources
from importlib.resources.abc import Traversable


def bundled_folder() -> Traversable:
    """The folder of the bundled scenarios, inside the installed package."""
    return resources.files("cosim").joinpath("scenarios")


def list_bundled_scenarios() -> list[str]:
    """Names of the scenarios shipped with cosim (usable wherever a scenario path is)."""
    folder = bundled_folder()
    if not folder.is_dir():
        return []
    return sorted(item.name[: -len(".toml")] for item in folder.iterdir() if item.name.endswith(".toml"))
