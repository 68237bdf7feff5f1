"""The layout is the architecture: these tests keep it true (docs/architecture.md).

Layers, from the bottom: ``cosim.errors``; the numerical core ``cosim.core``
(numpy, scipy, numba, sectionproperties); the adapters ``cosim.sumo`` and
``cosim.log``, the drawing module ``cosim.plots`` and the engineering analyses
``cosim.analysis`` (fatigue, extremes); orchestration
``cosim.run``; ``cosim.study`` and ``cosim.validation`` on top of it; the
scenario-testing API ``cosim.testing``; the command line ``cosim.cli``.
Dependencies point down only, modules of one layer do not import each other
across packages, and no module imports another's private names. The import
graph is read from the source (every ``import``, lazy ones inside functions
included), not maintained by hand.
"""
from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

import cosim

PACKAGE = Path(cosim.__file__).resolve().parent

#: Layer of every top-level part of the package (a package or a module).
LAYERS = {
    "cosim.errors": 0,
    "cosim.core": 1,
    "cosim.sumo": 2,
    "cosim.log": 2,
    "cosim.plots": 2,
    "cosim.analysis": 2,
    "cosim.run": 3,
    "cosim.study": 4,
    "cosim.validation": 4,
    "cosim.dataset": 4,
    "cosim.testing": 5,
    "cosim.cli": 6,
    "cosim.__main__": 7,
}

#: Libraries the numerical core must never load (adapters, logs, plotting, configuration, studies).
NOT_IN_CORE = ("libsumo", "traci", "sumolib", "mcap", "matplotlib", "dask", "distributed", "pydantic", "pandas")


def _modules() -> dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def _part(module: str) -> str:
    """The top-level part of ``cosim`` a module belongs to ("cosim.core.bridge" -> "cosim.core")."""
    return ".".join(module.split(".")[:2])


def _imports(module: str, path: Path) -> list[tuple[str, list[str], int]]:
    """(imported module, imported names, line) for every import of a cosim module in the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_package = path.name == "__init__.py"
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, [], node.lineno) for a in node.names if a.name.split(".")[0] == "cosim"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package else module.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] == "cosim":
                out.append((target, [a.name for a in node.names], node.lineno))
    return out


def test_every_part_of_the_package_has_a_layer():
    parts = {_part(m) for m in _modules() if m != "cosim"}
    assert parts <= set(LAYERS), f"give these a layer in LAYERS: {sorted(parts - set(LAYERS))}"


def test_dependencies_point_down_only():
    problems = []
    for module, path in _modules().items():
        if module == "cosim":
            continue  # the package root exports the public API lazily (checked below)
        own = _part(module)
        for target, names, line in _imports(module, path):
            if target == "cosim":  # "from cosim import X": a part of the package, or a root name (__version__)
                targets = [f"cosim.{n}" for n in names if f"cosim.{n}" in LAYERS]
            else:
                targets = [target]
            for t in targets:
                other = _part(t)
                if other == own:
                    continue
                if other not in LAYERS:
                    problems.append(f"{path.name}:{line}: imports {t}, which has no layer")
                elif LAYERS[other] > LAYERS[own]:
                    problems.append(f"{module}:{line}: imports {t} from a higher layer ({other})")
                elif LAYERS[other] == LAYERS[own]:
                    problems.append(f"{module}:{line}: imports {t} across one layer ({own} -> {other})")
    assert not problems, "\n".join(problems)


def test_no_module_imports_another_modules_private_names():
    problems = []
    for module, path in _modules().items():
        for target, names, line in _imports(module, path):
            private = [n for n in names if n.startswith("_") and not n.startswith("__")]
            if private:
                problems.append(f"{module}:{line}: imports {', '.join(private)} from {target}")
    assert not problems, "\n".join(problems)


def test_only_the_command_line_prints():
    """``print`` is called in ``cosim.cli`` only: the other layers return values, raise and report progress
    through callbacks (docstring examples are not calls, so they do not count)."""
    problems = []
    for module, path in _modules().items():
        if _part(module) == "cosim.cli":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "print":
                problems.append(f"{module}:{node.lineno}: calls print (only cosim.cli prints)")
    assert not problems, "\n".join(problems)


def test_the_root_package_imports_nothing_eagerly():
    tree = ast.parse((PACKAGE / "__init__.py").read_text(encoding="utf-8"))
    eager = [ast.unparse(n) for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))]
    allowed = {"from __future__ import annotations", "import importlib", "from typing import Any"}
    assert set(eager) <= allowed, "cosim/__init__.py must export lazily (importing cosim.core must not load the rest)"


def test_every_name_of_the_public_api_resolves():
    missing = [name for name in cosim.__all__ if getattr(cosim, name, None) is None]
    assert not missing, f"cosim.__all__ names that do not resolve: {missing}"


@pytest.mark.parametrize("part", ["cosim.core", "cosim"])
def test_importing_the_numerical_core_loads_no_adapter_plotting_or_configuration_library(part):
    core_modules = sorted(m for m in _modules() if _part(m) == "cosim.core") if part == "cosim.core" else ["cosim"]
    code = (
        "import importlib, sys\n"
        f"for m in {core_modules!r}:\n"
        "    importlib.import_module(m)\n"
        f"print(sorted({{name.split('.')[0] for name in sys.modules}} & set({NOT_IN_CORE!r})))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", f"importing {part} loaded {out.stdout.strip()}"


#: Where the repository's own files live: everything in them may cite only files inside the repository.
CITING = [PACKAGE, PACKAGE.parent / "docs", PACKAGE.parent / "tests", PACKAGE.parent / "benchmarks",
          PACKAGE.parent / "README.md"]

#: A design document and a shared folder next to the checkout: not in the repository, so nobody can follow
#: a citation of them. What they held is in docs/ (docs/theory.md, docs/validation.md).
OUTSIDE = re.compile(r"DESIGN\.md|\.\./shared\b|\bshared/(?:cases|seed|tools|data)/")

#: Files that still cite outside the repository, and why they are not changed yet.
NOT_YET = {
    # Bundled scenario files: issue 24 changes no scenario file (they are embedded in every log and the
    # reference logs); their comments should cite docs/validation.md.
    "cosim/scenarios/paper-double-tee.toml",
    "cosim/scenarios/paper-double-tee-asymmetric.toml",
    "cosim/scenarios/paper-bridge-traffic.toml",
}

BINARY = {".mcap", ".gz", ".png", ".parquet", ".npz", ".pyc", ".nbi", ".nbc"}


def test_code_and_docs_cite_only_files_in_the_repository():
    problems = []
    for root in CITING:
        for path in [root] if root.is_file() else sorted(root.rglob("*")):
            if not path.is_file() or path.suffix in BINARY or "__pycache__" in path.parts:
                continue
            if path == Path(__file__).resolve():
                continue
            rel = path.relative_to(PACKAGE.parent).as_posix()
            text = path.read_text(encoding="utf-8", errors="replace")
            for number, line in enumerate(text.splitlines(), start=1):
                if OUTSIDE.search(line) and rel not in NOT_YET:
                    problems.append(f"{rel}:{number}: {line.strip()}")
    assert not problems, "cite docs/ instead of files outside the repository:\n" + "\n".join(problems)
