"""``cosim validate``: the verification and validation cases, with a Markdown report and plots.

:func:`run_validation` runs every case of DESIGN.md section 8 -- the paper's
40 m double-tee bridge (``shared/cases/paper-double-tee.md``) and the closed-form
and independent references of :mod:`cosim.validation.references` -- and writes
``report.md`` and one PNG per plot into a directory::

    from cosim.validation.cases import run_validation

    report = run_validation("validation-out", quick=True)
    print(report.all_passed, report.report_path)
    for case in report.cases:
        print(case.name, case.error, case.tolerance, case.passed)

Errors are measured in the unit the case names (usually relative to the
reference's peak) and compared with a tolerance stated next to it; cases
without a tolerance are informational. ``quick=True`` uses coarser time steps
and shorter reference solves with the same tolerances (about 10 s against 20 s
for the full run, plus numba's one-off compilation of the coupled step). matplotlib is imported only while drawing (Agg canvas, no pyplot
state); this module prints nothing.
"""
from __future__ import annotations

import math
import time
import traceback
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import numpy.typing as npt

from cosim import __version__
from cosim.core.bridge import BridgeModel, ExplicitDamping, PointLoad, build_bridge
from cosim.core.element import DOF_INDEX, NODE_DOFS
from cosim.errors import CosimError
from .references import (
    STEEL,
    YANG_YAU,
    yang_yau_case,
    cantilever_tip_load_deflection,
    doubly_symmetric_section,
    euler_bernoulli_ss_frequency_hz,
    fryba_midspan_deflection,
    lateral_torsional_frequencies_hz,
    midspan_torque_twist,
    monosymmetric_section,
    rectangle_section,
    sprung_mass_modal_solution,
    ss_point_load_deflection,
    timoshenko_ss_frequency_hz,
    torsional_frequencies_hz,
)
from cosim.core.section import SectionProperties
from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel

__all__ = ["CaseResult", "ValidationReport", "ValidationSettings", "run_validation", "study_names"]

GRAVITY = 9.81  # m/s^2

#: Called as ``progress(done, total, label)``: before each study starts (``done``
#: studies finished so far, ``label`` names the one starting) and once at the end
#: with ``done == total`` and ``label == "done"``.
ProgressCallback = Callable[[int, int, str], None]

# The paper's vehicles (Table 2 with the units of DESIGN.md section 9; wheel masses from
# shared/cases/paper-double-tee.md) and its read-out points at mid-span, deck level.
PAPER_QC1 = QuarterCar(m_v=1000.0, m_w=100.0, k_v=39478.40, c_v=5026.55)
PAPER_QC2 = QuarterCar(m_v=2000.0, m_w=200.0, k_v=78956.80, c_v=10053.10)
PAPER_LANE_Y = 3.325  # m
PAPER_SPEED = 4.0  # m/s
PAPER_QC2_ENTRY = 7.5  # s (30 m behind QC-1)
PAPER_DURATION = 20.0  # s
PAPER_MODAL_MODES = 40
PAPER_NODES = (("Node 1", 0.0), ("Node 2", 6.655), ("Node 3", 3.325))  # (name, y in m) at x = L/2

# Tolerances (the same as the verification tests in tests/verification).
TOL_PAPER_BASES = 0.01  # max |direct - modal| / peak
TOL_NODAL_EXACT = 1e-9  # locking-free Timoshenko element: exact at the nodes for point loads
TOL_FREQ_TIMOSHENKO = 2e-3  # 40 elements, deep beam, O(h^2) in the shear strain
TOL_FE_40 = 2e-4  # 40 elements: torsion statics and frequencies, coupled frequencies
TOL_FRYBA = 0.01  # of the peak
TOL_SPRUNG = 0.02  # of the peak
TOL_ENERGY = 1e-9  # relative drift, average acceleration on a linear undamped system
TOL_ORDER_TIME = 0.2  # shortfall of the observed order below 2
TOL_ORDER_MESH_EB = 0.3  # below 4 (cubic bending field, Euler-Bernoulli limit)
TOL_ORDER_MESH_TIMOSHENKO = 0.2  # below 2 (constant shear strain per element)
TOL_ROUGHNESS = 0.10  # fitted G_d(n0) against the class value; the class band is a factor 2 either way
TOL_PARKED = 1e-4  # settled deflection and contact force against statics


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class CaseResult:
    """One validation case.

    Attributes:
        name: unique, human-readable name (used as the report's heading).
        reference: what the model is compared with, source named.
        metric: how ``error`` is measured (its unit).
        error: the measured error, or None for an informational case that has none.
        tolerance: the largest acceptable ``error``; None for informational cases.
        passed: the case met its tolerance (informational cases pass unless they crashed);
            by default judged from ``error`` and ``tolerance``.
        plots: PNG files of this case.
        details: Markdown with the numbers behind ``error`` (tables, peaks).
        group: the study the case belongs to (report section).
    """

    name: str
    reference: str
    metric: str
    error: float | None
    tolerance: float | None
    passed: bool | None = None
    plots: tuple[Path, ...] = ()
    details: str = ""
    group: str = ""

    def __post_init__(self) -> None:
        if self.passed is None:  # judged: within tolerance (an informational case passes)
            judged = self.tolerance is None or _judge(self.error, self.tolerance)
            object.__setattr__(self, "passed", judged)

    @property
    def informational(self) -> bool:
        """No tolerance: reported, not judged."""
        return self.tolerance is None

    @property
    def status(self) -> str:
        """``PASS``, ``FAIL`` or ``INFO``."""
        if not self.passed:
            return "FAIL"
        return "INFO" if self.informational else "PASS"


@dataclass(frozen=True)
class ValidationReport:
    """Everything :func:`run_validation` did.

    Attributes:
        out_dir: the output directory.
        quick: whether the coarse settings were used.
        cases: every case, in report order.
        files: every file written (report.md first, then the PNGs).
        wall_time: total run time, s.
    """

    out_dir: Path
    quick: bool
    cases: tuple[CaseResult, ...]
    files: tuple[Path, ...]
    wall_time: float

    @property
    def all_passed(self) -> bool:
        """True when no case failed (informational cases never fail unless they crash)."""
        return all(case.passed for case in self.cases)

    @property
    def failures(self) -> tuple[CaseResult, ...]:
        return tuple(case for case in self.cases if not case.passed)

    @property
    def report_path(self) -> Path:
        return self.out_dir / "report.md"

    @property
    def plots(self) -> tuple[Path, ...]:
        return tuple(p for p in self.files if p.suffix == ".png")

    def case(self, name: str) -> CaseResult:
        """The case called ``name``."""
        for case in self.cases:
            if case.name == name:
                return case
        raise KeyError(f"no validation case {name!r}")

    def summary_lines(self) -> list[str]:
        """One line per case plus a total, for a terminal (the CLI prints them)."""
        width = max(len(c.name) for c in self.cases) if self.cases else 0
        lines = [
            f"{c.status:4}  {c.name:<{width}}  error {_fmt(c.error)}  tolerance {_fmt(c.tolerance)}"
            for c in self.cases
        ]
        failed = len(self.failures)
        lines.append(
            f"{len(self.cases) - failed} of {len(self.cases)} cases passed"
            f"{'' if not failed else f', {failed} FAILED'} in {self.wall_time:.1f} s; report: {self.report_path}"
        )
        return lines


@dataclass(frozen=True)
class ValidationSettings:
    """Resolution of the cases (time steps, reference solves); :meth:`full` or :meth:`quick`."""

    name: str
    paper_dt: float
    fryba_steps: int
    sprung_steps: int
    sprung_modes: int
    sprung_rtol: float
    energy_steps: int
    roughness_length: float

    @classmethod
    def full(cls) -> "ValidationSettings":
        return cls("full", paper_dt=0.005, fryba_steps=2000, sprung_steps=4000, sprung_modes=20,
                   sprung_rtol=1e-10, energy_steps=2000, roughness_length=1000.0)

    @classmethod
    def quick(cls) -> "ValidationSettings":
        return cls("quick", paper_dt=0.005, fryba_steps=500, sprung_steps=1000, sprung_modes=10,
                   sprung_rtol=1e-8, energy_steps=500, roughness_length=1000.0)


# --------------------------------------------------------------------------- running


@dataclass
class _Run:
    """State shared by the studies of one validation run: where to write, how fine."""

    out_dir: Path
    settings: ValidationSettings
    files: list[Path] = field(default_factory=list)

    def save(self, fig, name: str) -> Path:  # noqa: ANN001 - a matplotlib Figure
        path = self.out_dir / name
        try:
            fig.savefig(path, dpi=110)
        except (OSError, ValueError) as exc:
            raise CosimError(f"{path}: cannot write the plot ({exc})") from None
        self.files.append(path)
        return path


_Study = Callable[[_Run], list[CaseResult]]


