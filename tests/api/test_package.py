"""The package's shape: imports only point down (no circles), and a function-level import never
hides one. Read from the source (``ast``), so it checks every module whether a test imports it
or not."""

from __future__ import annotations

import ast
import collections
from pathlib import Path

import jaxgear

ROOT = Path(jaxgear.__file__).resolve().parent


def _modules() -> dict[str, Path]:
    mods = {}
    for path in ROOT.rglob("*.py"):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        mods[name] = path
    return mods


def _target(mods, module: str, node: ast.ImportFrom) -> str | None:
    if node.level == 0:
        return node.module
    package = module.split(".") if mods[module].name == "__init__.py" else module.split(".")[:-1]
    base = package[: len(package) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _import_graph():
    """Edges module → module for every import of a jaxgear module, at module level or inside a
    function (lazy), with the parent packages whose ``__init__`` an import runs first; and the
    function-level imports found."""
    mods = _modules()
    edges = collections.defaultdict(set)
    lazy = []
    for module, path in mods.items():
        tree = ast.parse(path.read_text())
        inside = set()
        for fn in ast.walk(tree):
            if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
                inside.update(id(n) for n in ast.walk(fn) if n is not fn)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _target(mods, module, node)
                if not target or not target.startswith("jaxgear"):
                    continue
                names = [f"{target}.{a.name}" for a in node.names]
                targets = [n if n in mods else target for n in names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names if a.name.startswith("jaxgear")]
            else:
                continue
            for t in targets:
                if t not in mods:
                    continue
                edges[module].add(t)
                if id(node) in inside:
                    lazy.append((module, t))
                parts = t.split(".")
                for k in range(2, len(parts)):
                    parent = ".".join(parts[:k])
                    if parent in mods and not (module == parent or module.startswith(parent + ".")):
                        edges[module].add(parent)
    return mods, edges, lazy


def _cycles(mods, edges):
    colour, found = {}, []

    def visit(u, stack):
        colour[u] = 1
        stack.append(u)
        for v in sorted(edges[u]):
            if colour.get(v) == 1:
                found.append(stack[stack.index(v) :] + [v])
            elif v not in colour:
                visit(v, stack)
        stack.pop()
        colour[u] = 2

    for m in sorted(mods):
        if m not in colour:
            visit(m, [])
    return found


def test_the_import_graph_has_no_circles():
    mods, edges, lazy = _import_graph()
    # the check can fail: it sees the package's layers and its lazy imports
    assert len(mods) > 40 and any(m.startswith("jaxgear.dynamics") for m in edges)
    assert lazy, "the command-line modules import their commands lazily (start-up time)"
    cycles = _cycles(mods, edges)
    assert not cycles, "\n".join(" -> ".join(c) for c in cycles)


def test_the_cycle_finder_finds_a_planted_circle():
    # what the test above would report: a module importing one that imports it back
    mods = {"jaxgear.a": None, "jaxgear.b": None, "jaxgear.c": None}
    edges = collections.defaultdict(set, {"jaxgear.a": {"jaxgear.b"}, "jaxgear.b": {"jaxgear.a"}})
    assert _cycles(mods, edges) == [["jaxgear.a", "jaxgear.b", "jaxgear.a"]]
