"""The ``cosim`` command line: the only module that prints.

Subcommands::

    cosim modes SCENARIO [--count N] [--json] [--plot FILE.png]
    cosim run [SCENARIO] [--out LOG.mcap] [--csv OUT.csv] [--force] [--quiet]
    cosim replay LOG.mcap [--scenario OTHER] [--out NEW.mcap] [--force] [--quiet]
    cosim export LOG.mcap --csv OUT.csv [--topic TOPIC] [--force]
    cosim info LOG.mcap
    cosim plot LOG.mcap [--sensor NAME ...] -o FIG.png [--force]

The work is done by :mod:`cosim.run.logged`; this module parses and prints.

Every :class:`cosim.errors.CosimError` becomes ``cosim: error: <message>`` on
stderr and exit status 2 (as for usage errors); a :class:`cosim.errors.ModelError`
during the time integration (the solution diverged) exits with 1 (the log then
ends with status "error"); Ctrl-C exits with 130 (the log ends with status
"interrupted").
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import textwrap
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from cosim import __version__
from cosim.core.bridge import BridgeModel, ModalResult, PointLoad
from cosim.core.section import SectionProperties
from cosim.core.traffic import vehicle_of
from cosim.errors import CosimError
from cosim.log.writer import TOPIC_EVENTS, TOPIC_SENSORS, TOPIC_STATUS, TOPIC_VEHICLES
from cosim.run import logged as runner
from cosim.run.scenario import Scenario, list_bundled_scenarios, load_scenario

DEFAULT_SCENARIO = "paper-bridge-traffic"
STATIC_LOAD_N = 100e3
NO_VEHICLES = (
    "the scenario has no [[vehicles]]; "
    "this run does the modal analysis and a static load case"
)
#: Summary units per sensor quantity: (unit, factor from SI).
DISPLAY_UNITS = runner.DISPLAY_UNITS
EXIT_RUN_FAILED = 1
EXIT_INTERRUPTED = 130
MAX_PLOTTED_MODES = 6
NEGLIGIBLE_SHARE = 1e-3  # plotted fields below this share of the largest are drawn as zero

# --------------------------------------------------------------------------- payloads

_jsonable = runner.jsonable
_section_payload = runner.section_payload
_modes_payload = runner.modes_payload
_damping_payload = runner.damping_payload


# --------------------------------------------------------------------------- text


def _scenario_line(scenario: Scenario) -> str:
    if scenario.source == scenario.title:  # a bundled scenario, named by its name
        return f"Scenario: {scenario.title}"
    return f"Scenario: {scenario.title} ({scenario.source})"


def _fixed(value: float, digits: int = 4) -> str:
    """Fixed-point text without a "-0.0000" for round-off below the last digit."""
    return f"{round(float(value), digits) + 0.0:.{digits}f}"


def _section_lines(section: SectionProperties) -> list[str]:
    return [
        f"Section: {section.source}",
        f"  A      = {section.A:.6g} m^2",
        f"  C      = (y, z) = ({_fixed(section.y_c)}, {_fixed(section.z_c)}) m   centroid",
        f"  S      = (y, z) = ({_fixed(section.y_s)}, {_fixed(section.z_s)}) m   shear centre",
        f"  I_y    = {section.I_y:.6g} m^4   (vertical bending)",
        f"  I_z    = {section.I_z:.6g} m^4   (lateral bending)",
        f"  I_yz   = {section.I_yz:.6g} m^4",
        f"  J      = {section.J:.6g} m^4   (St Venant torsion)",
        f"  I_w    = {section.I_w:.6g} m^6   (warping, about S)",
        f"  A_sy   = {section.A_sy:.6g} m^2   (lateral shear, k_y = {section.A_sy / section.A:.4f})",
        f"  A_sz   = {section.A_sz:.6g} m^2   (vertical shear, k_z = {section.A_sz / section.A:.4f})",
        f"  deck   = {section.deck_y[0]:g} m <= y <= {section.deck_y[1]:g} m",
    ]


def _damping_lines(bridge: BridgeModel) -> list[str]:
    if bridge.alpha == 0 and bridge.beta == 0:
        return ["Damping: none (undamped)"]
    return [
        f"Damping: C = alpha M + beta K, alpha = {bridge.alpha:.6g} 1/s, beta = {bridge.beta:.6g} s",
        f"  {bridge.damping_note}",
    ]


def _modes_lines(modal: ModalResult) -> list[str]:
    part = modal.participation
    lines = [
        "Modes (effective modal mass fractions)",
        f"  {'#':>3}  {'f [Hz]':>9}  {'kind':<28}{'vertical':>9}{'lateral':>9}{'torsion':>9}",
    ]
    for i, f in enumerate(modal.f_hz):
        fractions = "".join(f"{float(part[k][i]):9.3f}" if k in part else f"{'-':>9}"
                            for k in ("vertical", "lateral", "torsion"))
        lines.append(f"  {i + 1:>3}  {f:9.4f}  {modal.kinds[i]:<28}{fractions}")
    return lines


def _print(lines: Sequence[str]) -> None:
    for line in lines:
        print(line)


# --------------------------------------------------------------------------- plotting


def _plot_modes(bridge: BridgeModel, modal: ModalResult, path: str, count: int) -> int:
    """Draw v, w and theta_x of the first modes along x (each normalised) into ``path``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = min(count, len(modal.f_hz), MAX_PLOTTED_MODES)
    x = np.linspace(0.0, bridge.length, 401)
    fig = Figure(figsize=(8.0, 2.0 * n + 0.8), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    styles = (("v", "v (lateral)", "-"), ("w", "w (vertical)", "--"), ("theta_x", "θ_x (twist)", ":"))
    # Each field is normalised to a peak of 1; its legend gives its size relative
    # to the largest one, the twist counted as its deck-edge displacement
    # theta_x * half_width. A field below NEGLIGIBLE_SHARE is round-off (e.g.
    # twist in a vertical mode of a symmetric section) and is drawn as zero.
    half_width = max(abs(bridge.section.deck_y[0]), abs(bridge.section.deck_y[1]), 1.0)
    for i, ax in enumerate(axes):
        values = {name: np.asarray(modal.field(i, name, x), dtype=float) for name, _, _ in styles}
        peaks = {name: float(np.max(np.abs(v))) for name, v in values.items()}
        scaled = {name: peak * (half_width if name == "theta_x" else 1.0) for name, peak in peaks.items()}
        reference = max(scaled.values())
        for name, label, style in styles:
            share = scaled[name] / reference if reference > 0 else 0.0
            if share <= NEGLIGIBLE_SHARE or peaks[name] == 0.0:
                ax.plot(x, np.zeros_like(x), style, label=f"{label} ≈ 0")
            else:
                ax.plot(x, values[name] / peaks[name], style, label=f"{label} {100 * share:.3g} %")
        ax.legend(loc="upper right", fontsize=7, ncols=3, framealpha=0.8)
        for xs in np.concatenate([[0.0], np.cumsum(bridge.spans)]):
            ax.axvline(xs, color="0.6", linewidth=0.8)
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.set_ylim(-1.2, 1.6)
        ax.set_title(f"mode {i + 1}: {modal.f_hz[i]:.3f} Hz, {modal.kinds[i]}", fontsize=10)
    axes[-1].set_xlabel("x [m]")
    try:
        fig.savefig(path, dpi=120)
    except (OSError, ValueError) as exc:
        raise CosimError(f"{path}: cannot write the plot ({exc})") from None
    return n


# --------------------------------------------------------------------------- commands


def _check_output(path: str, what: str, suffixes: Sequence[str] | None = None) -> None:
    """Fail before the work, not after it, when an output file cannot be written."""
    target = Path(path)
    if target.is_dir():
        raise CosimError(f"{path}: is a directory, expected a file name for the {what}")
    parent = target.parent
    if not parent.is_dir():
        raise CosimError(f"{path}: cannot write the {what}: directory {str(parent)!r} does not exist")
    if suffixes is not None and target.suffix.lower().lstrip(".") not in suffixes:
        raise CosimError(
            f"{path}: unsupported file type for the {what} (expected one of: "
            + ", ".join("." + s for s in suffixes) + ")"
        )


def _plot_suffixes() -> list[str]:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    return sorted(FigureCanvasAgg.get_supported_filetypes())


def _cmd_modes(args: argparse.Namespace) -> int:
    if args.plot:
        _check_output(args.plot, "plot", _plot_suffixes())
    scenario = load_scenario(args.scenario)
    bridge = scenario.build_bridge()
    modal = bridge.modes(count=args.count)
    if args.json:
        payload = {
            "scenario": scenario.title,
            "source": scenario.source,
            "modes": _modes_payload(modal),
            "section": _section_payload(bridge.section),
            "damping": _damping_payload(bridge),
        }
        print(json.dumps(_jsonable(payload), indent=2))
    else:
        _print([_scenario_line(scenario), ""])
        _print(_section_lines(bridge.section))
        _print(["", *_damping_lines(bridge), ""])
        _print(_modes_lines(modal))
    if args.plot:
        plotted = _plot_modes(bridge, modal, args.plot, args.count)
        if not args.json:
            print(f"\nWrote {plotted} mode shape(s) to {args.plot}")
    return 0


def _static_cases(scenario: Scenario, bridge: BridgeModel) -> list[dict[str, Any]]:
    """A 100 kN downward load at mid-span of the longest span: on the axis and at the left edge."""
    spans = scenario.bridge.spans
    longest = max(range(len(spans)), key=lambda i: spans[i])
    x_load = sum(spans[:longest]) + 0.5 * spans[longest]
    y_left = float(bridge.section.deck_y[1])
    cases = []
    for name, y_load in (("axis", 0.0), ("left_edge", y_left)):
        result = bridge.static([PointLoad(x=x_load, y=y_load, Fz=-STATIC_LOAD_N)])
        cases.append(
            {
                "name": name,
                "load": {"x": x_load, "y": y_load, "Fz": -STATIC_LOAD_N, "span": longest + 1},
                "w_load_point": result.deck_displacement(x_load, y_load),
                "sensors": {s.name: result.deck_displacement(s.x, s.y) for s in scenario.sensors},
            }
        )
    return cases


def _static_lines(scenario: Scenario, cases: list[dict[str, Any]]) -> list[str]:
    load = cases[0]["load"]
    heads = [f"load at y = {c['load']['y']:g} m" for c in cases]
    lines = [
        f"Static load case: {STATIC_LOAD_N / 1e3:g} kN downward at x = {load['x']:g} m "
        f"(mid-span of span {load['span']}); deck displacement w [mm], positive up",
    ]
    rows = [(s.name, s.quantity, s.x, s.y, [c["sensors"][s.name] for c in cases]) for s in scenario.sensors]
    rows.append(("(under the load)", "displacement", load["x"], None, [c["w_load_point"] for c in cases]))
    width = max(len(row[0]) for row in rows) + 2
    lines.append(f"  {'point':<{width}}{'quantity':<16}{'x [m]':>8}{'y [m]':>9}" + "".join(f"{h:>22}" for h in heads))
    for name, quantity, x, y, values in rows:
        y_text = f"{y:9.3f}" if y is not None else f"{'-':>9}"
        lines.append(f"  {name:<{width}}{quantity:<16}{x:8.3f}{y_text}" + "".join(f"{1e3 * v:22.4f}" for v in values))
    if not scenario.sensors:
        lines.append("  (the scenario has no [[sensors]]; only the load point is reported)")
    return lines


def _cmd_run(args: argparse.Namespace) -> int:
    if args.out is not None and Path(args.out).suffix.lower() == ".csv":
        raise CosimError(
            f"{args.out}: --out is the run's MCAP log (LOG.mcap); for a CSV of the sensors give --csv {args.out}"
        )
    scenario = load_scenario(args.scenario)
    if scenario.vehicles or scenario.traffic is not None:
        return _run_vehicles(scenario, args)
    return _run_static(scenario, args)


def _run_static(scenario: Scenario, args: argparse.Namespace) -> int:
    """Without vehicles: the modes and a static load case; ``--out`` writes them as JSON (no log)."""
    if args.out is not None and Path(args.out).suffix.lower() == ".mcap":
        raise CosimError(
            f"{args.out}: the scenario has no [[vehicles]], so there is no time simulation to log; "
            "--out writes the modes and static displacements as JSON (e.g. --out summary.json)"
        )
    if args.csv is not None:
        raise CosimError(f"{args.csv}: the scenario has no [[vehicles]]: no sensor time histories for --csv")
    if args.out is not None:
        _check_output(args.out, "summary")
    print(_scenario_line(scenario))
    print(f"note: {NO_VEHICLES}")
    bridge = scenario.build_bridge()
    modal = bridge.modes(count=10)
    cases = _static_cases(scenario, bridge)
    _print(["", *_damping_lines(bridge), ""])
    _print(_modes_lines(modal))
    print()
    _print(_static_lines(scenario, cases))
    if args.out is not None:
        summary = {
            "scenario": scenario.title,
            "source": scenario.source,
            "note": NO_VEHICLES,
            "section": _section_payload(bridge.section),
            "damping": _damping_payload(bridge),
            "modes": _modes_payload(modal),
            "static": cases,
            "units": {"x": "m", "y": "m", "Fz": "N", "w": "m (positive up)", "f_hz": "Hz"},
        }
        try:
            Path(args.out).write_text(json.dumps(_jsonable(summary), indent=2) + "\n", encoding="utf-8")
        except OSError as exc:
            raise CosimError(f"{args.out}: cannot write the summary ({exc.strerror or exc})") from None
        print(f"\nWrote the summary to {args.out}")
    return 0


class _Progress:
    """Progress of a run on stderr: a tqdm bar on a terminal, a line of percentages otherwise."""

    def __init__(self, duration: float, show: bool) -> None:
        self.duration = duration
        self.fraction = 0.0
        self._stream = sys.stderr
        self._bar: Any = None
        self._tenths: int | None = None  # the light form: tenths printed so far
        if not show:
            return
        if self._stream.isatty():
            from tqdm import tqdm

            self._bar = tqdm(
                total=duration, file=self._stream, desc="Simulating", leave=True, dynamic_ncols=True,
                bar_format="{desc} {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s [{elapsed}<{remaining}]",
            )
        else:
            self._tenths = 0
            print(f"Simulating {duration:g} s:", end="", file=self._stream, flush=True)

    def __call__(self, fraction: float) -> None:
        self.fraction = fraction
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


def _log_target(out: str | None, default: Path, force: bool) -> Path:
    """The log to write: ``out`` (must end in .mcap) or ``default``; checked before any work."""
    if out is not None:
        path = Path(out)
        if path.suffix.lower() != ".mcap":
            raise CosimError(f"{out}: the log is an MCAP file: give a path ending in .mcap")
    else:
        path = default
    runner.check_new_file(path, "log", force)
    return path


def _g(value: float, digits: int = 6) -> str:
    return f"{float(value):.{digits}g}"


_PARAMETER_UNITS = {"mass": "kg", "m_v": "kg", "m_w": "kg", "k_v": "N/m", "c_v": "N s/m", "k_t": "N/m", "c_t": "N s/m"}


def _traffic_line(scenario: Scenario) -> str:
    t = scenario.traffic
    assert t is not None
    level = f" (bundled {t.sumo_config} demand)" if t.bundled else ""
    seed = f", seed {t.seed}" if t.seed is not None else ", the config's seed"
    axis = t.axis or ((0.0, 0.0), (scenario.bridge.length, 0.0))
    where = f"sumo_networks/{t.sumo_config}.sumocfg" if t.bundled else str(scenario.sumo_config_path)
    return (f"Traffic: SUMO {where}{level}, step {_g(t.step)} s, SUMO time {_g(t.begin)} to "
            f"{_g(t.end)} s{seed}; bridge axis {axis[0]} -> {axis[1]} in network coordinates")


def _vehicle_lines(scenario: Scenario) -> list[str]:
    if scenario.traffic is not None:
        return [_traffic_line(scenario)]
    rows = []
    for v in scenario.vehicles:
        if v.profile is not None:
            speed = "profile " + " ".join(f"{_g(t)}s:{_g(vv)}" for t, vv in v.profile)
        else:
            speed = _g(v.speed or 0.0)
        params = ", ".join(f"{k} = {_g(val)} {_PARAMETER_UNITS[k]}" for k, val in v.parameters.items())
        rows.append((v.id, v.model, f"{v.y:.3f}", v.direction, speed, _g(v.entry_time), params))
    heads = ("id", "model", "y [m]", "dir", "speed [m/s]", "entry [s]", "parameters")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(heads[:-1])]
    fmt = "  " + "  ".join(f"{{:<{w}}}" for w in widths) + "  {}"
    return [f"Vehicles ({len(rows)})", fmt.format(*heads), *(fmt.format(*r) for r in rows)]


