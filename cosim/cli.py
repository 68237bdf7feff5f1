"""The ``cosim`` command line: the only module that prints.

Subcommands::

    cosim modes SCENARIO [--count N] [--json] [--plot FILE.png]
    cosim run [SCENARIO] [--out CSV] [--force] [--quiet]

Every :class:`cosim.errors.CosimError` becomes ``cosim: error: <message>`` on
stderr and exit status 2 (as for usage errors); a :class:`cosim.errors.ModelError`
during the time integration (the solution diverged) exits with 1; Ctrl-C exits
with 130.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import textwrap
from dataclasses import asdict
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from . import __version__
from .bridge import BridgeModel, ModalResult, PointLoad
from .errors import CosimError, ModelError
from .scenario import Scenario, list_bundled_scenarios, load_scenario
from .section import SectionProperties
from .simulation import SimulationResult

DEFAULT_SCENARIO = "paper-double-tee"
STATIC_LOAD_N = 100e3
NO_VEHICLES = (
    "the scenario has no [[vehicles]]; "
    "this run does the modal analysis and a static load case"
)
#: Summary units per sensor quantity: (unit, factor from SI).
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "displacement": ("mm", 1e3),
    "velocity": ("mm/s", 1e3),
    "acceleration": ("m/s^2", 1.0),
    "bending_moment": ("kN m", 1e-3),
}
EXIT_RUN_FAILED = 1
EXIT_INTERRUPTED = 130
MAX_PLOTTED_MODES = 6
NEGLIGIBLE_SHARE = 1e-3  # plotted fields below this share of the largest are drawn as zero

# --------------------------------------------------------------------------- payloads


def _jsonable(value: Any) -> Any:
    """Plain JSON types from numpy scalars/arrays, tuples and dataclass fields."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if hasattr(value, "tolist"):
        return _jsonable(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _section_payload(section: SectionProperties) -> dict[str, Any]:
    return _jsonable(asdict(section))


def _modes_payload(modal: ModalResult) -> list[dict[str, Any]]:
    f_hz = modal.f_hz
    return [
        {
            "n": i + 1,
            "f_hz": float(f_hz[i]),
            "kind": modal.kinds[i],
            "participation": {kind: float(values[i]) for kind, values in modal.participation.items()},
        }
        for i in range(len(f_hz))
    ]


def _damping_payload(bridge: BridgeModel) -> dict[str, Any]:
    return {
        "alpha": float(bridge.alpha),
        "beta": float(bridge.beta),
        "note": bridge.damping_note,
    }


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
    if args.out is not None and Path(args.out).suffix.lower() == ".mcap":
        raise CosimError(
            f"{args.out}: MCAP logs are not implemented yet; give a .csv path for the sensor time histories"
        )
    scenario = load_scenario(args.scenario)
    if scenario.vehicles:
        return _run_vehicles(scenario, args)
    return _run_static(scenario, args)


def _run_static(scenario: Scenario, args: argparse.Namespace) -> int:
    """Without vehicles: the modes and a static load case; ``--out`` writes them as JSON."""
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


def _prepare_csv(path: Path, force: bool) -> None:
    """Fail before the run when the CSV cannot be written; create its folder."""
    if path.is_dir():
        raise CosimError(f"{path}: is a directory, expected a file name for the sensor CSV")
    if path.exists() and not force:
        raise CosimError(f"{path}: already exists; use --force to overwrite it, or --out to write elsewhere")
    blocking = next((folder for folder in reversed(path.parents) if folder.exists() and not folder.is_dir()), None)
    if blocking is not None:
        raise CosimError(f"{path}: cannot create the folder for the sensor CSV: {str(blocking)!r} is a file")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CosimError(
            f"{path}: cannot create the folder for the sensor CSV ({exc.strerror or exc})"
        ) from None


def _write_csv(result: SimulationResult, path: Path, force: bool) -> None:
    """Write through a temporary file, so a failed write leaves no half file behind."""
    if path.exists() and not force:  # appeared during the run
        raise CosimError(f"{path}: already exists (created during the run); use --force to overwrite it")
    partial = path.with_name(path.name + ".part")
    try:
        result.write_csv(partial)
        os.replace(partial, path)
    except OSError as exc:
        partial.unlink(missing_ok=True)
        raise CosimError(f"{path}: cannot write the sensor CSV ({exc.strerror or exc})") from None


def _g(value: float, digits: int = 6) -> str:
    return f"{float(value):.{digits}g}"


_PARAMETER_UNITS = {"mass": "kg", "m_v": "kg", "m_w": "kg", "k_v": "N/m", "c_v": "N s/m", "k_t": "N/m", "c_t": "N s/m"}


def _vehicle_lines(scenario: Scenario) -> list[str]:
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
    paths = ", ".join(f"{y:g}" for y in scenario.wheel_paths())
    if road.random:
        return (f"Road: ISO 8608 class {road.road_class}, seed {road.seed}, one profile per wheel path "
                f"(y = {paths} m), x = -10 m to L + 10 m")
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
    else:
        how = f"last vehicle leaves the deck at {_g(scenario.leave_time or 0.0, 4)} s, + 2 s"
    steps = int(round(duration / solver.dt))
    every = f", sampled every {scenario.output.every} steps" if scenario.output.every > 1 else ""
    return (f"Solver: {scheme}, {basis} basis, dt = {_g(solver.dt)} s, duration {_g(duration, 4)} s ({how}), "
            f"{steps} steps{every}, g = {_g(solver.gravity)} m/s^2")


def _sensor_summary(scenario: Scenario, result: SimulationResult) -> list[str]:
    if not scenario.sensors:
        return ["Sensors: none (the scenario has no [[sensors]]; the CSV has only the time column)"]
    names = [s.name for s in scenario.sensors]
    width = max(len("name"), *(len(n) for n in names))
    lines = [
        "Sensors: peaks over the run",
        f"  {'name':<{width}}  {'quantity':<14}{'x [m]':>8}{'y [m]':>8}{'min':>12}{'max':>12}  unit",
    ]
    for s in scenario.sensors:
        unit, factor = DISPLAY_UNITS[s.quantity]
        values = result.sensors[s.name] * factor
        lo, hi = (float(values.min()), float(values.max())) if len(values) else (0.0, 0.0)
        lines.append(f"  {s.name:<{width}}  {s.quantity:<14}{s.x:8.3f}{s.y:8.3f}{lo:12.4g}{hi:12.4g}  {unit}")
    return lines


def _vehicle_summary(scenario: Scenario, result: SimulationResult) -> list[str]:
    ids = [v.id for v in scenario.vehicles]
    width = max(len("id"), *(len(i) for i in ids))
    sampled = " (sampled)" if scenario.output.every > 1 else ""
    lines = [
        f"Vehicles: contact force, compression positive{sampled}",
        f"  {'id':<{width}}  {'on the deck [s]':<18}{'min [kN]':>10}{'max [kN]':>10}  lifted off",
    ]
    for vid in ids:
        if vid not in result.vehicle_ids:
            lines.append(f"  {vid:<{width}}  not on the deck during the run")
            continue
        data = result.vehicle(vid)
        force = data["contact_force"] / 1e3
        t = data["t"]
        on_deck = f"{t.min():.3f} - {t.max():.3f}"
        lifted = "yes" if force.min() < 0 else "no"
        lines.append(f"  {vid:<{width}}  {on_deck:<18}{force.min():10.3f}{force.max():10.3f}  {lifted}")
    return lines


def _run_lines(result: SimulationResult, duration: float) -> list[str]:
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
    return lines


def _run_vehicles(scenario: Scenario, args: argparse.Namespace) -> int:
    """With [[vehicles]]: the time simulation, the sensor CSV and a summary."""
    csv_path = Path(args.out) if args.out is not None else scenario.csv_path
    _prepare_csv(csv_path, args.force)
    duration = scenario.duration
    print(_scenario_line(scenario))
    bridge = scenario.build_bridge()
    spans = " + ".join(f"{span:g}" for span in bridge.spans)
    print(f"Bridge: {spans} m, {len(bridge.nodes_x) - 1} elements")
    _print(_damping_lines(bridge))
    _print(_vehicle_lines(scenario))
    print(_road_line(scenario))
    print(_solver_line(scenario, duration))
    sys.stdout.flush()
    progress = _Progress(duration, show=not args.quiet)
    try:
        result = scenario.simulate(progress, bridge=bridge)
    except ModelError as exc:
        progress.close()
        _report(f"{exc} (the run failed; {csv_path} was not written)")
        return EXIT_RUN_FAILED
    except KeyboardInterrupt:
        progress.close()
        print(f"cosim: interrupted at about t = {progress.fraction * duration:.3g} s of {duration:g} s; "
              f"{csv_path} was not written", file=sys.stderr)
        return EXIT_INTERRUPTED
    progress.close()
    _write_csv(result, csv_path, args.force)
    print()
    _print(_sensor_summary(scenario, result))
    _print(_vehicle_summary(scenario, result))
    _print(_run_lines(result, duration))
    columns = ",".join(["t", *result.sensors])
    print(f"Wrote {len(result.t)} rows to {csv_path} (columns {columns}; SI units: m, m/s, m/s^2, N m)")
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
            rotary inertia, uniform and non-uniform torsion) driven by vehicles.
            Scenarios are TOML files (see docs/scenario.md); SI units throughout."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the bundled default bridge ({DEFAULT_SCENARIO})
              cosim modes paper-double-tee --count 12 --plot modes.png
              cosim modes my-bridge.toml --json
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
            f"""\
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
        help="run a scenario: the time simulation of its vehicles (or, without any, modes and a static case)",
        description=textwrap.dedent(
            f"""\
            Run a scenario; without SCENARIO, the bundled '{DEFAULT_SCENARIO}' (the paper's
            two quarter-cars crossing its 40 m double-tee bridge).

            With [[vehicles]]: integrate the coupled vehicle-bridge equations in time,
            write every sensor's time history to a CSV file (columns t,<sensor names>,
            SI units) and print a summary: sensor peaks, each vehicle's contact
            force and whether it lifted off, steps, wall time, real-time factor and
            factorisation count. A progress display goes to stderr.

            Without [[vehicles]]: the modal analysis (first 10 modes) and a static load
            case, a {STATIC_LOAD_N / 1e3:g} kN downward point load at mid-span of the longest span, once
            on the bridge axis (y = 0) and once at the left deck edge (largest y),
            with each sensor's deck displacement for both.

            Exit status: 0 done, 1 the solution diverged, 2 bad input, 130 interrupted
            (Ctrl-C; no CSV is written then)."""
        ),
        epilog=textwrap.dedent(
            f"""\
            examples:
              cosim run                              # the paper's case -> runs/{DEFAULT_SCENARIO}.csv
              cosim run my-bridge.toml --out results/run1.csv --force
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
                     help="with vehicles: the sensor CSV (default: [output].csv, else runs/<scenario name>.csv; "
                          "its folder is created); without vehicles: write the modes and static "
                          "displacements as JSON to PATH")
    run.add_argument("--force", "-f", action="store_true",
                     help="overwrite the sensor CSV if it exists (default: refuse)")
    run.add_argument("--quiet", "-q", action="store_true",
                     help="no progress display on stderr")
    run.set_defaults(func=_cmd_run)
    return parser


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
