"""The package layout: only cross-cutting modules at lanevil_core's top level, and no import circle between its
packages.

A package here is a subpackage of ``lanevil_core`` (``world``, ``camera``, ``illusions``, ...) or one of its
top-level modules (``case``, ...). The graph has an edge A -> B when a module of A imports one of B at module level;
imports inside functions, and imports under ``if TYPE_CHECKING:`` (names used in annotations only, as
``world`` names ``Case`` and ``camera``'s ``EgoPath``), are left out.
"""

from __future__ import annotations

import ast
from pathlib import Path

import lanevil_core

PACKAGE = Path(lanevil_core.__file__).parent
# The façade and the modules every layer reads: the case model, its named presets, array/choice types, atomic files.
TOP_LEVEL = {"__init__", "case", "files", "presets", "typed"}


def _module_level_imports(statements: list[ast.stmt]) -> list[ast.Import | ast.ImportFrom]:
    """Imports of a module body, through ``if`` and ``try`` blocks, except ``if TYPE_CHECKING:`` bodies."""
    found: list[ast.Import | ast.ImportFrom] = []
    for statement in statements:
        if isinstance(statement, ast.Import | ast.ImportFrom):
            found.append(statement)
        elif isinstance(statement, ast.If):
            if "TYPE_CHECKING" not in ast.unparse(statement.test):
                found += _module_level_imports(statement.body)
            found += _module_level_imports(statement.orelse)
        elif isinstance(statement, ast.Try):
            for block in (statement.body, *(handler.body for handler in statement.handlers), statement.orelse,
                          statement.finalbody):
                found += _module_level_imports(block)
    return found


def _imported_parts(node: ast.Import | ast.ImportFrom, package: tuple[str, ...]) -> list[tuple[str, ...]]:
    """What an import names, as parts relative to ``lanevil_core`` (``("world", "paint")``); others left out."""
    if isinstance(node, ast.Import):
        return [tuple(alias.name.split(".")[1:]) for alias in node.names if alias.name.startswith("lanevil_core.")]
    if node.level == 0:
        module = node.module or ""
        return [tuple(module.split(".")[1:])] if module.startswith("lanevil_core.") else []
    base = package[: len(package) - (node.level - 1)] + tuple(node.module.split(".") if node.module else ())
    return [base] if base else [(alias.name,) for alias in node.names]


def package_graph() -> dict[str, dict[str, list[str]]]:
    """package -> imported package -> the ``file:line`` of each import."""
    graph: dict[str, dict[str, list[str]]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts == ("__init__",):
            continue  # the façade imports every package by design
        source = parts[0]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in _module_level_imports(tree.body):
            for target in _imported_parts(node, parts[:-1]):
                if target and target[0] != source:
                    where = f"{path.relative_to(PACKAGE).as_posix()}:{node.lineno}"
                    graph.setdefault(source, {}).setdefault(target[0], []).append(where)
    return graph


def find_cycle(graph: dict[str, dict[str, list[str]]]) -> list[str] | None:
    """One cycle of the graph as a list of packages (first = last), or None."""
    state: dict[str, int] = {}  # 1 = on the current path, 2 = done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(graph.get(node, {})):
            if state.get(target) == 1:
                return path[path.index(target):] + [target]
            if target not in state and (cycle := visit(target)) is not None:
                return cycle
        state[node] = 2
        path.pop()
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)) is not None:
            return cycle
    return None


def test_only_cross_cutting_modules_sit_at_the_top_level() -> None:
    modules = {path.stem for path in PACKAGE.glob("*.py")}
    assert modules <= TOP_LEVEL, f"move {sorted(modules - TOP_LEVEL)} into a package"


def test_packages_import_each_other_without_a_circle() -> None:
    graph = package_graph()
    cycle = find_cycle(graph)
    if cycle is not None:
        steps = [f"{a} -> {b} ({', '.join(graph[a][b][:3])})" for a, b in zip(cycle, cycle[1:])]
        raise AssertionError("import circle between packages:\n  " + "\n  ".join(steps))


def test_the_cycle_finder_finds_a_circle() -> None:
    graph = {"a": {"b": ["a.py:1"]}, "b": {"c": ["b.py:1"]}, "c": {"a": ["c.py:1"]}, "d": {"a": ["d.py:1"]}}
    assert find_cycle(graph) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b": ["a.py:1"]}, "b": {}}) is None


def test_illusions_do_not_know_the_case_model() -> None:
    """The case model holds the illusion specs; the illusions compile from a ``CompileContext`` (not even an
    annotation names ``Case``)."""
    for path in sorted((PACKAGE / "illusions").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                parts = _imported_parts(node, ("illusions",))
                assert ("case",) not in parts, f"{path.name}:{node.lineno} imports the case model"
