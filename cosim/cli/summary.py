"""What ``cosim run`` and ``cosim replay`` print around a logged run: its header before the time stepping,
the progress on stderr, the summary after it, and the line a failed or stopped run ends with.

Imported by those commands when they run (it loads the numerical core), never to build the parser.
"""
from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cosim.core.fields import vehicle_of
from cosim.core.modal_bridge import ModalBridge
from cosim.run.api import RunStart
from cosim.run.logged import LogCutShort, RunFailed, RunInterrupted, RunOutcome
from cosim.run.scenario import Scenario
from cosim.run.simulate import SumoPlan
from cosim.run.units import display_unit

from .text import EXIT_RUN_FAILED, damping_lines, fmt_g, print_lines, report_error, size_text


class Progress:
    """Progress of a run on stderr: a tqdm bar on a terminal, a line of percentages otherwise.

    It appears with the first block of time steps: a run refused while it is
    being set up (bad input, a limit, SUMO) prints its one error line alone.
    """

    def __init__(self, duration: float, show: bool) -> None:
        self.duration = duration
        self.fraction = 0.0
        self._stream = sys.stderr
        self._bar: Any = None
        self._tenths: int | None = None  # the light form: tenths printed so far
        self._show = show

    def _start(self) -> None:
        self._show = False
        if self._stream.isatty():
            from tqdm import tqdm

            self._bar = tqdm(
                total=self.duration, file=self._stream, desc="Simulating", leave=True, dynamic_ncols=True,
                bar_format="{desc} {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s [{elapsed}<{remaining}]",
            )
        else:
            self._tenths = 0
            print(f"Simulating {self.duration:g} s:", end="", file=self._stream, flush=True)

    def __call__(self, fraction: float) -> None:
        self.fraction = fraction
        if self._show:
            self._start()
        if self._bar is not None:
            self._bar.update(min(fraction * self.duration, self.duration) - self._bar.n)
        elif self._tenths is not None:
            reached = int(fraction * 10 + 1e-9)
            if reached > self._tenths:
                self._tenths = reached
                print(f" {10 * reached}%", end="", file=self._stream, flush=True)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self._tenths is not None:
            print(file=self._stream, flush=True)
            self._tenths = None


def _parameter_text(key: str, value: Any, unit: str) -> str:
    if key == "axles":
        return f"{len(value)} axles at {', '.join(fmt_g(a.distance) for a in value)} m"
    if key == "pitch":
        return "pitch" if value else "no pitch"
    if isinstance(value, bool):
        return f"{key} = {'true' if value else 'false'}"
    if isinstance(value, tuple):
        return f"{len(value)} {key}"
    return f"{key} = {fmt_g(value)} {unit}".rstrip()


def _traffic_line(scenario: Scenario, plan: SumoPlan | None = None) -> str:
    t = scenario.traffic
    assert t is not None
    level = f" (bundled {t.sumo_config} demand)" if t.bundled else ""
    seed = f", seed {t.seed}" if t.seed is not None else ", the config's seed"
    where = f"sumo_networks/{t.sumo_config}.sumocfg" if t.bundled else str(scenario.sumo_config_path)
    if plan is not None:
        start, end = plan.axis.start, plan.axis.end
        axis = (f"bridge axis ({start[0]:.3f}, {start[1]:.3f}) -> ({end[0]:.3f}, {end[1]:.3f}) in network "
                f"coordinates, {plan.axis.length:.3f} m ({plan.axis_from})")
    elif t.axis is not None:
        axis = f"bridge axis {t.axis[0]} -> {t.axis[1]} in network coordinates"
    elif t.edges:
        axis = f"bridge axis derived from edges {', '.join(t.edges)}"
    else:
        axis = f"bridge axis {(0.0, 0.0)} -> {(scenario.bridge.length, 0.0)} in network coordinates"
    return (f"Traffic: SUMO {where}{level}, step {fmt_g(t.step)} s, SUMO time {fmt_g(t.begin)} to "
            f"{fmt_g(t.end)} s{seed}; {axis}")