def _road_line(scenario: Scenario) -> str:
    road = scenario.road
    wheel = scenario.wheel_paths()
    paths = "y = " + ", ".join(f"{y:g}" for y in wheel) + " m"
    if scenario.traffic is not None or len(wheel) > 6:
        paths = f"{len(wheel)} paths, y = {wheel[0]:g} to {wheel[-1]:g} m, each wheel on the nearest"
    if road.random:
        return (f"Road: ISO 8608 class {road.road_class}, seed {road.seed}, one profile per wheel path "
                f"({paths}), x = -10 m to L + 10 m")
    if road.profile is not None:
        return f"Road: profile {scenario.road_profile_path} (x, r), on every wheel path"
    return "Road: smooth"


def _solver_line(scenario: Scenario, duration: float) -> str:
    solver = scenario.solver
    scheme = solver.scheme if solver.scheme != "hht" else f"hht (alpha = {_g(solver.hht_alpha or 0.0)})"
    basis = solver.basis
    if solver.basis == "modal":
        if solver.modes is not None:
            basis += f" ({solver.modes} modes)"
        else:
            basis += f" (modes below {_g(solver.cutoff_hz or 0.0)} Hz)"
    if solver.duration is not None:
        how = "given"
    elif scenario.traffic is not None:
        how = "[traffic] end - begin"
    elif not scenario.vehicles:
        how = "the replayed log's"
    else:
        how = f"last vehicle leaves the deck at {_g(scenario.leave_time or 0.0, 4)} s, + 2 s"
    steps = int(round(duration / solver.dt))
    return (f"Solver: {scheme}, {basis} basis, dt = {_g(solver.dt)} s, duration {_g(duration, 4)} s ({how}), "
            f"{steps} steps, g = {_g(solver.gravity)} m/s^2")


