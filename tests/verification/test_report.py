"""The report of ``cosim validate`` written from the studies the verification tests judged.

The studies come from the session's cache (``computed``), so writing the
report here costs only the drawing: every case appears with its numbers, and
every figure is a real PNG.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from cosim.validation import ValidationReport, write_report

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MIN_PNG_BYTES = 10_000  # a plot with axes, curves and a legend; an empty canvas is ~3 kB


@pytest.fixture(scope="module")
def report(all_computed, tmp_path_factory: pytest.TempPathFactory) -> ValidationReport:
    return write_report(tmp_path_factory.mktemp("validate") / "out", all_computed, quick=True)


def test_every_case_is_reported_and_passes(report: ValidationReport) -> None:
    assert report.all_passed, [(c.name, c.error, c.tolerance) for c in report.failures]
    assert len(report.cases) >= 20
    judged = [c for c in report.cases if not c.informational]
    assert all(c.error is not None and c.error <= c.tolerance for c in judged)


def test_the_brief_s_cases_are_all_there(report: ValidationReport) -> None:
    names = " | ".join(c.name for c in report.cases)
    for expected in (
        "Paper case, Node 1", "Paper case, Node 2", "Paper case, Node 3", "asymmetric section",
        "Timoshenko static deflection, simply supported", "Timoshenko static deflection, cantilever",
        "Timoshenko frequencies", "warping free", "warping restrained", "Torsional frequencies",
        "lateral-torsional", "Fryba), α = 0.1", "Fryba), α = 0.5", "sprung mass: mid-span deflection",
        "sprung mass: body acceleration", "Energy conservation", "Time-step convergence",
        "roughness PSD, class A", "roughness PSD, class C", "Mesh convergence", "Parked vehicle",
        "Benscoter torsion, mid-span torque, warping restrained", "Benscoter torsion, mid-span torque, warping free",
        "Benscoter torsional frequencies", "Benscoter torsion, mesh convergence", "Vlasov vs Benscoter",
        "VBI-2D sprung vehicle",
    ):
        assert expected in names, expected


def test_report_names_every_case_with_its_numbers_and_plots(report: ValidationReport) -> None:
    path = report.report_path
    assert path.is_file() and report.files[0] == path
    text = path.read_text(encoding="utf-8")
    assert "quick settings" in text
    for case in report.cases:
        assert f"### {case.name}" in text, case.name
        assert case.reference in text
        assert f"## {case.group}" in text
    assert "FAIL" not in text
    linked = set(re.findall(r"\]\(([^)#]+\.png)\)", text))
    assert linked == {p.name for p in report.plots}
    assert linked == {name for case in report.cases for name in case.figures}


def test_every_plot_is_a_real_png(report: ValidationReport) -> None:
    expected = {"paper_node1.png", "paper_node2.png", "paper_node3.png", "paper_asymmetric.png",
                "timoshenko_static.png", "torsion_static.png", "fryba_moving_force.png", "sprung_mass.png",
                "energy_drift.png", "time_step_convergence.png", "roughness_psd.png", "mesh_convergence.png",
                "parked_vehicle.png", "benscoter_torsion.png", "paper_torsion_theories.png", "vbi2d_sprung_mass.png"}
    assert {p.name for p in report.plots} == expected
    for plot in report.plots:
        assert plot.parent == report.out_dir
        data = plot.read_bytes()
        assert data[:8] == PNG_MAGIC, plot.name
        assert len(data) > MIN_PNG_BYTES, (plot.name, len(data))


def test_summary_lines_end_with_the_total(report: ValidationReport) -> None:
    lines = report.summary_lines()
    assert len(lines) == len(report.cases) + 1
    assert lines[-1].startswith(f"{len(report.cases)} of {len(report.cases)} cases passed")


def test_figure_data_is_frozen(all_computed) -> None:
    # The studies return values, not views into live state: every array of every figure is read-only.
    for result in all_computed:
        for figure in result.figures:
            for name, value in vars(figure).items():
                arrays = value if isinstance(value, tuple) else (value,)
                assert not any(isinstance(a, np.ndarray) and a.flags.writeable for a in arrays), (figure.file, name)
