"""``cosim replay``: a bridge re-driven with the traffic recorded in a log, and its sensors against the log's.

The replay is one call, :func:`cosim.run.replay.replay_log`; this module shows
its header and progress through the call's callbacks (:mod:`.summary`) and
prints what it returns.
"""
from __future__ import annotations

import argparse
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.run.units import display_unit

from .options import FORMATTER, Subcommands
from .text import EXIT_RUN_FAILED, print_lines

if TYPE_CHECKING:
    from cosim.run.replay import Comparison, ReplayPlan
    from cosim.run.scenario import Scenario

NAME = "replay"


def add_parser(commands: Subcommands) -> None:
    """``cosim replay``: its arguments and help."""
    replay = commands.add_parser(
        "replay",
        help="re-drive a bridge with the traffic recorded in a log",
        description=textwrap.dedent(
            """\
            Re-drive a bridge with the traffic of a log: the [[vehicles]] of the scenario
            embedded in the log (parsed, never executed). Without --scenario, the log's own
            scenario runs again: its sensor channels are compared with the log's and must
            be identical, bit for bit (exit status 1 if they are not). With --scenario
            OTHER, the bridge, sensors, road and solver come from OTHER and the vehicles
            from the log: what would this traffic do to that bridge? The replay is logged
            like a run; [output].log and [output].csv of the scenarios are not used.

            Exit status: 0 done, 1 the solution diverged or (own scenario) the channels
            differ, 2 bad input (unreadable or damaged log, an input file the log does not
            hold, a vehicle off OTHER's deck, ...), 128 + N stopped by signal N (130
            Ctrl-C, 143 SIGTERM, 129 SIGHUP)."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim replay runs/paper-double-tee-20250101-120000.mcap
              cosim replay runs/run1.mcap --scenario paper-double-tee-asymmetric --out runs/asym.mcap
            """
        ),
        formatter_class=FORMATTER,
    )
    replay.add_argument("log", metavar="LOG.mcap", help="a log written by cosim run (or replay)")
    replay.add_argument("--scenario", metavar="OTHER",
                        help="scenario file or bundled name whose bridge, sensors, road and solver to use")
    replay.add_argument("--out", metavar="NEW.mcap",
                        help="the replay's log (default: runs/<scenario name>-replay-<YYYYmmdd-HHMMSS>.mcap)")
    replay.add_argument("--force", "-f", action="store_true", help="overwrite NEW.mcap if it exists")
    replay.add_argument("--quiet", "-q", action="store_true", help="no progress display on stderr")
    replay.set_defaults(func=cmd_replay)


def cmd_replay(args: argparse.Namespace) -> int:
    """Re-drive the log's bridge (or ``--scenario``'s) with its traffic, logged; compare the sensors."""
    from cosim.run.logged import RunFailed, RunInterrupted
    from cosim.run.replay import replay_log

    from .summary import RunDisplay, print_outcome

    log = Path(args.log)
    display = RunDisplay(quiet=args.quiet)

    def checked(plan: ReplayPlan) -> None:
        scenario = plan.scenario
        if plan.traffic is not None:
            what = f"its SUMO traffic ({plan.record.get('traffic', 'logged frames')}; SUMO is not run again)"
        else:
            ids = ", ".join(v.id for v in scenario.vehicles)
            what = f"its {len(scenario.vehicles)} scripted vehicle(s) {ids}"
        print(f"Replay of {log} ({plan.record['log_scenario']}, {plan.overview.status_word}): {what}")
        bridge_from = "the log's own scenario" if plan.own else plan.record["scenario"]
        print(f"Bridge, sensors, road and solver: {bridge_from} ({scenario.title})")

    try:
        done = replay_log(log, args.scenario, out=args.out, force=args.force, checked=checked,
                          ready=display.ready, progress=display)
    except (RunFailed, RunInterrupted) as exc:
        return display.stopped(exc)
    finally:
        display.close()
    print_outcome(done.outcome)
    print()
    if done.own:
        return _print_reproduction(done.comparison, log)
    print_lines(_comparison_lines(done.comparison, log, done.outcome.log_path, done.start.scenario))
    return 0


def _print_reproduction(comparison: Comparison, log: Path) -> int:
    n = len(comparison.names)
    part = ""
    if comparison.samples_a != comparison.samples_b:  # e.g. the log was interrupted: compare what it holds
        part = f"; the log holds {comparison.samples_a}, the replay {comparison.samples_b}"
    if comparison.identical:
        print(f"Compared with {log}: the {n} sensor channel(s) are identical, bit for bit "
              f"({comparison.compared} samples{part})")
        return 0
    worst = ", ".join(f"{k} {v:.3g}" for k, v in comparison.max_abs_diff.items())
    print(f"Compared with {log}: the sensor channels DIFFER (largest |difference|, SI units: {worst}; "
          f"{comparison.compared} samples compared)")
    return EXIT_RUN_FAILED


def _comparison_lines(comparison: Comparison, log: Path, new: Path, scenario: Scenario) -> list[str]:
    quantities = {s.name: s.quantity for s in scenario.sensors}
    if not comparison.names:
        return [f"Compared with {log}: no sensor of the same name in both logs"]
    width = max(len("name"), *(len(n) for n in comparison.names))
    lines = [f"Sensors of the same name, the logged run vs this bridge ({new}):",
             f"  {'name':<{width}}{'log min':>12}{'log max':>12}{'new min':>12}{'new max':>12}  unit"]
    for name in comparison.names:
        unit, factor = display_unit(quantities.get(name, ""))
        (a0, a1), (b0, b1) = comparison.extremes_a[name], comparison.extremes_b[name]
        lines.append(f"  {name:<{width}}{a0 * factor:12.4g}{a1 * factor:12.4g}{b0 * factor:12.4g}"
                     f"{b1 * factor:12.4g}  {unit}")
    return lines
