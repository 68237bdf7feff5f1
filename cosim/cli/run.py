"""``cosim run``: a scenario run into an MCAP log with its summary, or (without vehicles) its modes and a
static case.

The run is one call, :func:`cosim.run.api.run_scenario`, which checks, builds,
runs and writes; this module shows the run's header and progress through the
call's callbacks (:mod:`.summary`) and prints what it returns.
"""
from __future__ import annotations

import argparse
import textwrap
from typing import TYPE_CHECKING, Any

from cosim.run.static import STATIC_LOAD_N

from .options import FORMATTER, Subcommands, bundled_text
from .text import damping_lines, modes_lines, print_lines, scenario_line

if TYPE_CHECKING:
    from cosim.run.scenario import Scenario

NAME = "run"
#: The scenario of ``cosim run`` without one.
DEFAULT_SCENARIO = "paper-bridge-traffic"


def add_parser(commands: Subcommands) -> None:
    """``cosim run``: its arguments and help."""
    run = commands.add_parser(
        "run",
        help="run a scenario into an MCAP log (or, without vehicles, modes and a static case)",
        description=textwrap.dedent(
            f"""\
            Run a scenario; without SCENARIO, the bundled '{DEFAULT_SCENARIO}': the paper's
            40 m double-tee bridge under 10 minutes of medium two-way SUMO traffic on an
            ISO 8608 class A road.

            With [[vehicles]] (scripted) or [traffic] (SUMO): integrate the coupled vehicle-bridge equations in time and
            stream everything into an MCAP log: sensor samples, vehicles on the deck with
            their contact forces, traffic events (entered/left the deck, lift-off) and the
            run's status, with the scenario, its input files, resolved parameters, section
            constants and frequencies embedded (a log alone is enough to run it again:
            cosim replay). Then print a summary: sensor peaks, each vehicle's contact force
            and whether it lifted off, steps, wall time, real-time factor. A progress
            display goes to stderr. The log is finished whatever ends the run: Ctrl-C,
            SIGTERM or SIGHUP leave status "interrupted", a diverging solution status
            "error" with its likely cause. An existing file is replaced only with --force,
            and never the scenario or its input files.

            Without [[vehicles]]: the modal analysis (first 10 modes) and a static load
            case, a {STATIC_LOAD_N / 1e3:g} kN downward point load at mid-span of the longest span, once
            on the bridge axis (y = 0) and once at the left deck edge (largest y),
            with each sensor's deck displacement for both (no log).

            Exit status: 0 done, 1 the run failed after it started (the log ends with
            status "error"), 2 bad input, SUMO's included (nothing is written), 128 + N
            stopped by signal N: 130 Ctrl-C, 143 SIGTERM, 129 SIGHUP (the log ends with
            status "interrupted"; nothing is written if the run had not started)."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the default traffic run
                                                     # -> runs/{DEFAULT_SCENARIO}-<date>-<time>.mcap
              cosim run paper-double-tee             # the paper's two quarter-cars
              cosim run my-bridge.toml --out results/run1.mcap --csv results/run1.csv
              cosim run my-bridge-no-vehicles.toml --out summary.json
            """
        )
        + "\n"
        + bundled_text(),
        formatter_class=FORMATTER,
    )
    run.add_argument("scenario", metavar="SCENARIO", nargs="?", default=DEFAULT_SCENARIO,
                     help=f"scenario file (.toml) or bundled scenario name (default: {DEFAULT_SCENARIO})")
    run.add_argument("--out", metavar="PATH",
                     help="with vehicles: the MCAP log, LOG.mcap (default: [output].log, else "
                          "runs/<scenario name>-<YYYYmmdd-HHMMSS>.mcap; its folder is created); without "
                          "vehicles: write the modes and static displacements as JSON to PATH")
    run.add_argument("--csv", metavar="OUT.csv",
                     help="also write the sensor channels as CSV, columns t,<sensor names> (default: [output].csv "
                          "if given); the same as 'cosim export LOG --csv OUT.csv' after the run")
    run.add_argument("--force", "-f", action="store_true",
                     help="overwrite the log, the CSV or the summary if they exist (default: refuse; never "
                          "the scenario or its input files)")
    run.add_argument("--quiet", "-q", action="store_true",
                     help="no progress display on stderr")
    run.set_defaults(func=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    """With vehicles or traffic: the logged time simulation and its summary; without: modes and a static case."""
    from cosim.run.api import NO_VEHICLES, StaticRun, run_scenario
    from cosim.run.logged import RunFailed, RunInterrupted

    from .summary import RunDisplay, print_outcome

    display = RunDisplay(quiet=args.quiet)

    def checked(scenario: Scenario) -> None:
        print(scenario_line(scenario))
        if not scenario.vehicles and scenario.traffic is None:
            print(f"note: {NO_VEHICLES}")

    try:
        done = run_scenario(args.scenario, out=args.out, csv=args.csv, force=args.force, checked=checked,
                            ready=display.ready, progress=display)
    except (RunFailed, RunInterrupted) as exc:
        return display.stopped(exc)
    finally:
        display.close()
    if isinstance(done, StaticRun):
        print_lines(["", *damping_lines(done.bridge), ""])
        print_lines(modes_lines(done.modal))
        print()
        print_lines(_static_lines(done.scenario, done.cases))
        if args.out is not None:
            print(f"\nWrote the summary to {args.out}")
        return 0
    print_outcome(done.outcome)
    if done.csv_path is not None:
        print(f"Wrote {done.csv_rows} rows to {done.csv_path} (columns {','.join(done.csv_columns)}; "
              "SI units: m, m/s, m/s^2, N m)")
    return 0


def _static_lines(scenario: Scenario, cases: tuple[dict[str, Any], ...]) -> list[str]:
    load = cases[0]["load"]
    heads = [f"load at y = {c['load']['y']:g} m" for c in cases]
    lines = [
        f"Static load case: {STATIC_LOAD_N / 1e3:g} kN downward at x = {load['x']:g} m "
        f"(mid-span of span {load['span']}); deck displacement w [mm], positive up",
    ]
    rows: list[tuple[str, str, float, float | None, list[float]]] = [
        (s.name, s.quantity, s.x, s.y, [c["sensors"][s.name] for c in cases]) for s in scenario.sensors]
    rows.append(("(under the load)", "displacement", load["x"], None, [c["w_load_point"] for c in cases]))
    width = max(len(row[0]) for row in rows) + 2
    lines.append(f"  {'point':<{width}}{'quantity':<16}{'x [m]':>8}{'y [m]':>9}" + "".join(f"{h:>22}" for h in heads))
    for name, quantity, x, y, values in rows:
        y_text = f"{y:9.3f}" if y is not None else f"{'-':>9}"
        lines.append(f"  {name:<{width}}{quantity:<16}{x:8.3f}{y_text}" + "".join(f"{1e3 * v:22.4f}" for v in values))
    if not scenario.sensors:
        lines.append("  (the scenario has no [[sensors]]; only the load point is reported)")
    return lines
