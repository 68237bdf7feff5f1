"""What is done with a scenario, one call each: the command line's ``cosim run``, ``modes`` and ``static``.

- :func:`run_scenario` (``cosim run``): with ``[[vehicles]]`` or ``[traffic]``
  it checks every output, reads SUMO's network and vehicle types, builds the
  bridge, streams the run into its MCAP log
  (:func:`cosim.run.logged.run_logged`) and writes the sensor CSV
  (:class:`LoggedRun`); without, it computes the modes and the static load
  case (:class:`StaticRun`). Callbacks say when the scenario is checked and
  when the time stepping is about to start (:class:`RunStart`, shared with
  :func:`cosim.run.replay.replay_log`), so that the command line can show a
  run's header before a long run.
- :func:`bridge_modes` (``cosim modes``): the bridge's lowest modes, and a figure of their shapes.
- :func:`static_loads` (``cosim static``): the deck under point loads anywhere on it.

Each returns a frozen outcome and prints nothing.
"""
from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim import plots
from cosim.core.bridge import BridgeModel, ModalResult, PointLoad
from cosim.errors import CosimError

from .export import export_csv
from .figures import plot_modes
from .inputs import scenario_files
from .logged import RunOutcome, run_logged
from .outputs import atomic_write, check_new_file, check_not_input, check_writable, unique_path
from .payloads import damping_payload, jsonable, modes_payload, section_payload
from .scenario import Scenario, load_scenario
from .simulate import SumoPlan, plan_sumo
from .static import static_cases, static_response

#: What a run of a scenario without vehicles does instead of a time simulation.
NO_VEHICLES = (
    "the scenario has no [[vehicles]]; "
    "this run does the modal analysis and a static load case"
)
#: Modes computed for a scenario without vehicles.
STATIC_MODES = 10


@dataclass(frozen=True)
class RunStart:
    """A logged run about to start its time stepping (``cosim run`` and ``cosim replay`` print it first).

    Attributes:
        scenario: what runs; bridge: its model, built.
        log_path: the log it writes (checked: it may be written).
        duration: the simulated time, s.
        plan: with SUMO traffic, its network and vehicle types as read (None for scripted vehicles and replays).
    """

    scenario: Scenario
    bridge: BridgeModel
    log_path: Path
    duration: float
    plan: SumoPlan | None = None

    @property
    def replayed_frames(self) -> bool:
        """Whether the traffic is a log's SUMO frames replayed (the scenario names no vehicles and no SUMO)."""
        return not self.scenario.vehicles and self.scenario.traffic is None


@dataclass(frozen=True)
class LoggedRun:
    """A finished logged run of a scenario with vehicles or traffic.

    Attributes:
        start: what the run was (its scenario, bridge, log and duration).
        outcome: the finished run: its log, extremes, vehicles on the deck, fatigue.
        csv_path: the sensor CSV written after the run, or None; csv_rows, csv_columns: its rows and columns.
    """

    start: RunStart
    outcome: RunOutcome
    csv_path: Path | None = None
    csv_rows: int = 0
    csv_columns: tuple[str, ...] = ()


@dataclass(frozen=True)
class StaticRun:
    """A scenario without vehicles: its modes and the static load case (no time simulation, no log).

    Attributes:
        scenario, bridge: the scenario and its model.
        modal: the lowest :data:`STATIC_MODES` modes.
        cases: the static load case (:func:`cosim.run.static.static_cases`).
        summary_path: the JSON summary written (``out``), or None.
    """

    scenario: Scenario
    bridge: BridgeModel
    modal: ModalResult
    cases: tuple[dict[str, Any], ...]
    summary_path: Path | None = None


def log_target(out: str | os.PathLike[str] | None, default: Path, force: bool) -> Path:
    """The log to write: ``out`` (must end in .mcap) or ``default``; checked before any work.

    Raises:
        CosimError: ``out`` is not an .mcap path, or the log exists (without ``force``) or cannot be created.
    """
    if out is not None:
        path = Path(out)
        if path.suffix.lower() != ".mcap":
            raise CosimError(f"{os.fspath(out)}: the log is an MCAP file: give a path ending in .mcap")
    else:
        path = default
    check_new_file(path, "log", force)
    return path


def run_scenario(
    scenario: str | os.PathLike[str] | Scenario,
    *,
    out: str | os.PathLike[str] | None = None,
    csv: str | os.PathLike[str] | None = None,
    force: bool = False,
    checked: Callable[[Scenario], None] | None = None,
    ready: Callable[[RunStart], None] | None = None,
    progress: Callable[[float], None] | None = None,
) -> LoggedRun | StaticRun:
    """Run a scenario: with vehicles or traffic, the logged time simulation; without, its modes and static case.

    Every output is checked before anything is built or written. With vehicles the log goes to ``out``,
    else ``[output].log``, else ``runs/<scenario name>-<YYYYmmdd-HHMMSS>.mcap``, and the sensor CSV to
    ``csv``, else ``[output].csv``; without, ``out`` is the JSON summary of the modes and static case.

    Args:
        scenario: a scenario, or its file or bundled name (:func:`cosim.run.scenario.load_scenario`).
        out: the log (.mcap) with vehicles; the JSON summary without.
        csv: the sensor CSV (vehicles only).
        force: overwrite existing outputs (never the scenario or its input files).
        checked: called with the scenario once it and the outputs are checked (with SUMO: its network and
            vehicle types read), before the bridge is built.
        ready: with vehicles, called when the bridge is built, just before the time stepping.
        progress: called with the fraction done after every block of time steps.

    Raises:
        CosimError (ConfigError, ...): bad input or an output that may not be written, before anything is written.
        RunInterrupted: a signal stopped the run (:func:`cosim.run.logged.run_logged`).
        RunFailed: the run failed after it started; its log ends with status "error".
    """
    if out is not None and Path(out).suffix.lower() == ".csv":
        out = os.fspath(out)
        raise CosimError(f"{out}: --out is the run's MCAP log (LOG.mcap); for a CSV of the sensors give --csv {out}")
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.vehicles or scenario.traffic is not None:
        return _logged_run(scenario, out, csv, force, checked, ready, progress)
    return _static_run(scenario, out, csv, force, checked)


