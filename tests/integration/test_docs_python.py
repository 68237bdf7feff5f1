"""The Python examples of the documentation, run as written.

- README.md: its one Python example prints what the README shows after it (numbers within
  :data:`README_RTOL`);
- docs/python.md: its code runs in an empty folder and writes what it says it writes.
"""
from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

import pytest

import cosim

REPO = Path(cosim.__file__).resolve().parents[1]


def python_blocks(path: Path) -> list[str]:
    """The ```python blocks of a Markdown file, in order."""
    return re.findall(r"(?ms)^```python\n(.*?)^```", path.read_text(encoding="utf-8"))


def run_block(code: str, folder: Path, name: str) -> str:
    """Execute ``code`` as a script in ``folder`` and return what it printed."""
    out = io.StringIO()
    previous = Path.cwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, name, "exec"), {"__name__": "__main__"})
    finally:
        os.chdir(previous)
    return out.getvalue()


def test_the_python_page_runs_and_writes_its_csv(tmp_path: Path) -> None:
    (block,) = [b for b in python_blocks(REPO / "docs" / "python.md") if "simulate_scenario" in b]
    printed = run_block(block, tmp_path, "docs/python.md")
    assert "node2" in printed and "vertical" in printed
    assert (tmp_path / "paper.csv").read_text().startswith("t,node1,node2,node3,node3_acc\n")


#: How far a printed number may be from the README's: one unit in the 4th significant digit. The README's
#: output is what its code printed on the 2-core build machine (cosim 0.1.0, the commit that wrote it); the
#: same peaks are `cosim run paper-double-tee`'s summary (docs/cli.md) and the frequencies `cosim modes
#: paper-double-tee`'s. Another BLAS may change the last bits of the sums, never the 4th digit but by rounding.
README_RTOL = 1e-3

NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def test_the_readme_python_example_prints_what_the_readme_shows(tmp_path: Path) -> None:
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    (code,) = python_blocks(REPO / "README.md")
    (shown,) = re.findall(r"(?ms)^```python\n.*?^```\n\n```text\n(.*?)^```", readme)
    printed = run_block(code, tmp_path, "README.md").splitlines()
    expected = shown.splitlines()
    assert len(printed) == len(expected), "\n".join(printed)
    for got, want in zip(printed, expected):
        assert NUMBER.sub("#", got) == NUMBER.sub("#", want), (got, want)
        got_numbers = [float(x) for x in NUMBER.findall(got)]
        want_numbers = [float(x) for x in NUMBER.findall(want)]
        assert got_numbers == pytest.approx(want_numbers, rel=README_RTOL), (got, want)
