"""``cosim validate`` as a library call: every case passes and the report and plots are real files."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import cosim.validation.cases as validation
from cosim.errors import CosimError
from cosim.validation.cases import ValidationReport, run_validation, study_names

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MIN_PNG_BYTES = 10_000  # a plot with axes, curves and a legend; an empty canvas is ~3 kB


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[ValidationReport, list[tuple[int, int, str]]]:
    """One quick validation run (``out`` does not exist yet: run_validation creates it) and its progress calls."""
    calls: list[tuple[int, int, str]] = []
    report = run_validation(tmp_path_factory.mktemp("validate") / "out", quick=True,
                            progress=lambda done, total, label: calls.append((done, total, label)))
    return report, calls


@pytest.fixture(scope="module")
def quick_report(quick_run: tuple[ValidationReport, list[tuple[int, int, str]]]) -> ValidationReport:
    return quick_run[0]


def test_every_case_passes(quick_report: ValidationReport) -> None:
    failed = [(c.name, c.error, c.tolerance, c.details) for c in quick_report.failures]
    assert quick_report.all_passed, failed
    assert len(quick_report.cases) >= 20
    judged = [c for c in quick_report.cases if not c.informational]
    assert all(c.error is not None and c.error <= c.tolerance for c in judged)
    names = [c.name for c in quick_report.cases]
    assert len(set(names)) == len(names), "case names must be unique"


def test_the_brief_s_cases_are_all_there(quick_report: ValidationReport) -> None:
    names = " | ".join(c.name for c in quick_report.cases)
    for expected in (
        "Paper case, Node 1", "Paper case, Node 2", "Paper case, Node 3", "asymmetric section",
        "Timoshenko static deflection, simply supported", "Timoshenko static deflection, cantilever",
        "Timoshenko frequencies", "warping free", "warping restrained", "Torsional frequencies",
        "lateral-torsional", "Fryba), α = 0.1", "Fryba), α = 0.5", "sprung mass: mid-span deflection",
        "sprung mass: body acceleration", "Energy conservation", "Time-step convergence",
        "roughness PSD, class A", "roughness PSD, class C", "Mesh convergence",
        "Benscoter torsion, mid-span torque, warping restrained", "Benscoter torsional frequencies",
        "Benscoter torsion, mesh convergence", "Vlasov vs Benscoter", "VBI-2D sprung vehicle",
    ):
        assert expected in names, expected


def test_report_names_every_case_with_its_numbers_and_plots(quick_report: ValidationReport) -> None:
    path = quick_report.report_path
    assert path.is_file() and quick_report.files[0] == path
    text = path.read_text(encoding="utf-8")
    for case in quick_report.cases:
        assert f"### {case.name}" in text, case.name
        assert case.reference in text
    assert "FAIL" not in text
    linked = set(re.findall(r"\]\(([^)#]+\.png)\)", text))
    assert linked == {p.name for p in quick_report.plots}


def test_every_plot_is_a_real_png(quick_report: ValidationReport) -> None:
    plots = quick_report.plots
    expected = {"paper_node1.png", "paper_node2.png", "paper_node3.png", "paper_asymmetric.png",
                "timoshenko_static.png", "torsion_static.png", "fryba_moving_force.png", "sprung_mass.png",
                "energy_drift.png", "time_step_convergence.png", "roughness_psd.png", "mesh_convergence.png",
                "benscoter_torsion.png", "paper_torsion_theories.png", "vbi2d_sprung_mass.png"}
    assert expected <= {p.name for p in plots}
    for plot in plots:
        assert plot.parent == quick_report.out_dir
        data = plot.read_bytes()
        assert data[:8] == PNG_MAGIC, plot.name
        assert len(data) > MIN_PNG_BYTES, (plot.name, len(data))


def test_progress_is_reported_per_study(quick_run: tuple[ValidationReport, list[tuple[int, int, str]]]) -> None:
    calls = quick_run[1]
    total = len(study_names())
    assert [c[0] for c in calls] == list(range(total + 1))
    assert all(c[1] == total for c in calls)
    assert [c[2] for c in calls] == study_names() + ["done"]


def test_summary_lines_end_with_the_total(quick_report: ValidationReport) -> None:
    lines = quick_report.summary_lines()
    assert len(lines) == len(quick_report.cases) + 1
    assert lines[-1].startswith(f"{len(quick_report.cases)} of {len(quick_report.cases)} cases passed")


def test_a_crashing_study_is_a_failed_case_not_an_exception(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def boom(run):  # noqa: ANN001, ANN202
        raise ZeroDivisionError("deliberate")

    monkeypatch.setattr(validation, "_STUDIES", (("boom", boom),))
    report = run_validation(tmp_path, quick=True)
    assert not report.all_passed
    assert [c.status for c in report.cases] == ["FAIL"]
    text = report.report_path.read_text(encoding="utf-8")
    assert "ZeroDivisionError: deliberate" in text and "**FAIL**" in text


def test_unknown_study_is_a_cosim_error(tmp_path: Path) -> None:
    with pytest.raises(CosimError, match="unknown validation studies"):
        run_validation(tmp_path, only=["no-such-study"])


def test_importing_the_validation_module_does_not_import_matplotlib() -> None:
    code = "import sys, cosim.validation.cases, cosim.validation.references; print('matplotlib' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "False"
