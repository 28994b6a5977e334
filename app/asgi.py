"""A base of the app's small ASGI middlewares: HTTP requests go to ``handle``, anything else passes through."""

from __future__ import annotations

from collections.abc import Callable

from starlette.types import ASGIApp, Message, Receive, Scope, Send


class HttpMiddleware:
    """Subclasses implement ``handle`` for HTTP requests (websockets and lifespan pass through unchanged)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        await self.handle(scope, receive, send)

    async def handle(self, scope: Scope, receive: Receive, send: Send) -> None:  # pragma: no cover - overridden
        await self.app(scope, receive, send)


def editing_start(send: Send, edit: Callable[[Message], None]) -> Send:
    """``send`` with ``edit`` applied to the ``http.response.start`` message (status and headers) first."""

    async def edited(message: Message) -> None:
        if message["type"] == "http.response.start":
            edit(message)
        await send(message)

    return edited
