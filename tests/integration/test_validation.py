"""``cosim validate`` as a library call: studies run, progress is reported, crashes become failed cases.

Every registered case is judged in ``tests/verification`` (the same studies at the
same quick settings); here :func:`run_validation` runs end to end on a few cheap studies.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cosim.errors import CosimError
from cosim.validation import STUDIES, Study, StudyResult, ValidationReport, run_validation, study_names
from cosim.validation.results import CaseResult

CHEAP = ["timoshenko-static", "torsion-static", "roughness"]


@pytest.fixture(scope="module")
def cheap_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[ValidationReport, list[tuple[int, int, str]]]:
    """A quick run of three cheap studies (``out`` does not exist yet: run_validation creates it) and its progress."""
    calls: list[tuple[int, int, str]] = []
    report = run_validation(tmp_path_factory.mktemp("validate") / "out", quick=True, only=CHEAP,
                            progress=lambda done, total, label: calls.append((done, total, label)))
    return report, calls


def test_a_run_writes_its_report_and_plots(cheap_run: tuple[ValidationReport, list]) -> None:
    report = cheap_run[0]
    assert report.out_dir.is_dir() and report.report_path == report.files[0] and report.report_path.is_file()
    assert report.all_passed and report.quick
    assert {c.group for c in report.cases} == {s.title for s in STUDIES if s.name in CHEAP}
    assert {p.name for p in report.plots} == {"timoshenko_static.png", "torsion_static.png", "roughness_psd.png"}
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in report.plots)
    lines = report.summary_lines()
    assert lines[-1].startswith(f"{len(report.cases)} of {len(report.cases)} cases passed")


def test_progress_is_reported_per_study(cheap_run: tuple[ValidationReport, list[tuple[int, int, str]]]) -> None:
    calls = cheap_run[1]
    assert calls == [(0, 3, CHEAP[0]), (1, 3, CHEAP[1]), (2, 3, CHEAP[2]), (3, 3, "done")]


def test_study_names_follow_the_registry() -> None:
    assert study_names() == [s.name for s in STUDIES]
    assert len(set(study_names())) == len(study_names())
    assert study_names()[0] == "paper"


def test_a_crashing_study_is_a_failed_case_not_an_exception(tmp_path: Path) -> None:
    def boom() -> StudyResult:
        raise ZeroDivisionError("deliberate")

    report = run_validation(tmp_path, quick=True, studies=[Study("boom", "Boom", boom)])
    assert not report.all_passed
    assert [c.status for c in report.cases] == ["FAIL"]
    text = report.report_path.read_text(encoding="utf-8")
    assert "ZeroDivisionError: deliberate" in text and "**FAIL**" in text


def test_a_figure_that_cannot_be_drawn_is_a_failed_case(tmp_path: Path) -> None:
    from cosim.validation.cases import ParkedFigure

    def bad_figure() -> StudyResult:
        case = CaseResult("fine", "a reference", "a metric", 0.0, 1.0, figures=("parked_vehicle.png",))
        return StudyResult((case,), (ParkedFigure("parked_vehicle.png", "title", [0.0, 1.0], [1.0], 0.0, 1.0),))

    report = run_validation(tmp_path, studies=[Study("bad", "Bad", bad_figure)])
    assert [c.status for c in report.cases] == ["PASS", "FAIL"]
    assert "figure parked_vehicle.png crashed" in report.cases[1].name
    assert "](parked_vehicle.png)" not in report.report_path.read_text(encoding="utf-8")  # not linked


def test_unknown_study_is_a_cosim_error(tmp_path: Path) -> None:
    with pytest.raises(CosimError, match="unknown validation studies"):
        run_validation(tmp_path, only=["no-such-study"])


def test_importing_the_validation_package_does_not_import_matplotlib() -> None:
    code = ("import sys, cosim.validation, cosim.validation.cases, cosim.validation.references, "
            "cosim.validation.report; print('matplotlib' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "False"
