"""The layering of tribodem as tests, beside the import-linter contracts of pyproject.toml
(``lint-imports``: the rooms in layers, no room importing a command, no cycle between
siblings):

- no import cycle between any two modules of tribodem (a package's ``__init__`` counts as a
  module; imports inside functions count): nothing is left out;
- no private name (``_name``) imported from another module of tribodem;
- ``python -m tribodem`` is the command, through the same entry as the installed script.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "tribodem"


def strongly_connected(adj: dict[str, set[str]]) -> list[list[str]]:
    """The cycles of a directed graph as its strongly connected components with more than
    one node or a self-loop (Tarjan's algorithm, iterative), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    order = {v: sorted(ws) for v, ws in adj.items()}
    for root in sorted(adj):
        if root in index:
            continue
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        work = [(root, 0)]
        while work:
            v, i = work[-1]
            if i < len(order[v]):
                work[-1] = (v, i + 1)
                w = order[v][i]
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, 0))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                u = work[-1][0]
                low[u] = min(low[u], low[v])
            if low[v] == index[v]:
                comp: list[str] = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1 or v in adj[v]:
                    found.append(sorted(comp))
    return found


def test_strongly_connected_finds_cycles() -> None:
    adj = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"d"}, "e": {"a"}, "f": set()}
    assert sorted(strongly_connected(adj)) == [["a", "b", "c"], ["d"]]
    assert strongly_connected({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_between_modules() -> None:
    graph = grimp.build_graph("tribodem", cache_dir=None)
    adj = {m: set(graph.find_modules_directly_imported_by(m)) for m in graph.modules}
    cycles = strongly_connected(adj)
    lines = []
    for comp in cycles:
        members = set(comp)
        lines.append(", ".join(comp) + ": " + "; ".join(
            f"{m} -> {i}" for m in comp for i in sorted(adj[m] & members)))
    assert not cycles, "import cycles:\n" + "\n".join(lines)


def module_name(path: Path) -> str:
    """The dotted name of a module file of the package."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imported_from(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """The absolute name of the module an ``import from`` names (relative ones resolved)."""
    if not node.level:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[:len(base) - (node.level - 1)]
    return ".".join([*base, *([node.module] if node.module else [])])


def private(name: str) -> bool:
    """``_name`` but not a dunder (``__version__``)."""
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_no_private_name_imported_across_modules() -> None:
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = module_name(path)
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom):
                continue
            source = imported_from(node, module, path.name == "__init__.py")
            if source.split(".")[0] != "tribodem" or source == module:
                continue
            found += [f"{path.relative_to(ROOT)}:{node.lineno}: from {source} import "
                      f"{alias.name}" for alias in node.names if private(alias.name)]
    assert not found, "private names imported from another module:\n" + "\n".join(found)


def test_python_m_tribodem_is_the_command() -> None:
    r = subprocess.run([sys.executable, "-m", "tribodem", "--version"], capture_output=True,
                       text=True, timeout=120, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("tribodem ")
    r = subprocess.run([sys.executable, "-m", "tribodem", "dem", "run"], capture_output=True,
                       text=True, timeout=120, cwd=ROOT)
    assert r.returncode == 2 and "--out" in r.stderr and "Traceback" not in r.stderr