def _logging_line(scenario: Scenario, log_path: Path) -> str:
    every = scenario.output_every
    steps = "every step" if every == 1 else f"every {every} steps"
    return f"Log: {log_path}, sampled at {_g(scenario.output_rate_hz, 4)} Hz ({steps})"


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
        unit, factor = DISPLAY_UNITS[s.quantity]
        lo = min(result.sensor_min.get(s.name, 0.0), 0.0) * factor  # t = 0: at rest
        hi = max(result.sensor_max.get(s.name, 0.0), 0.0) * factor
        lines.append(f"  {s.name:<{width}}  {s.quantity:<14}{s.x:8.3f}{s.y:8.3f}"
                     f"{lo + 0.0:12.4g}{hi + 0.0:12.4g}  {unit}")
    return lines


def _vehicle_summary(outcome: runner.RunOutcome, limit: int = 12) -> list[str]:
    result = outcome.result
    scripted = [v.id for v in outcome.scenario.vehicles]
    ids = scripted or sorted(outcome.on_deck, key=lambda v: -result.contact_force_range.get(v, (0, 0))[1])
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


def _run_lines(outcome: runner.RunOutcome) -> list[str]:
    result, duration = outcome.result, outcome.duration
    events, steps = result.liftoff_events, result.liftoff_steps
    lines = [f"Lift-off events: {events} ({steps} vehicle-steps with a negative contact force)"]
    if events:
        lines.append("  the contact is kept (bilateral) through a lift-off, as in the paper: "
                     "results after it assume the wheel stays on the deck")
    wall = result.wall_time
    factor = f"{duration / wall:.3g}" if wall > 0 else "inf"
    lines.append(f"Time stepping: {result.steps} steps in {wall:.2f} s wall time; "
                 f"real-time factor {factor} (simulated time / wall time)")
    basis = result.info.get("basis", "?")
    lines.append(f"Effective-matrix factorisations: {result.factorizations} "
                 f"({basis} basis, {result.info.get('n_reduced', '?')} unknowns)")
    lines.append(f"Wall time with logging: {outcome.wall_time:.2f} s")
    return lines


