"""The Python examples of the documentation, run as written.

docs/python.md: its code runs in an empty folder and writes what it says it writes.
"""
from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

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
