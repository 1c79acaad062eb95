"""No import cycle among granrs's modules (issue 18).

The Python layer was split into packages (``granrs.report``, ``granrs.calibrate``) partly to
remove the ``report <-> report_calibration`` cycle: the report imported its calibration
chapter at its end, which imported the report back. This test parses every module under
``python/granrs`` (without importing it) and fails on a cycle of module-level imports of
granrs modules. Imports inside functions are lazy and not counted, nor are those under
``if TYPE_CHECKING:``.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent / "python"


def _modules() -> dict[str, Path]:
    """Every granrs module by dotted name (a package by its own name); an extension module
    (``granrs._granrs``) by its stub, which imports nothing of granrs."""
    out = {}
    for path in sorted((ROOT / "granrs").rglob("*.py")) + sorted((ROOT / "granrs").rglob("*.pyi")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _top_level_imports(tree: ast.Module) -> list[ast.Import | ast.ImportFrom]:
    """The import statements run when the module is imported (not in functions or classes,
    not under ``if TYPE_CHECKING:``)."""
    found: list[ast.Import | ast.ImportFrom] = []

    def visit(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                found.append(node)
            elif isinstance(node, ast.If):
                test = ast.unparse(node.test)
                if test not in ("TYPE_CHECKING", "typing.TYPE_CHECKING"):
                    visit(node.body)
                visit(node.orelse)
            elif isinstance(node, ast.Try):
                visit(node.body)
                for handler in node.handlers:
                    visit(handler.body)
                visit(node.orelse)
                visit(node.finalbody)

    visit(tree.body)
    return found


def import_graph() -> dict[str, set[str]]:
    """Module -> the granrs modules it imports at module level.

    ``from .pkg import name`` is an edge to ``pkg.name`` when that is a module, else to
    ``pkg`` (whose ``__init__`` must then have run).
    """
    modules = _modules()
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        if path.suffix == ".pyi":
            continue
        is_package = path.name == "__init__.py"
        package = name if is_package else name.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in _top_level_imports(tree):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            else:
                if node.level:
                    base_parts = package.split(".")
                    base_parts = base_parts[: len(base_parts) - (node.level - 1)]
                    base = ".".join(base_parts + ([node.module] if node.module else []))
                else:
                    base = node.module or ""
                targets = [
                    f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                    for alias in node.names
                ]
            graph[name] |= {t for t in targets if t in modules and t != name}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a list of modules (first == last), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def dfs(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return [*path[path.index(nxt) :], nxt]
            if nxt not in state:
                found = dfs(nxt)
                if found:
                    return found
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = dfs(node)
            if found:
                return found
    return None


def test_graph_sees_the_packages() -> None:
    """The check reads the split packages and resolves relative imports to them."""
    graph = import_graph()
    assert "granrs.report.framework" in graph["granrs.report.ch3_free_link"]
    assert "granrs.report.format" in graph["granrs.report.ch4_chain"]
    assert "granrs.calibrate" in graph["granrs.report.calibration"]
    assert "granrs.calibrate.fit" in graph["granrs.calibrate"]


def test_find_cycle_finds_one() -> None:
    """The cycle search itself: a two-module cycle is found, a chain is not."""
    assert find_cycle({"a": {"b"}, "b": {"a"}}) == ["a", "b", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycle() -> None:
    """No cycle of module-level imports among granrs's modules."""
    cycle = find_cycle(import_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_report_framework_imports_no_chapter() -> None:
    """The report's framework and format modules never import a chapter (the package does)."""
    graph = import_graph()
    chapters = {
        "granrs.report.ch3_free_link",
        "granrs.report.ch4_chain",
        "granrs.report.ch5_leg",
        "granrs.report.calibration",
    }
    for name in ("granrs.report.framework", "granrs.report.format"):
        assert not graph[name] & chapters, name
