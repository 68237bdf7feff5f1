"""The SUMO that cosim runs: the ``sumo`` binary of the eclipse-sumo wheel, the networks shipped with cosim,
and SUMO's console captured into a file (it writes from C++, below Python's streams).

Light on purpose: resolving a bundled scenario's SUMO config loads neither libsumo nor the adapter.
"""
from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

__all__ = ["bundled_networks", "captured_output", "sumo_binary"]


def bundled_networks() -> Path:
    """Folder of the SUMO networks shipped with cosim (sumo_networks/)."""
    return Path(str(resources.files("sumo_networks")))


def sumo_binary() -> str:
    """The ``sumo`` executable of the eclipse-sumo wheel (for SUMO_HOME and data files)."""
    try:
        import sumo  # eclipse-sumo

        return str(Path(sumo.SUMO_HOME) / "bin" / "sumo")
    except (ImportError, AttributeError):
        return "sumo"


@contextlib.contextmanager
def captured_output(into: Path) -> Iterator[None]:
    """Whatever the process writes on its standard output and error inside the block goes to ``into``.

    SUMO reports a broken config on its standard error before its log exists;
    libsumo only raises "Process Error". Redirected at the file-descriptor
    level, since SUMO writes from C++.
    """
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(into, "ab") as sink:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            try:
                yield
            finally:
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
    finally:
        for fd in saved:
            os.close(fd)