def run_validation(
    out_dir: str | Path,
    quick: bool = False,
    progress: ProgressCallback | None = None,
    only: Sequence[str] | None = None,
) -> ValidationReport:
    """Run the verification and validation cases; write ``report.md`` and PNG plots to ``out_dir``.

    Args:
        out_dir: output directory, created (with parents) if missing; files of
            the same names are overwritten.
        quick: coarser time steps and reference solves (for tests and a first look).
        progress: called as ``progress(done, total, label)`` before each study and at the end.
        only: run only the studies with these names (see :func:`study_names`).

    Returns:
        The cases with their errors, tolerances and verdicts, and the files written.

    Raises:
        CosimError: ``out_dir`` cannot be created or written, or ``only`` names an unknown study.
        A case that raises is reported as failed (with its traceback in the report), not re-raised.
    """
    started = time.perf_counter()
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CosimError(f"{out}: cannot create the output directory ({exc.strerror})") from None
    if not out.is_dir():
        raise CosimError(f"{out}: is not a directory")
    studies = _select(only)
    run = _Run(out, ValidationSettings.quick() if quick else ValidationSettings.full())
    cases: list[CaseResult] = []
    for i, (label, study) in enumerate(studies):
        if progress is not None:
            progress(i, len(studies), label)
        try:
            cases.extend(study(run))
        except Exception:  # noqa: BLE001 - a crashing case is a failed case; the report says why
            cases.append(CaseResult(
                name=f"{label}: crashed", reference="-", metric="-", error=None, tolerance=None, passed=False,
                details="```\n" + traceback.format_exc().rstrip() + "\n```", group=label,
            ))
    if progress is not None:
        progress(len(studies), len(studies), "done")
    wall = time.perf_counter() - started
    report_path = out / "report.md"
    text = _report_markdown(cases, run.settings, wall, out)
    try:
        report_path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise CosimError(f"{report_path}: cannot write the report ({exc.strerror})") from None
    return ValidationReport(out, quick, tuple(cases), (report_path, *run.files), wall)


def study_names() -> list[str]:
    """Names of the studies, in run order (each yields one or more cases)."""
    return [label for label, _ in _STUDIES]


def _select(only: Sequence[str] | None) -> list[tuple[str, _Study]]:
    if only is None:
        return list(_STUDIES)
    known = dict(_STUDIES)
    unknown = [name for name in only if name not in known]
    if unknown:
        raise CosimError(f"unknown validation studies {unknown} (known: {', '.join(known)})")
    return [(label, study) for label, study in _STUDIES if label in only]


# --------------------------------------------------------------------------- small helpers


def _fmt(value: float | None, digits: int = 3) -> str:
    if value is None:
        return "-"
    if value == 0:
        return "0"
    return f"{value:.{digits}g}" if 1e-3 <= abs(value) < 1e4 else f"{value:.{digits - 1}e}"


def _rel_peak(fe: npt.ArrayLike, ref: npt.ArrayLike) -> float:
    """max |fe - ref| / max |ref|."""
    fe, ref = np.asarray(fe, dtype=float), np.asarray(ref, dtype=float)
    return float(np.max(np.abs(fe - ref)) / np.max(np.abs(ref)))


def _judge(error: float, tolerance: float) -> bool:
    return bool(np.isfinite(error) and error <= tolerance)


def _figure(rows: int = 1, cols: int = 1, size: tuple[float, float] = (8.0, 4.5), **subplots):  # noqa: ANN202
    """A Figure on an Agg canvas (no pyplot state) and its axes array (rows, cols)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.subplots(rows, cols, squeeze=False, **subplots)


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def _first_kind(bridge: BridgeModel, kind: str, count: int, n_modes: int = 40) -> npt.NDArray[np.float64]:
    """Frequencies (Hz) of the first ``count`` modes classified as ``kind``."""
    modal = bridge.modes(n_modes)
    found = np.array([f for f, k in zip(modal.f_hz, modal.kinds) if k == kind])
    if len(found) < count:
        raise CosimError(f"only {len(found)} {kind} modes among the first {n_modes}")
    return found[:count]


def _orders(h: npt.ArrayLike, errors: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Observed orders log(e_i / e_i+1) / log(h_i / h_i+1) between successive refinements."""
    h, errors = np.asarray(h, dtype=float), np.asarray(errors, dtype=float)
    return np.log(errors[:-1] / errors[1:]) / np.log(h[:-1] / h[1:])


# --------------------------------------------------------------------------- 1. the paper case


def _paper_traffic(first: VehicleModel, second: VehicleModel, length: float):  # noqa: ANN202
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle

    return ScriptedTraffic((
        ScriptedVehicle("QC-1", first, PAPER_LANE_Y, PAPER_SPEED, 0.0),
        ScriptedVehicle("QC-2", second, PAPER_LANE_Y, PAPER_SPEED, PAPER_QC2_ENTRY),
    ), length)


def _paper_runs(bridge: BridgeModel, dt: float, runs: Sequence[tuple[str, str, bool]]) -> dict[str, dict[str, np.ndarray]]:
    """Mid-span histories at the three nodes: ``{run name: {"t": ..., node name: w (m)}}``.

    ``runs`` are (name, basis, moving_force) triples.
    """
    from cosim.core.simulation import Sensor, SolverSettings, simulate

    x_mid = bridge.length / 2.0
    sensors = [Sensor(name, x_mid, y) for name, y in PAPER_NODES]
    out = {}
    for name, basis, moving_force in runs:
        if moving_force:
            traffic = _paper_traffic(MovingForce(PAPER_QC1.total_mass), MovingForce(PAPER_QC2.total_mass), bridge.length)
        else:
            traffic = _paper_traffic(PAPER_QC1, PAPER_QC2, bridge.length)
        solver = SolverSettings(dt=dt, basis=basis, modes=PAPER_MODAL_MODES if basis == "modal" else None,
                                gravity=GRAVITY)
        res = simulate(bridge, traffic, PAPER_DURATION, solver, sensors)
        out[name] = {"t": res.t, **res.sensors}
    return out


def _y(y: float) -> str:
    """A lateral offset with its sign (0 without one)."""
    return "0" if y == 0 else f"{y:+g}"


def _paper_node_figure(t: np.ndarray, w_qc: np.ndarray, w_mf: np.ndarray, w_modal: np.ndarray, length: float,
                       title: str):  # noqa: ANN202 - a matplotlib Figure
    """Displacement histories (top) and the differences that are too small to see there (bottom)."""
    fig, axes = _figure(2, 1, size=(8.0, 5.6), sharex=True, height_ratios=[3.0, 1.2])
    top, bottom = axes[0, 0], axes[1, 0]
    top.plot(t, 1e3 * w_mf, "-", color="C3", lw=3.0, alpha=0.45, label="moving forces (1100 kg, 2200 kg), direct basis")
    top.plot(t, 1e3 * w_qc, "-", color="C0", lw=1.3, label="quarter-cars, direct FE basis")
    top.plot(t, 1e3 * w_modal, "--", color="k", lw=0.9, label=f"quarter-cars, modal basis ({PAPER_MODAL_MODES} modes)")
    lo, hi = 1e3 * min(w_qc.min(), w_mf.min()), 1e3 * max(w_qc.max(), w_mf.max())
    top.set_ylim(lo - 0.05 * (hi - lo), hi + 0.15 * (hi - lo))
    events = ((PAPER_QC2_ENTRY, "QC-2 on"), (length / PAPER_SPEED, "QC-1 off"),
              (PAPER_QC2_ENTRY + length / PAPER_SPEED, "QC-2 off"))
    for ax in (top, bottom):
        ax.axhline(0.0, color="0.85", lw=0.6)
        for t_event, _ in events:
            ax.axvline(t_event, color="0.75", lw=0.8, ls=":")
    for t_event, text in events:
        top.text(t_event, 0.985, text, transform=top.get_xaxis_transform(), fontsize=7, color="0.4",
                 ha="center", va="top")
    top.set_ylabel("vertical displacement w [mm]")
    top.set_title(title, fontsize=10)
    top.legend(loc="lower left", fontsize=8)
    bottom.plot(t, 1e6 * (w_qc - w_mf), "-", color="C3", lw=1.0, label="quarter-cars - moving forces")
    bottom.plot(t, 1e6 * (w_qc - w_modal), "-", color="k", lw=0.8, label="direct - modal (quarter-cars)")
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("difference [µm]")
    bottom.set_xlim(0.0, PAPER_DURATION)
    bottom.legend(loc="lower left", fontsize=7, ncols=2)
    return fig


def _paper_case_setup(bridge: BridgeModel, dt: float) -> str:
    return (
        "Set-up (`shared/cases/paper-double-tee.md`): bundled scenario `paper-double-tee` "
        f"({bridge.n_elements} elements, rigid ends, {bridge.damping_note}; alpha = {bridge.alpha:.6g} 1/s, "
        f"beta = {bridge.beta:.6g} s). QC-1 (m_v 1000 kg, m_w 100 kg, k_v 39478.40 N/m, c_v 5026.55 N s/m) enters "
        f"at t = 0, QC-2 (m_v 2000 kg, m_w 200 kg, k_v 78956.80 N/m, c_v 10053.10 N s/m) at {PAPER_QC2_ENTRY} s, "
        f"both at y = +{PAPER_LANE_Y} m, {PAPER_SPEED} m/s along +x, smooth road, g = {GRAVITY} m/s2, "
        f"dt = {dt} s, 0-{PAPER_DURATION:g} s. Moving-force model: MovingForce({PAPER_QC1.total_mass:g} kg) and "
        f"MovingForce({PAPER_QC2.total_mass:g} kg). Modal basis: {PAPER_MODAL_MODES} modes. "
        "Displacements are at mid-span (x = 20 m), deck level, positive up."
    )


