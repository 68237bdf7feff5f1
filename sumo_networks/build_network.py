"""Rebuild bridge.net.xml from the plain-XML sources with SUMO's netconvert.

Run from anywhere: ``python sumo_networks/build_network.py``. Coordinates are
kept as written (no offset normalisation) so that the bridge axis is x = 0..40
m, y = 0 in network coordinates; internal junction lanes are not generated so
that a vehicle is always on one of the named edges.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def netconvert_binary() -> str:
    """netconvert from the eclipse-sumo wheel, else from PATH."""
    try:
        import sumo  # the eclipse-sumo package

        candidate = Path(sumo.SUMO_HOME) / "bin" / "netconvert"
        if candidate.exists():
            return str(candidate)
    except (ImportError, AttributeError):
        pass
    found = shutil.which("netconvert")
    if not found:
        sys.exit("netconvert not found: pip install eclipse-sumo")
    return found


def main() -> int:
    cmd = [
        netconvert_binary(),
        "--node-files", str(HERE / "bridge.nod.xml"),
        "--edge-files", str(HERE / "bridge.edg.xml"),
        "--output-file", str(HERE / "bridge.net.xml"),
        "--offset.disable-normalization", "true",
        "--no-internal-links", "true",
        "--no-turnarounds", "true",
        "--output.street-names", "false",
        "--no-warnings", "true",
    ]
    return subprocess.call(cmd)


if __name__ == "__main__":
    raise SystemExit(main())