def _size(n: int) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} B"


def _log_done_line(outcome: runner.RunOutcome) -> str:
    return (f"Wrote the log {outcome.log_path} ({_size(outcome.log_bytes)}; {outcome.samples} sensor samples "
            f"at {_g(outcome.rate_hz, 4)} Hz from t = 0; status finished)")


def _header_lines(scenario: Scenario, bridge: BridgeModel, log_path: Path, duration: float | None = None) -> list[str]:
    spans = " + ".join(f"{span:g}" for span in bridge.spans)
    replayed = not scenario.vehicles and scenario.traffic is None
    return [
        f"Bridge: {spans} m, {len(bridge.nodes_x) - 1} elements",
        *_damping_lines(bridge),
        *(["Traffic: the replayed log's SUMO frames"] if replayed else _vehicle_lines(scenario)),
        _road_line(scenario),
        _solver_line(scenario, duration if duration is not None else scenario.duration),
        _logging_line(scenario, log_path),
    ]


def _simulate_logged(scenario: Scenario, bridge: BridgeModel, log_path: Path, args: argparse.Namespace,
                     **extra: Any) -> tuple[int, runner.RunOutcome | None]:
    """The time simulation into ``log_path``: (exit status, outcome) with the failure messages printed."""
    duration = extra.get("duration") or scenario.duration
    sys.stdout.flush()
    progress = _Progress(duration, show=not args.quiet)
    try:
        outcome = runner.run_logged(scenario, log_path, force=args.force, bridge=bridge, progress=progress, **extra)
    except runner.RunFailed as exc:
        progress.close()
        _report(f"{exc}\nthe run failed; the log {exc.log_path} is finished and ends with status \"error\"")
        return EXIT_RUN_FAILED, None
    except KeyboardInterrupt:
        progress.close()
        where = (f"the log up to there is in {log_path} (finished, status \"interrupted\")" if log_path.exists()
                 else "no log was written")
        print(f"cosim: interrupted at about t = {progress.fraction * duration:.4g} s of {duration:g} s; {where}",
              file=sys.stderr)
        return EXIT_INTERRUPTED, None
    progress.close()
    return 0, outcome