def _study_paper(run: _Run) -> list[CaseResult]:
    from cosim.run.scenario import load_scenario

    group = "Paper case: 40 m double-tee (Figs. 4-6)"
    dt = run.settings.paper_dt
    bridge = load_scenario("paper-double-tee").build_bridge()
    res = _paper_runs(bridge, dt, [("qc", "direct", False), ("qc_modal", "modal", False), ("mf", "direct", True)])
    setup = _paper_case_setup(bridge, dt)
    reference = (
        "Direct (full FE) basis as the reference for the modal basis; the set-up of the source paper "
        "(Figs. 4-6) as fixed by shared/cases/paper-double-tee.md"
    )
    cases = []
    for i, (node, y) in enumerate(PAPER_NODES):
        t = res["qc"]["t"]
        w_qc, w_modal, w_mf = res["qc"][node], res["qc_modal"][node], res["mf"][node]
        peak = float(np.max(np.abs(w_qc)))
        error = float(np.max(np.abs(w_qc - w_modal)) / peak)
        ratio = float(np.min(w_qc) / np.min(w_mf))
        fig = _paper_node_figure(
            t, w_qc, w_mf, w_modal, bridge.length,
            f"Paper case, {node}: mid-span x = {bridge.length / 2:g} m, y = {_y(y)} m (deck level)",
        )
        path = run.save(fig, f"paper_node{i + 1}.png")
        details = _table(
            ["quantity", "value"],
            [
                ["peak, quarter-cars, direct [mm]", f"{1e3 * np.min(w_qc):.4f} at t = {t[np.argmin(w_qc)]:.2f} s"],
                ["peak, quarter-cars, modal [mm]", f"{1e3 * np.min(w_modal):.4f}"],
                ["peak, moving forces [mm]", f"{1e3 * np.min(w_mf):.4f} at t = {t[np.argmin(w_mf)]:.2f} s"],
                ["peak ratio quarter-car / moving force", f"{ratio:.4f}"],
                ["max abs(direct - modal) [mm]", f"{1e3 * np.max(np.abs(w_qc - w_modal)):.3g}"],
            ],
        )
        if i == 0:
            details = setup + "\n\n" + details
        cases.append(CaseResult(
            name=f"Paper case, {node} (y = {_y(y)} m): direct vs modal basis",
            reference=reference,
            metric="max abs(w_direct - w_modal) / max abs(w_direct), quarter-car model",
            error=error, tolerance=TOL_PAPER_BASES,
            plots=(path,), details=details, group=group,
        ))
    mins = [float(np.min(res["qc"][node])) for node, _ in PAPER_NODES]
    ordered = mins[1] < mins[2] < mins[0] < 0
    extra = (
        "\n\nTwist from the eccentric lane: the loaded edge (Node 2) deflects more than the wheel path "
        f"(Node 3), which deflects more than the axis (Node 1): {'yes' if ordered else 'NO'}."
    )
    cases[-1] = replace(cases[-1], details=cases[-1].details + extra)

    # The asymmetric variant: informational peaks, one plot (symmetric section dotted for comparison).
    asym_bridge = load_scenario("paper-double-tee-asymmetric").build_bridge()
    asym = _paper_runs(asym_bridge, dt, [("qc", "direct", False)])["qc"]
    fig, axes = _figure(size=(8.0, 4.8))
    ax = axes[0, 0]
    rows = []
    for i, (node, y) in enumerate(PAPER_NODES):
        ax.plot(asym["t"], 1e3 * asym[node], "-", color=f"C{i}", lw=1.4, label=f"{node} (y = {_y(y)} m), asymmetric")
    for i, (node, y) in enumerate(PAPER_NODES):
        ax.plot(res["qc"]["t"], 1e3 * res["qc"][node], ":", color=f"C{i}", lw=1.0, label=f"{node}, symmetric")
        rows.append([node, _y(y), f"{1e3 * np.min(asym[node]):.4f}", f"{1e3 * np.min(res['qc'][node]):.4f}",
                     f"{np.min(asym[node]) / np.min(res['qc'][node]):.4f}"])
    ax.axhline(0.0, color="0.85", lw=0.6)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("vertical displacement w [mm]")
    ax.set_xlim(0.0, PAPER_DURATION)
    ax.set_title("Paper case, asymmetric section (right web 0.25 m): quarter-cars, direct basis, mid-span",
                 fontsize=10)
    fig.legend(loc="outside lower center", fontsize=8, ncols=2)
    path = run.save(fig, "paper_asymmetric.png")
    details = (
        f"Bundled scenario `paper-double-tee-asymmetric` ({asym_bridge.damping_note}), same vehicles and settings.\n\n"
        + _table(["node", "y [m]", "peak, asymmetric [mm]", "peak, symmetric [mm]", "ratio"], rows)
    )
    cases.append(CaseResult(
        name="Paper case, asymmetric section: peaks (informational)",
        reference="none (no published values); compared with the symmetric section",
        metric="peaks only", error=None, tolerance=None, passed=True, plots=(path,), details=details, group=group,
    ))
    return cases


# --------------------------------------------------------------------------- 2. statics


def _study_timoshenko_static(run: _Run) -> list[CaseResult]:
    group = "Timoshenko static deflection"
    E, G = STEEL.E, STEEL.G
    fig, axes = _figure(1, 2, size=(10.0, 4.0))
    cases = []

    # Simply supported deep beam (L/h = 5), point load at a = 0.5 L and 0.3 L.
    sec = rectangle_section(0.3, 1.2)
    L, P = 6.0, -2.0e5
    bridge = build_bridge([L], 20, STEEL, sec, ["pinned", "fork"])
    x_fine = np.linspace(0.0, L, 301)
    errors, rows = [], []
    ax = axes[0, 0]
    for k, a_over_l in enumerate((0.5, 0.3)):
        a = a_over_l * L
        fe = bridge.static([PointLoad(a, 0.0, P)]).field("w", bridge.nodes_x)
        ref = ss_point_load_deflection(bridge.nodes_x, a, L, P, E * sec.I_y, G * sec.A_sz)
        errors.append(_rel_peak(fe, ref))
        shear = P * a * (L - a) / (G * sec.A_sz * L)
        ref_a = float(ss_point_load_deflection(a, a, L, P, E * sec.I_y, G * sec.A_sz))
        rows.append([f"{a_over_l:g}", f"{1e3 * fe[np.argmin(np.abs(bridge.nodes_x - a))]:.6f}", f"{1e3 * ref_a:.6f}",
                     f"{100 * shear / ref_a:.1f} %", _fmt(errors[-1])])
        ax.plot(x_fine, 1e3 * ss_point_load_deflection(x_fine, a, L, P, E * sec.I_y, G * sec.A_sz), "-",
                color=f"C{k}", label=f"closed form, load at a = {a_over_l:g} L")
        ax.plot(bridge.nodes_x, 1e3 * fe, "o", ms=4, mfc="none", color=f"C{k}", label=f"FE nodes, a = {a_over_l:g} L")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title("Simply supported, L = 6 m, 0.3 x 1.2 m, P = 200 kN", fontsize=10)
    ax.legend(fontsize=7)
    error = max(errors)
    ss_details = _table(["a / L", "FE at load [mm]", "closed form [mm]", "shear share", "error"], rows)

    # Cantilever with a tip load.
    Lc, Pc = 4.0, -1.0e5
    cbridge = build_bridge([Lc], 8, STEEL, sec, ["fixed", "free"])
    fe_c = cbridge.static([PointLoad(Lc, 0.0, Pc)]).field("w", cbridge.nodes_x)
    ref_c = cantilever_tip_load_deflection(cbridge.nodes_x, Lc, Pc, E * sec.I_y, G * sec.A_sz)
    error_c = _rel_peak(fe_c, ref_c)
    ax = axes[0, 1]
    xc = np.linspace(0.0, Lc, 201)
    ax.plot(xc, 1e3 * cantilever_tip_load_deflection(xc, Lc, Pc, E * sec.I_y, G * sec.A_sz), "-", color="C0",
            label="closed form (bending + shear)")
    ax.plot(xc, 1e3 * cantilever_tip_load_deflection(xc, Lc, Pc, E * sec.I_y, np.inf), ":", color="0.5",
            label="bending only (Euler-Bernoulli)")
    ax.plot(cbridge.nodes_x, 1e3 * fe_c, "o", ms=4, mfc="none", color="C0", label="FE nodes")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title("Cantilever, L = 4 m, 0.3 x 1.2 m, tip load 100 kN", fontsize=10)
    ax.legend(fontsize=7)
    path = run.save(fig, "timoshenko_static.png")

    cases.append(CaseResult(
        name="Timoshenko static deflection, simply supported",
        reference="P b x (L^2 - b^2 - x^2)/(6 EI L) + P b x/(kGA L) (Gere & Timoshenko, Mechanics of Materials)",
        metric="max over nodes abs(w_FE - w_ref) / max abs(w_ref), loads at 0.5 L and 0.3 L (20 elements)",
        error=error, tolerance=TOL_NODAL_EXACT, plots=(path,),
        details=ss_details, group=group,
    ))
    tip = float(ref_c[-1])
    cases.append(CaseResult(
        name="Timoshenko static deflection, cantilever",
        reference="P x^2 (3L - x)/(6 EI) + P x/(kGA) (Timoshenko & Gere)",
        metric="max over nodes abs(w_FE - w_ref) / max abs(w_ref) (8 elements)",
        error=error_c, tolerance=TOL_NODAL_EXACT, plots=(path,),
        details=f"Tip deflection: FE {1e3 * fe_c[-1]:.6f} mm, closed form {1e3 * tip:.6f} mm "
                f"(shear part {100 * Pc * Lc / (G * sec.A_sz) / tip:.1f} %).",
        group=group,
    ))
    return cases


