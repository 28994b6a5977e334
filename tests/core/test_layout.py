"""The package layout: only cross-cutting modules at lanevil_core's top level, and every import in the layer order
of docs/architecture.md.

A package here is a subpackage of ``lanevil_core`` (``world``, ``camera``, ``illusions``, ...) or one of its
top-level modules (``case``, ``images``, ...). Every import counts, at module level or inside a function; imports
under ``if TYPE_CHECKING:`` (names used in annotations only, as ``world``'s compiled scene names ``Case`` and
``camera``'s ``EgoPath``) are left out. A package may import only the packages on the lines above its own in the
architecture's layer list; ``ALLOWED`` names the exceptions and why.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import lanevil_core

PACKAGE = Path(lanevil_core.__file__).parent
ROOT = PACKAGE.parent
ARCHITECTURE = ROOT / "docs" / "architecture.md"
FACADE = "__init__"  # lanevil_core/__init__.py: the public API, which imports every package by design
# The façade and the modules every layer reads: the case model, its named presets, array/choice types, atomic
# files, pixels in and out.
TOP_LEVEL = {FACADE, "case", "files", "images", "presets", "typed"}
# (importing package, imported package) -> why it may point up the layer list.
ALLOWED: dict[tuple[str, str], str] = {
    ("cli", FACADE): "`lanevil --version` prints the façade's __version__ (the package metadata, read once)",
}
# Packages whose modules never read the case back from a compiled scene (what they need is compiled in).
CASE_FREE = ("render", "labels", "export")


def layer_ranks(text: str) -> dict[str, int]:
    """package -> its line in the architecture's layer list (0 = the bottom line, which imports nothing)."""
    block = text.split("Packages import one way", 1)[1].split("```", 2)[1]
    lines = [line for line in block.splitlines() if line.strip()]
    return {name.strip(): rank for rank, line in enumerate(lines)
            for name in re.split(r"\s{2,}", line.strip())[0].split(",")}


def _imports(statements: list[ast.stmt]) -> list[ast.Import | ast.ImportFrom]:
    """Every import in ``statements`` and the blocks and functions they hold, except ``if TYPE_CHECKING:`` bodies."""
    found: list[ast.Import | ast.ImportFrom] = []
    for statement in statements:
        if isinstance(statement, ast.Import | ast.ImportFrom):
            found.append(statement)
        elif isinstance(statement, ast.If) and "TYPE_CHECKING" in ast.unparse(statement.test):
            found += _imports(statement.orelse)
        else:
            for child in ast.iter_child_nodes(statement):
                if isinstance(child, ast.ExceptHandler | ast.match_case):
                    found += _imports(child.body)
                elif isinstance(child, ast.stmt):
                    found += _imports([child])
    return found


def _imported_parts(node: ast.Import | ast.ImportFrom, package: tuple[str, ...]) -> list[tuple[str, ...]]:
    """What an import names, as parts relative to ``lanevil_core`` (``("world", "paint")``); others left out."""
    if isinstance(node, ast.Import):
        return [tuple(alias.name.split(".")[1:]) for alias in node.names if alias.name.startswith("lanevil_core.")]
    if node.level == 0:
        module = node.module or ""
        if module == "lanevil_core":
            return [(alias.name,) for alias in node.names]
        return [tuple(module.split(".")[1:])] if module.startswith("lanevil_core.") else []
    base = package[: len(package) - (node.level - 1)] + tuple(node.module.split(".") if node.module else ())
    return [base] if base else [(alias.name,) for alias in node.names]


def _package_of(name: str, root: Path) -> str:
    """The package a first import part names: a subpackage or top-level module of ``root``, else (a name the
    façade defines, such as ``__version__``) the façade."""
    return name if (root / name).is_dir() or (root / f"{name}.py").is_file() else FACADE


def import_edges(root: Path = PACKAGE) -> list[tuple[str, str, str]]:
    """(importing package, imported package, ``file:line``) of every import between two packages of ``root``."""
    edges = []
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root).with_suffix("").parts
        if parts == (FACADE,):
            continue
        where = path.relative_to(root).as_posix()
        for node in _imports(ast.parse(path.read_text(encoding="utf-8")).body):
            for target in _imported_parts(node, parts[:-1]):
                if target and target[0] != parts[0]:
                    edges.append((parts[0], _package_of(target[0], root), f"{where}:{node.lineno}"))
    return edges


def layer_breaks(edges: list[tuple[str, str, str]], ranks: dict[str, int]) -> list[str]:
    """One line per import that points to its own layer line or above it and is not in ``ALLOWED``."""
    return [f"{where}: {source} imports {target} (layer {ranks.get(source)} -> {ranks.get(target)})"
            for source, target, where in edges
            if (source, target) not in ALLOWED and not ranks.get(target, 99) < ranks.get(source, -1)]


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


