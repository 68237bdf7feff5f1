"""``cosim layout``: the Foxglove layout made for a log's run, as a file to import into Foxglove."""
from __future__ import annotations

import argparse
from pathlib import Path

from cosim.errors import CosimError
from cosim.log.layout import inputs_from_log, layout_bytes, make_layout
from cosim.log.reader import open_log
from cosim.run.outputs import atomic_write, check_new_file, check_not_input


def cmd_layout(args: argparse.Namespace) -> int:
    """Write the layout of a log's run (made from what the log records, as the run attached it)."""
    log, out = Path(args.log), Path(args.output)
    check_not_input(out, "layout", [("the log", log)])
    if out.suffix.lower() != ".json":
        raise CosimError(f"{out}: a Foxglove layout is a JSON file: expected a name ending in .json")
    overview = open_log(log)
    inputs = inputs_from_log(overview)
    check_new_file(out, "layout", args.force)
    with atomic_write(out, "layout") as partial:
        partial.write_bytes(layout_bytes(make_layout(inputs)))
    panels = ["a plot per sensor quantity" if inputs.sensors else "", "contact forces",
              "SUMO traffic" if inputs.sumo else "vehicle positions", "the vehicles on the deck", "events, status",
              "the 3D scene" if inputs.scene else ""]
    print(f"Wrote the Foxglove layout of {log} to {out} ({', '.join(p for p in panels if p)}); "
          "import it in Foxglove with Layouts -> Import from file")
    return 0