def _sumo_lines(plan: SumoPlan) -> list[str]:
    """Where the deck is in the network, and one line per vType: model, mass, axles and where each came from."""
    lines = []
    location = plan.location
    if location is not None:
        lanes = ", ".join(f"{lane.id} (y = {lane.y:+.2f} m, {'+x' if lane.direction > 0 else '-x'})"
                          for lane in location.lanes)
        also = f"; also watched: {', '.join(location.opposite)} (opposite direction)" if location.opposite else ""
        lines.append(f"Deck lanes: {lanes}; carriageway y = {location.carriageway[0]:.2f} to "
                     f"{location.carriageway[1]:.2f} m{also}")
        from cosim.sumo.network import wheel_paths_beyond

        beyond = wheel_paths_beyond(location, plan.deck_y)
        if beyond:
            lines.append(f"  {beyond}")
    types = plan.types
    if not types:  # a config without demand of its own (WIM records inserted into SUMO drive alone)
        brought = "; the WIM records (above) bring their own" if plan.settings.records is not None else ""
        lines.append(f"Vehicle types: none (no vehicle, trip or flow in the SUMO config's files){brought}")
        return lines  # nor anything to draw loads for
    lines.append(f"Vehicle types ({len(types)}): model, gross mass, axles, suspension, and where each came from "
                 "(vType params, SUMO mass, cosim default)")
    width = max([len(t.id) for t in types] + [4])
    vwidth = max([len(t.vclass) for t in types] + [6])
    for t in types:
        lines.append(f"  {t.id:<{width}}  {t.vclass:<{vwidth}}  {t.line()}")
    loads = plan.settings.loads
    if loads is not None:
        from cosim.sumo.loads import VehicleLoads

        draws = VehicleLoads(loads)
        wander = loads.wander if isinstance(loads.wander, str) else f"normal, sd {fmt_g(loads.wander)} m"
        lines.append(f"Loads: each vehicle's own, drawn from the {loads.model.name} WIM model (Grave's; "
                     f"seed {loads.seed}; wander {wander}); per vType:")
        for t in types:
            choice = draws.plan(t)
            what = ("the light (car) distribution" if choice == "car" else "its own weights (above)"
                    if choice == "fixed" else "trucks of " + " or ".join(str(c) for c in choice) + " axles")
            lines.append(f"  {t.id:<{width}}  {what}")
    return lines


def _records_line(scenario: Scenario) -> str:
    """``[traffic.records]``: the file, its window, its lanes and how its vehicles are driven."""
    records = scenario.records
    assert records is not None
    check = scenario.records_check()
    summary = check.summary
    counts = dict(check.per_lane)
    lanes = ", ".join(f"{lane.lane} (y = {lane.y:+.3f} m, {lane.direction}, {counts.get(lane.lane, 0)} records)"
                      for lane in records.lanes)
    begin, end = scenario.records_window
    window = ("the whole file" if begin == 0 and end == float("inf") else
              f"{fmt_g(begin)} s to " + (f"{fmt_g(end)} s" if end != float("inf") else "its end"))
    if records.via == "scripted":
        axles = ("moving forces" if records.axle_model == "moving-force" else
                 "tyre quarter-cars on cosim's library suspensions")
        how = f"each driven at its recorded time, lane and speed (no SUMO), its axles {axles}"
        clock = f"t = 0 at {fmt_g(records.begin)} s"
    else:
        how = ("each inserted into SUMO upstream of the deck to reach it at its recorded time (if undisturbed), lane "
               "and speed, as long as its axles, each a tyre quarter-car of its recorded load on cosim's library "
               "suspension of its vClass (SUMO's vType cosim-records-car, -truck or -trailer)")
        clock = "SUMO's clock"
    wander = "no wander" if records.wander == "none" else (
        f"wander {records.wander}" if isinstance(records.wander, str) else f"wander sd {fmt_g(records.wander)} m") + (
        f", seed {records.seed}" if records.seed is not None else "")
    return (f"Records: {check.path} ({records.format}), {check.count} of its {summary.count} records in {window} "
            f"(times from midnight of {summary.origin.isoformat()}; {clock}), lanes "
            f"{lanes}; {how}; {wander}")


def _vehicle_lines(scenario: Scenario, plan: SumoPlan | None = None) -> list[str]:
    if scenario.traffic is not None and not scenario.sumo:
        return [_records_line(scenario)]
    if scenario.traffic is not None:
        records = [_records_line(scenario)] if scenario.records is not None else []
        return [_traffic_line(scenario, plan), *records, *(_sumo_lines(plan) if plan is not None else [])]
    rows = []
    for v in scenario.vehicles:
        if v.profile is not None:
            speed = "profile " + " ".join(f"{fmt_g(t)}s:{fmt_g(vv)}" for t, vv in v.profile)
        else:
            speed = fmt_g(v.speed or 0.0)
        params = ", ".join(_parameter_text(k, val, v.spec.parameter(k).unit) for k, val in v.parameters.items())
        if v.contact == "unilateral":
            params += ", unilateral contact"
        rows.append((v.id, v.model, f"{v.y:.3f}", v.direction, speed, fmt_g(v.entry_time), params))
    heads = ("id", "model", "y [m]", "dir", "speed [m/s]", "entry [s]", "parameters")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(heads[:-1])]
    fmt = "  " + "  ".join(f"{{:<{w}}}" for w in widths) + "  {}"
    return [f"Vehicles ({len(rows)})", fmt.format(*heads), *(fmt.format(*r) for r in rows)]


