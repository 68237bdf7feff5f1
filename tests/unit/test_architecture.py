"""The layout is the architecture: these tests keep it true (docs/architecture.md).

Layers, from the bottom: ``cosim.errors``; the numerical core ``cosim.core``
(numpy, scipy, numba, sectionproperties); the adapters ``cosim.sumo``,
``cosim.log`` and ``cosim.bridges`` (modes files and importers), the drawing
module ``cosim.plots`` and the engineering analyses ``cosim.analysis``
(fatigue, extremes); orchestration
``cosim.run``; ``cosim.study`` and ``cosim.validation`` on top of it; the
scenario-testing API ``cosim.testing``; the command line ``cosim.cli``.
Dependencies point down only, modules of one layer do not import each other
across packages, and no module imports or reads another's private names
(nor a third-party package's, but for one isolated function), nor is over
800 lines (issue 24; the modules still over it are listed as pending). The import
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
    "cosim.bridges": 2,
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


# --------------------------------------------------------------------------- size of a module, private names

#: Lines a module may have: a module over it holds several concepts (issue 24).
MAX_MODULE_LINES = 800

#: Pending in issue 24: modules still over :data:`MAX_MODULE_LINES`, to be split by their owners (and then
#: removed from here; the lead empties this list). Do not add to it: split the module instead.
PENDING_LONG_MODULES: set[str] = set()


def _relative(path: Path) -> str:
    return path.relative_to(PACKAGE.parent).as_posix()


def test_no_module_is_over_800_lines():
    long = {}
    for path in _modules().values():
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > MAX_MODULE_LINES and _relative(path) not in PENDING_LONG_MODULES:
            long[_relative(path)] = lines
    assert not long, (f"modules over {MAX_MODULE_LINES} lines (split them along their concepts): "
                      + ", ".join(f"{p} ({n})" for p, n in sorted(long.items())))


def _nodes_by_function(tree: ast.AST) -> list[tuple[str, ast.AST]]:
    """Every node of a module with the qualified name of the function (or class) around it ("" at the top)."""
    out: list[tuple[str, ast.AST]] = []

    def visit(node: ast.AST, where: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = where
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                inner = f"{where}.{child.name}" if where else child.name
            out.append((inner, child))
            visit(child, inner)

    visit(tree, "")
    return out


#: A name-mangled attribute (``obj._Class__name``): another class's private attribute, read from outside it.
MANGLED = re.compile(r"^_[A-Za-z][A-Za-z0-9]*__\w+$")

#: The one function that reads a third-party object's name-mangled attributes, and why: mcap's Writer has no
#: public bulk path for pre-encoded messages (tests/unit/test_log.py fails if mcap's internals change).
MANGLED_READER = ("cosim/log/writer.py", "_mcap_chunk_state")


def test_no_name_mangled_attribute_is_read_outside_the_one_isolated_function():
    problems, isolated = [], 0
    for path in _modules().values():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for where, node in _nodes_by_function(tree):
            if isinstance(node, ast.Attribute):
                name = node.attr
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                name = node.value  # getattr(obj, "_Class__name")
            else:
                continue
            if not MANGLED.match(name):
                continue
            if (_relative(path), where) == MANGLED_READER:
                isolated += 1
            else:
                problems.append(f"{_relative(path)}:{node.lineno} ({where or 'module'}): reads {name}")
    assert not problems, ("name-mangled attributes read outside "
                          f"{MANGLED_READER[0]}:{MANGLED_READER[1]}:\n" + "\n".join(problems))
    assert isolated, f"{MANGLED_READER} reads no name-mangled attribute: update MANGLED_READER"


#: Names with a leading underscore that are public API (namedtuple's methods and attributes).
PUBLIC_UNDERSCORE = {"_replace", "_asdict", "_fields", "_make", "_field_defaults"}

#: Reads of a package's private names that no public API replaces, each isolated in one function that says why,
#: with a test that fails if the package changes them: numba offers no public way to key a function's disk cache
#: on more than its own file (cosim.core.jit._install_core_locator; tests/unit/test_jit.py).
ISOLATED_PRIVATE_READS = {
    ("cosim/core/jit.py", "_locator_classes"),  # numba's cache locators, extended with cosim's
    ("cosim/core/jit.py", "_CacheImpl"),  # numba.core.caching's CacheImpl before numba 0.61
    ("cosim/sumo/reads.py", "_libsumo"),  # libsumo's SWIG functions, its public getters when a build lacks them
}


def _own_names(tree: ast.AST) -> set[str]:
    """The names a module defines itself: its functions and classes, and every name or attribute it assigns."""
    own = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            own.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            own.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) \
                and isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            own.add(node.attr)
    return own


def test_no_module_reads_another_modules_or_packages_private_names():
    """``obj._name`` (not ``self``'s or ``cls``'s, nor a name the module defines itself), ``getattr(obj,
    "_name")`` and ``from package import _name``: reaching into what another module or package keeps private."""
    problems = []
    for path in _modules().values():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        own = _own_names(tree)
        found = []
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute):
                owner = node.value.id if isinstance(node.value, ast.Name) else None
                if owner not in ("self", "cls") and (node.attr not in own or isinstance(node.ctx, ast.Store)):
                    found.append((node.lineno, node.attr))
            elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in (
                    "getattr", "setattr", "hasattr") and len(node.args) >= 2 and isinstance(node.args[1], ast.Constant):
                owner = node.args[0].id if isinstance(node.args[0], ast.Name) else None
                if owner not in ("self", "cls") and isinstance(node.args[1].value, str):
                    found.append((node.lineno, node.args[1].value))
            elif isinstance(node, ast.ImportFrom) and not node.level:
                found += [(node.lineno, a.name) for a in node.names]
        for line, name in found:
            private = name.startswith("_") and not name.startswith("__") and not MANGLED.match(name)
            if private and name not in PUBLIC_UNDERSCORE and (_relative(path), name) not in ISOLATED_PRIVATE_READS:
                problems.append(f"{_relative(path)}:{line}: {name}")
    assert not problems, "private names of other modules or packages:\n" + "\n".join(problems)


#: The one function that imports OpenSeesPy: a user's tool and a test oracle, never a dependency of cosim
#: (docs/modal-decks.md); it reads the model the user has built in the running process.
OPENSEES_IMPORTER = ("cosim/bridges/opensees.py", "_ops")


def test_openseespy_is_imported_by_the_opensees_importer_only_and_inside_a_function():
    problems, found = [], 0
    for path in _modules().values():
        for where, node in _nodes_by_function(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            else:
                continue
            if not any(n.split(".")[0] in ("openseespy", "opensees") for n in names):
                continue
            if (_relative(path), where) == OPENSEES_IMPORTER:
                found += 1
            else:
                problems.append(f"{_relative(path)}:{node.lineno} ({where or 'module'}): imports {', '.join(names)}")
    assert not problems, f"OpenSeesPy imported outside {OPENSEES_IMPORTER}:\n" + "\n".join(problems)
    assert found == 1, f"{OPENSEES_IMPORTER} does not import OpenSeesPy: update OPENSEES_IMPORTER"


# --------------------------------------------------------------------------- citations

#: Where the repository's own files live: everything in them may cite only files inside the repository.
CITING = [PACKAGE, PACKAGE.parent / "docs", PACKAGE.parent / "tests", PACKAGE.parent / "benchmarks",
          PACKAGE.parent / "README.md"]

#: A design document and a shared folder next to the checkout: not in the repository, so nobody can follow
#: a citation of them. What they held is in docs/ (docs/theory.md, docs/validation.md).
OUTSIDE = re.compile(r"DESIGN\.md|\.\./shared\b|\bshared/(?:cases|seed|tools|data)/")

#: Files that still cite outside the repository, and why they are not changed yet (none).
NOT_YET: set[str] = set()

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