def _print_outcome(scenario: Scenario, outcome: runner.RunOutcome) -> None:
    """The end-of-run summary: sensor peaks, vehicles, counters, the log written."""
    print()
    _print(_sensor_summary(scenario, outcome.result))
    _print(_vehicle_summary(outcome))
    _print(_run_lines(outcome))
    print(_log_done_line(outcome))


def _run_vehicles(scenario: Scenario, args: argparse.Namespace) -> int:
    """With [[vehicles]]: the time simulation into an MCAP log, an optional sensor CSV and a summary."""
    default = scenario.log_path or runner.unique_path(scenario.default_log_path())
    log_path = _log_target(args.out, default, args.force)
    csv_path = Path(args.csv) if args.csv is not None else scenario.csv_path
    if csv_path is not None:
        runner.check_new_file(csv_path, "sensor CSV", args.force)
    print(_scenario_line(scenario))
    bridge = scenario.build_bridge()
    _print(_header_lines(scenario, bridge, log_path))
    status, outcome = _simulate_logged(scenario, bridge, log_path, args)
    if outcome is None:
        return status
    _print_outcome(scenario, outcome)
    if csv_path is not None:
        rows, columns = runner.export_csv(log_path, csv_path, force=args.force)
        print(f"Wrote {rows} rows to {csv_path} (columns {','.join(columns)}; SI units: m, m/s, m/s^2, N m)")
    return 0


def _cmd_replay(args: argparse.Namespace) -> int:
    other = load_scenario(args.scenario) if args.scenario is not None else None
    log = Path(args.log)
    with tempfile.TemporaryDirectory(prefix="cosim-replay-") as scratch:
        plan = runner.replay_scenario(log, Path(scratch), other)
        scenario = plan.scenario
        default = runner.unique_path(scenario.default_log_path(suffix="-replay"))
        log_path = _log_target(args.out, default, args.force)
        if log_path.resolve() == log.resolve():
            raise CosimError(f"{log_path}: the replay cannot overwrite the log it replays")
        status_word = runner.status_word(plan.overview)
        if plan.traffic is not None:
            what = f"its SUMO traffic ({plan.record.get('traffic', 'logged frames')}; SUMO is not run again)"
        else:
            ids = ", ".join(v.id for v in scenario.vehicles)
            what = f"its {len(scenario.vehicles)} scripted vehicle(s) {ids}"
        print(f"Replay of {log} ({plan.record['log_scenario']}, {status_word}): {what}")
        if plan.own:
            print(f"Bridge, sensors, road and solver: the log's own scenario ({scenario.title})")
        else:
            print(f"Bridge, sensors, road and solver: {other.source if other else ''} ({scenario.title})")
        bridge = scenario.build_bridge()
        _print(_header_lines(scenario, bridge, log_path, plan.duration))
        status, outcome = _simulate_logged(scenario, bridge, log_path, args, replay=plan.record,
                                           attachments=plan.attachments, traffic=plan.traffic,
                                           duration=plan.duration)
    if outcome is None:
        return status
    _print_outcome(scenario, outcome)
    comparison = runner.compare_sensors(log, log_path)
    print()
    if plan.own:
        return _print_reproduction(comparison, log)
    _print(_comparison_lines(comparison, log, log_path, scenario))
    return 0


