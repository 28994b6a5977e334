"""The REST API's layout (docs/architecture.md, CONTRIBUTING.md "Add an API route"): one router module per resource
in ``app/api/routes/``, all mounted under ``/api`` by the one loop of ``routes/__init__.py``; the rest of the app
(``app/api/``'s shared infrastructure included) never imports a route module."""

from __future__ import annotations

import ast
from pathlib import Path

from app.api.openapi import API_PREFIX
from app.api.routes import RESOURCES

APP = Path(__file__).resolve().parents[2] / "app"
ROUTES = APP / "api" / "routes"
MOUNTS = {APP / "main.py", ROUTES / "__init__.py"}  # where routers may be included


def _trees() -> dict[Path, ast.Module]:
    return {path: ast.parse(path.read_text(encoding="utf-8")) for path in sorted(APP.rglob("*.py"))}


def _where(path: Path, node: ast.AST) -> str:
    return f"{path.relative_to(APP.parent).as_posix()}:{getattr(node, 'lineno', 0)}"


def _keyword(call: ast.Call, name: str) -> ast.expr | None:
    return next((keyword.value for keyword in call.keywords if keyword.arg == name), None)


def test_every_route_module_is_a_mounted_resource() -> None:
    modules = {path.stem for path in ROUTES.glob("*.py") if path.stem != "__init__"}
    assert modules == {module.__name__.rsplit(".", 1)[1] for module in RESOURCES}, "add it to RESOURCES"
    assert all(hasattr(module, "router") for module in RESOURCES)


def test_routers_are_mounted_under_api_in_one_place() -> None:
    """No router carries an ``/api`` prefix of its own, no include adds one, and only ``MOUNTS`` include routers
    into the API (``site.py`` and ``docs.py`` mount their own pages, outside ``/api``)."""
    breaks = []
    for path, tree in _trees().items():
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Name | ast.Attribute):
                continue
            name = node.func.id if isinstance(node.func, ast.Name) else node.func.attr
            prefix = _keyword(node, "prefix")
            if name == "APIRouter" and isinstance(prefix, ast.Constant) and str(prefix.value).startswith(API_PREFIX):
                breaks.append(f"{_where(path, node)}: a router prefixed {prefix.value!r}")
            if name == "include_router" and prefix is not None:
                breaks.append(f"{_where(path, node)}: include_router(prefix=...)")
            if name == "include_router" and path.parent == APP / "api" and path not in MOUNTS:
                breaks.append(f"{_where(path, node)}: a router included outside {sorted(p.name for p in MOUNTS)}")
    assert breaks == []


def test_nothing_but_the_mount_imports_a_route_module() -> None:
    """Shared infrastructure (``app/api/*.py``) and the domain (``store``, ``study`` …) stand below the routes."""
    uses = []
    for path, tree in _trees().items():
        if path in MOUNTS or path.parent == ROUTES:
            continue
        package = ".".join(path.relative_to(APP.parent).with_suffix("").parts[:-1])
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = package.rsplit(".", node.level - 1)[0] if node.level else ""
                module = ".".join(part for part in (base, node.module or "") if part) if node.level else node.module
                names = [module or ""] + [f"{module}.{alias.name}" for alias in node.names]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            else:
                continue
            if any(name == "app.api.routes" or name.startswith("app.api.routes.") for name in names):
                uses.append(_where(path, node))
    assert uses == [], "only routes/__init__.py and main.py import a route module; share through app/api/ instead"
