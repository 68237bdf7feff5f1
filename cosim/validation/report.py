"""``cosim validate``: run the registered studies and write ``report.md`` with their figures.

:func:`run_validation` computes every study of :mod:`cosim.validation.registry`
and hands the results to :func:`write_report`, which draws each figure through
:mod:`cosim.plots` and writes the Markdown::

    from cosim.validation import run_validation

    report = run_validation("validation-out", quick=True)
    print(report.all_passed, report.report_path)
    for case in report.cases:
        print(case.name, case.error, case.tolerance, case.passed)

``quick=True`` uses the registry's quick settings (the verification tests' too)
with the same tolerances: about 10 s against 20 s for the full settings on two
cores, plus numba's one-off compilation of the coupled step. matplotlib is
imported only while drawing; this module prints nothing.
"""
from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from pathlib import Path

from cosim import __version__, plots
from cosim.errors import CosimError

from . import cases
from .registry import STUDIES, Study, select
from .results import CaseResult, FigureData, StudyResult, Table, format_number

__all__ = ["ProgressCallback", "ValidationReport", "run_validation", "write_report"]

#: Called as ``progress(done, total, label)``: before each study starts (``done``
#: studies finished so far, ``label`` names the one starting) and once at the end
#: with ``done == total`` and ``label == "done"``.
ProgressCallback = Callable[[int, int, str], None]

#: The drawing function of every kind of figure data (keyword arguments: the data's fields but ``file``).
PLOTTERS: dict[type, Callable[..., Path]] = {
    cases.PaperNodeFigure: plots.validation_paper_node,
    cases.PaperAsymmetricFigure: plots.validation_paper_asymmetric,
    cases.TimoshenkoStaticFigure: plots.validation_timoshenko_static,
    cases.TorsionStaticFigure: plots.validation_torsion_static,
    cases.FrybaFigure: plots.validation_fryba,
    cases.SprungMassFigure: plots.validation_sprung_mass,
    cases.EnergyFigure: plots.validation_energy,
    cases.TimeStepFigure: plots.validation_time_step,
    cases.RoughnessFigure: plots.validation_roughness,
    cases.MeshFigure: plots.validation_mesh,
    cases.ParkedFigure: plots.validation_parked,
    cases.BenscoterFigure: plots.validation_benscoter,
    cases.PaperTheoriesFigure: plots.validation_paper_theories,
    cases.Vbi2dFigure: plots.validation_vbi2d,
}


@dataclass(frozen=True)
class ValidationReport:
    """Everything :func:`run_validation` did.

    Attributes:
        out_dir: the output directory.
        quick: whether the quick settings were used.
        cases: every case, in report order.
        files: every file written (report.md first, then the PNGs).
        wall_time: total run time (computing and drawing), s.
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
            f"{c.status:4}  {c.name:<{width}}  error {format_number(c.error)}  tolerance {format_number(c.tolerance)}"
            for c in self.cases
        ]
        failed = len(self.failures)
        lines.append(
            f"{len(self.cases) - failed} of {len(self.cases)} cases passed"
            f"{'' if not failed else f', {failed} FAILED'} in {self.wall_time:.1f} s; report: {self.report_path}"
        )
        return lines


def run_validation(
    out_dir: str | Path,
    quick: bool = False,
    progress: ProgressCallback | None = None,
    only: Sequence[str] | None = None,
    *,
    studies: Sequence[Study] | None = None,
) -> ValidationReport:
    """Run the verification and validation studies; write ``report.md`` and PNG plots to ``out_dir``.

    Args:
        out_dir: output directory, created (with parents) if missing; files of
            the same names are overwritten.
        quick: the quick settings (for tests and a first look).
        progress: called as ``progress(done, total, label)`` before each study and at the end.
        only: run only the studies with these names (see :func:`~cosim.validation.registry.study_names`).
        studies: the studies to choose from; default the registered ones.

    Returns:
        The cases with their errors, tolerances and verdicts, and the files written.

    Raises:
        CosimError: ``out_dir`` cannot be created or written, or ``only`` names an unknown study.
        A study that raises is reported as a failed case (with its traceback in the report), not re-raised.
    """
    started = time.perf_counter()
    out = _output_dir(out_dir)
    chosen = select(only, STUDIES if studies is None else studies)
    results: list[StudyResult] = []
    for i, study in enumerate(chosen):
        if progress is not None:
            progress(i, len(chosen), study.name)
        try:
            results.append(study.run(quick))
        except Exception:  # noqa: BLE001 - a crashing study is a failed case; the report says why
            results.append(StudyResult((_crashed(f"{study.name}: crashed", study.title),)))
    if progress is not None:
        progress(len(chosen), len(chosen), "done")
    return write_report(out, results, quick=quick, started=started)


def write_report(
    out_dir: str | Path, results: Sequence[StudyResult], quick: bool, started: float | None = None
) -> ValidationReport:
    """Draw the figures of computed studies and write ``report.md`` (no computing).

    Args:
        out_dir: output directory, created if missing.
        results: studies as :meth:`Study.run <cosim.validation.registry.Study.run>` returns them, in report order.
        quick: whether they were computed with the quick settings (the report says so).
        started: ``time.perf_counter()`` when the computing began (for the run time; default: now).

    Returns:
        The report. A figure that fails to draw (not to write) becomes a failed case.

    Raises:
        CosimError: ``out_dir`` or a file in it cannot be written.
    """
    started = time.perf_counter() if started is None else started
    out = _output_dir(out_dir)
    all_cases: list[CaseResult] = []
    files: list[Path] = []
    for result in results:
        all_cases.extend(result.cases)
        group = result.cases[0].group if result.cases else ""
        for figure in result.figures:
            try:
                files.append(draw(figure, out))
            except CosimError:
                raise
            except Exception:  # noqa: BLE001 - a figure that cannot be drawn is a failure, reported
                all_cases.append(_crashed(f"{group}: figure {figure.file} crashed", group))
    wall = time.perf_counter() - started
    report_path = out / "report.md"
    text = report_markdown(all_cases, quick, wall, {p.name for p in files})
    try:
        report_path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise CosimError(f"{report_path}: cannot write the report ({exc.strerror})") from None
    return ValidationReport(out, quick, tuple(all_cases), (report_path, *files), wall)


def draw(figure: FigureData, out_dir: Path) -> Path:
    """Draw one figure's data into ``out_dir / figure.file`` with its function of :mod:`cosim.plots`."""
    plotter = PLOTTERS.get(type(figure))
    if plotter is None:
        raise TypeError(f"no drawing function for {type(figure).__name__}")
    data = {f.name: getattr(figure, f.name) for f in fields(figure) if f.name != "file"}
    return plotter(out_dir / figure.file, **data)


