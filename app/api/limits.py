"""Request body limits, enforced before a body is read: ``Content-Length`` is checked up front and streamed
(chunked) bodies are counted as they arrive, so no request makes the server buffer more than the limit."""

from __future__ import annotations

from starlette.datastructures import Headers
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from .errors import ApiError, error_response

MULTIPART = "multipart/form-data"
# A multipart request (study images) may carry several uploads; the route reading it checks each file against
# ``max_upload_bytes``, this bounds the whole request.
UPLOADS_PER_REQUEST = 50


class BodyLimitMiddleware:
    """413 for bodies over ``max_body_bytes`` (JSON and everything else) or, for multipart uploads,
    ``UPLOADS_PER_REQUEST * max_upload_bytes``."""

    def __init__(self, app: ASGIApp, max_body_bytes: int, max_upload_bytes: int) -> None:
        self.app = app
        self.max_body_bytes = max_body_bytes
        self.max_upload_bytes = max_upload_bytes

    def limit(self, headers: Headers) -> int:
        content_type = headers.get("content-type", "").lower()
        if content_type.startswith(MULTIPART):
            return UPLOADS_PER_REQUEST * self.max_upload_bytes
        return self.max_body_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        limit = self.limit(headers)
        declared = headers.get("content-length", "")
        if declared.isdigit() and int(declared) > limit:
            await too_large(limit)(scope, receive, send)
            return
        received = 0
        started = False

        async def limited_receive() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise too_large_error(limit)
            return message

        async def tracking_send(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, limited_receive, tracking_send)
        except ApiError as error:  # raised by limited_receive outside a route that converts it
            if started or error.status_code != 413:
                raise
            await too_large(limit)(scope, receive, send)


def too_large_error(limit: int) -> ApiError:
    return ApiError(413, f"request body is larger than {limit} bytes", "body")


def too_large(limit: int):  # noqa: ANN201 - a Starlette response (an ASGI app)
    error = too_large_error(limit)
    return error_response(413, str(error.detail), error.field, {"Connection": "close"})