def _road_line(scenario: Scenario) -> str:
    road = scenario.road
    wheel = scenario.wheel_paths()
    paths = "y = " + ", ".join(f"{y:g}" for y in wheel) + " m"
    if scenario.sumo or len(wheel) > 6 or (scenario.records is not None and scenario.records.wander != "none"):
        paths = f"{len(wheel)} paths, y = {wheel[0]:g} to {wheel[-1]:g} m, each wheel on the nearest"
    if road.random:
        return (f"Road: ISO 8608 class {road.road_class}, seed {road.seed}, one profile per wheel path "
                f"({paths}), x = -10 m to L + 10 m")
    if road.profile is not None:
        return f"Road: profile {scenario.road_profile_path} (x, r), on every wheel path"
    return "Road: smooth"


def _solver_line(scenario: Scenario, duration: float) -> str:
    solver = scenario.solver
    scheme = solver.scheme if solver.scheme != "hht" else f"hht (alpha = {fmt_g(solver.hht_alpha or 0.0)})"
    basis = solver.basis
    if scenario.bridge.is_modal:
        kept = scenario.bridge.deck.select(solver.modes, solver.cutoff_hz).n_modes
        basis = f"modal (the deck's {kept} of its file's {scenario.bridge.deck.n_modes} modes)"
    elif solver.basis == "modal":
        if solver.modes is not None:
            basis += f" ({solver.modes} modes)"
        else:
            basis += f" (modes below {fmt_g(solver.cutoff_hz or 0.0)} Hz)"
    if solver.duration is not None:
        how = "given"
    elif scenario.scripted_records is not None:
        how = f"the last record's vehicle leaves the deck at {fmt_g(scenario.records_check().leave, 6)} s, + 2 s"
    elif scenario.traffic is not None:
        how = "[traffic] end - begin"
    elif not scenario.vehicles:
        how = "the replayed log's"
    else:
        how = f"last vehicle leaves the deck at {fmt_g(scenario.leave_time or 0.0, 4)} s, + 2 s"
    steps = int(round(duration / solver.dt))
    return (f"Solver: {scheme}, {basis} basis, dt = {fmt_g(solver.dt)} s, duration {fmt_g(duration, 4)} s ({how}), "
            f"{steps} steps, g = {fmt_g(solver.gravity)} m/s^2")


def _logging_line(scenario: Scenario, log_path: Path) -> str:
    every = scenario.output_every
    steps = "every step" if every == 1 else f"every {every} steps"
    return f"Log: {log_path}, sampled at {fmt_g(scenario.output_rate_hz, 4)} Hz ({steps})"


def _sensor_summary(scenario: Scenario, result) -> list[str]:  # noqa: ANN001 - SimulationResult
    if not scenario.sensors:
        return ["Sensors: none (the scenario has no [[sensors]]; the log has only the time of each sample)"]
    names = [s.name for s in scenario.sensors]
    width = max(len("name"), *(len(n) for n in names))
    lines = [
        "Sensors: peaks over the run (every step)",
        f"  {'name':<{width}}  {'quantity':<14}{'x [m]':>8}{'y [m]':>8}{'min':>12}{'max':>12}  unit",
    ]
    for s in scenario.sensors:
        unit, factor = display_unit(s.quantity)
        lo = min(result.sensor_min.get(s.name, 0.0), 0.0) * factor  # t = 0: at rest
        hi = max(result.sensor_max.get(s.name, 0.0), 0.0) * factor
        lines.append(f"  {s.name:<{width}}  {s.quantity:<14}{s.x:8.3f}{s.y:8.3f}"
                     f"{lo + 0.0:12.4g}{hi + 0.0:12.4g}  {unit}")
    return lines


def _fatigue_summary(outcome: RunOutcome) -> list[str]:
    """Rainflow and Miner damage of the stress sensors with an S-N curve (none: no lines)."""
    if not outcome.fatigue:
        return []
    width = max(len("name"), *(len(n) for n in outcome.fatigue))
    curve_width = max(len("S-N curve"), *(len(r.curve.name) for r in outcome.fatigue.values()))
    lines = ["Fatigue: rainflow count of the logged samples, Miner damage; per year: the run's traffic all year",
             f"  {'name':<{width}}  {'S-N curve':<{curve_width}}{'cycles':>10}{'damage':>12}{'per year':>12}"
             f"{'eq. range':>11}{'max range':>11}  unit"]
    for name, r in outcome.fatigue.items():
        per_year = r.damage_per_year if r.damage_per_year is not None else float("nan")
        lines.append(f"  {name:<{width}}  {r.curve.name:<{curve_width}}{r.cycles:10.4g}{r.damage:12.4g}"
                     f"{per_year:12.4g}{r.equivalent_stress_range * 1e-6:11.4g}{r.max_stress_range * 1e-6:11.4g}  MPa")
    return lines


