"""The package's layers (docs/development.md, "Layers"): no import circle between modules or between
packages, and no import from a lower layer into a higher one. Every import counts, those inside
functions too: a circle broken only by a late import is still a circle."""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

import pytest

from conftest import TOP

PACKAGE = TOP / "src" / "rail_monitor" / "rail_monitor"

# Lowest first. A package may import its own layer's packages and lower layers', never a higher one's.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("models",),                                                  # pure physics
    ("core",),                                                    # what every layer shares
    ("corrugation", "noise", "squeal", "measured", "alerts", "advice", "economics"),  # the per-model packages
    ("engine",),                                                  # a site's state, live and batch alike
    ("codec", "messages", "bagio", "site_file", "batch", "report", "simulation", "station", "whatif"),  # I/O, apps
    ("nodes", "cli"),                                             # ROS 2 glue and the command line
)
ROOT = "<root>"  # rail_monitor/__init__.py: the version, importable from every layer


def _modules(package: Path) -> dict[str, Path]:
    out = {}
    for path in package.rglob("*.py"):
        parts = path.relative_to(package.parent).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _imports(name: str, path: Path, known: Iterable[str]) -> set[str]:
    """The package's modules that module ``name`` imports anywhere in its text."""
    known = set(known)
    is_package = path.name == "__init__.py"
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = name.split(".")[: len(name.split(".")) - node.level + is_package]
                base = ".".join([*up, *([node.module] if node.module else [])])
            found.add(base)
            found.update(f"{base}.{a.name}" for a in node.names)
    return {m for m in found if m in known and m != name}


def import_graph(package: Path) -> dict[str, set[str]]:
    mods = _modules(package)
    return {name: _imports(name, path, mods) for name, path in mods.items()}


def _package_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ROOT


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The graph's strongly connected components of more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            v, edges = work[-1]
            w = next(edges, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
    return found


def package_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for module, deps in graph.items():
        out.setdefault(_package_of(module), set()).update(
            _package_of(d) for d in deps if _package_of(d) != _package_of(module))
    return out


def upward_imports(graph: dict[str, set[str]], layers=LAYERS) -> list[str]:
    rank = {pkg: i for i, layer in enumerate(layers) for pkg in layer}
    rank[ROOT] = -1
    return [f"{m} -> {d}" for m, deps in sorted(graph.items()) for d in sorted(deps)
            if rank[_package_of(d)] > rank[_package_of(m)]]


@pytest.fixture(scope="module")
def graph():
    return import_graph(PACKAGE)


def test_every_package_has_a_layer(graph):
    placed = {pkg for layer in LAYERS for pkg in layer} | {ROOT}
    assert {_package_of(m) for m in graph} <= placed, sorted({_package_of(m) for m in graph} - placed)
    assert len(graph) > 100  # the walk found the package


def test_no_module_imports_itself_round_a_circle(graph):
    assert circles(graph) == []


def test_no_package_imports_itself_round_a_circle(graph):
    assert circles(package_graph(graph)) == []


def test_no_import_runs_up_a_layer(graph):
    assert upward_imports(graph) == []


def test_the_checks_catch_a_circle_and_an_upward_import(tmp_path):
    """The same checks on a small package that has both faults (so they can fail)."""
    pkg = tmp_path / "rail_monitor"
    for rel, text in {
        "__init__.py": "",
        "models/__init__.py": "",
        "models/a.py": "def f():\n    from rail_monitor.models import b\n",  # the circle's late half
        "models/b.py": "from rail_monitor.models.a import f\n",
        "models/c.py": "from rail_monitor.core.x import y\n",                # models -> core: upward
        "core/__init__.py": "",
        "core/x.py": "from . import y\ny = 1\n",
        "core/y.py": "",
    }.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(text)
    g = import_graph(pkg)
    assert circles(g) == [["rail_monitor.models.a", "rail_monitor.models.b"]]
    assert upward_imports(g) == ["rail_monitor.models.c -> rail_monitor.core.x"]
    assert g["rail_monitor.core.x"] == {"rail_monitor.core", "rail_monitor.core.y"}  # resolved relative to core
    assert circles(package_graph(g)) == []
