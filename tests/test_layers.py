"""The import graph: layers import one way only, and no module cycle.

Layers, bottom to top (ARCHITECTURE.md): the base modules (``errors``,
``atomic``, ``progress``) ← body ← notation ← io ← calibrate ← keypoints ← fitting ← quantise ← effort
← compare, then ``synthetic`` and ``pipelines`` beside each other above the
library (pipelines may use synthetic for its demo and study; nothing in the
library imports either).  Every import counts, including those inside
functions: a deferred import hides a cycle from Python, not from a reader.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("capture2notation", "synthetic", "pipelines")
LAYERS = (
    "base",
    "body",
    "notation",
    "io",
    "calibrate",
    "keypoints",
    "fitting",
    "quantise",
    "effort",
    "compare",
    "synthetic",
    "pipelines",
)


def _modules() -> dict[str, Path]:
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """First-party modules `name` imports (resolved to the longest known module)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            mod = ".".join(base + ([node.module] if node.module else []))
            targets = [f"{mod}.{a.name}" for a in node.names] + [mod]
        else:
            continue
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name:
                found.add(t)
    return found


def _layer(module: str) -> str:
    parts = module.split(".")
    if parts[0] != "capture2notation":
        return parts[0]
    if len(parts) == 1 or parts[1] in ("errors", "atomic", "progress"):
        return "base"
    return parts[1]


def _graph() -> dict[str, set[str]]:
    mods = _modules()
    known = set(mods)
    return {m: _imports(m, p, known) for m, p in mods.items()}


GRAPH = _graph()


def test_every_module_has_a_layer():
    assert {_layer(m) for m in GRAPH} <= set(LAYERS)


@pytest.mark.parametrize("module", sorted(GRAPH))
def test_imports_point_down(module):
    here = LAYERS.index(_layer(module))
    up = []
    for target in sorted(GRAPH[module]):
        there = _layer(target)
        # synthetic and pipelines sit beside each other: only pipelines may use synthetic.
        if LAYERS.index(there) > here or (_layer(module) == "synthetic" and there == "pipelines"):
            up.append(f"{module} -> {target}")
    assert not up, "imports that run upwards: " + "; ".join(up)


def _strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components with more than one module."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycle():
    # A package's __init__ re-exports its modules, so an edge from a module
    # to its own enclosing package is how Python resolves `from . import x`,
    # not a dependency of design; every other edge counts.
    graph = {m: {t for t in ts if not m.startswith(t + ".")} for m, ts in GRAPH.items()}
    cycles = _strongly_connected(graph)
    assert not cycles, "import cycles: " + "; ".join(" <-> ".join(c) for c in cycles)


def test_the_cycle_check_sees_a_cycle():
    assert _strongly_connected({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == [["a", "b", "c"]]
