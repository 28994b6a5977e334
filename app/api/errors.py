"""One error format for the REST API: ``{"detail": "<field>: <message>", "field": "<field>"}``.

``field`` is the dotted path of what was wrong: a query or header name (``width``, ``If-Match``, ``Content-Type``),
a path parameter (``case_id``), ``body`` for a body that is not strict JSON (the message says line and column), or
a path inside the JSON body (``road.lanes_per_direction``, ``case.ego.frames``). Every 4xx of the API (validation,
store, job and limit errors) uses this body; ``ApiRoute`` reads JSON bodies strictly (``json_body``) and converts the
exceptions raised while a request is handled, so malformed input never becomes a 500.
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine, Mapping, Sequence
from typing import Any

from fastapi import HTTPException, Request, Response, params
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi.routing import APIRoute
from pydantic import BaseModel, ValidationError

from lanevil_core.case import CaseError
from lanevil_core.illusions import MeshFileError

from ..frames import RenderBusy
from ..headers import SECURITY_HEADERS
from ..jobs import JobLimit, JobNotFound
from ..store import CaseExists, CaseNotFound, InvalidId, StoreError, VersionConflict
from .json_body import BodyError, check_json_type, parse_json

# Where FastAPI says a bad value came from; dropped from the field path (the name alone is unambiguous).
REQUEST_SOURCES = ("query", "path", "header", "cookie", "body")
STORE_STATUS: dict[type[StoreError], int] = {InvalidId: 422, CaseNotFound: 404, CaseExists: 409,
                                             VersionConflict: 409}


class ErrorBody(BaseModel):
    """The JSON body of every API error."""

    detail: str
    field: str | None = None


class ApiError(HTTPException):
    """An HTTP error whose body names the offending field."""

    def __init__(self, status_code: int, message: str, field: str | None = None,
                 headers: dict[str, str] | None = None) -> None:
        detail = f"{field}: {message}" if field else message
        super().__init__(status_code, detail=detail, headers=headers)
        self.field = field


def error_response(status_code: int, detail: str, field: str | None = None,
                   headers: Mapping[str, str] | None = None) -> JSONResponse:
    return JSONResponse(ErrorBody(detail=detail, field=field).model_dump(), status_code=status_code, headers=headers)


def field_path(loc: Sequence[Any]) -> str:
    """``("body", "road", "lanes")`` -> ``road.lanes``, ``("query", "width")`` -> ``width``, ``("body",)`` ->
    ``body``."""
    parts = [str(part) for part in loc]
    if len(parts) > 1 and parts[0] in REQUEST_SOURCES:
        parts = parts[1:]
    return ".".join(parts)


def first_error(errors: Sequence[Any], prefix: str = "") -> tuple[str, str]:
    """(field, message) of the first pydantic/FastAPI error, with ``(and N more errors)`` appended."""
    first = errors[0]
    field = field_path(first.get("loc", ()))
    if prefix:
        field = f"{prefix}.{field}" if field else prefix
    message = str(first.get("msg", "invalid value")).removeprefix("Value error, ")
    more = len(errors) - 1
    if more:
        message += f" (and {more} more error{'s' if more > 1 else ''})"
    return field or "body", message


def validation_response(errors: Sequence[Any], prefix: str = "") -> JSONResponse:
    field, message = first_error(errors, prefix)
    return error_response(422, f"{field}: {message}", field)


def exception_response(error: Exception) -> JSONResponse | None:
    """The API's response for a known client error, or None for anything else (a real server error)."""
    if isinstance(error, ApiError):
        return error_response(error.status_code, str(error.detail), error.field, error.headers)
    if isinstance(error, RequestValidationError):
        return validation_response(error.errors())
    if isinstance(error, ValidationError):
        return validation_response(error.errors())
    if isinstance(error, StoreError):
        status = next((code for kind, code in STORE_STATUS.items() if isinstance(error, kind)), 422)
        return error_response(status, f"{error.field}: {error}", error.field)
    if isinstance(error, JobNotFound):
        return error_response(404, f"job_id: {error}", "job_id")
    if isinstance(error, JobLimit):
        return error_response(429, str(error), None, {"Retry-After": str(error.retry_after_s)})
    if isinstance(error, RenderBusy):
        return error_response(503, str(error), None, {"Retry-After": str(error.retry_after_s)})
    if isinstance(error, BodyError):
        return error_response(error.status, f"{error.field}: {error}", error.field)
    if isinstance(error, MeshFileError):
        return error_response(422, str(error), error.field)
    if isinstance(error, CaseError):
        return error_response(422, str(error), "case")
    return None


