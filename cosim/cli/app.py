"""The ``cosim`` command line: the parser, :func:`main` and how errors become exit statuses.

Subcommands (each in its module: :mod:`.run`, :mod:`.logs`, :mod:`.layout`, :mod:`.modes`,
:mod:`.static`, :mod:`.study`, :mod:`.validate`)::

    cosim modes SCENARIO [--count N] [--json] [--plot FILE.png]
    cosim static SCENARIO --load X Y FZ [--load X Y FZ ...] [--json]
    cosim run [SCENARIO] [--out LOG.mcap] [--csv OUT.csv] [--force] [--quiet]
    cosim replay LOG.mcap [--scenario OTHER] [--out NEW.mcap] [--force] [--quiet]
    cosim export LOG.mcap --csv OUT.csv [--topic TOPIC] [--from T0] [--to T1] [--force]
    cosim info LOG.mcap [--verify]
    cosim plot LOG.mcap [--sensor NAME ...] [--from T0] [--to T1] -o FIG.png [--force]
    cosim layout LOG.mcap -o LAYOUT.json [--force]
    cosim validate [--out DIR] [--quick]
    cosim study STUDY.toml [--workers N] ...
    cosim dataset SPEC.toml [--out FOLDER] [--force]
    cosim bridge NET_OR_SUMOCFG [--edge ID ...] [--near X Y] [--plot FIG.png]

The work is done by :mod:`cosim.run` (and :mod:`cosim.study`,
:mod:`cosim.validation`); the command line parses, checks and prints, and is
the only package that prints.

Every :class:`cosim.errors.CosimError` becomes ``cosim: error: <message>`` on
stderr and exit status 2 (as for usage errors); a :class:`cosim.errors.ModelError`
after the time stepping started (the solution diverged) exits with 1 (the log then
ends with status "error"); SIGINT (Ctrl-C), SIGTERM and SIGHUP exit with 128 +
the signal's number, 130, 143 and 129 (a started log ends with status "interrupted").
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import textwrap

from cosim import __version__
from cosim.errors import CosimError
from cosim.log.schemas import TOPIC_EVENTS, TOPIC_SENSORS, TOPIC_STATUS, TOPIC_VEHICLES
from cosim.plots import MAX_MODE_SHAPES
from cosim.run.export import EXPORT_TOPICS
from cosim.run.scenario import list_bundled_scenarios
from cosim.run.static import STATIC_LOAD_N

from . import report_interruption
from .bridge import DEFAULT_COUNT, cmd_bridge
from .dataset import cmd_dataset
from .layout import cmd_layout
from .logs import cmd_export, cmd_info, cmd_plot
from .modes import cmd_modes
from .run import DEFAULT_SCENARIO, cmd_replay, cmd_run
from .static import cmd_static
from .study import cmd_study
from .text import EXIT_USAGE, report_error
from .validate import cmd_validate


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {value}")
    return value


def finite_float(text: str) -> float:
    """argparse type: a finite number (``nan`` and ``inf`` are refused)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


#: Negative numbers argparse must read as values, not options: Python < 3.13 reads "-1e5" as an option.
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def bundled_text() -> str:
    """The help's note on SCENARIO, with the bundled scenarios' names."""
    names = ", ".join(list_bundled_scenarios()) or "none"
    return textwrap.fill(f"SCENARIO is a path to a .toml file or the name of a bundled scenario ({names}).", 79)