def _print_reproduction(comparison: runner.Comparison, log: Path) -> int:
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


def _comparison_lines(comparison: runner.Comparison, log: Path, new: Path, scenario: Scenario) -> list[str]:
    quantities = {s.name: s.quantity for s in scenario.sensors}
    if not comparison.names:
        return [f"Compared with {log}: no sensor of the same name in both logs"]
    width = max(len("name"), *(len(n) for n in comparison.names))
    lines = [f"Sensors of the same name, the logged run vs this bridge ({new}):",
             f"  {'name':<{width}}{'log min':>12}{'log max':>12}{'new min':>12}{'new max':>12}  unit"]
    for name in comparison.names:
        unit, factor = DISPLAY_UNITS.get(quantities.get(name, ""), ("SI", 1.0))
        (a0, a1), (b0, b1) = comparison.extremes_a[name], comparison.extremes_b[name]
        lines.append(f"  {name:<{width}}{a0 * factor:12.4g}{a1 * factor:12.4g}{b0 * factor:12.4g}"
                     f"{b1 * factor:12.4g}  {unit}")
    return lines


def _cmd_export(args: argparse.Namespace) -> int:
    overview = runner.open_log(args.log)
    rows, columns = runner.export_csv(args.log, args.csv, topic=args.topic, force=args.force)
    if overview.truncated:
        print(f"note: {args.log} was cut short (truncated); exported what it holds up to its last complete chunk",
              file=sys.stderr)
    units = "SI units: m, m/s, m/s^2, N m" if args.topic == TOPIC_SENSORS else "SI units"
    print(f"Wrote {rows} rows of {args.topic} to {args.csv} (columns {','.join(columns)}; {units})")
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    _print(_info_lines(runner.open_log(args.log)))
    return 0


def _info_lines(o: runner.LogOverview) -> list[str]:
    info = o.info
    lines = [f"Log: {o.path} ({_size(o.size)}, {'finished file' if o.complete else 'TRUNCATED'})"]
    if info:
        lines.append(f"Scenario: {info.get('scenario', '?')} (source: {info.get('source', '?')})")
        lines.append(f"Written by: cosim {info.get('version', '?')} ({info.get('kind', 'run')}), "
                     f"started {info.get('started', '?')}")
        replay = o.metadata.get(runner.REPLAY_METADATA_NAME)
        if replay:
            lines.append(f"Replay of: {replay.get('log', '?')} (traffic of {replay.get('log_scenario', '?')}; "
                         f"bridge of {replay.get('scenario', '?')})")
        every = info.get("every", "?")
        steps = "every step" if every == "1" else f"every {every} steps"
        rate = _g(float(info["rate_hz"]), 4) if "rate_hz" in info else "?"
        lines.append(f"Solver: {info.get('scheme', '?')}, {info.get('basis', '?')} basis, "
                     f"dt = {info.get('dt', '?')} s; logged at {rate} Hz ({steps})")
        planned = info.get("duration")
        planned_text = f" of {_g(float(planned), 6)} s" if planned else ""
        lines.append(f"Simulated: {_g(o.end_time, 6)} s{planned_text}")
    else:
        lines.append("Scenario: (no cosim metadata in this log)")
        lines.append(f"Simulated: {_g(o.end_time, 6)} s")
    sensors = ", ".join(f"{n} ({q})" if q else n for n, q in zip(o.sensor_names, o.quantities)) or "none"
    lines.append(f"Sensors ({len(o.sensor_names)}): {sensors}")
    if "vehicles" in info:
        try:
            vehicles = json.loads(info["vehicles"])
            lines.append(f"Vehicles ({len(vehicles)}): {', '.join(vehicles) or 'none'}")
        except ValueError:
            pass
    lines.append("Topics:")
    width = max([len(t) for t in o.counts] + [10])
    for topic, count in sorted(o.counts.items()):
        lines.append(f"  {topic:<{width}}  {count:>9} messages")
    status = o.final_status
    if status is None:
        lines.append("Status: none logged")
    else:
        message = f": {status['message']}" if status.get("message") else ""
        lines.append(f"Status: {status.get('state', '?')} at t = {_g(float(status.get('t', 0.0)), 6)} s{message}")
    if o.complete:
        lines.append("Truncated: no")
    else:
        lines.append("Truncated: yes - the file was cut short (the process was killed?); "
                     "it is read up to its last complete chunk")
    atts = ", ".join(f"{name} ({_size(len(data))})" for name, data in o.attachments.items()) or "none"
    lines.append(f"Attachments: {atts}")
    return lines


