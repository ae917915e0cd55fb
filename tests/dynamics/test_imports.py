"""The dynamics package has no import cycle, function-level imports counted (issue 23).

import-linter sees only module-level imports; an import inside a function (``def
__reduce__(self): from robodyn.dynamics.pickling import restore``) closes a cycle all the
same. This reads every module of robodyn/dynamics with ``ast`` and counts every import
anywhere in it, except those under ``if TYPE_CHECKING:`` (never run).
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.conftest import ROOT

PACKAGE = "robodyn.dynamics"


def _run_time_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement of a module, at any depth, except under ``if TYPE_CHECKING:``."""
    found: list[ast.Import | ast.ImportFrom] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import | ast.ImportFrom):
            found.append(node)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def import_graph(folder: Path, package: str) -> dict[str, set[str]]:
    """Module of ``package`` -> the modules of ``package`` it imports (at any depth)."""
    modules = {package if path.stem == "__init__" else f"{package}.{path.stem}": path for path in folder.glob("*.py")}
    graph: dict[str, set[str]] = {}
    for module, path in modules.items():
        targets: set[str] = set()
        for node in _run_time_imports(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif node.level:  # relative: from . import x, from .x import y
                base = package if node.level == 1 else package.rsplit(".", node.level - 1)[0]
                base = f"{base}.{node.module}" if node.module else base
                names = [base] + [f"{base}.{alias.name}" for alias in node.names]
            else:
                names = [node.module or ""] + [f"{node.module}.{alias.name}" for alias in node.names]
            targets |= {name for name in names if name in modules and name != module}
        graph[module] = targets
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the graph (its modules in order, the first repeated at the end), or None."""
    state: dict[str, str] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = "open"
        path.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == "open":
                return [*path[path.index(target) :], target]
            if target not in state and (cycle := visit(target)):
                return cycle
        state[node] = "done"
        path.pop()
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_the_cycle_finder_finds_a_cycle_closed_by_a_function_level_import(tmp_path):
    (tmp_path / "a.py").write_text("import pkg.b\n")
    (tmp_path / "b.py").write_text("def f():\n    from pkg.c import g\n")
    (tmp_path / "c.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import pkg.b\nfrom pkg import a\n")
    assert find_cycle(import_graph(tmp_path, "pkg")) == ["pkg.a", "pkg.b", "pkg.c", "pkg.a"]
    (tmp_path / "c.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg import a\n")
    assert find_cycle(import_graph(tmp_path, "pkg")) is None


def test_the_dynamics_package_has_no_import_cycle_function_level_imports_counted():
    graph = import_graph(ROOT / "robodyn" / "dynamics", PACKAGE)
    assert {"robodyn.dynamics.robot", "robodyn.dynamics.loading", "robodyn.dynamics.pickling"} <= set(graph)
    assert "robodyn.dynamics.pickling" in graph["robodyn.dynamics.loading"]  # the graph sees imports
    assert find_cycle(graph) is None


def test_no_import_linter_exception_is_left():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert "ignore_imports" not in text