async def handle_exception(request: Request, error: Exception) -> Response:
    """Exception handler for ``app.add_exception_handler`` (store and job errors raised outside ``/api``)."""
    response = exception_response(error)
    if response is None:
        raise error
    return response


async def handle_server_error(request: Request, error: Exception) -> Response:
    """The 500 of an uncaught exception: the API's error body (no traceback, no message that might quote the
    server's files) with the security headers. Starlette answers it from its outermost middleware, outside every
    middleware the app adds, so the headers are set here; the exception is then logged by the server."""
    return error_response(500, "internal server error: the request could not be completed", None, SECURITY_HEADERS)


class StrictJsonRequest(Request):
    """A request whose ``json()`` is strict JSON (``json_body.parse_json``); FastAPI parses bodies through it."""

    async def json(self) -> Any:
        if not hasattr(self, "_strict_json"):
            try:
                self._strict_json = parse_json(await self.body())
            except BodyError as error:  # FastAPI passes an HTTPException raised here on unchanged
                raise ApiError(error.status, str(error), error.field) from None
        return self._strict_json


def takes_json_body(route: APIRoute) -> bool:
    """Whether a route reads a JSON body (a body parameter that is not a form)."""
    return route.body_field is not None and not isinstance(route.body_field.field_info, params.Form)


async def check_json_request(request: Request) -> None:
    """415 for a body that is not declared as JSON (a missing ``Content-Type`` is fine while the body is empty)."""
    content_type = request.headers.get("content-type")
    if content_type or await request.body():
        check_json_type(content_type)


class ApiRoute(APIRoute):
    """A route whose client errors (including FastAPI's request validation) answer in the API's error format, and
    whose JSON body is read strictly (415 for another content type, 422 naming ``body`` for malformed JSON)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()
        json_body = takes_json_body(self)

        async def route_handler(request: Request) -> Response:
            try:
                if json_body:
                    request = StrictJsonRequest(request.scope, request.receive)
                    await check_json_request(request)
                return await handler(request)
            except Exception as error:
                response = exception_response(error)
                if response is None:
                    raise
                return response

        return route_handler


# The error responses API routes document (FastAPI's default 422 schema is replaced by ErrorBody).
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    422: {"model": ErrorBody, "description": "invalid input; `field` names it"},
}
# What every route that takes a JSON body may answer as well.
BODY_RESPONSES: dict[int | str, dict[str, Any]] = {
    413: {"model": ErrorBody, "description": "the body is over the server's limit (`field`: `body`)"},
    415: {"model": ErrorBody, "description": "the body is not sent as JSON (`field`: `Content-Type`)"},
}
# What every route that renders frames may answer when the render queue is full (``frames.RenderSlots``).
RENDER_BUSY: dict[int | str, dict[str, Any]] = {
    503: {"model": ErrorBody, "description": "too many frames waiting to render: try again after `Retry-After` seconds",
          "headers": {"Retry-After": {"description": "seconds to wait", "schema": {"type": "integer"}}}},
}
TOO_MANY: dict[int | str, dict[str, Any]] = {
    429: {"model": ErrorBody, "description": "too many jobs queued: try again after `Retry-After` seconds",
          "headers": {"Retry-After": {"description": "seconds to wait", "schema": {"type": "integer"}}}},
}
