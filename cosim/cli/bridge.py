"""``cosim bridge NET_OR_SUMOCFG [--edge ID ...] [--near X Y] [--plot FIG.png]``: find a bridge in a network.

Without ``--edge``: candidate bridges (two-way edge pairs between two
junctions, one-way edges), those the network marks as OSM bridges first, then
the nearest to ``--near`` (else the longest). With ``--edge``: where that
bridge is (the rule of :mod:`cosim.sumo.network`), its lanes, and the
``[bridge]``/``[traffic]`` lines to paste into a scenario; ``--plot`` draws the
network around it with the deck outline, the axis and the lanes.
"""
from __future__ import annotations

import argparse
import json
import math
import shlex
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.errors import CosimError

from .options import FORMATTER, DashValue, Subcommands, positive_int
from .text import print_lines

if TYPE_CHECKING:
    from cosim.sumo.network import BridgeLocation

NAME = "bridge"
#: ``--edge -148050455#0``: a SUMO edge id beginning with "-" is a value (:func:`cosim.cli.options.dash_values_kept`).
DASH_VALUES = {"--edge": DashValue(numbers=False)}
#: Candidates listed without --count.
DEFAULT_COUNT = 15


def add_parser(commands: Subcommands) -> None:
    """``cosim bridge``: its arguments and help."""
    bridge = commands.add_parser(
        "bridge",
        help="find a bridge in a SUMO network: candidates, or one bridge's axis, lanes and scenario lines",
        description=textwrap.dedent(
            """\
            Without --edge: list candidate bridges of a SUMO network (or of the network a
            .sumocfg names): two-way edge pairs between two junctions and one-way edges,
            with length, lanes, street names and the OSM bridge attribute where the network
            kept them; edges marked as OSM bridges first, then the nearest to --near X Y
            (network coordinates), else the longest.

            With --edge (repeat it for each edge the deck carries): the bridge's axis (the
            carriageway's centre line, x = 0 where the named lanes begin, +x the first edge's
            direction of travel), length, lanes and their lateral positions, the junctions at
            its ends, and the [bridge]/[traffic] lines to paste into a scenario; --plot draws
            the network around it with the deck outline, the axis and the lanes."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim bridge city.sumocfg --near 720 230
              cosim bridge city.sumocfg --edge 39 --edge 40
              cosim bridge city.net.xml.gz --edge 113 --edge "43[1]" --plot bridge.png
            """
        ),
        formatter_class=FORMATTER,
    )
    bridge.add_argument("network", metavar="NET_OR_SUMOCFG", help="a SUMO network (.net.xml[.gz]) or config (.sumocfg)")
    bridge.add_argument("--edge", action="append", metavar="ID", help="an edge the deck carries (repeat for more)")
    bridge.add_argument("--near", nargs=2, type=float, metavar=("X", "Y"),
                        help="list the candidates nearest to this point (network coordinates, m) first")
    bridge.add_argument("--count", "-n", type=positive_int, metavar="N",
                        help=f"candidates to list (default: {DEFAULT_COUNT})")
    bridge.add_argument("--plot", metavar="FIG.png", help="draw the network around the bridge (needs --edge)")
    bridge.add_argument("--force", "-f", action="store_true", help="overwrite FIG if it exists")
    bridge.set_defaults(func=cmd_bridge)


def cmd_bridge(args: argparse.Namespace) -> int:
    """List candidate bridges, or describe one and print its scenario lines."""
    from cosim.run.figures import plot_bridge_location
    from cosim.run.outputs import check_new_file
    from cosim.sumo.network import locate_bridge, net_path

    source = Path(args.network)
    if not source.is_file():
        raise CosimError(f"{source}: no such file (give a SUMO network, .net.xml[.gz], or a config, .sumocfg)")
    net = net_path(source)
    if args.plot is not None:
        if not args.edge:
            raise CosimError("--plot draws one bridge: give its edges with --edge")
        check_new_file(Path(args.plot), "plot", args.force)
    if not args.edge:
        print_lines(_candidate_lines(net, args))
        return 0
    location = locate_bridge(net, args.edge)
    print_lines(_location_lines(location, source, args))
    if args.plot is not None:
        plot_bridge_location(location, Path(args.plot))
        print(f"\nWrote the network around the bridge to {args.plot}")
    return 0


