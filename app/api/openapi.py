"""The OpenAPI description, made to say what the API does: every error of ``/api`` is an ``ErrorBody``.

Two limits apply to every route that reads a body, whatever route declares them: ``BodyLimitMiddleware`` (413) and
``ApiRoute``'s strict JSON (415 for another content type). They are documented here, once, for every operation
with a request body, and FastAPI's own 422 schema (``HTTPValidationError``, which ``ApiRoute`` never sends) is
replaced by ``ErrorBody``, so a client generated from ``/openapi.json`` parses the errors it really gets.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from fastapi import FastAPI

from .errors import ErrorBody

API_PREFIX = "/api/"
ERROR_REF = {"$ref": f"#/components/schemas/{ErrorBody.__name__}"}
FASTAPI_VALIDATION_SCHEMAS = ("HTTPValidationError", "ValidationError")
BODY_ERRORS: dict[str, str] = {
    "413": "the body is over the server's limit (`field`: `body`)",
    "415": "the body is not sent with a content type the route reads (`field`: `Content-Type`)",
    "422": "invalid input; `field` names it",
}


def error_response(description: str) -> dict[str, Any]:
    return {"description": description, "content": {"application/json": {"schema": dict(ERROR_REF)}}}


def document_errors(schema: dict[str, Any], schemas: Mapping[str, dict[str, Any]] | None = None) -> dict[str, Any]:
    """``schema`` with ErrorBody as the body of every 4xx of ``/api``, 413/415 on every operation with a body, and
    ``schemas`` (models that request bodies described by hand refer to) among its components."""
    for path, item in schema.get("paths", {}).items():
        if not path.startswith(API_PREFIX):
            continue
        for operation in item.values():
            if not isinstance(operation, dict) or "responses" not in operation:
                continue
            responses = operation["responses"]
            if "requestBody" in operation:
                for status, description in BODY_ERRORS.items():
                    responses.setdefault(status, error_response(description))
            for status, response in responses.items():
                if status.startswith("4"):
                    response.setdefault("content", {}).setdefault("application/json", {})["schema"] = dict(ERROR_REF)
    components = schema.setdefault("components", {}).setdefault("schemas", {})
    components.setdefault(ErrorBody.__name__, ErrorBody.model_json_schema())
    for name, model_schema in (schemas or {}).items():
        components.setdefault(name, model_schema)
    text = repr(schema.get("paths", {}))
    for name in FASTAPI_VALIDATION_SCHEMAS:
        if f"#/components/schemas/{name}'" not in text:
            components.pop(name, None)
    return schema


def install(app: FastAPI, schemas: Mapping[str, dict[str, Any]] | None = None) -> None:
    """Make ``app.openapi()`` answer the documented-errors schema (built once, then cached like FastAPI's)."""
    build: Callable[[], dict[str, Any]] = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            app.openapi_schema = document_errors(build(), schemas)
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
