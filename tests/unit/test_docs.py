"""The documentation holds together: the README stays a front page, every relative link and anchor
resolves, and every ``cosim.<module>.<name>`` the pages mention exists."""
from __future__ import annotations

import importlib
import importlib.util
import re
from pathlib import Path

import pytest

import cosim
from cosim.sumo.vtypes import param_keys

REPO = Path(cosim.__file__).resolve().parents[1]
PAGES = [REPO / "README.md", REPO / "benchmarks" / "README.md", *sorted((REPO / "docs").glob("*.md"))]

#: The README is a front page (issue 24): what cosim is, setup, the default run, one example, what it is
#: verified against, links. The manual is in docs/.
README_MAX_BYTES = 15_000


def _prose(text: str) -> str:
    """The Markdown without fenced code blocks and inline code (links there are not links)."""
    text = re.sub(r"(?ms)^```.*?^```", "", text)
    return re.sub(r"`[^`\n]*`", "", text)


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: its text (code spans and link text kept), lower case, punctuation
    dropped, spaces to hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading).replace("`", "").strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors of a Markdown file's headings (repeated headings get -1, -2, ... as on GitHub)."""
    seen: dict[str, int] = {}
    found = set()
    for line in re.sub(r"(?ms)^```.*?^```", "", path.read_text(encoding="utf-8")).splitlines():
        heading = re.match(r"#{1,6} (.*)", line)
        if heading:
            slug = _slug(heading[1])
            found.add(f"{slug}-{seen[slug]}" if slug in seen else slug)
            seen[slug] = seen.get(slug, 0) + 1
    return found


def links(path: Path) -> list[str]:
    """The targets of the Markdown links and images of a file, outside code."""
    return re.findall(r"!?\[[^\]]*\]\(([^)\s]+)\)", _prose(path.read_text(encoding="utf-8")))


def test_the_readme_is_a_front_page() -> None:
    size = len((REPO / "README.md").read_bytes())
    assert size <= README_MAX_BYTES, f"README.md is {size} bytes; move the details into docs/"


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(REPO)) for p in PAGES])
def test_every_relative_link_and_anchor_resolves(page: Path) -> None:
    broken = []
    for target in links(page):
        if re.match(r"[a-z]+:", target):  # https:, mailto:: not checked here
            continue
        file, _, anchor = target.partition("#")
        resolved = (page.parent / file).resolve() if file else page
        if not resolved.exists():
            broken.append(f"{target}: no such file")
        elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
            broken.append(f"{target}: no heading with that anchor in {resolved.relative_to(REPO)}")
    assert not broken, f"{page.relative_to(REPO)}: " + "; ".join(broken)


def _resolves(dotted: str) -> bool:
    """Whether ``cosim.a.b.c`` is a module, or a name in the longest module prefix of it (modules found
    without importing them where nothing inside is named: ``cosim.__main__`` would run the command line)."""
    parts = dotted.split(".")
    for i in range(len(parts), 1, -1):
        try:
            spec = importlib.util.find_spec(".".join(parts[:i]))
        except ModuleNotFoundError:
            spec = None
        if spec is None:
            continue
        obj = importlib.import_module(".".join(parts[:i])) if i < len(parts) else None
        for name in parts[i:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return hasattr(cosim, parts[1])


#: ``cosim.<key>`` names that are not Python: SUMO vType params, and the misspelt one an error example shows.
# The log's protobuf messages (package cosim: cosim/log/cosim.proto, and each run's cosim.SensorSample) and the
# .proto file itself are names of the log, not of the package.
PROTO_MESSAGES = {f"cosim.{name}" for name in
                  re.findall(r"^message (\w+)", (REPO / "cosim" / "log" / "cosim.proto").read_text(), re.M)}
NOT_PYTHON = ({f"cosim.{key}" for key in param_keys()} | {"cosim.kv", "cosim.proto", "cosim.SensorSample"}
              | PROTO_MESSAGES)


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(REPO)) for p in PAGES])
def test_every_cosim_name_the_pages_mention_exists(page: Path) -> None:
    names = set(re.findall(r"\bcosim(?:\.[A-Za-z_]\w*)+", page.read_text(encoding="utf-8")))
    missing = sorted(n for n in names - NOT_PYTHON if not _resolves(n))
    assert not missing, f"{page.relative_to(REPO)} names what the package does not have: {missing}"
