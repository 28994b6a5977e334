"""viser's page with the editor's script (``static/page.js``), and what that script reports of the browser.

The script runs before viser's code: it reads the WebGL renderer string and, for software WebGL (no GPU), asks
viser for a lower pixel ratio and sets the ``lanevil_webgl`` cookie, which the browser sends with the websocket
handshake; ``browser_webgl`` reads it there when the tab connects. It also keeps arrow keys on a focused slider
from moving the 3D camera. ``serve_page`` is a request hook (``origins.hooking_requests``) answering the page
itself; viser serves every other file.
"""

from __future__ import annotations

import http
from dataclasses import dataclass
from http.cookies import SimpleCookie
from pathlib import Path
from urllib.parse import unquote

import viser
from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

SCRIPT = (Path(__file__).parent / "static" / "page.js").read_text(encoding="utf-8")
VISER_PAGE = Path(viser.__file__).parent / "client" / "build" / "index.html"
PAGE_PATHS = ("/", "/index.html")


def page_html() -> bytes:
    """viser's index.html with the editor's script first in its head."""
    html = VISER_PAGE.read_text(encoding="utf-8")
    return html.replace("<head>", f"<head><script>{SCRIPT}</script>", 1).encode("utf-8")


def serve_page(connection: ServerConnection, request: Request) -> Response | None:
    """The page with the editor's script for ``/`` (any query); None for everything else (viser serves it)."""
    if request.headers.get("Upgrade", "").lower() == "websocket" or request.path.partition("?")[0] not in PAGE_PATHS:
        return None
    body = page_html()
    headers = Headers({"Content-Type": "text/html; charset=utf-8", "Content-Length": str(len(body)),
                       "Cache-Control": "no-store"})
    return Response(http.HTTPStatus.OK, "OK", headers, body)


@dataclass(frozen=True)
class BrowserWebGL:
    """What the page found: whether WebGL runs in software, and the renderer string (``unknown``: no report, as
    for a client that is not the page, such as ``HeadlessTab``)."""

    software: bool = False
    renderer: str = "unknown"


def browser_webgl(server: viser.ViserServer, client_id: int) -> BrowserWebGL:
    """The page's report for a connected client, from the cookies of its websocket handshake. viser keeps the
    handshake's connection per client id in its websocket server (``_live_connections``, viser 1.x)."""
    connections = getattr(getattr(server, "_websock_server", None), "_live_connections", {})
    connection = connections.get(client_id)
    request = getattr(connection, "request", None)
    if request is None:
        return BrowserWebGL()
    cookie = SimpleCookie()
    cookie.load(request.headers.get("Cookie", ""))
    if "lanevil_webgl" not in cookie:
        return BrowserWebGL()
    renderer = unquote(cookie["lanevil_renderer"].value) if "lanevil_renderer" in cookie else "unknown"
    return BrowserWebGL(software=cookie["lanevil_webgl"].value == "software", renderer=renderer)