def _window_arguments(parser: argparse.ArgumentParser, verb: str) -> None:
    """``--from T0`` and ``--to T1``: a window of simulated time (export and plot)."""
    parser.add_argument("--from", dest="start", type=float, metavar="T0",
                        help=f"{verb} from t = T0 s of simulated time (default: the log's start)")
    parser.add_argument("--to", dest="end", type=float, metavar="T1",
                        help=f"{verb} up to t = T1 s, included (default: the log's end)")
    parser._negative_number_matcher = NEGATIVE_NUMBER  # "--from -5" is a value (see NEGATIVE_NUMBER)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``cosim`` program."""
    formatter = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(
        prog="cosim",
        description=textwrap.dedent(
            """\
            Co-simulation of road traffic and bridge vibration: a 7-DOF
            Timoshenko-Vlasov beam model of the bridge (shear deformation,
            rotary inertia, uniform and non-uniform torsion) driven by scripted
            vehicles or by SUMO traffic, every run logged to MCAP.
            Scenarios are TOML files (see docs/scenario.md); SI units throughout."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the bundled default bridge ({DEFAULT_SCENARIO}) -> runs/*.mcap
              cosim run my-bridge.toml --out run1.mcap
              cosim info run1.mcap
              cosim export run1.mcap --csv run1.csv
              cosim plot run1.mcap -o run1.png
              cosim layout run1.mcap -o run1-layout.json   # for Foxglove
              cosim replay run1.mcap --scenario other-bridge.toml
              cosim modes paper-double-tee --count 12 --plot modes.png
              cosim static paper-double-tee --load 20 3.325 -100e3
            """
        )
        + "\n"
        + bundled_text()
        + "\nErrors print 'cosim: error: ...' on stderr and exit with status 2; SIGINT, SIGTERM and SIGHUP\n"
        "exit with 128 + the signal's number. Limits on input sizes: docs/limits.md.",
        formatter_class=formatter,
    )
    parser.add_argument("--version", action="version", version=f"cosim {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")
    commands.required = True

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
        formatter_class=formatter,
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
        formatter_class=formatter,
    )
    static.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml) or bundled scenario name")
    static.add_argument("--load", nargs=3, type=finite_float, action="append", required=True,
                        metavar=("X", "Y", "FZ"),
                        help="a point load: x along the bridge (m), y lateral (m, positive left), Fz (N, positive "
                             "up: a downward load is negative); repeat for more loads")
    static.add_argument("--json", action="store_true",
                        help="print JSON (scenario, theory, loads and sensors with w in m, units) and nothing else")
    static._negative_number_matcher = NEGATIVE_NUMBER  # "-1e5" is a value here (see NEGATIVE_NUMBER)
    static.set_defaults(func=cmd_static)

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
        formatter_class=formatter,
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
        formatter_class=formatter,
    )
    replay.add_argument("log", metavar="LOG.mcap", help="a log written by cosim run (or replay)")
    replay.add_argument("--scenario", metavar="OTHER",
                        help="scenario file or bundled name whose bridge, sensors, road and solver to use")
    replay.add_argument("--out", metavar="NEW.mcap",
                        help="the replay's log (default: runs/<scenario name>-replay-<YYYYmmdd-HHMMSS>.mcap)")
    replay.add_argument("--force", "-f", action="store_true", help="overwrite NEW.mcap if it exists")
    replay.add_argument("--quiet", "-q", action="store_true", help="no progress display on stderr")
    replay.set_defaults(func=cmd_replay)

    topics = ", ".join(EXPORT_TOPICS)
    export = commands.add_parser(
        "export",
        help="write a topic of a log as CSV (default: the sensor channels)",
        description=textwrap.dedent(
            f"""\
            Write a topic of a log as CSV with a header row, SI units, numbers in their
            shortest exact form. {TOPIC_SENSORS} (default): columns t,<sensor names>, one row
            per sample. {TOPIC_VEHICLES}: one row per vehicle on the deck per sample (t, id,
            model, x, y, speed, acceleration, body_displacement, body_acceleration,
            contact_force). {TOPIC_EVENTS} and {TOPIC_STATUS}: one row per message.
            --from/--to: only the messages from T0 to T1 s of simulated time (both
            included; either bound alone is fine): a finished log's chunk index is used
            to read only the chunks in the window (10 minutes of a day-long log take about
            as long as a 10-minute log). A log cut short is exported up to its last
            complete chunk (it has no index: it is read whole)."""
        ),
        epilog="examples:\n  cosim export runs/run1.mcap --csv run1.csv\n"
               f"  cosim export runs/run1.mcap --topic {TOPIC_VEHICLES} --csv vehicles.csv\n"
               "  cosim export runs/day.mcap --from 43200 --to 43800 --csv noon.csv\n",
        formatter_class=formatter,
    )
    export.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    export.add_argument("--csv", metavar="OUT.csv", required=True, help="the CSV file to write")
    export.add_argument("--topic", default=TOPIC_SENSORS, metavar="TOPIC",
                        help=f"the topic to export (one of: {topics}; default: {TOPIC_SENSORS})")
    # float, not finite_float: a time that is not finite is then the window check's one-line error.
    _window_arguments(export, "export")
    export.add_argument("--force", "-f", action="store_true", help="overwrite OUT.csv if it exists")
    export.set_defaults(func=cmd_export)

    info = commands.add_parser(
        "info",
        help="summarise a log: scenario, duration, topics, status, truncated or not",
        description=textwrap.dedent(
            """\
            Summarise a log: its scenario, cosim version, simulated time, sensors, topics
            with message counts, final status and message, whether the file is truncated
            (cut short by a killed process: exit status 0, the readable part is shown) and
            its attachments. A finished log is read through its summary (counts, times,
            chunk index) in seconds however long it is; every byte is checked against the
            file's checksums, and the chunk holding the final status is decompressed.
            --verify also decompresses every chunk, verifies its checksum and counts the
            messages (the summary must agree). A damaged file or one that is not a cosim
            MCAP log exits with status 2."""
        ),
        epilog="examples:\n  cosim info runs/run1.mcap\n  cosim info --verify runs/run1.mcap\n",
        formatter_class=formatter,
    )
    info.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    info.add_argument("--verify", action="store_true",
                      help="decompress every chunk and verify every checksum (seconds per 100 MB of log)")
    info.set_defaults(func=cmd_info)

    plot = commands.add_parser(
        "plot",
        help="draw the sensor time histories of a log",
        description=textwrap.dedent(
            """\
            Draw the time histories of a log's sensors, one panel each, over time in s
            (displacements in mm, velocities in mm/s, accelerations in m/s^2, bending
            moments in kN m). --from/--to: only T0 to T1 s of simulated time, read from
            the chunks in that window. More than 20000 samples are drawn as their min/max
            envelope."""
        ),
        epilog="examples:\n  cosim plot runs/run1.mcap -o run1.png\n"
               "  cosim plot runs/run1.mcap --sensor node1 --sensor node3_acc -o two.png\n"
               "  cosim plot runs/day.mcap --sensor node1 --from 43200 --to 43260 -o noon.png\n",
        formatter_class=formatter,
    )
    plot.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    plot.add_argument("--sensor", action="append", metavar="NAME",
                      help="a sensor to draw (repeat for more; default: all)")
    plot.add_argument("-o", "--output", required=True, metavar="FIG.png", help="the figure (.png, .pdf, .svg, ...)")
    _window_arguments(plot, "draw")
    plot.add_argument("--force", "-f", action="store_true", help="overwrite FIG if it exists")
    plot.set_defaults(func=cmd_plot)

    layout = commands.add_parser(
        "layout",
        help="write the Foxglove layout made for a log's run",
        description=textwrap.dedent(
            """\
            Write the Foxglove layout of a log's run, the one the run attached to its log
            (foxglove_layout.json), made from what the log records: a plot per sensor
            quantity with its sensors, the vehicles' contact forces (per vehicle for
            scripted vehicles, all together for SUMO traffic), the positions of the traffic
            near the deck, a table of the vehicles on the deck, the events and status, and
            the 3D scene of the deck and its vehicles when the log has one. Logs written
            before layouts existed get one too. Open the log in Foxglove (desktop app or
            app.foxglove.dev: Open local file) and import the layout with Layouts ->
            Import from file. An existing file is replaced only with --force, never the log."""
        ),
        epilog="examples:\n  cosim layout runs/run1.mcap -o run1-layout.json\n",
        formatter_class=formatter,
    )
    layout.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    layout.add_argument("-o", "--output", required=True, metavar="LAYOUT.json", help="the layout file to write")
    layout.add_argument("--force", "-f", action="store_true", help="overwrite LAYOUT.json if it exists")
    layout.set_defaults(func=cmd_layout)

    validate = commands.add_parser(
        "validate",
        help="run the verification and validation cases; write a report with plots",
        description=textwrap.dedent(
            """\
            Run every verification case against its closed form or independent solution
            (Timoshenko statics and frequencies, non-uniform torsion, torsional and coupled
            lateral-torsional frequencies, Fryba's moving force, a sprung mass against an
            independent modal ODE, energy conservation, time-step and mesh convergence,
            ISO 8608 spectra, a parked vehicle, Benscoter torsion against its closed forms
            and frequency equation, VBI-2D's sprung vehicle on an Euler-Bernoulli beam) and
            the paper's 40 m double-tee case (Nodes 1-3 like its Figs. 4-6, quarter-cars
            and moving forces, direct and modal bases, Vlasov and Benscoter torsion).
            Writes DIR/report.md with each case's reference, error and tolerance, and PNG
            plots next to it.

            Exit status: 0 every case within its tolerance, 1 a case failed, 2 bad input."""
        ),
        epilog="examples:\n  cosim validate\n  cosim validate --out validation --quick\n",
        formatter_class=formatter,
    )
    validate.add_argument("--out", default="validation", metavar="DIR",
                          help="folder for report.md and the plots (default: validation)")
    validate.add_argument("--quick", action="store_true", help="coarser settings (seconds instead of a minute)")
    validate.add_argument("--force", "-f", action="store_true",
                          help="replace the report (and plots) in DIR if it has one (default: refuse)")
    validate.set_defaults(func=cmd_validate)

    study = commands.add_parser(
        "study",
        help="traffic-volume studies: a base scenario swept over demand, trucks, speed, road and seeds, on Dask",
        description=textwrap.dedent(
            """\
            Run every combination of the sweep axes of STUDY.toml (vehicles per hour, truck
            share, speed limit, SUMO demand, road class, seeds) on a Dask cluster, each run
            logged to MCAP, and write one table of results (results.csv, results.parquet)
            and plots into the output folder (default studies/<name>/). Running the same
            command again resumes: runs whose logs are complete are not run again. A
            failing run is recorded in the table; the others go on. docs/studies.md
            documents the study file and the output folder.

            Exit status: 0 every run ok, 1 some run failed (see the table), 2 bad input
            (also: --out is another study's folder), 128 + N stopped by signal N (130
            Ctrl-C, 143 SIGTERM, 129 SIGHUP): the runs in progress stop with finished logs,
            the table of the completed runs is written, the same command resumes."""
        ),
        epilog=textwrap.dedent(
            """\
            examples:
              cosim study examples/studies/volumes.toml
              cosim study examples/studies/volumes.toml --workers 2 --out /data/volumes
              cosim study examples/studies/volumes.toml --scheduler tcp://10.0.0.5:8786
            """
        ),
        formatter_class=formatter,
    )
    study.add_argument("study", metavar="STUDY.toml", help="the study file")
    study.add_argument("--workers", "-w", type=int, metavar="N",
                       help="worker processes of the local Dask cluster (default: one per CPU; 0: run one "
                            "after another in this process, without Dask)")
    study.add_argument("--scheduler", metavar="ADDRESS",
                       help="submit to an existing Dask scheduler (tcp://HOST:PORT) instead of a local cluster; "
                            "its workers need cosim and the output folder at the same path")
    study.add_argument("--out", metavar="FOLDER",
                       help="the output folder (default: [study].output, else studies/<name>)")
    study.add_argument("--redo", action="store_true", help="run every run again, even those already done")
    study.add_argument("--no-plots", action="store_true", help="write the table only")
    study.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    study.set_defaults(func=cmd_study)

    dataset = commands.add_parser(
        "dataset",
        help="write a labelled monitoring dataset (healthy and damaged, temperature, instruments)",
        description="Run a base scenario window by window for every damage case of the dataset file, measure the "
                    "responses with its instruments (anti-aliasing, sampling, noise, quantisation) and write one "
                    "row per window with its labels to dataset.parquet, plus the MCAP logs. docs/analysis.md "
                    "documents the dataset file.",
    )
    dataset.add_argument("dataset", metavar="SPEC.toml", help="the dataset file")
    dataset.add_argument("--out", metavar="FOLDER",
                         help="the output folder (default: [dataset].output, else datasets/<name>)")
    dataset.add_argument("--force", action="store_true", help="overwrite an existing dataset and its logs")
    dataset.add_argument("--quiet", "-q", action="store_true", help="no progress on stderr")
    dataset.set_defaults(func=cmd_dataset)
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
        formatter_class=formatter,
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
    return parser


#: Options whose value may begin with "-": SUMO edge ids (OSM imports name a street's reverse direction "-<id>").
_DASH_VALUES = ("--edge",)


def _dash_values_joined(argv: list[str]) -> list[str]:
    """``--edge -148050455#0`` as ``--edge=-148050455#0``: argparse would read the id as an option."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        if argv[i] in _DASH_VALUES and i + 1 < len(argv) and argv[i + 1][:1] == "-" and argv[i + 1][:2] != "--":
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
            continue
        out.append(argv[i])
        i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the ``cosim`` command line; returns the exit status.

    Args:
        argv: the arguments without the program name (default: ``sys.argv[1:]``).
    """
    parser = build_parser()
    try:
        args = parser.parse_args(_dash_values_joined(sys.argv[1:] if argv is None else list(argv)))
    except SystemExit as exc:  # --help, --version (0) and usage errors (2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    try:
        return int(args.func(args))
    except CosimError as exc:
        report_error(str(exc))
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # SIGINT, SIGTERM or SIGHUP where the command did not report it itself
        return report_interruption(exc)
    except BrokenPipeError:  # e.g. `cosim modes ... | head`
        try:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        except OSError:
            pass
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
