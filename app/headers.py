"""Security headers on every HTTP response of the app (API, website, study, API docs).

The pages load scripts, styles and images from this server only; styles may be inline (Swagger UI and ReDoc set
them at run time) and images may be ``data:``/``blob:`` URLs (frames fetched as blobs, Swagger's icons). A route
whose page needs more (the docs' inline start-up script) sets its own ``Content-Security-Policy``, which is kept.
"""

from __future__ import annotations

import base64
import hashlib
import re

from starlette.datastructures import MutableHeaders
from starlette.types import ASGIApp, Message, Receive, Scope, Send

SCRIPT_SRC = "'self'"


def content_security_policy(script_src: str = SCRIPT_SRC) -> str:
    return ("default-src 'self'; "
            f"script-src {script_src}; "
            "style-src 'self' 'unsafe-inline'; "
            "img-src 'self' data: blob:; "
            "worker-src 'self' blob:; "
            "object-src 'none'; base-uri 'self'; form-action 'self'; frame-ancestors 'none'")


SECURITY_HEADERS: dict[str, str] = {
    "Content-Security-Policy": content_security_policy(),
    "X-Frame-Options": "DENY",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "same-origin",
}
_INLINE_SCRIPT = re.compile(r"<script>(.*?)</script>", re.DOTALL)


def inline_script_policy(html: str) -> str:
    """The policy of a page whose inline ``<script>`` blocks (and nothing else inline) may run: one hash each."""
    hashes = [base64.b64encode(hashlib.sha256(body.encode("utf-8")).digest()).decode("ascii")
              for body in _INLINE_SCRIPT.findall(html)]
    return content_security_policy(" ".join([SCRIPT_SRC, *(f"'sha256-{digest}'" for digest in hashes)]))


class SecurityHeadersMiddleware:
    """Adds ``SECURITY_HEADERS`` to every response that does not set them itself."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                for name, value in SECURITY_HEADERS.items():
                    headers.setdefault(name, value)
            await send(message)

        await self.app(scope, receive, send_with_headers)
