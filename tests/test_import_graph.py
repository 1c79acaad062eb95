"""No import cycle among granrs's modules, Python or Rust (issue 18; issue 33: function-level
imports count).

The Python layer was split into packages (``granrs.report``, ``granrs.calibrate``) partly to
remove the ``report <-> report_calibration`` cycle: the report imported its calibration
chapter at its end, which imported the report back. Two more cycles hid behind imports
inside functions (``scene <-> scenefile``: ``Scene.from_toml`` imported the file reader,
which imports ``Scene``; ``result -> animate -> _animation -> animate``), which a check of
module-level imports alone did not see. This test parses every module under
``python/granrs`` (without importing it) and fails on a cycle of imports of granrs modules
at any level: module level, in a function or a method. Only imports under
``if TYPE_CHECKING:`` (which never run) are not counted.

The Rust part reads ``use crate::...``, ``use super::...``, ``use self::...`` and inline
``crate::a::b`` paths of ``rust/**/*.rs`` into a file-level graph (comments, strings and
``#[cfg(test)]`` items left out, ``tests.rs`` files too) and looks for cycles the same way.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
ROOT = REPO / "python"
RUST = REPO / "rust"


# --- Python ----------------------------------------------------------------------------------


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


def _is_type_checking(node: ast.If) -> bool:
    return ast.unparse(node.test) in ("TYPE_CHECKING", "typing.TYPE_CHECKING")


def _imports(tree: ast.Module, *, lazy: bool = True) -> list[ast.Import | ast.ImportFrom]:
    """The import statements that can run: at module level, and (``lazy``) inside functions,
    methods and classes; never those under ``if TYPE_CHECKING:``."""
    found: list[ast.Import | ast.ImportFrom] = []

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                found.append(child)
            elif isinstance(child, ast.If) and _is_type_checking(child):
                for other in child.orelse:
                    visit_statement(other)
            elif not lazy and isinstance(
                child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)
            ):
                continue
            else:
                visit(child)

    def visit_statement(node: ast.stmt) -> None:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        else:
            visit(node)

    visit(tree)
    return found


def _edges(name: str, path: Path, modules: dict[str, Path], *, lazy: bool = True) -> set[str]:
    """The granrs modules that module ``name`` imports. ``from .pkg import name`` is an edge
    to ``pkg.name`` when that is a module, else to ``pkg`` (whose ``__init__`` must then
    have run)."""
    is_package = path.name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    out: set[str] = set()
    for node in _imports(tree, lazy=lazy):
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
        out |= {t for t in targets if t in modules and t != name}
    return out


def import_graph(*, lazy: bool = True) -> dict[str, set[str]]:
    """Module -> the granrs modules it imports anywhere (``lazy=False``: at module level
    only, what the check read before function-level imports counted)."""
    modules = _modules()
    return {
        name: set() if path.suffix == ".pyi" else _edges(name, path, modules, lazy=lazy)
        for name, path in modules.items()
    }


# --- cycles ----------------------------------------------------------------------------------


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a list of nodes (first == last), or None."""
    cycles = find_cycles(graph)
    return cycles[0] if cycles else None


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One shortest cycle per strongly connected component of ``graph`` that has a cycle
    (first node == last), sorted; an empty list when the graph is acyclic."""
    out = []
    for component in _components(graph):
        inside = {n: graph[n] & component for n in component}
        best: list[str] | None = None
        for start in sorted(component):
            path = _shortest_path_back(inside, start)
            if path is not None and (best is None or len(path) < len(best)):
                best = path
        assert best is not None
        out.append(best)
    return sorted(out)


def _components(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components that hold a cycle (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[set[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work: list[tuple[str, list[str]]] = [(root, sorted(graph.get(root, ())))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, todo = work[-1]
            if todo:
                nxt = todo.pop(0)
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, sorted(graph.get(nxt, ()))))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1 or node in graph.get(node, ()):
                    found.append(component)
    return found


def _shortest_path_back(graph: dict[str, set[str]], start: str) -> list[str] | None:
    """The shortest cycle through ``start`` (breadth first), or None."""
    parent: dict[str, str] = {}
    frontier = [start]
    seen = {start}
    while frontier:
        nxt_frontier = []
        for node in frontier:
            for nxt in sorted(graph[node]):
                if nxt == start:
                    path = [node]
                    while path[-1] != start:
                        path.append(parent[path[-1]])
                    return [*reversed(path), start]
                if nxt not in seen:
                    seen.add(nxt)
                    parent[nxt] = node
                    nxt_frontier.append(nxt)
        frontier = nxt_frontier
    return None


# --- Rust ------------------------------------------------------------------------------------

_TOKEN = re.compile(
    r"""//[^\n]*                      # a line comment (doc comments too)
      | /\*(?:[^*]|\*(?!/))*\*/        # a block comment (not nested)
      | b?r(\#*)".*?"\1               # a raw string
      | b?"(?:\\.|[^"\\])*"            # a string
      | b?'(?:\\.|[^'\\\n])'           # a character (not a lifetime)
    """,
    re.VERBOSE | re.DOTALL,
)
_CFG_TEST = re.compile(r"#\[cfg\(test\)\]")
_USE = re.compile(r"\buse\s+([^;]*);")
_PATH = re.compile(r"\b((?:crate|super|self)(?:\s*::\s*\w+)+)")


def _strip(source: str) -> str:
    """Rust source without comments, strings and ``#[cfg(test)]`` items."""
    text = _TOKEN.sub(lambda m: '""' if m.group(0).lstrip("br").startswith(('"', "#")) else " ",
                      source)  # fmt: skip
    while (m := _CFG_TEST.search(text)) is not None:
        i = m.end()
        # Skip further attributes, then the item: up to its ';' or its balanced braces.
        while True:
            rest = text[i:].lstrip()
            if rest.startswith("#["):
                i = text.index("]", i) + 1
                continue
            break
        semi, brace = text.find(";", i), text.find("{", i)
        if brace == -1 or (semi != -1 and semi < brace):
            end = semi + 1
        else:
            depth, end = 0, brace
            while True:
                c = text[end]
                depth += c == "{"
                depth -= c == "}"
                end += 1
                if depth == 0:
                    break
        text = text[: m.start()] + text[end:]
    return text


