"""Which pages may open the editor's websocket: a check of the ``Origin`` of every websocket handshake.

A browser sends any page's origin with a websocket handshake and lets the page read the answers, so without a
check any web site a user visits could drive the editor on ``localhost:8080``. Allowed: the editor's and the API's
own ports on loopback names and the bound host, same-origin pages when the server listens on every interface, and
``Settings.allowed_origins`` (``*`` = any). A handshake without ``Origin`` (not a browser) is let through.

viser 1.x builds its ``websockets`` server inside ``ViserServer()`` with no option for this, so ``hooking_requests``
wraps ``websockets.asyncio.server.serve`` while that server starts, adding hooks (this check, and ``page.py``'s page
with the editor's script) in front of viser's own ``process_request`` (which serves the client files); nothing else
of viser changes.
"""

from __future__ import annotations

import http
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any
from urllib.parse import urlsplit

import websockets.asyncio.server
from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")
WILDCARD_HOSTS = ("0.0.0.0", "::", "")
_patch_lock = threading.Lock()


class OriginCheck:
    """Whether an ``Origin`` may open the websocket; ``ports()`` are the editor's and the API's (known once bound)."""

    def __init__(self, host: str, ports: Callable[[], set[int]], extra: list[str] | tuple[str, ...] = ()) -> None:
        self.hosts = {*LOOPBACK_NAMES, host.strip("[]")} - set(WILDCARD_HOSTS)
        self.same_origin = host in WILDCARD_HOSTS  # listening everywhere: the address the user typed is fine
        self.ports = ports
        self.extra = {origin.rstrip("/") for origin in extra}

    def allows(self, origin: str | None, host_header: str | None = None) -> bool:
        if origin is None:
            return True
        if "*" in self.extra or origin.rstrip("/") in self.extra:
            return True
        parts = urlsplit(origin)
        if parts.scheme not in ("http", "https"):
            return False
        if self.same_origin and host_header and parts.netloc == host_header:
            return True
        try:
            port = parts.port or (443 if parts.scheme == "https" else 80)
        except ValueError:
            return False
        return parts.hostname in self.hosts and port in self.ports()

    def process_request(self, connection: ServerConnection, request: Request) -> Response | None:
        """A 403 for a websocket handshake from a page that may not open it (``websockets``' hook)."""
        if request.headers.get("Upgrade", "").lower() != "websocket":
            return None
        if self.allows(request.headers.get("Origin"), request.headers.get("Host")):
            return None
        return connection.respond(http.HTTPStatus.FORBIDDEN, "this page's origin may not open the editor\n")


RequestHook = Callable[[ServerConnection, Request], Response | None]


@contextmanager
def hooking_requests(hooks: list[RequestHook]) -> Iterator[None]:
    """While the block runs, websocket servers started through ``websockets.asyncio.server.serve`` pass every
    HTTP request (page, files, websocket handshake) through ``hooks`` in order before their own
    ``process_request``; the first response a hook gives is the answer."""
    serve = websockets.asyncio.server.serve

    def hooked_serve(*args: Any, process_request: Any = None, **kwargs: Any) -> Any:
        def process(connection: ServerConnection, request: Request) -> Any:
            for hook in hooks:
                answer = hook(connection, request)
                if answer is not None:
                    return answer
            return None if process_request is None else process_request(connection, request)

        return serve(*args, process_request=process, **kwargs)

    with _patch_lock:
        websockets.asyncio.server.serve = hooked_serve  # type: ignore[misc,assignment]
        try:
            yield
        finally:
            websockets.asyncio.server.serve = serve  # type: ignore[misc]


def checking_origins(check: OriginCheck) -> Any:
    """``hooking_requests`` with the origin check alone."""
    return hooking_requests([check.process_request])