def _vehicle_summary(outcome: RunOutcome, limit: int = 12) -> list[str]:
    result = outcome.result
    scripted = [v.id for v in outcome.scenario.vehicles]
    # A scripted vehicle with several axles is reported axle by axle ("truck#0", "truck#1", ...).
    contacts = [c for vid in scripted for c in (sorted(c for c in outcome.on_deck if vehicle_of(c) == vid
                                                       and c != vid) or [vid])]
    ids = contacts or sorted(outcome.on_deck, key=lambda v: -result.contact_force_range.get(v, (0, 0))[1])
    lifted_total = sum(1 for v in outcome.on_deck if result.contact_force_range.get(v, (0.0, 0.0))[0] < 0)
    of = f" of {len(scripted)}" if scripted else ""
    vehicles = {vehicle_of(c) for c in outcome.on_deck}
    axles = "" if len(vehicles) == len(outcome.on_deck) else f" ({len(outcome.on_deck)} axles)"
    lines = [
        f"Vehicles: {len(vehicles)}{of}{axles} on the deck during the run, at most {result.max_on_deck} "
        f"at once, {lifted_total} lifted off; contact force, compression positive"
        + ("" if scripted or len(ids) <= limit else f" (the {limit} heaviest shown)"),
    ]
    if not ids:
        return lines
    shown = ids if scripted else ids[:limit]
    width = max(len("id"), *(len(i) for i in shown))
    lines.append(f"  {'id':<{width}}  {'on the deck [s]':<18}{'min [kN]':>10}{'max [kN]':>10}  lifted off")
    for vid in shown:
        if vid not in outcome.on_deck:
            lines.append(f"  {vid:<{width}}  not on the deck during the run")
            continue
        first, last = outcome.on_deck[vid]
        lo, hi = result.contact_force_range.get(vid, (0.0, 0.0))
        on_deck = f"{first:.3f} - {last:.3f}"
        lifted = "yes" if lo < 0 else "no"
        lines.append(f"  {vid:<{width}}  {on_deck:<18}{lo / 1e3:10.3f}{hi / 1e3:10.3f}  {lifted}")
    return lines


def _run_lines(outcome: RunOutcome) -> list[str]:
    result, duration = outcome.result, outcome.duration
    events, steps = result.liftoff_events, result.liftoff_steps
    lines = [f"Lift-off events: {events} ({steps} vehicle-steps with a negative contact force)"]
    if result.weights:
        parts = [f"{name} {w.count} (mean {w.mean / 1e3:.1f}, sd {w.sd / 1e3:.1f}, {w.low / 1e3:.1f} to "
                 f"{w.high / 1e3:.1f})" for name, w in result.weights.items()]
        lines.append("Gross weights per class, kN (vehicles that came onto the deck; /cosim/vehicle_loads has each "
                     "one's): " + "; ".join(parts))
    if events:
        lines.append("  the contact is kept (bilateral) through a lift-off, as in the paper: "
                     "results after it assume the wheel stays on the deck")
    if result.offdeck_events:
        lines.append(f"Off the deck: {result.offdeck_events} times a wheel went beside the deck's surface over its "
                     f"length ({result.offdeck_steps} wheel-steps); it loaded nothing there (\"offdeck\" events in "
                     "the log name each): widen the section's deck if those lanes are on the bridge")
    wall = result.wall_time
    factor = f"{duration / wall:.3g}" if wall > 0 else "inf"
    lines.append(f"Time stepping: {result.steps} steps in {wall:.2f} s wall time; "
                 f"real-time factor {factor} (simulated time / wall time)")
    basis = result.info.get("basis", "?")
    lines.append(f"Effective-matrix factorisations: {result.factorizations} "
                 f"({basis} basis, {result.info.get('n_reduced', '?')} unknowns)")
    lines.append(f"Wall time with logging: {outcome.wall_time:.2f} s")
    return lines


def _log_done_line(outcome: RunOutcome) -> str:
    return (f"Wrote the log {outcome.log_path} ({size_text(outcome.log_bytes)}; {outcome.samples} sensor samples "
            f"at {fmt_g(outcome.rate_hz, 4)} Hz from t = 0; status finished)")