def _expand(tree: str) -> list[str]:
    """The paths of a ``use`` tree: ``a::{b, c::{d, e}}`` -> ``a::b``, ``a::c::d``, ``a::c::e``
    (``as`` renames and ``*`` dropped)."""
    tree = re.sub(r"\s+", "", tree)
    brace = tree.find("{")
    if brace == -1:
        return [re.sub(r"as\w+$", "", tree).removesuffix("::*")] if tree else []
    prefix, inner = tree[:brace], tree[brace + 1 : tree.rindex("}")]
    parts, depth, start = [], 0, 0
    for i, c in enumerate(inner):
        depth += c == "{"
        depth -= c == "}"
        if c == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    out = []
    for part in parts:
        if part == "self":
            out.append(prefix.removesuffix("::"))
        else:
            out.extend(prefix + p for p in _expand(part))
    return out


def _module_of(path: Path, root: Path) -> tuple[str, ...]:
    """The module path of a file: ``forces/rft.rs`` -> (forces, rft); ``forces/mod.rs`` and
    ``lib.rs`` -> their directory's."""
    parts = path.relative_to(root).with_suffix("").parts
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return tuple(parts)


def _file_of(module: tuple[str, ...], files: dict[tuple[str, ...], Path]) -> Path | None:
    """The file of the deepest module along ``module`` (``crate::forces::rft::Rft`` is
    ``forces/rft.rs``, ``crate::forces::Real`` ``forces/mod.rs``)."""
    for k in range(len(module), -1, -1):
        if module[:k] in files:
            return files[module[:k]]
    return None


