"""``OPTIONS`` and ``405`` answers that list every method a path takes (``Allow``), not only the first route's.

Starlette answers a method a path does not take with the ``Allow`` of the first route whose path matched, and
``OPTIONS`` (which no route declares) the same way; a path served by several routes (``GET``/``POST`` of
``/api/cases``) then seems to take only ``GET``.
"""

from __future__ import annotations

from starlette.datastructures import MutableHeaders
from starlette.responses import Response
from starlette.routing import BaseRoute, Match, Mount
from starlette.types import Message, Receive, Scope, Send

from ..asgi import HttpMiddleware, editing_start

METHODS = ("GET", "HEAD", "POST", "PUT", "PATCH", "DELETE")


def allowed_methods(routes: list[BaseRoute], scope: Scope) -> set[str]:
    """The methods some route (not a static mount, which takes any path below it) fully matches ``scope`` with."""
    methods: set[str] = set()
    for route in routes:
        if isinstance(route, Mount):
            continue
        methods.update(method for method in METHODS if route.matches({**scope, "method": method})[0] == Match.FULL)
    return methods


def allow_header(methods: set[str]) -> str:
    return ", ".join(sorted(methods | {"OPTIONS"}))


class AllowMiddleware(HttpMiddleware):
    """204 with ``Allow`` for ``OPTIONS`` on a routed path; a 405's ``Allow`` lists every method of the path."""

    async def handle(self, scope: Scope, receive: Receive, send: Send) -> None:
        methods = allowed_methods(scope["app"].router.routes, scope)
        if not methods:
            await self.app(scope, receive, send)
            return
        if scope["method"] == "OPTIONS":
            await Response(status_code=204, headers={"Allow": allow_header(methods)})(scope, receive, send)
            return

        def fix_allow(start: Message) -> None:
            if start["status"] == 405:
                MutableHeaders(scope=start)["Allow"] = allow_header(methods)

        await self.app(scope, receive, editing_start(send, fix_allow))