def test_the_layer_list_places_every_package() -> None:
    ranks = layer_ranks(ARCHITECTURE.read_text(encoding="utf-8"))
    packages = {path.name for path in PACKAGE.iterdir() if (path / "__init__.py").is_file()}
    packages |= {path.stem for path in PACKAGE.glob("*.py")} - {FACADE}
    assert packages - set(ranks) == set(), "add the package to the layer list of docs/architecture.md"
    assert ranks["typed"] == 0 and ranks["cli"] == max(ranks.values())


def test_every_import_follows_the_layer_order() -> None:
    breaks = layer_breaks(import_edges(), layer_ranks(ARCHITECTURE.read_text(encoding="utf-8")))
    assert breaks == [], "imports against the layer order of docs/architecture.md:\n  " + "\n  ".join(breaks)


def test_the_allow_list_is_used() -> None:
    edges = {(source, target) for source, target, _ in import_edges()}
    assert set(ALLOWED) <= edges, f"drop {sorted(set(ALLOWED) - edges)} from ALLOWED: nothing imports that way now"


def test_packages_import_each_other_without_a_circle() -> None:
    graph: dict[str, dict[str, list[str]]] = {}
    for source, target, where in import_edges():
        if (source, target) not in ALLOWED:
            graph.setdefault(source, {}).setdefault(target, []).append(where)
    cycle = find_cycle(graph)
    if cycle is not None:
        steps = [f"{a} -> {b} ({', '.join(graph[a][b][:3])})" for a, b in zip(cycle, cycle[1:])]
        raise AssertionError("import circle between packages:\n  " + "\n  ".join(steps))


def test_the_checks_see_function_level_imports_and_skip_type_checking_ones(tmp_path: Path) -> None:
    (tmp_path / "world").mkdir()
    (tmp_path / "world" / "__init__.py").write_text("")
    (tmp_path / "world" / "road.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from ..case import Case\n"
        "def f():\n    try:\n        from ..render import frame\n    except ImportError:\n        pass\n")
    (tmp_path / "case.py").write_text("from .world import road\n")
    (tmp_path / "render").mkdir()
    edges = import_edges(tmp_path)
    assert [(source, target) for source, target, _ in edges] == [("case", "world"), ("world", "render")]
    assert layer_breaks(edges, {"world": 1, "case": 3, "render": 5}) == [
        "world/road.py:6: world imports render (layer 1 -> 5)"]


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


def case_uses(root: Path, keep: set[str]) -> list[str]:
    """``file:line`` of every import of ``Case`` (even under ``if TYPE_CHECKING:``) and every parameter named ``case``
    in the modules below ``root``, except the files ``keep`` (paths relative to ``root``)."""
    uses = []
    for path in sorted(root.rglob("*.py")):
        where = path.relative_to(root).as_posix()
        if where in keep:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and any(alias.name == "Case" for alias in node.names):
                uses.append(f"{where}:{node.lineno} imports Case")
            elif isinstance(node, ast.arg) and node.arg == "case":
                uses.append(f"{where}:{node.lineno} takes a case")
    return uses


def test_the_world_builds_from_its_own_inputs() -> None:
    """The world's functions take what they read (``RoadsideInputs``, a weather and a sun), which
    ``pipeline/compile.py`` takes from the case; only the compiled scene names ``Case`` (``CompiledScene.case``)."""
    uses = case_uses(PACKAGE / "world", keep={"scene.py"})
    assert uses == [], f"pass the world what it reads of the case instead: {uses}"


def test_the_case_check_sees_type_checking_imports_and_parameters(tmp_path: Path) -> None:
    (tmp_path / "scenery.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from ..case import Case, Road\n"
        "def f(network, case):\n    return network\n")
    (tmp_path / "scene.py").write_text("from ..case import Case\n")
    assert case_uses(tmp_path, keep={"scene.py"}) == ["scenery.py:3 imports Case", "scenery.py:4 takes a case"]


@pytest.mark.parametrize("package", CASE_FREE)
def test_renderer_labels_and_exporters_never_read_the_case_of_a_scene(package: str) -> None:
    reads = [f"{path.relative_to(PACKAGE).as_posix()}:{node.lineno}"
             for path in sorted((PACKAGE / package).rglob("*.py"))
             for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
             if isinstance(node, ast.Attribute) and node.attr == "case" and isinstance(node.value, ast.Name)
             and node.value.id == "scene"]
    assert reads == [], f"compile what these need into the scene instead: {reads}"


def test_the_app_takes_nothing_from_the_core_command_line_but_the_command() -> None:
    """Parsers and listings the app shares with the command line live with what they parse or list."""
    uses = [f"{path.relative_to(ROOT).as_posix()}:{node.lineno}"
            for path in sorted((ROOT / "app").rglob("*.py")) if path != ROOT / "app" / "cli.py"
            for node in _imports(ast.parse(path.read_text(encoding="utf-8")).body)
            for name in ([alias.name for alias in node.names] if isinstance(node, ast.Import) else [node.module or ""])
            if name == "lanevil_core.cli" or name.startswith("lanevil_core.cli.")]
    assert uses == []