def rust_graph(root: Path = RUST) -> dict[str, set[str]]:
    """File (relative to ``root``) -> the files of the crate it uses: ``use crate::...``,
    ``use super::...``, ``use self::...`` and inline ``crate::a::b`` / ``super::a`` paths.
    A module ``foo`` is ``foo.rs`` or ``foo/mod.rs``; the crate root is ``lib.rs``.
    ``#[cfg(test)]`` items and ``tests.rs`` files are left out."""
    files = {_module_of(p, root): p for p in sorted(root.rglob("*.rs")) if p.name != "tests.rs"}
    graph: dict[str, set[str]] = {str(p.relative_to(root)): set() for p in files.values()}
    for here, path in files.items():
        text = _strip(path.read_text(encoding="utf-8"))
        paths = [p for use in _USE.findall(text) for p in _expand(use)]
        paths += [re.sub(r"\s+", "", m) for m in _PATH.findall(text)]
        for p in paths:
            segments = [s for s in p.split("::") if s]
            if not segments:
                continue
            if segments[0] == "crate":
                module: tuple[str, ...] = ()
            elif segments[0] in ("super", "self"):
                module = here
            else:
                continue  # another crate (std, nalgebra, pyo3) or a child module's re-export
            rest = segments[1:] if segments[0] != "super" else segments
            while rest and rest[0] == "super":
                module = module[:-1]
                rest = rest[1:]
            if segments[0] == "self":
                rest = segments[1:]
            target = _file_of(module + tuple(rest), files)
            if target is not None and target != path:
                graph[str(path.relative_to(root))].add(str(target.relative_to(root)))
    return graph


def module_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """A file graph collapsed to the crate's top modules (``forces/rft.rs`` is ``forces``,
    ``simd.rs`` is ``simd``, ``lib.rs`` is ``lib``), without the edges inside a module."""
    top = lambda path: path.split("/")[0].removesuffix(".rs")  # noqa: E731
    out: dict[str, set[str]] = {}
    for a, targets in graph.items():
        out.setdefault(top(a), set()).update(top(b) for b in targets if top(b) != top(a))
    return out