def _study_timoshenko_frequencies(run: _Run) -> list[CaseResult]:
    sec = rectangle_section(0.3, 0.8)
    L = 6.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    n = np.arange(1, 5)
    fe = _first_kind(bridge, "vertical", 4, n_modes=30)
    ref = timoshenko_ss_frequency_hz(n, L, STEEL, sec)
    euler = euler_bernoulli_ss_frequency_hz(n, L, STEEL.E * sec.I_y, STEEL.rho * sec.A)
    rel = np.abs(fe / ref - 1)
    error = float(np.max(rel))
    rows = [[str(k), f"{f:.5f}", f"{r:.5f}", f"{e:.5f}", _fmt(x)] for k, f, r, e, x in zip(n, fe, ref, euler, rel)]
    details = (
        "Deep beam L = 6 m, 0.3 x 0.8 m steel, 40 elements, pinned / fork.\n\n"
        + _table(["n", "FE [Hz]", "Timoshenko [Hz]", "Euler-Bernoulli [Hz]", "rel. error"], rows)
    )
    return [CaseResult(
        name="Timoshenko frequencies, simply supported",
        reference="frequency equation of the simply supported Timoshenko beam (Han, Benaroya & Wei, JSV 225, 1999)",
        metric="max over modes 1-4 abs(f_FE / f_ref - 1)",
        error=error, tolerance=TOL_FREQ_TIMOSHENKO,
        details=details, group="Timoshenko frequencies",
    )]


# --------------------------------------------------------------------------- torsion