# --------------------------------------------------------------------------- Markdown


def report_markdown(cases: Sequence[CaseResult], quick: bool, wall: float, drawn: set[str]) -> str:
    """The report: a summary table, then every case with its reference, metric, details and figures.

    ``drawn`` are the figure files that exist; a case's other figures are left out.
    """
    failed = [c for c in cases if not c.passed]
    judged = [c for c in cases if not c.informational]
    lines = [
        "# cosim validation report",
        "",
        f"cosim {__version__}, {'quick' if quick else 'full'} settings, run time {wall:.1f} s. "
        f"**{len(judged) - len([c for c in failed if not c.informational])} of {len(judged)} judged cases passed**"
        + (f", {len(failed)} FAILED" if failed else "")
        + f"; {len(cases) - len(judged)} informational.",
        "",
        "Each case compares the model with a reference named below; the error is measured as its metric says "
        "and must not exceed the tolerance. Sign convention: z up, deflections downward are negative. "
        "Verification cases: docs/validation.md, docs/theory.md §8; validation case: docs/validation.md.",
        "",
        "## Summary",
        "",
        _table(Table(
            ("#", "case", "error", "tolerance", "result"),
            [(str(i + 1), f"[{c.name}](#{_anchor(c.name)})", format_number(c.error), format_number(c.tolerance),
              f"**{c.status}**") for i, c in enumerate(cases)],
        )),
        "",
    ]
    group = None
    shown: set[str] = set()
    for c in cases:
        if c.group != group:
            group = c.group
            lines += [f"## {group}", ""]
        lines += [
            f"### {c.name}",
            "",
            f"- Reference: {c.reference}",
            f"- Metric: {c.metric}",
            f"- Error: {format_number(c.error, 4)}; tolerance: {format_number(c.tolerance)}; result: **{c.status}**",
            "",
        ]
        for block in c.details:
            lines += [_table(block) if isinstance(block, Table) else block, ""]
        for name in c.figures:
            if name not in drawn:
                continue
            if name in shown:
                lines += [f"Plot: [{name}]({name}) (shown above)", ""]
            else:
                lines += [f"![{c.name}]({name})", ""]
                shown.add(name)
    return "\n".join(lines).rstrip() + "\n"


def _table(table: Table) -> str:
    lines = ["| " + " | ".join(table.header) + " |", "|" + "|".join("---" for _ in table.header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in table.rows]
    return "\n".join(lines)


def _anchor(name: str) -> str:
    """GitHub-style heading anchor."""
    keep = "".join(ch for ch in name.lower() if ch.isalnum() or ch in " -_")
    return keep.replace(" ", "-")


def _crashed(name: str, group: str) -> CaseResult:
    return CaseResult(
        name=name, reference="-", metric="-", error=None, tolerance=None, passed=False,
        details=("```\n" + traceback.format_exc().rstrip() + "\n```",), group=group,
    )


def _output_dir(out_dir: str | Path) -> Path:
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CosimError(f"{out}: cannot create the output directory ({exc.strerror})") from None
    if not out.is_dir():
        raise CosimError(f"{out}: is not a directory")
    return out