def mutual_pairs(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """The pairs of nodes that use each other directly, sorted."""
    return sorted((a, b) for a in graph for b in graph[a] if a < b and a in graph.get(b, ()))


# --- the tests -------------------------------------------------------------------------------


def test_graph_sees_the_packages() -> None:
    """The check reads the split packages and resolves relative imports to them."""
    graph = import_graph()
    assert "granrs.report.framework" in graph["granrs.report.ch3_free_link"]
    assert "granrs.report.format" in graph["granrs.report.ch4_chain"]
    assert "granrs.calibrate" in graph["granrs.report.calibration"]
    assert "granrs.calibrate.fit" in graph["granrs.calibrate"]


def test_graph_counts_imports_inside_functions(tmp_path: Path) -> None:
    """An import in a function or a method is an edge (it runs when called); one under
    ``if TYPE_CHECKING:`` is not. The module-level reading of the old check saw neither
    cycle below."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from .c import C\n"
        "class A:\n    def load(self):\n        from . import b\n        return b\n"
    )
    (package / "b.py").write_text("from .a import A\n")
    (package / "c.py").write_text("from .a import A\n")
    modules = {"pkg": package / "__init__.py"} | {f"pkg.{n}": package / f"{n}.py" for n in "abc"}
    graph = {name: _edges(name, path, modules) for name, path in modules.items()}
    assert graph["pkg.a"] == {"pkg.b"}
    assert find_cycles(graph) == [["pkg.a", "pkg.b", "pkg.a"]]
    eager = {name: _edges(name, path, modules, lazy=False) for name, path in modules.items()}
    assert find_cycles(eager) == []


def test_find_cycle_finds_one() -> None:
    """The cycle search itself: a two-module cycle is found, a chain is not; each strongly
    connected part gives its shortest cycle."""
    assert find_cycle({"a": {"b"}, "b": {"a"}}) == ["a", "b", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None
    graph = {
        "a": {"b"},
        "b": {"c", "a"},
        "c": {"a"},
        "d": {"e"},
        "e": {"f"},
        "f": {"d"},
        "g": {"a"},
    }
    assert find_cycles(graph) == [["a", "b", "a"], ["d", "e", "f", "d"]]


def test_no_import_cycle() -> None:
    """No cycle of imports (module or function level) among granrs's modules."""
    graph = import_graph()
    cycles = find_cycles(graph)
    tangles = "; ".join(", ".join(sorted(c)) for c in _components(graph))
    assert not cycles, (
        "import cycles: " + "; ".join(" -> ".join(c) for c in cycles) + f" (in: {tangles})"
    )


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


def test_rust_graph_reads_a_small_tree(tmp_path: Path) -> None:
    """The Rust reader on a synthetic crate: ``use crate::``, grouped and nested ``use``
    trees, ``super::``, inline ``crate::`` paths, a module as ``foo.rs`` or ``foo/mod.rs``;
    comments, strings, ``#[cfg(test)]`` items and ``tests.rs`` ignored; the cycles found."""
    (tmp_path / "forces").mkdir()
    (tmp_path / "lib.rs").write_text("pub mod forces;\npub mod simd;\npub mod error;\n")
    (tmp_path / "forces" / "mod.rs").write_text(
        "pub mod rft;\npub trait Real {}\n/// see [`crate::simd::F64x4`]\n"
    )
    (tmp_path / "forces" / "rft.rs").write_text(
        'use super::Real;\nconst S: &str = "crate::error::nothing";\n'
        "fn f() -> bool { crate::simd::avx2() }\n"
        "#[cfg(test)]\nmod tests {\n    use crate::error::Error;\n}\n"
    )
    (tmp_path / "forces" / "tests.rs").write_text("use crate::error::Error;\n")
    (tmp_path / "simd.rs").write_text(
        "use crate::{error::{Error, Result as R}, forces::rft::Rft};\n"
        "// use crate::forces::Real;\n/* crate::lib */\n"
    )
    (tmp_path / "error.rs").write_text(
        "pub struct Error;\nfn f() { let _c = '\"'; crate::forces::rft::g() }\n"
        # A string continued on the next line, then a path after it.
        'const M: &str = "over \\\n crate::simd::nothing"; fn g() { crate::simd::avx2() }\n'
    )
    graph = rust_graph(tmp_path)
    assert graph == {
        "lib.rs": set(),
        "error.rs": {"forces/rft.rs", "simd.rs"},
        "simd.rs": {"error.rs", "forces/rft.rs"},
        "forces/mod.rs": set(),
        "forces/rft.rs": {"forces/mod.rs", "simd.rs"},
    }
    assert _components(graph) == [{"error.rs", "simd.rs", "forces/rft.rs"}]
    assert find_cycles(graph) == [["error.rs", "simd.rs", "error.rs"]]
    # Between the crate's top modules: forces (mod.rs and rft.rs) and simd, error.
    assert module_graph(graph) == {
        "lib": set(),
        "error": {"forces", "simd"},
        "simd": {"error", "forces"},
        "forces": {"simd"},
    }
    assert mutual_pairs(module_graph(graph)) == [("error", "simd"), ("forces", "simd")]


def test_rust_graph_sees_the_crate() -> None:
    """The reader resolves the crate's real paths (a check that it reads anything at all)."""
    graph = rust_graph()
    assert "error.rs" in graph["spec/mod.rs"]  # use crate::error::{...}
    assert "num.rs" in graph["forces/mod.rs"]  # pub use crate::num::Real
    assert "num.rs" in graph["forces/rft/lone_rod.rs"]  # crate::num::avx2(), a nested module
    assert "fields.rs" in graph["error.rs"]  # crate::fields::info
    assert "forces/rft.rs" not in graph["forces/rft.rs"]


def _report(title: str, graph: dict[str, set[str]]) -> list[list[str]]:
    cycles = find_cycles(graph)
    for component in _components(graph):
        print(f"{title}: strongly connected: {', '.join(sorted(component))}")
    for cycle in cycles:
        print(f"{title}: shortest cycle: {' -> '.join(cycle)}")
    for a, b in mutual_pairs(graph):
        print(f"{title}: {a} <-> {b}")
    return cycles


def test_no_rust_file_cycle() -> None:
    """No cycle of ``use`` among the crate's files."""
    cycles = _report("rust file cycle", rust_graph())
    assert not cycles, "rust file cycles: " + "; ".join(" -> ".join(c) for c in cycles)


def test_no_rust_module_cycle() -> None:
    """No cycle of ``use`` among the crate's top modules (a folder's files are one module):
    a lane-type file using ``forces`` while ``forces/rft.rs`` uses it, or ``error.rs``
    reaching into ``spec/`` while ``spec`` uses ``error``, are loops here though no two files
    import each other (both were, before the ground floor ``num.rs`` and ``fields.rs``)."""
    cycles = _report("rust module cycle", module_graph(rust_graph()))
    assert not cycles, "rust module cycles: " + "; ".join(" -> ".join(c) for c in cycles)