def _study_torsion_static(run: _Run) -> list[CaseResult]:
    group = "Non-uniform torsion"
    sec = doubly_symmetric_section()
    E, G = STEEL.E, STEEL.G
    L, T, n_el = 10.0, 1.0e4, 40
    x_fine = np.linspace(0.0, L, 401)
    fig, axes = _figure(size=(8.0, 4.2))
    ax = axes[0, 0]
    ax.plot(x_fine, 1e3 * T * np.minimum(x_fine, L - x_fine) / (2 * G * sec.J), ":", color="0.5",
            label="uniform (St Venant) torsion only")
    results = []
    for k, (warping, supports) in enumerate((("free", ["pinned", "fork"]), ("restrained", ["rigid-end", "rigid-end"]))):
        bridge = build_bridge([L], n_el, STEEL, sec, supports)
        f = np.zeros(bridge.ndof)
        f[NODE_DOFS * (n_el // 2) + DOF_INDEX["theta_x"]] = T
        fe = bridge.static(f=f).field("theta_x", bridge.nodes_x)
        ref = midspan_torque_twist(bridge.nodes_x, L, T, G * sec.J, E * sec.I_w, warping)
        results.append((warping, _rel_peak(fe, ref), fe[n_el // 2], ref[n_el // 2]))
        ax.plot(x_fine, 1e3 * midspan_torque_twist(x_fine, L, T, G * sec.J, E * sec.I_w, warping), "-",
                color=f"C{k}", label=f"closed form, warping {warping}")
        ax.plot(bridge.nodes_x, 1e3 * fe, "o", ms=3.5, mfc="none", color=f"C{k}", label=f"FE nodes, warping {warping}")
    lam = math.sqrt(G * sec.J / (E * sec.I_w))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("twist θx [mrad]")
    ax.set_title(f"Torque {T / 1e3:g} kN m at mid-span, L = {L:g} m, λL = {lam * L:.2f}", fontsize=10)
    ax.legend(fontsize=8)
    path = run.save(fig, "torsion_static.png")
    cases = []
    for warping, error, fe_mid, ref_mid in results:
        ends = "theta = theta'' = 0 (fork)" if warping == "free" else "theta = theta' = 0 (rigid end)"
        cases.append(CaseResult(
            name=f"Non-uniform torsion, warping {warping}",
            reference=f"Vlasov torsion GJ θ' - E I_w θ''' = T/2, {ends}, hyperbolic closed form "
                      "(Kollbrunner & Basler, Torsion in Structures, ch. 4)",
            metric="max over nodes abs(θ_FE - θ_ref) / max abs(θ_ref) (40 elements)",
            error=error, tolerance=TOL_FE_40, plots=(path,),
            details=f"Mid-span twist: FE {1e3 * fe_mid:.6f} mrad, closed form {1e3 * ref_mid:.6f} mrad "
                    f"(λ = sqrt(GJ / E I_w) = {lam:.4g} 1/m).",
            group=group,
        ))
    return cases


def _frequency_case(name: str, reference: str, fe: np.ndarray, ref: np.ndarray, labels: Sequence[str],
                    setup: str, group: str) -> CaseResult:
    rel = np.abs(fe / ref - 1)
    error = float(np.max(rel))
    rows = [[lab, f"{f:.5f}", f"{r:.5f}", _fmt(x)] for lab, f, r, x in zip(labels, fe, ref, rel)]
    return CaseResult(
        name=name, reference=reference, metric=f"max over the {len(fe)} modes abs(f_FE / f_ref - 1)",
        error=error, tolerance=TOL_FE_40,
        details=setup + "\n\n" + _table(["mode", "FE [Hz]", "reference [Hz]", "rel. error"], rows), group=group,
    )


def _study_torsional_frequencies(run: _Run) -> list[CaseResult]:
    sec = doubly_symmetric_section()
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    fe = _first_kind(bridge, "torsion", 3, n_modes=40)
    ref = torsional_frequencies_hz(np.arange(1, 4), L, STEEL, sec)
    return [_frequency_case(
        "Torsional frequencies with warping",
        "ω² = (GJ k² + E I_w k⁴) / (ρ I_p + ρ I_w k²), k = nπ/L, fork supports (Vlasov; DESIGN.md section 8)",
        fe, ref, [f"torsion {n}" for n in range(1, 4)],
        "Doubly symmetric I-like section (J = 1e-6 m4, I_w = 2e-6 m6), L = 10 m, 40 elements, fork supports.",
        "Torsional frequencies",
    )]


def _study_lateral_torsional(run: _Run) -> list[CaseResult]:
    sec = monosymmetric_section(e_z=0.12)
    L = 10.0
    bridge = build_bridge([L], 40, STEEL, sec, ["pinned", "fork"])
    modal = bridge.modes(6)
    ref = lateral_torsional_frequencies_hz(8, L, STEEL, sec)[:6]
    uncoupled = build_bridge([L], 40, STEEL, monosymmetric_section(e_z=0.0), ["pinned", "fork"]).modes(1).f_hz[0]
    setup = (
        f"Mono-symmetric section, shear centre {sec.z_s:g} m above the centroid, L = {L:g} m, 40 elements, fork "
        f"supports. Without the offset the first frequency would be {uncoupled:.4f} Hz "
        f"(coupling moves it by {100 * (modal.f_hz[0] / uncoupled - 1):+.1f} %)."
    )
    return [_frequency_case(
        "Coupled lateral-torsional frequencies, mono-symmetric section",
        "2x2 frequency determinant per mode number, sine modes in v and θx (Timoshenko & Gere, Theory of "
        "Elastic Stability; rotary and warping inertia kept)",
        modal.f_hz[:6], ref, [f"{i + 1}: {k}" for i, k in enumerate(modal.kinds[:6])], setup,
        "Coupled lateral-torsional frequencies",
    )]


# --------------------------------------------------------------------------- moving loads


def _euler_bernoulli_bridge(L: float = 20.0, n_el: int = 40) -> tuple[BridgeModel, SectionProperties]:
    sec = rectangle_section(0.5, 1.0, shear_factor=1e6)  # no shear flexibility: Euler-Bernoulli references apply
    return build_bridge([L], n_el, STEEL, sec, ["pinned", "fork"]), sec


def _study_fryba(run: _Run) -> list[CaseResult]:
    from cosim.core.simulation import Sensor, SolverSettings, simulate
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle

    group = "Moving force (Fryba)"
    bridge, sec = _euler_bernoulli_bridge()
    L = bridge.length
    EI, m = STEEL.E * sec.I_y, STEEL.rho * sec.A
    f1 = np.pi / (2 * L**2) * np.sqrt(EI / m)
    P = 1e5
    steps = run.settings.fryba_steps
    fig, axes = _figure(1, 2, size=(10.0, 4.0))
    results = []
    for k, speed_parameter in enumerate((0.1, 0.5)):
        v = speed_parameter * 2 * f1 * L  # alpha = v / (2 f1 L)
        traffic = ScriptedTraffic((ScriptedVehicle("F", MovingForce(P / GRAVITY), 0.0, v),), L)
        T = L / v
        res = simulate(bridge, traffic, T, SolverSettings(dt=T / steps, gravity=GRAVITY), [Sensor("mid", L / 2)])
        ref = fryba_midspan_deflection(res.t, L, v, P, EI, m)
        error = _rel_peak(res.sensors["mid"], ref)
        static = -P * L**3 / (48 * EI)
        results.append((speed_parameter, v, error, float(np.min(res.sensors["mid"])), float(np.min(ref)), static))
        ax = axes[0, k]
        ax.plot(res.t * v / L, 1e3 * res.sensors["mid"], "-", color="C0", lw=1.6, label="FE, direct basis")
        ax.plot(res.t * v / L, 1e3 * ref, "--", color="k", lw=1.0, label="Fryba series (80 modes)")
        ax.axhline(1e3 * static, color="0.6", ls=":", lw=0.8, label="static P L³ / 48 EI")
        ax.set_xlabel("load position v t / L [-]")
        ax.set_ylabel("mid-span deflection w [mm]")
        ax.set_title(f"speed parameter α = v / (2 f1 L) = {speed_parameter:g} (v = {v:.1f} m/s)", fontsize=10)
        ax.legend(fontsize=8, loc="upper right")
    path = run.save(fig, "fryba_moving_force.png")
    cases = []
    for speed_parameter, v, error, fe_min, ref_min, static in results:
        cases.append(CaseResult(
            name=f"Moving force (Fryba), α = {speed_parameter:g}",
            reference="modal series for a constant force crossing an undamped simply supported beam "
                      "(Fryba, Vibration of Solids and Structures under Moving Loads, 1972, ch. 1)",
            metric=f"max abs(w_FE - w_ref) / max abs(w_ref) at mid-span while the force is on the beam "
                   f"({steps} steps, 40 elements)",
            error=error, tolerance=TOL_FRYBA, plots=(path,),
            details=f"v = {v:.2f} m/s; peak: FE {1e3 * fe_min:.4f} mm, series {1e3 * ref_min:.4f} mm, "
                    f"dynamic amplification {ref_min / static:.3f}.",
            group=group,
        ))
    return cases


def _study_sprung_mass(run: _Run) -> list[CaseResult]:
    from cosim.core.simulation import Sensor, SolverSettings, simulate

    group = "Moving sprung mass"
    s = run.settings
    # Yang & Yau (1997): L 25 m, EI 2.943e10 N m2, m 2303 kg/m, sprung mass 5750 kg, k 1.595e6 N/m, 100 km/h.
    bridge, traffic, T = yang_yau_case()
    L, EI, m, m_v, k_v, c_v, v = (YANG_YAU[k] for k in ("L", "EI", "m", "m_v", "k_v", "c_v", "v"))
    res = simulate(bridge, traffic, T, SolverSettings(dt=T / s.sprung_steps, gravity=GRAVITY), [Sensor("mid", L / 2)])
    w_ref, acc_ref = sprung_mass_modal_solution(res.t, L, EI, m, m_v, k_v, c_v, v, gravity=GRAVITY,
                                                n_modes=s.sprung_modes, rtol=s.sprung_rtol, atol=s.sprung_rtol * 1e-3)
    body = res.vehicle("S")
    acc_on_deck = np.interp(body["t"], res.t, acc_ref)
    err_w = _rel_peak(res.sensors["mid"], w_ref)
    err_a = _rel_peak(body["body_acceleration"], acc_on_deck)

    fig, axes = _figure(1, 2, size=(10.0, 4.0))
    ax = axes[0, 0]
    ax.plot(res.t, 1e3 * res.sensors["mid"], "-", color="C0", lw=1.6, label="FE, direct basis")
    ax.plot(res.t, 1e3 * w_ref, "--", color="k", lw=1.0, label=f"modal ODE ({s.sprung_modes} modes, solve_ivp)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("mid-span deflection w [mm]")
    ax.set_title("Bridge", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(body["t"], body["body_acceleration"], "-", color="C1", lw=1.6, label="FE, direct basis")
    ax.plot(body["t"], acc_on_deck, "--", color="k", lw=1.0, label="modal ODE")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("body acceleration [m/s²]")
    ax.set_title("Sprung mass", fontsize=10)
    ax.legend(fontsize=8)
    fig.suptitle("Sprung mass (5750 kg, 1.595 MN/m) at 27.78 m/s on a 25 m simply supported beam", fontsize=10)
    path = run.save(fig, "sprung_mass.png")
    reference = (
        "independent modal solution of the continuous beam with the sprung mass, solve_ivp DOP853 "
        "(benchmark of Yang & Yau, J. Struct. Eng. 1997; Biggs)"
    )
    steps = f"{s.sprung_steps} steps, 40 elements; reference {s.sprung_modes} modes, rtol {s.sprung_rtol:g}"
    return [
        CaseResult(
            name="Moving sprung mass: mid-span deflection", reference=reference,
            metric=f"max abs(w_FE - w_ref) / max abs(w_ref) ({steps})",
            error=err_w, tolerance=TOL_SPRUNG, plots=(path,),
            details=f"Peak deflection: FE {1e3 * res.sensors['mid'].min():.4f} mm, reference {1e3 * w_ref.min():.4f} mm.",
            group=group,
        ),
        CaseResult(
            name="Moving sprung mass: body acceleration", reference=reference,
            metric=f"max abs(a_FE - a_ref) / max abs(a_ref) while on the beam ({steps})",
            error=err_a, tolerance=TOL_SPRUNG, plots=(path,),
            details=f"Peak body acceleration: FE {np.max(np.abs(body['body_acceleration'])):.4f} m/s2, "
                    f"reference {np.max(np.abs(acc_on_deck)):.4f} m/s2.",
            group=group,
        ),
    ]


# --------------------------------------------------------------------------- time integration


def _study_energy(run: _Run) -> list[CaseResult]:
    import scipy.sparse.linalg as spla

    from cosim.core.coupling import CoupledSystem
    from cosim.core.bases import make_basis
    from cosim.core.schemes import Scheme
    from cosim.core.traffic import TrafficFrame

    bridge, _ = _euler_bernoulli_bridge()
    dt, steps = 1e-3, run.settings.energy_steps
    scheme = Scheme.newmark()
    basis = make_basis(bridge, dt, scheme)
    system = CoupledSystem(bridge, basis, scheme, dt)
    K, M = bridge.K_ff, bridge.M_ff
    d0 = bridge.static([PointLoad(7.0, 0.0, -1e6)]).d[bridge.free]
    system.set_state(d0, np.zeros_like(d0), spla.spsolve(M.tocsc(), -(K @ d0)))  # consistent a0: M a0 = -K d0

    def energies() -> tuple[float, float]:
        return float(0.5 * system.v @ (M @ system.v)), float(0.5 * system.d @ (K @ system.d))

    kinetic, strain = np.empty(steps + 1), np.empty(steps + 1)
    kinetic[0], strain[0] = energies()
    e0 = kinetic[0] + strain[0]
    empty = TrafficFrame((), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), ())
    for k in range(1, steps + 1):
        system.step(empty)
        kinetic[k], strain[k] = energies()
    drift = (kinetic[1:] + strain[1:]) / e0 - 1.0
    error = float(np.max(np.abs(drift)))
    fig, axes = _figure(2, 1, size=(8.0, 5.2), sharex=True)
    t = dt * np.arange(0, steps + 1)
    top, bottom = axes[0, 0], axes[1, 0]
    top.plot(t, kinetic, "-", color="C0", lw=1.0, label="kinetic")
    top.plot(t, strain, "-", color="C1", lw=1.0, label="strain")
    top.plot(t, kinetic + strain, "-", color="k", lw=1.2, label="total")
    top.set_ylabel("energy [J]")
    top.set_title("Undamped free vibration of a 20 m beam (40 elements, direct basis, Newmark, dt = 1 ms)",
                  fontsize=10)
    top.legend(fontsize=8, loc="center right")
    bottom.plot(t, np.concatenate([[0.0], drift]), "-", color="k", lw=0.8, label="(E(t) - E0) / E0")
    bottom.axhline(0.0, color="0.8", lw=0.6)
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("relative drift [-]")
    bottom.legend(fontsize=8, loc="upper right", title=f"tolerance ±{TOL_ENERGY:g}", title_fontsize=8)
    path = run.save(fig, "energy_drift.png")
    return [CaseResult(
        name="Energy conservation, undamped free vibration",
        reference="average acceleration conserves the energy of a linear undamped system exactly (Hughes, The FEM, 9.3)",
        metric=f"max abs(E(t) / E0 - 1) over {steps} steps, E = kinetic + strain energy",
        error=error, tolerance=TOL_ENERGY, plots=(path,),
        details=f"Initial state: static deflection under 1 MN at x = 7 m, released from rest; E0 = {e0:.6g} J.",
        group="Energy conservation",
    )]


def _study_time_step(run: _Run) -> list[CaseResult]:
    from cosim.core.schemes import Scheme
    from cosim.core.simulation import Sensor, SolverSettings, simulate
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle

    bridge, _ = _euler_bernoulli_bridge(L=10.0, n_el=10)
    duration, ref_steps = 0.4, 12800
    steps = np.array([100, 200, 400, 800, 1600])
    asymptotic = steps >= 400  # the orders judged: 400 -> 800 -> 1600 steps (as in the verification tests)
    combos = [
        ("quarter-car", QuarterCar(2e4, 2e3, 2e6, 5e4), Scheme.newmark()),
        ("quarter-car", QuarterCar(2e4, 2e3, 2e6, 5e4), Scheme.hht(-0.1)),
        ("tyre quarter-car", TyreQuarterCar(2e4, 2e3, 2e6, 5e4, 2e7, 0.0), Scheme.newmark()),
        ("tyre quarter-car", TyreQuarterCar(2e4, 2e3, 2e6, 5e4, 2e7, 0.0), Scheme.hht(-0.1)),
    ]

    def midspan_at_end(n: int, model: VehicleModel, scheme: Scheme) -> float:
        traffic = ScriptedTraffic((ScriptedVehicle("Q", model, 0.0, 20.0),), 10.0)
        # Six modes: each retained mode is resolved by every step used, so the error is asymptotic.
        settings = SolverSettings(dt=duration / n, scheme=scheme.name, hht_alpha=scheme.alpha, basis="modal",
                                  modes=6, gravity=GRAVITY)
        return float(simulate(bridge, traffic, duration, settings, [Sensor("mid", 5.0)]).sensors["mid"][-1])

    fig, axes = _figure(size=(7.0, 5.0))
    ax = axes[0, 0]
    dts = duration / steps
    rows, worst = [], 0.0
    for k, (label, model, scheme) in enumerate(combos):
        ref = midspan_at_end(ref_steps, model, scheme)
        errors = np.array([abs(midspan_at_end(int(n), model, scheme) - ref) for n in steps])
        orders = _orders(dts[asymptotic], errors[asymptotic])
        worst = max(worst, max(0.0, 2.0 - float(np.min(orders))))
        name = f"{label}, {scheme.name}" + (f" (α = {scheme.alpha:g})" if scheme.name == "hht" else "")
        rows.append([name, ", ".join(f"{e:.3g}" for e in errors), ", ".join(f"{p:.2f}" for p in orders)])
        ax.loglog(dts, errors, "o-", color=f"C{k}", ms=4, label=name)
        if k == 0:
            anchor = errors[-1]
    ax.loglog(dts, anchor * (dts / dts[-1]) ** 2, "k--", lw=1.0, label="slope 2")
    from matplotlib.ticker import NullFormatter

    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("time step dt [s]")
    ax.set_ylabel("error of the mid-span deflection at t = 0.4 s [m]")
    ax.set_title(f"Time-step convergence (reference: dt = {duration / ref_steps:.3g} s)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", color="0.92", lw=0.5)
    path = run.save(fig, "time_step_convergence.png")
    details = (
        f"Vehicle at 20 m/s on a 10 m beam (10 elements, modal basis with 6 modes); error against dt = "
        f"{duration / ref_steps:.3g} s; steps per 0.4 s: {', '.join(str(n) for n in steps)}.\n\n"
        + _table(["model, scheme", "errors [m]", "observed orders 400→800, 800→1600"], rows)
    )
    return [CaseResult(
        name="Time-step convergence (Newmark, HHT)",
        reference="second-order accuracy of Newmark average acceleration and HHT-α (Hilber, Hughes & Taylor 1977)",
        metric="order shortfall max(0, 2 - min observed order) over 400 -> 800 -> 1600 steps",
        error=worst, tolerance=TOL_ORDER_TIME, plots=(path,),
        details=details, group="Time-step convergence",
    )]


# --------------------------------------------------------------------------- roughness


def _study_roughness(run: _Run) -> list[CaseResult]:
    from cosim.core.roughness import N0, N_MAX, N_MIN, averaged_psd, iso8608_band, iso8608_gd0, iso8608_profile

    group = "ISO 8608 roughness"
    length = run.settings.roughness_length
    # Third-octave bands over the classification range of ISO 8608 (0.011 to 2.83 cycle/m).
    edges = 0.011 * 2.0 ** (np.arange(0, 25) / 3.0)
    fig, axes = _figure(size=(8.0, 5.0))
    ax = axes[0, 0]
    n_line = np.logspace(np.log10(N_MIN), np.log10(N_MAX), 200)
    cases = []
    for k, (road_class, seed) in enumerate((("A", 1), ("C", 2))):
        profile = iso8608_profile(road_class, seed, 0.0, length)
        r = profile.r[0, :-1]  # one period (the last point repeats the first)
        centres, psd = averaged_psd(r, profile.dx, edges)
        # Least-squares fit of log G_d = log G_d(n0) - 2 log(n / n0) (ISO 8608 classification, waviness 2).
        gd_fit = float(np.exp(np.mean(np.log(psd * (centres / N0) ** 2))))
        slope = float(np.polyfit(np.log(centres), np.log(psd), 1)[0])
        gd0 = iso8608_gd0(road_class)
        lo, hi = iso8608_band(road_class)
        error = abs(gd_fit / gd0 - 1.0)
        inside = lo <= gd_fit <= hi
        color = f"C{k}"
        ax.fill_between(n_line, lo * (n_line / N0) ** -2, hi * (n_line / N0) ** -2, color=color, alpha=0.15,
                        label=f"class {road_class} band ({lo:.3g}-{hi:.3g} m³)")
        ax.loglog(n_line, gd0 * (n_line / N0) ** -2, "--", color=color, lw=1.0,
                  label=f"class {road_class} value {gd0:.3g} m³")
        ax.loglog(centres, psd, "o", color=color, ms=4, label=f"generated class {road_class} (seed {seed}), 1/3 octaves")
        cases.append(CaseResult(
            name=f"ISO 8608 roughness PSD, class {road_class}",
            reference="ISO 8608: G_d(n) = G_d(n0) (n/n0)^-2, n0 = 0.1 cycle/m, class value the geometric mean of its band",
            metric="abs(fitted G_d(n0) / class value - 1) (least squares over third-octave bands, waviness 2); "
                   "the fit must also lie inside the class band",
            error=error, tolerance=TOL_ROUGHNESS, passed=_judge(error, TOL_ROUGHNESS) and inside, plots=(),
            details=f"Profile {length:g} m, dx = {profile.dx:g} m, seed {seed}: fitted G_d(n0) = {gd_fit:.4g} m3 "
                    f"(class value {gd0:.4g} m3, band {lo:.3g}-{hi:.3g} m3: {'inside' if inside else 'OUTSIDE'}), "
                    f"fitted waviness {-slope:.3f} (ISO: 2).",
            group=group,
        ))
    ax.axvline(N0, color="0.6", ls=":", lw=0.8)
    ax.text(N0, 0.02, " n0", transform=ax.get_xaxis_transform(), fontsize=8, color="0.4")
    ax.set_xlim(0.008, 4.0)
    ax.set_xlabel("spatial frequency n [cycle/m]")
    ax.set_ylabel("displacement PSD G_d(n) [m³]")
    ax.set_title("Generated road profiles against their ISO 8608 classes", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, which="both", color="0.92", lw=0.5)
    path = run.save(fig, "roughness_psd.png")
    return [replace(c, plots=(path,)) for c in cases]


# --------------------------------------------------------------------------- mesh convergence


def _study_mesh(run: _Run) -> list[CaseResult]:
    group = "Mesh convergence"
    L = 6.0
    beams = (
        ("Euler-Bernoulli limit (no shear flexibility)", rectangle_section(0.3, 0.8, shear_factor=1e6),
         np.array([2, 4, 8, 16]), 4.0, TOL_ORDER_MESH_EB),
        ("Timoshenko (deep beam, shear flexible)", rectangle_section(0.3, 0.8), np.array([4, 8, 16, 32]), 2.0,
         TOL_ORDER_MESH_TIMOSHENKO),
    )
    fig, axes = _figure(size=(7.0, 5.0))
    ax = axes[0, 0]
    cases = []
    for k, (label, sec, counts, order, tol) in enumerate(beams):
        ref = float(timoshenko_ss_frequency_hz(1, L, STEEL, sec))
        fe = np.array([_first_kind(build_bridge([L], int(n), STEEL, sec, ["pinned", "fork"]), "vertical", 1, 20)[0]
                       for n in counts])
        errors = fe / ref - 1.0
        if np.any(errors <= 0):
            raise CosimError(f"{label}: the consistent-mass frequency must converge from above (errors {errors})")
        orders = _orders(L / counts, errors)
        shortfall = max(0.0, order - float(np.min(orders)))
        ax.loglog(counts, errors, "o-", color=f"C{k}", ms=4, label=label)
        ax.loglog(counts, errors[0] * (counts / counts[0]) ** -order, "--", color=f"C{k}", lw=0.8,
                  label=f"slope {order:g}")
        rows = [[str(n), f"{f:.6f}", _fmt(e)] for n, f, e in zip(counts, fe, errors)]
        cases.append(CaseResult(
            name=f"Mesh convergence, first vertical frequency: {label}",
            reference=f"Timoshenko frequency equation (Han, Benaroya & Wei 1999) = {ref:.6f} Hz; expected order "
                      f"{order:g} (Strang & Fix: h^(2(p+1-m)))",
            metric=f"order shortfall max(0, {order:g} - min observed order) over {', '.join(map(str, counts))} elements",
            error=shortfall, tolerance=tol, plots=(),
            details=_table(["elements", "f1 FE [Hz]", "rel. error"], rows)
            + f"\n\nObserved orders: {', '.join(f'{p:.2f}' for p in orders)}.",
            group=group,
        ))
    from matplotlib.ticker import NullFormatter

    ticks = sorted({int(n) for _, _, counts, _, _ in beams for n in counts})
    ax.set_xticks(ticks, [str(n) for n in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("elements in the span [-]")
    ax.set_ylabel("relative error of the first vertical frequency [-]")
    ax.set_title("Simply supported beam, L = 6 m, 0.3 x 0.8 m steel", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", color="0.92", lw=0.5)
    path = run.save(fig, "mesh_convergence.png")
    return [replace(c, plots=(path,)) for c in cases]


# --------------------------------------------------------------------------- parked vehicle


def _study_parked(run: _Run) -> list[CaseResult]:
    from cosim.core.simulation import Sensor, SolverSettings, simulate
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle

    bridge = build_bridge([20.0], 20, STEEL, rectangle_section(1.0, 1.0), ["rigid-end", "rigid-end"],
                          ExplicitDamping(5.0, 1e-3))
    car = QuarterCar(m_v=1.5e4, m_w=1.5e3, k_v=5e5, c_v=4e4)
    v0 = 10.0
    stop_time = 2 * 10.0 / v0  # uniform deceleration over 10 m: stops at mid-span
    traffic = ScriptedTraffic((ScriptedVehicle("P", car, 0.3, v0, profile=((0.0, v0), (stop_time, 0.0))),), 20.0)
    res = simulate(bridge, traffic, 30.0, SolverSettings(dt=0.01, gravity=GRAVITY), [Sensor("load", 10.0, 0.3)])
    static = bridge.static([PointLoad(10.0, 0.3, -car.total_mass * GRAVITY)]).deck_displacement(10.0, 0.3)
    veh = res.vehicle("P")
    err_w = abs(res.sensors["load"][-1] / static - 1.0)
    err_p = abs(veh["contact_force"][-1] / (car.total_mass * GRAVITY) - 1.0)
    error = max(err_w, err_p)
    fig, axes = _figure(size=(8.0, 3.8))
    ax = axes[0, 0]
    ax.plot(res.t, 1e3 * res.sensors["load"], "-", color="C0", lw=1.2, label="FE, under the wheel (x = 10 m, y = 0.3 m)")
    ax.axhline(1e3 * static, color="k", ls="--", lw=1.0, label="static deflection under (m_v + m_w) g")
    ax.axvline(stop_time, color="0.7", ls=":", lw=0.8)
    ax.text(stop_time, 0.95, " stops at mid-span", transform=ax.get_xaxis_transform(), fontsize=8, color="0.4")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("deflection w [mm]")
    ax.set_title("Quarter-car braking to a stop at mid-span, heavily damped 20 m deck", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    path = run.save(fig, "parked_vehicle.png")
    return [CaseResult(
        name="Parked vehicle: settled deflection and contact force",
        reference="static solution of the same FE model under the vehicle's weight (m_v + m_w) g",
        metric="max of abs(w_end / w_static - 1) and abs(P_end / (m g) - 1) after 30 s",
        error=error, tolerance=TOL_PARKED, plots=(path,),
        details=f"Deflection at 30 s {1e3 * res.sensors['load'][-1]:.6f} mm, static {1e3 * static:.6f} mm; contact force "
                f"{veh['contact_force'][-1]:.2f} N, weight {car.total_mass * GRAVITY:.2f} N; final position "
                f"x = {veh['x'][-1]:.6f} m (exercises the a != 0 contact kinematics).",
        group="Parked vehicle",
    )]


# --------------------------------------------------------------------------- beam theories (docs/theory.md §10)

TOL_BENSCOTER_STATIC = 5e-5  # 40 elements: O(h^2) towards the hyperbolic closed form (measured 2.7e-5)
TOL_BENSCOTER_FREQ = 5e-4  # 40 elements, first three torsional modes (measured up to 3.6e-4, the third)
TOL_VBI2D = 5e-3  # the 0.5 % of VBI-2D's published peak
# A stocky I-like girder (the Vlasov checks' section) whose warping shear matters: I_ws / I_w = 10 1/m^2.
_STOCKY_I_WS = 2.0e-5


def _study_benscoter(run: _Run) -> list[CaseResult]:
    from cosim.core.bridge import BeamTheory

    from .references import benscoter_midspan_torque_twist, benscoter_torsional_frequencies_hz

    group = "Shear-deformable warping (Benscoter)"
    sec = replace(doubly_symmetric_section(), I_ws=_STOCKY_I_WS)
    theory = BeamTheory(torsion="benscoter")
    E, G = STEEL.E, STEEL.G
    L, T, n_el = 10.0, 1.0e4, 40
    gj, eiw, giws = G * sec.J, E * sec.I_w, G * _STOCKY_I_WS
    fig, axes = _figure(1, 3, size=(14.0, 4.2))
    cases = []

    # Static twist under a mid-span torque, warping restrained and free.
    ax = axes[0, 0]
    x_fine = np.linspace(0.0, L, 401)
    for k, (warping, supports) in enumerate((("restrained", ["rigid-end", "rigid-end"]), ("free", ["pinned", "fork"]))):
        bridge = build_bridge([L], n_el, STEEL, sec, supports, theory=theory)
        f = np.zeros(bridge.ndof)
        f[NODE_DOFS * (n_el // 2) + DOF_INDEX["theta_x"]] = T
        fe = bridge.static(f=f).field("theta_x", bridge.nodes_x)
        ref = benscoter_midspan_torque_twist(bridge.nodes_x, L, T, gj, eiw, giws, warping)
        vlasov = float(midspan_torque_twist(L / 2, L, T, gj, eiw, warping))
        ax.plot(x_fine, 1e3 * benscoter_midspan_torque_twist(x_fine, L, T, gj, eiw, giws, warping), "-",
                color=f"C{k}", label=f"closed form, warping {warping}")
        ax.plot(x_fine, 1e3 * midspan_torque_twist(x_fine, L, T, gj, eiw, warping), ":", color=f"C{k}",
                label=f"Vlasov (ψ = θx'), warping {warping}")
        ax.plot(bridge.nodes_x, 1e3 * fe, "o", ms=3.0, mfc="none", color=f"C{k}", label=f"FE nodes, {warping}")
        ends = "θ = ψ = 0 (rigid end)" if warping == "restrained" else "θ = 0, ψ' = 0 (fork)"
        cases.append(CaseResult(
            name=f"Benscoter torsion, mid-span torque, warping {warping}",
            reference="GJ θ' + G I_ws (θ' - ψ) = T/2, E I_w ψ'' + G I_ws (θ' - ψ) = 0 (Benscoter, J. Appl. Mech. 21, "
                      f"1954), {ends}: hyperbolic closed form of docs/theory.md §10.4",
            metric=f"max over nodes abs(θ_FE - θ_ref) / max abs(θ_ref) ({n_el} elements)",
            error=_rel_peak(fe, ref), tolerance=TOL_BENSCOTER_STATIC,
            details=f"Mid-span twist: FE {1e3 * fe[n_el // 2]:.6f} mrad, closed form {1e3 * ref[n_el // 2]:.6f} mrad, "
                    f"Vlasov {1e3 * vlasov:.6f} mrad ({100 * (ref[n_el // 2] / vlasov - 1):+.1f} % from the warping "
                    f"shear). Section: J = {sec.J:g} m4, I_w = {sec.I_w:g} m6, I_ws = {sec.I_ws:g} m4, L = {L:g} m.",
            group=group,
        ))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("twist θx [mrad]")
    ax.set_title(f"Torque {T / 1e3:g} kN m at mid-span, L = {L:g} m", fontsize=10)
    ax.legend(fontsize=6)

    # Frequencies with fork supports against the frequency equation.
    def torsion_hz(n: int, count: int = 3) -> np.ndarray:
        return _first_kind(build_bridge([L], n, STEEL, sec, ["pinned", "fork"], theory=theory), "torsion", count, 40)

    modes = np.arange(1, 4)
    ref_f = benscoter_torsional_frequencies_hz(modes, L, STEEL, sec)
    vlasov_f = torsional_frequencies_hz(modes, L, STEEL, sec)
    fe_f = torsion_hz(n_el)
    ax = axes[0, 1]
    ax.plot(modes, vlasov_f, "s:", color="0.5", label="Vlasov frequency equation")
    ax.plot(modes, ref_f, "-", color="C0", label="Benscoter frequency equation")
    ax.plot(modes, fe_f, "o", mfc="none", color="C0", label=f"FE, {n_el} elements")
    ax.set_xticks(modes)
    ax.set_xlabel("torsional mode n [-]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("Fork supports", fontsize=10)
    ax.legend(fontsize=7)
    rel = np.abs(fe_f / ref_f - 1)
    rows = [[str(n), f"{f:.5f}", f"{r:.5f}", f"{v:.5f}", _fmt(e)] for n, f, r, v, e in zip(modes, fe_f, ref_f,
                                                                                               vlasov_f, rel)]
    cases.append(CaseResult(
        name="Benscoter torsional frequencies",
        reference="(G_t k² - ω² ρ I_ps)(E I_w k² + G I_ws - ω² ρ I_w) - (G I_ws k)² = 0, k = nπ/L, G_t = GJ + G I_ws, "
                  "smaller root (docs/theory.md §10.4)",
        metric=f"max over the first 3 torsional modes abs(f_FE / f_ref - 1) ({n_el} elements)",
        error=float(np.max(rel)), tolerance=TOL_BENSCOTER_FREQ,
        details=_table(["n", "FE [Hz]", "Benscoter [Hz]", "Vlasov [Hz]", "rel. error"], rows), group=group,
    ))

    # Mesh convergence of the third torsional frequency.
    counts = np.array([5, 10, 20, 40])
    errors = np.array([torsion_hz(int(n))[2] / ref_f[2] - 1.0 for n in counts])
    orders = _orders(L / counts, errors)
    ax = axes[0, 2]
    ax.loglog(counts, errors, "o-", color="C0", ms=4, label="third torsional frequency")
    ax.loglog(counts, errors[0] * (counts / counts[0]) ** -2.0, "--", color="0.5", lw=0.8, label="slope 2")
    from matplotlib.ticker import NullFormatter

    ax.set_xticks(counts, [str(n) for n in counts])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("elements [-]")
    ax.set_ylabel("relative error [-]")
    ax.set_title("Mesh convergence", fontsize=10)
    ax.legend(fontsize=7)
    path = run.save(fig, "benscoter_torsion.png")
    cases.append(CaseResult(
        name="Benscoter torsion, mesh convergence",
        reference="Benscoter frequency equation; expected order 2 (constant secondary shear strain per element, "
                  "as the Timoshenko element)",
        metric=f"order shortfall max(0, 2 - min observed order) over {', '.join(map(str, counts))} elements",
        error=max(0.0, 2.0 - float(np.min(orders))) if np.all(errors > 0) else math.inf,
        tolerance=TOL_ORDER_MESH_TIMOSHENKO,
        details=_table(["elements", "rel. error"], [[str(n), _fmt(e)] for n, e in zip(counts, errors)])
        + f"\n\nObserved orders: {', '.join(f'{p:.2f}' for p in orders)}.",
        group=group,
    ))
    return [replace(c, plots=(path,)) for c in cases]


def _study_paper_theories(run: _Run) -> list[CaseResult]:
    from cosim.core.bridge import BeamTheory
    from cosim.run.scenario import load_scenario

    group = "Paper case: Vlasov and Benscoter torsion"
    scenario = load_scenario("paper-double-tee")
    cfg = scenario.bridge
    damping = cfg.damping.to_damping() if cfg.damping is not None else None
    section = scenario.build_section()
    dt = run.settings.paper_dt
    results, rows = {}, []
    for name in ("vlasov", "benscoter"):
        bridge = build_bridge(cfg.spans, cfg.elements_per_span, scenario.material(), section, cfg.supports, damping,
                              theory=BeamTheory(torsion=name))
        modal = bridge.modes(12)
        f_t = [f for f, k in zip(modal.f_hz, modal.kinds) if k == "torsion"]
        res = _paper_runs(bridge, dt, [("mf", "direct", True)])["mf"]
        results[name] = (f_t, res)
        rows.append([name, f"{f_t[0]:.4f}", f"{f_t[1]:.4f}"]
                    + [f"{1e3 * np.min(res[node]):.4f}" for node, _ in PAPER_NODES])
    fig, axes = _figure(1, 3, size=(14.0, 4.0), sharey=True)
    for i, (node, y) in enumerate(PAPER_NODES):
        ax = axes[0, i]
        for name, style in (("vlasov", "-"), ("benscoter", "--")):
            res = results[name][1]
            ax.plot(res["t"], 1e3 * res[node], style, lw=1.2, label=f"{name} (torsion-1 {results[name][0][0]:.3f} Hz)")
        ax.set_xlabel("time t [s]")
        ax.set_title(f"{node}: mid-span, y = {_y(y)} m", fontsize=10)
        ax.set_xlim(0.0, PAPER_DURATION)
        ax.legend(fontsize=7, loc="lower left")
    axes[0, 0].set_ylabel("vertical displacement w [mm]")
    fig.suptitle("Paper case, moving forces (1100 kg, 2200 kg) at 4 m/s, direct basis", fontsize=10)
    path = run.save(fig, "paper_torsion_theories.png")
    f_v, f_b = results["vlasov"][0][0], results["benscoter"][0][0]
    details = (
        f"Bundled scenario `paper-double-tee` (40 elements, rigid ends: warping restrained; Rayleigh 2 % at "
        f"vertical-1 and torsion-1 of each model) with `torsion` switched; section I_ws = {section.I_ws:.4g} m4 "
        f"(FE warping shear constant, docs/theory.md §10.2). Moving forces as in the paper case, dt = {dt} s.\n\n"
        + _table(["torsion", "torsion-1 [Hz]", "torsion-2 [Hz]"] + [f"{n} peak [mm]" for n, _ in PAPER_NODES], rows)
        + f"\n\nBenscoter lowers the first torsional frequency by {100 * (1 - f_b / f_v):.1f} % "
          f"({f_v:.3f} -> {f_b:.3f} Hz)."
    )
    return [CaseResult(
        name="Paper case, Vlasov vs Benscoter torsion: frequencies and moving-force peaks (informational)",
        reference="none (the issue quotes a 3D shell model about 10 % below the Vlasov torsion-1, 4.51 Hz)",
        metric="frequencies and peaks only", error=None, tolerance=None, passed=True, plots=(path,),
        details=details, group=group,
    )]


def _study_vbi2d(run: _Run) -> list[CaseResult]:
    from cosim.core.simulation import Sensor, SolverSettings, simulate

    from .references import VBI2D_SPRUNG, vbi2d_sprung_case

    group = "VBI-2D sprung vehicle (Euler-Bernoulli beam)"
    bridge, traffic, crossing = vbi2d_sprung_case()
    p = VBI2D_SPRUNG
    res = simulate(bridge, traffic, crossing, SolverSettings(dt=1e-3, gravity=GRAVITY), [Sensor("mid", p["L"] / 2)])
    w = res.sensors["mid"]
    k = int(np.argmin(w))
    s = run.settings
    ref_w, ref_a = sprung_mass_modal_solution(res.t, p["L"], p["E"] * p["I"], p["m"], p["m_v"], p["k_v"], 0.0, p["v"],
                                              gravity=GRAVITY, n_modes=s.sprung_modes, rtol=s.sprung_rtol,
                                              atol=s.sprung_rtol * 1e-3)
    body = res.vehicle("sprung")
    fig, axes = _figure(1, 2, size=(10.0, 4.0))
    ax = axes[0, 0]
    ax.plot(res.t, 1e3 * w, "-", color="C0", lw=1.6, label="cosim, Euler-Bernoulli, 20 elements")
    ax.plot(res.t, 1e3 * ref_w, "--", color="k", lw=1.0, label=f"modal ODE ({s.sprung_modes} modes, solve_ivp)")
    ax.plot([p["peak_t"]], [1e3 * p["peak_w"]], "x", color="C3", ms=8, label="VBI-2D peak (-0.41855 mm, 0.436 s)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("mid-span deflection w [mm]")
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    ax.plot(body["t"], body["body_acceleration"], "-", color="C1", lw=1.6, label="cosim")
    ax.plot(res.t, ref_a, "--", color="k", lw=1.0, label="modal ODE")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("body acceleration [m/s²]")
    ax.legend(fontsize=7)
    fig.suptitle("VBI-2D 'SprungVeh': 5750 kg on 1.595 MN/m at 25 m/s, L = 25 m, EI = 4.865e10 N m², 18358 kg/m",
                 fontsize=10)
    path = run.save(fig, "vbi2d_sprung_mass.png")
    error = abs(w[k] / p["peak_w"] - 1.0)
    return [CaseResult(
        name="VBI-2D sprung vehicle: mid-span peak",
        reference="VBI-2D verification case 'SprungVeh' (D. Cantero, github.com/DanielCanteroNTNU/VBI-2D, "
                  "V01_Analytical_Verification_Examples.m): -0.41855 mm at 0.436 s",
        metric="abs(w_peak / w_peak,ref - 1)",
        error=error, tolerance=TOL_VBI2D, passed=_judge(error, TOL_VBI2D) and abs(res.t[k] - p["peak_t"]) <= 0.005,
        plots=(path,),
        details=f"The model of `examples/scenarios/vbi2d-sprung-mass.toml` (bending = \"euler-bernoulli\", "
                f"mass_per_length = 18358 kg/m, rotary_inertia = false, quarter-car with m_w = 0, 20 elements, "
                f"dt = 1 ms, entering at x = 0 at t = 0). Peak: "
                f"cosim {1e3 * w[k]:.5f} mm at {res.t[k]:.3f} s; VBI-2D -0.41855 mm at 0.436 s; independent modal "
                f"ODE {1e3 * ref_w.min():.5f} mm at {res.t[int(np.argmin(ref_w))]:.3f} s. Max abs difference to the "
                f"modal ODE over the crossing: {_rel_peak(w, ref_w):.2e} of its peak (deflection), "
                f"{_rel_peak(np.interp(res.t, body['t'], body['body_acceleration']), ref_a):.2e} (body acceleration).",
        group=group,
    )]


# --------------------------------------------------------------------------- registry and report

_STUDIES: tuple[tuple[str, _Study], ...] = (
    ("paper", _study_paper),
    ("timoshenko-static", _study_timoshenko_static),
    ("timoshenko-frequencies", _study_timoshenko_frequencies),
    ("torsion-static", _study_torsion_static),
    ("torsional-frequencies", _study_torsional_frequencies),
    ("lateral-torsional", _study_lateral_torsional),
    ("fryba", _study_fryba),
    ("sprung-mass", _study_sprung_mass),
    ("energy", _study_energy),
    ("time-step", _study_time_step),
    ("roughness", _study_roughness),
    ("mesh", _study_mesh),
    ("parked-vehicle", _study_parked),
    ("benscoter", _study_benscoter),
    ("paper-torsion-theories", _study_paper_theories),
    ("vbi2d", _study_vbi2d),
)


def _anchor(name: str) -> str:
    """GitHub-style heading anchor."""
    keep = "".join(ch for ch in name.lower() if ch.isalnum() or ch in " -_")
    return keep.replace(" ", "-")


def _report_markdown(cases: Sequence[CaseResult], settings: ValidationSettings, wall: float, out_dir: Path) -> str:
    failed = [c for c in cases if not c.passed]
    judged = [c for c in cases if not c.informational]
    lines = [
        "# cosim validation report",
        "",
        f"cosim {__version__}, {settings.name} settings, run time {wall:.1f} s. "
        f"**{len(judged) - len([c for c in failed if not c.informational])} of {len(judged)} judged cases passed**"
        + (f", {len(failed)} FAILED" if failed else "")
        + f"; {len(cases) - len(judged)} informational.",
        "",
        "Each case compares the model with a reference named below; the error is measured as its metric says "
        "and must not exceed the tolerance. Sign convention: z up, deflections downward are negative. "
        "Verification cases: DESIGN.md section 8; validation case: shared/cases/paper-double-tee.md.",
        "",
        "## Summary",
        "",
        _table(
            ["#", "case", "error", "tolerance", "result"],
            [[str(i + 1), f"[{c.name}](#{_anchor(c.name)})", _fmt(c.error), _fmt(c.tolerance), f"**{c.status}**"]
             for i, c in enumerate(cases)],
        ),
        "",
    ]
    group = None
    shown: set[Path] = set()
    for c in cases:
        if c.group != group:
            group = c.group
            lines += [f"## {group}", ""]
        lines += [
            f"### {c.name}",
            "",
            f"- Reference: {c.reference}",
            f"- Metric: {c.metric}",
            f"- Error: {_fmt(c.error, 4)}; tolerance: {_fmt(c.tolerance)}; result: **{c.status}**",
            "",
        ]
        if c.details:
            lines += [c.details, ""]
        for plot in c.plots:
            rel = plot.relative_to(out_dir) if plot.is_relative_to(out_dir) else plot
            if plot in shown:
                lines += [f"Plot: [{rel.as_posix()}]({rel.as_posix()}) (shown above)", ""]
            else:
                lines += [f"![{c.name}]({rel.as_posix()})", ""]
                shown.add(plot)
    return "\n".join(lines).rstrip() + "\n"