def _cmd_plot(args: argparse.Namespace) -> int:
    drawn = runner.plot_sensors(args.log, args.output, args.sensor, force=args.force)
    print(f"Wrote {len(drawn)} sensor time histor{'y' if len(drawn) == 1 else 'ies'} ({', '.join(drawn)}) "
          f"to {args.output}")
    return 0


# --------------------------------------------------------------------------- parser


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {value}")
    return value


def _bundled_text() -> str:
    names = ", ".join(list_bundled_scenarios()) or "none"
    return textwrap.fill(f"SCENARIO is a path to a .toml file or the name of a bundled scenario ({names}).", 79)


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
              cosim replay run1.mcap --scenario other-bridge.toml
              cosim modes paper-double-tee --count 12 --plot modes.png
            """
        )
        + "\n"
        + _bundled_text()
        + "\nErrors print 'cosim: error: ...' on stderr and exit with status 2.",
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
        + _bundled_text(),
        formatter_class=formatter,
    )
    modes.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml) or bundled scenario name")
    modes.add_argument("--count", "-n", type=_positive_int, default=10, metavar="N",
                       help="number of modes to compute (default: 10)")
    modes.add_argument("--json", action="store_true",
                       help="print JSON (scenario, section, damping, modes with n, f_hz, kind, participation) "
                            "and nothing else on stdout")
    modes.add_argument("--plot", metavar="FILE.png",
                       help=f"draw the first N (at most {MAX_PLOTTED_MODES}) mode shapes: v, w and twist theta_x "
                            "along x, each normalised")
    modes.set_defaults(func=_cmd_modes)

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
            display goes to stderr. The log is finished whatever ends the run: Ctrl-C
            leaves status "interrupted", a diverging solution status "error".

            Without [[vehicles]]: the modal analysis (first 10 modes) and a static load
            case, a {STATIC_LOAD_N / 1e3:g} kN downward point load at mid-span of the longest span, once
            on the bridge axis (y = 0) and once at the left deck edge (largest y),
            with each sensor's deck displacement for both (no log).

            Exit status: 0 done, 1 the solution diverged (the log ends with status
            "error"), 2 bad input (before any file is written), 130 interrupted (Ctrl-C;
            the log ends with status "interrupted")."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the default traffic run -> runs/{DEFAULT_SCENARIO}-<date>-<time>.mcap
              cosim run paper-double-tee             # the paper's two quarter-cars
              cosim run my-bridge.toml --out results/run1.mcap --csv results/run1.csv
              cosim run my-bridge-no-vehicles.toml --out summary.json
            """
        )
        + "\n"
        + _bundled_text(),
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
                     help="overwrite the log and the CSV if they exist (default: refuse)")
    run.add_argument("--quiet", "-q", action="store_true",
                     help="no progress display on stderr")
    run.set_defaults(func=_cmd_run)

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
            differ, 2 bad input (unreadable log, a vehicle off OTHER's deck, ...),
            130 interrupted."""
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
    replay.set_defaults(func=_cmd_replay)

    topics = ", ".join(runner.EXPORT_TOPICS)
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
            A log cut short is exported up to its last complete chunk."""
        ),
        epilog="examples:\n  cosim export runs/run1.mcap --csv run1.csv\n"
               f"  cosim export runs/run1.mcap --topic {TOPIC_VEHICLES} --csv vehicles.csv\n",
        formatter_class=formatter,
    )
    export.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    export.add_argument("--csv", metavar="OUT.csv", required=True, help="the CSV file to write")
    export.add_argument("--topic", default=TOPIC_SENSORS, metavar="TOPIC",
                        help=f"the topic to export (one of: {topics}; default: {TOPIC_SENSORS})")
    export.add_argument("--force", "-f", action="store_true", help="overwrite OUT.csv if it exists")
    export.set_defaults(func=_cmd_export)

    info = commands.add_parser(
        "info",
        help="summarise a log: scenario, duration, topics, status, truncated or not",
        description=textwrap.dedent(
            """\
            Summarise a log: its scenario, cosim version, simulated time, sensors, topics
            with message counts, final status and message, whether the file is truncated
            (cut short by a killed process: exit status 0, the readable part is shown) and
            its attachments. Every chunk's checksum is verified: a damaged file or one that
            is not a cosim MCAP log exits with status 2."""
        ),
        epilog="example:\n  cosim info runs/run1.mcap\n",
        formatter_class=formatter,
    )
    info.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    info.set_defaults(func=_cmd_info)

    plot = commands.add_parser(
        "plot",
        help="draw the sensor time histories of a log",
        description=textwrap.dedent(
            """\
            Draw the time histories of a log's sensors, one panel each, over time in s
            (displacements in mm, velocities in mm/s, accelerations in m/s^2, bending
            moments in kN m)."""
        ),
        epilog="examples:\n  cosim plot runs/run1.mcap -o run1.png\n"
               "  cosim plot runs/run1.mcap --sensor node1 --sensor node3_acc -o two.png\n",
        formatter_class=formatter,
    )
    plot.add_argument("log", metavar="LOG.mcap", help="a cosim log")
    plot.add_argument("--sensor", action="append", metavar="NAME",
                      help="a sensor to draw (repeat for more; default: all)")
    plot.add_argument("-o", "--output", required=True, metavar="FIG.png", help="the figure (.png, .pdf, .svg, ...)")
    plot.add_argument("--force", "-f", action="store_true", help="overwrite FIG if it exists")
    plot.set_defaults(func=_cmd_plot)

    validate = commands.add_parser(
        "validate",
        help="run the verification and validation cases; write a report with plots",
        description=textwrap.dedent(
            """\
            Run every verification case against its closed form or independent solution
            (Timoshenko statics and frequencies, non-uniform torsion, torsional and coupled
            lateral-torsional frequencies, Fryba's moving force, a sprung mass against an
            independent modal ODE, energy conservation, time-step and mesh convergence,
            ISO 8608 spectra, a parked vehicle) and the paper's 40 m double-tee case
            (Nodes 1-3 like its Figs. 4-6, quarter-cars and moving forces, direct and
            modal bases). Writes DIR/report.md with each case's reference, error and
            tolerance, and PNG plots next to it.

            Exit status: 0 every case within its tolerance, 1 a case failed, 2 bad input."""
        ),
        epilog="examples:\n  cosim validate\n  cosim validate --out validation --quick\n",
        formatter_class=formatter,
    )
    validate.add_argument("--out", default="validation", metavar="DIR",
                          help="folder for report.md and the plots (default: validation)")
    validate.add_argument("--quick", action="store_true", help="coarser settings (seconds instead of a minute)")
    validate.set_defaults(func=_cmd_validate)

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

            Exit status: 0 every run ok, 1 some run failed (see the table), 2 bad input,
            130 interrupted (the same command resumes)."""
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
    study.add_argument("--out", metavar="FOLDER", help="the output folder (default: [study].output, else studies/<name>)")
    study.add_argument("--redo", action="store_true", help="run every run again, even those already done")
    study.add_argument("--no-plots", action="store_true", help="write the table only")
    study.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    study.set_defaults(func=_cmd_study)
    return parser


def _cmd_study(args: argparse.Namespace) -> int:
    from cosim.study.study import load_study, run_study, summary_text

    study = load_study(args.study, output=args.out)
    bar: Any = None
    failures: list[str] = []

    def progress(done: int, total: int, row: dict | None) -> None:
        nonlocal bar
        if row is not None and row.get("status") != "ok":
            failures.append(row["run_id"])
        if args.quiet:
            return
        if not sys.stderr.isatty():  # a log file: one line per finished run
            if row is not None:
                state = "ok" if row.get("status") == "ok" else f"FAILED: {(row.get('error') or '').splitlines()[0]}"
                print(f"run {done}/{total} {row['run_id']}: {state}", file=sys.stderr, flush=True)
            elif done:
                print(f"{done} of {total} runs done earlier", file=sys.stderr, flush=True)
            return
        if bar is None:
            from tqdm import tqdm

            bar = tqdm(total=total, initial=done, file=sys.stderr, desc=f"Study {study.name}", unit="run",
                       dynamic_ncols=True,
                       bar_format="{desc}: {n}/{total} runs |{bar}| [{elapsed}<{remaining}]{postfix}")
        if failures:
            bar.set_postfix_str(f"{len(failures)} failed", refresh=False)
        bar.update(done - bar.n)

    try:
        outcome = run_study(study, workers=args.workers, scheduler=args.scheduler, progress=progress,
                            redo=args.redo, plots=False if args.no_plots else None)
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        print(f"cosim: interrupted; the runs finished so far are in {study.output / 'results.csv'}; "
              "run the same command again to resume", file=sys.stderr)
        return 130
    if bar is not None:
        bar.close()
    print(summary_text(outcome))
    return 1 if outcome.failed else 0


def _cmd_validate(args: argparse.Namespace) -> int:
    from cosim.validation.cases import run_validation

    def progress(done: int, total: int, label: str) -> None:
        print(f"[{done}/{total}] {label}", file=sys.stderr, flush=True)

    report = run_validation(Path(args.out), quick=args.quick, progress=progress)
    _print(report.summary_lines())
    return 0 if report.all_passed else EXIT_RUN_FAILED


# --------------------------------------------------------------------------- entry point


def _report(message: str) -> None:
    lines = message.splitlines() or [""]
    print(f"cosim: error: {lines[0]}", file=sys.stderr)
    for line in lines[1:]:
        print(f"  {line}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Run the ``cosim`` command line; returns the exit status.

    Args:
        argv: the arguments without the program name (default: ``sys.argv[1:]``).
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version (0) and usage errors (2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    try:
        return int(args.func(args))
    except CosimError as exc:
        _report(str(exc))
        return 2
    except KeyboardInterrupt:
        print("cosim: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `cosim modes ... | head`
        try:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        except OSError:
            pass
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
