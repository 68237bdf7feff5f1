"""``cosim modes``: a scenario's section constants, damping and natural modes (a table, JSON or a figure)."""
from __future__ import annotations

import argparse
import json
import textwrap
from typing import TYPE_CHECKING

from cosim.plots import MAX_MODE_SHAPES

from .options import FORMATTER, Subcommands, bundled_text, positive_int
from .text import damping_lines, modes_lines, print_lines, scenario_line, section_lines

if TYPE_CHECKING:
    from cosim.core.bridge import BridgeModel

NAME = "modes"


def add_parser(commands: Subcommands) -> None:
    """``cosim modes``: its arguments and help."""
    modes = commands.add_parser(
        "modes",
        help="section constants and natural modes of a scenario's bridge",
        description=textwrap.dedent(
            """\
            Build the scenario's bridge and print its section constants (A, centroid C,
            shear centre S, I_y, I_z, I_yz, J, I_w, shear areas), its Rayleigh damping
            coefficients and a table of its lowest natural modes: frequency, kind
            (vertical, lateral, torsion, axial or coupled) and effective modal mass
            fractions for vertical, lateral and torsional motion."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim modes paper-double-tee
              cosim modes paper-double-tee --count 20 --json > modes.json
              cosim modes my-bridge.toml --plot modes.png
            """
        )
        + "\n"
        + bundled_text(),
        formatter_class=FORMATTER,
    )
    modes.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml) or bundled scenario name")
    modes.add_argument("--count", "-n", type=positive_int, default=10, metavar="N",
                       help="number of modes to compute (default: 10)")
    modes.add_argument("--json", action="store_true",
                       help="print JSON (scenario, theory, section, damping, nodes_x, modes with n, f_hz, kind, "
                            "participation and the mass-normalised nodal shape: w on the axis, theta_x, v) and "
                            "nothing else on stdout")
    modes.add_argument("--plot", metavar="FILE.png",
                       help=f"draw the first N (at most {MAX_MODE_SHAPES}) mode shapes: v, w and twist theta_x "
                            "along x, each normalised")
    modes.add_argument("--force", "-f", action="store_true", help="overwrite the --plot figure if it exists")
    modes.set_defaults(func=cmd_modes)


def theory_lines(bridge: BridgeModel) -> list[str]:
    """The element's theories (docs/theory.md §10), and the constants only they use."""
    theory, section = bridge.theory, bridge.section
    lines = [f"Element: {theory.torsion} torsion, {theory.bending} bending"]
    if section.I_ws is not None:
        lines.append(f"  I_ws   = {section.I_ws:.6g} m^4   (warping shear, secondary torsion"
                     f"{'' if theory.torsion == 'benscoter' else '; used by torsion = benscoter'})")
    if section.mass_per_length is not None:
        lines.append(f"  mass   = {section.mass_per_length:.6g} kg/m   (given, replaces rho A)")
    if not section.rotary_inertia:
        lines.append("  rotary inertia of the bending rotations: off")
    return lines


def cmd_modes(args: argparse.Namespace) -> int:
    """Print the modes of a scenario's bridge (``--json``: only JSON); ``--plot`` draws the first shapes."""
    from cosim.run.api import bridge_modes
    from cosim.run.payloads import SHAPE_NOTE, damping_payload, jsonable, modes_payload, section_payload

    done = bridge_modes(args.scenario, args.count, plot=args.plot, force=args.force)
    scenario, bridge, modal = done.scenario, done.bridge, done.modal
    if args.json:
        payload = {
            "scenario": scenario.title,
            "source": scenario.source,
            "theory": {"torsion": bridge.theory.torsion, "bending": bridge.theory.bending},
            "nodes_x": bridge.nodes_x,
            "shape_note": SHAPE_NOTE,
            "modes": modes_payload(modal, shapes=True),
            "section": section_payload(bridge.section),
            "damping": damping_payload(bridge),
        }
        print(json.dumps(jsonable(payload), indent=2))
    else:
        print_lines([scenario_line(scenario), ""])
        print_lines(section_lines(bridge.section))
        print_lines(theory_lines(bridge))
        print_lines(["", *damping_lines(bridge), ""])
        print_lines(modes_lines(modal))
    if args.plot and not args.json:
        print(f"\nWrote {done.plotted} mode shape(s) to {args.plot}")
    return 0
