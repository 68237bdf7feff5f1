"""``cosim static``: the deck's static displacements under point loads anywhere on it (a table or JSON)."""
from __future__ import annotations

import argparse
import json
import textwrap
from typing import Any

from .options import FORMATTER, DashValue, Subcommands, bundled_text, finite_float
from .text import print_lines, scenario_line

NAME = "static"
#: ``--load X Y FZ``: "-1e5" is a value (:func:`cosim.cli.options.dash_values_kept`).
DASH_VALUES = {"--load": DashValue(nargs=3)}


def add_parser(commands: Subcommands) -> None:
    """``cosim static``: its arguments and help."""
    static = commands.add_parser(
        "static",
        help="static deck displacements under point loads anywhere on the deck",
        description=textwrap.dedent(
            """\
            Build the scenario's bridge, load it with the given vertical point loads acting
            together (consistent nodal loads, a static solve) and print the deck
            displacement under each load and at every sensor's point (mm, positive up),
            with the bending moment at bending-moment sensors. A load off the deck is an
            error (exit status 2). Vehicles and traffic of the scenario are ignored."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim static paper-double-tee --load 20 3.325 -100e3
              cosim static paper-double-tee --load 20 3.325 -50e3 --load 20 -3.325 -50e3 --json
            """
        )
        + "\n"
        + bundled_text(),
        formatter_class=FORMATTER,
    )
    static.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml) or bundled scenario name")
    static.add_argument("--load", nargs=3, type=finite_float, action="append", required=True,
                        metavar=("X", "Y", "FZ"),
                        help="a point load: x along the bridge (m), y lateral (m, positive left), Fz (N, positive "
                             "up: a downward load is negative); repeat for more loads")
    static.add_argument("--json", action="store_true",
                        help="print JSON (scenario, theory, loads and sensors with w in m, units) and nothing else")
    static.set_defaults(func=cmd_static)


def cmd_static(args: argparse.Namespace) -> int:
    """Solve the scenario's bridge under the ``--load`` point loads together; print the deck displacements."""
    from cosim.run.api import static_loads
    from cosim.run.payloads import jsonable
    from cosim.run.static import STATIC_UNITS

    done = static_loads(args.scenario, args.load)
    scenario, bridge, response = done.scenario, done.bridge, done.response
    if args.json:
        payload = {
            "scenario": scenario.title,
            "source": scenario.source,
            "theory": {"torsion": bridge.theory.torsion, "bending": bridge.theory.bending},
            **response,
            "units": STATIC_UNITS,
        }
        print(json.dumps(jsonable(payload), indent=2))
        return 0
    print(scenario_line(scenario))
    print_lines(static_lines(response))
    return 0


def static_lines(response: dict[str, Any]) -> list[str]:
    """The loads and the sensors with the deck displacement at each, in mm (positive up)."""
    rows = [(f"load {i}", "", p["x"], p["y"], f"{p['Fz'] / 1e3:.6g} kN", p["w"], None)
            for i, p in enumerate(response["loads"], start=1)]
    rows += [(s["name"], s["quantity"], s["x"], s["y"], "", s["w"], s.get("bending_moment"))
             for s in response["sensors"]]
    width = max(len(r[0]) for r in rows) + 2
    lines = ["Static point loads, acting together; deck displacement w [mm], positive up",
             f"  {'point':<{width}}{'quantity':<16}{'x [m]':>9}{'y [m]':>9}{'Fz':>14}{'w [mm]':>14}{'M [kN m]':>14}"]
    for name, quantity, x, y, force, w, moment in rows:
        moment_text = f"{moment / 1e3:14.4f}" if moment is not None else f"{'':>14}"
        lines.append(f"  {name:<{width}}{quantity:<16}{x:9.3f}{y:9.3f}{force:>14}{1e3 * w:14.4f}{moment_text}")
    if not response["sensors"]:
        lines.append("  (the scenario has no [[sensors]]: only the load points are reported)")
    return lines
