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
from starlette.types import Message, Receive, Scope, Send

from .asgi import HttpMiddleware, editing_start

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


def add_security_headers(start: Message) -> None:
    headers = MutableHeaders(scope=start)
    for name, value in SECURITY_HEADERS.items():
        headers.setdefault(name, value)


class SecurityHeadersMiddleware(HttpMiddleware):
    """Adds ``SECURITY_HEADERS`` to every response that does not set them itself."""

    async def handle(self, scope: Scope, receive: Receive, send: Send) -> None:
        await self.app(scope, receive, editing_start(send, add_security_headers))
