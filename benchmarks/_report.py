"""What every benchmark script does with its Markdown report: write it (its folder made) and say where."""
from __future__ import annotations

from pathlib import Path


def write_report(text: str, out: str | Path) -> None:
    """Write ``text`` to ``out`` (UTF-8), creating its folder, and print where it went."""
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    print(f"written: {path}")