def _logged_run(scenario: Scenario, out: str | os.PathLike[str] | None, csv: str | os.PathLike[str] | None,
                force: bool, checked: Callable[[Scenario], None] | None, ready: Callable[[RunStart], None] | None,
                progress: Callable[[float], None] | None) -> LoggedRun:
    default = scenario.log_path or unique_path(scenario.default_log_path())
    log_path = log_target(out, default, force)
    csv_path = Path(csv) if csv is not None else scenario.csv_path
    inputs = scenario_files(scenario)
    check_not_input(log_path, "log", inputs)
    if csv_path is not None:
        check_not_input(csv_path, "sensor CSV", [*inputs, ("the run's log (--out)", log_path)])
        check_new_file(csv_path, "sensor CSV", force)
    # SUMO: the network and demand are read (and a wrong edge or vType reported) before anything is written.
    plan = plan_sumo(scenario) if scenario.sumo else None
    if checked is not None:
        checked(scenario)
    bridge = scenario.build_bridge()
    start = RunStart(scenario, bridge, log_path, scenario.duration, plan)
    if ready is not None:
        ready(start)
    outcome = run_logged(scenario, log_path, force=force, bridge=bridge, progress=progress)
    if csv_path is None:
        return LoggedRun(start, outcome)
    rows, columns = export_csv(log_path, csv_path, force=force)
    return LoggedRun(start, outcome, csv_path, rows, tuple(columns))


def _static_run(scenario: Scenario, out: str | os.PathLike[str] | None, csv: str | os.PathLike[str] | None,
                force: bool, checked: Callable[[Scenario], None] | None) -> StaticRun:
    if out is not None and Path(out).suffix.lower() == ".mcap":
        raise CosimError(
            f"{os.fspath(out)}: the scenario has no [[vehicles]], so there is no time simulation to log; "
            "--out writes the modes and static displacements as JSON (e.g. --out summary.json)"
        )
    if csv is not None:
        raise CosimError(f"{os.fspath(csv)}: the scenario has no [[vehicles]]: no sensor time histories for --csv")
    if out is not None:
        check_not_input(out, "summary", scenario_files(scenario))
        check_writable(out, "summary", force=force)
    if checked is not None:
        checked(scenario)
    bridge = scenario.build_bridge()
    modal = bridge.modes(count=STATIC_MODES)
    cases = tuple(static_cases(scenario, bridge))
    if out is None:
        return StaticRun(scenario, bridge, modal, cases)
    summary = {
        "scenario": scenario.title,
        "source": scenario.source,
        "note": NO_VEHICLES,
        "section": section_payload(bridge.section),
        "damping": damping_payload(bridge),
        "modes": modes_payload(modal),
        "static": list(cases),
        "units": {"x": "m", "y": "m", "Fz": "N", "w": "m (positive up)", "f_hz": "Hz"},
    }
    with atomic_write(out, "summary") as partial:
        partial.write_text(json.dumps(jsonable(summary), indent=2) + "\n", encoding="utf-8")
    return StaticRun(scenario, bridge, modal, cases, Path(out))


@dataclass(frozen=True)
class BridgeModes:
    """A scenario's bridge and its lowest natural modes (``cosim modes``).

    Attributes:
        scenario, bridge: the scenario and its model.
        modal: the lowest modes: frequencies, kinds, effective modal mass fractions, shapes.
        plotted: how many mode shapes the figure shows (0: no figure asked for).
    """

    scenario: Scenario
    bridge: BridgeModel
    modal: ModalResult
    plotted: int = 0


def bridge_modes(scenario: str | os.PathLike[str] | Scenario, count: int = 10, *,
                 plot: str | os.PathLike[str] | None = None, force: bool = False) -> BridgeModes:
    """Build a scenario's bridge and compute its lowest ``count`` modes; ``plot``: draw the first shapes there.

    Raises:
        CosimError (ConfigError, ModelError, ...): a bad scenario, or a figure that may not be written (checked
            before the bridge is built).
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if plot:
        check_not_input(plot, "plot", scenario_files(scenario))
        check_writable(plot, "plot", plots.figure_formats(), force=force)
    bridge = scenario.build_bridge()
    modal = bridge.modes(count=count)
    plotted = plot_modes(bridge, modal, plot, count) if plot else 0
    return BridgeModes(scenario, bridge, modal, plotted)


@dataclass(frozen=True)
class StaticLoads:
    """A scenario's deck under vertical point loads acting together (``cosim static``).

    Attributes:
        scenario, bridge: the scenario and its model.
        response: the deck displacement under each load and at each sensor
            (:func:`cosim.run.static.static_response`).
    """

    scenario: Scenario
    bridge: BridgeModel
    response: dict[str, Any]


def static_loads(scenario: str | os.PathLike[str] | Scenario,
                 loads: Sequence[tuple[float, float, float]]) -> StaticLoads:
    """Solve a scenario's bridge under point loads ``(x, y, Fz)`` (m, m, N positive up) acting together.

    Raises:
        CosimError (ConfigError, ...): a bad scenario, or a load that is not finite or lies off the deck.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    points = [PointLoad(x=x, y=y, Fz=fz) for x, y, fz in loads]
    bridge = scenario.build_bridge()
    return StaticLoads(scenario, bridge, static_response(scenario, bridge, points))
