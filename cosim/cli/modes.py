"""``cosim modes``: a scenario's section constants, damping and natural modes (a table, JSON or a figure)."""
from __future__ import annotations

import argparse
import json

from cosim import plots
from cosim.core.bridge import BridgeModel
from cosim.run.figures import plot_modes
from cosim.run.inputs import scenario_files
from cosim.run.outputs import check_not_input, check_writable
from cosim.run.payloads import SHAPE_NOTE, damping_payload, jsonable, modes_payload, section_payload
from cosim.run.scenario import load_scenario

from .text import damping_lines, modes_lines, print_lines, scenario_line, section_lines


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
    scenario = load_scenario(args.scenario)
    if args.plot:
        check_not_input(args.plot, "plot", scenario_files(scenario))
        check_writable(args.plot, "plot", plots.figure_formats(), force=args.force)
    bridge = scenario.build_bridge()
    modal = bridge.modes(count=args.count)
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
    if args.plot:
        plotted = plot_modes(bridge, modal, args.plot, args.count)
        if not args.json:
            print(f"\nWrote {plotted} mode shape(s) to {args.plot}")
    return 0
