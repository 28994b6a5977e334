"""Multipart form bodies read with the API's errors: a malformed form (no boundary, a broken part) is a 422 naming
``Content-Type`` or ``body``, never Starlette's bare ``{"detail": ...}``."""

from __future__ import annotations

from fastapi import Request
from starlette.datastructures import FormData
from starlette.exceptions import HTTPException as StarletteHTTPException

from .errors import ApiError


async def read_form(request: Request, max_files: int = 1000) -> FormData:
    """The parsed form of ``request``; ``ApiError`` (422, as malformed JSON is) whose field says what is malformed."""
    try:
        return await request.form(max_files=max_files)
    except StarletteHTTPException as error:
        if isinstance(error, ApiError):
            raise
        message = str(error.detail)
        field = "Content-Type" if "boundary" in message.lower() else "body"
        raise ApiError(422, f"malformed multipart form: {message}", field) from None