def _candidate_lines(net: Path, args: argparse.Namespace) -> list[str]:
    from cosim.sumo.network import bridge_candidates, edge_options

    near = tuple(args.near) if args.near is not None else None
    found = bridge_candidates(net, near=near)
    count = args.count or DEFAULT_COUNT
    order = (f"nearest to ({near[0]:g}, {near[1]:g}) first" if near is not None else "longest first")
    lines = [f"Candidate bridges in {net.name}: {len(found)} (OSM bridges first, then {order}; "
             f"{min(count, len(found))} shown)"]
    if not found:
        return lines
    rows = []
    for c in found[:count]:
        where = f"({c.middle[0]:.1f}, {c.middle[1]:.1f})"
        distance = f"{math.dist(c.middle, near):.0f} m away" if near is not None else ""
        extra = "; ".join(x for x in (", ".join(c.names), f"OSM bridge={'/'.join(c.osm_bridge)}"
                                      if c.osm_bridge else "", distance) if x)
        rows.append((edge_options(c.edges), c.kind, f"{c.length:.1f}",
                     " + ".join(str(n) for n in c.lanes), where, extra))
    heads = ("edges", "kind", "length [m]", "lanes", "middle (x, y)", "")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(heads[:-1])]
    fmt = "  " + "  ".join(f"{{:<{w}}}" for w in widths) + "  {}"
    lines += [fmt.format(*heads).rstrip(), *(fmt.format(*r).rstrip() for r in rows)]
    lines.append(f"Describe one and get its scenario lines: cosim bridge {shlex.quote(str(args.network))} "
                 "--edge=ID [--edge=ID]")
    return lines


def _location_lines(loc: BridgeLocation, source: Path, args: argparse.Namespace) -> list[str]:
    from cosim.sumo.network import wheel_paths_beyond

    axis = loc.axis
    (x0, y0), (x1, y1) = axis.start, axis.end
    heading = math.degrees(math.atan2(y1 - y0, x1 - x0))
    lo, hi = loc.carriageway
    per_direction = {d: sum(1 for lane in loc.lanes if lane.direction == d) for d in (1, -1)}
    kind = (f"two-way, {per_direction[1]} + {per_direction[-1]} lanes" if loc.two_way
            else f"one-way, {per_direction[1]} lane{'s' if per_direction[1] > 1 else ''}")
    lines = [
        f"Bridge on edges {', '.join(loc.edges)} of {loc.net.name} ({kind})",
        f"  axis: ({x0:.3f}, {y0:.3f}) -> ({x1:.3f}, {y1:.3f}) in network coordinates, {axis.length:.3f} m, "
        f"heading {heading:.1f} deg from the network's x axis; +x is edge {loc.edges[0]}'s direction of travel",
        "  rule: the axis runs along the carriageway's centre line (midway between the outer edges of the outer "
        "lanes), from where the named lanes begin to where they end",
        f"  carriageway: y = {lo:.3f} to {hi:.3f} m ({hi - lo:.3f} m wide)",
    ]
    for lane in loc.lanes:
        lines.append(f"  lane {lane.id}: y = {lane.y:+.3f} m, {lane.width:.2f} m wide, "
                     f"{'+x' if lane.direction > 0 else '-x'}, x = {lane.x_range[0]:.2f} to {lane.x_range[1]:.2f} m")
    beyond = wheel_paths_beyond(loc, loc.carriageway, "the carriageway")
    if beyond:
        lines.append(f"  {beyond}")
    for lane in loc.footways:
        lines.append(f"  sidewalk {lane.id}: y = {lane.y:+.3f} m, {lane.width:.2f} m wide: not loaded (cosim models no "
                     "pedestrians), so the deck need not cover it")
    if loc.opposite:
        lines.append(f"  also watched in a run: {', '.join(loc.opposite)} (the other direction between the same "
                     "junctions; name it too if the deck carries it)")
    lines.append("  junctions at the ends: " + ", ".join(f"{j} ({t})" for j, t in loc.junctions))
    lines.append(f"  street: {', '.join(loc.names) or 'no name in the network'}; OSM bridge: "
                 f"{', '.join(loc.osm_bridge) or 'not recorded in the network'}")
    config = str(source) if source.name.endswith(".sumocfg") else "YOUR.sumocfg"
    margin = 0.5
    lines += [
        "",
        "Scenario lines (paste them; the section's deck must cover the carriageway):",
        "[bridge]",
        f"spans = [{axis.length:.3f}]                # the deck along the axis, m (split it as the real bridge's "
        "spans are)",
        f"# deck: at least y = {lo:.3f} to {hi:.3f} m, e.g. [bridge.section.constants] "
        f"deck_y = [{lo - margin:.2f}, {hi + margin:.2f}]",
        "",
        "[traffic]",
        f"sumo_config = {json.dumps(config)}" + ("" if config != "YOUR.sumocfg" else "   # the config to run")
        + "   # relative to the scenario file's folder",
        f"edges = {json.dumps(list(loc.edges))}",
        f"# axis = [[{x0:.3f}, {y0:.3f}], [{x1:.3f}, {y1:.3f}]]   # derived from the edges as above; "
        "give it only to override",
    ]
    return lines