def header_lines(start: RunStart) -> list[str]:
    """What a logged run prints before its time stepping: bridge, damping, traffic, road, solver, log."""
    scenario, bridge = start.scenario, start.bridge
    if isinstance(bridge, ModalBridge):
        lo, hi = bridge.deck_y
        structure = [f"Bridge: a deck given by its modes, {bridge.source}: {bridge.n_modes} modes, "
                     f"{fmt_g(float(bridge.f_hz[0]), 4)} to {fmt_g(float(bridge.f_hz[-1]), 4)} Hz; "
                     f"{bridge.deck.points.shape[0]} deck points, 0 <= x <= {bridge.length:g} m, "
                     f"{lo:g} <= y <= {hi:g} m ({bridge.placement})",
                     f"Damping: {bridge.damping_note}"]
    else:
        spans = " + ".join(f"{span:g}" for span in bridge.spans)
        structure = [f"Bridge: {spans} m, {len(bridge.nodes_x) - 1} elements", *damping_lines(bridge)]
    return [
        *structure,
        *(["Traffic: the replayed log's SUMO frames"] if start.replayed_frames
          else _vehicle_lines(scenario, start.plan)),
        _road_line(scenario),
        _solver_line(scenario, start.duration),
        _logging_line(scenario, start.log_path),
    ]


class CompileNotice:
    """One line on stderr when the solver's kernels are being compiled, not loaded from numba's cache: the first
    run after installing or upgrading cosim waits about a minute for it before its first time step."""

    LINE = ("Compiling cosim's solver for this computer: once after installing or upgrading cosim, "
            "about a minute before the first time step ...")
    #: What ``cosim study`` says (its runs compile on the workers, each before its first run ends).
    STUDY_LINE = ("Compiling cosim's solver for this computer: once after installing or upgrading cosim, "
                  "about a minute before the first runs finish ...")

    def __init__(self) -> None:
        self.shown = False
        self._stop: Callable[[], None] | None = None

    def start(self) -> None:
        from cosim.core.jit import on_compile

        if self._stop is None:
            self._stop = on_compile(self._compiling)

    def _compiling(self, name: str) -> None:
        if not self.shown:
            self.shown = True
            print(self.LINE, file=sys.stderr, flush=True)

    def stop(self) -> None:
        if self._stop is not None:
            self._stop()
            self._stop = None


class RunDisplay:
    """What ``cosim run`` and ``cosim replay`` show while a logged run goes: its header on stdout once the
    bridge is built (:meth:`ready`), then its progress on stderr (a progress callback); and the one line
    a failed or stopped run ends with (:meth:`stopped`)."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.duration = 0.0
        self.progress: Progress | None = None
        self.notice = CompileNotice()

    def ready(self, start: RunStart) -> None:
        print_lines(header_lines(start))
        sys.stdout.flush()
        self.duration = start.duration
        self.progress = Progress(start.duration, show=not self.quiet)
        if not self.quiet:
            self.notice.start()

    def __call__(self, fraction: float) -> None:
        if self.progress is not None:
            self.progress(fraction)

    def close(self) -> None:
        self.notice.stop()
        if self.progress is not None:
            self.progress.close()

    def stopped(self, exc: RunFailed | RunInterrupted) -> int:
        """Report a run that failed or was stopped after it was set up (one line on stderr); its exit status."""
        self.close()
        if isinstance(exc, LogCutShort):  # its own message says what the file holds
            report_error(str(exc))
            return EXIT_RUN_FAILED
        if isinstance(exc, RunFailed):
            report_error(f"{exc} (the run failed; its log {exc.log_path} is finished, status \"error\")")
            return EXIT_RUN_FAILED
        fraction = self.progress.fraction if self.progress is not None else 0.0
        where = (f"the log up to there is in {exc.log_path} (finished, status \"interrupted\")"
                 if exc.log_path is not None else "the run had not started: no log was written")
        try:
            print(f"cosim: interrupted by {exc.name} at about t = {fraction * self.duration:.4g} s of "
                  f"{self.duration:g} s; {where}", file=sys.stderr)
        except (OSError, ValueError):  # SIGHUP: the terminal may be gone
            pass
        return 128 + exc.signum


def print_outcome(outcome: RunOutcome) -> None:
    """The end-of-run summary: sensor peaks, vehicles, counters, the log written."""
    print()
    print_lines(_sensor_summary(outcome.scenario, outcome.result))
    print_lines(_fatigue_summary(outcome))
    print_lines(_vehicle_summary(outcome))
    print_lines(_run_lines(outcome))
    print(_log_done_line(outcome))
