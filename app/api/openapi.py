"""The OpenAPI description, made to say what the API does: every error of ``/api`` is an ``ErrorBody``.

Two limits apply to every route that reads a body, whatever route declares them: ``BodyLimitMiddleware`` (413) and
``ApiRoute``'s strict JSON (415 for another content type). They are documented here, once, for every operation
with a request body, and FastAPI's own 422 schema (``HTTPValidationError``, which ``ApiRoute`` never sends) is
replaced by ``ErrorBody``, so a client generated from ``/openapi.json`` parses the errors it really gets.

It also says what the server takes, no more: a query, path or header parameter is absent or a value, never JSON
``null`` (FastAPI describes an optional one as ``anyOf: [..., null]``, which clients then send as the text
``null``), and bounds that come from the server's settings (the largest image) are filled in from them
(``SERVER_LIMIT``).
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping
from typing import Any

from fastapi import FastAPI

from .errors import ErrorBody

API_PREFIX = "/api"  # where app/api/routes mounts every resource
ERROR_REF = {"$ref": f"#/components/schemas/{ErrorBody.__name__}"}
FASTAPI_VALIDATION_SCHEMAS = ("HTTPValidationError", "ValidationError")
BODY_ERRORS: dict[str, str] = {
    "413": "the body is over the server's limit (`field`: `body`)",
    "415": "the body is not sent with a content type the route reads (`field`: `Content-Type`)",
    "422": "invalid input; `field` names it",
}


# A schema key naming the setting (``max_width`` …) that is the ``maximum`` of the value it describes.
SERVER_LIMIT = "x-server-limit"
NULL = {"type": "null"}


def error_response(description: str) -> dict[str, Any]:
    return {"description": description, "content": {"application/json": {"schema": dict(ERROR_REF)}}}


def document_errors(schema: dict[str, Any], schemas: Mapping[str, dict[str, Any]] | None = None) -> dict[str, Any]:
    """``schema`` with ErrorBody as the body of every 4xx of ``/api``, 413/415 on every operation with a body, and
    ``schemas`` (models that request bodies described by hand refer to) among its components."""
    for path, item in schema.get("paths", {}).items():
        if not path.startswith(f"{API_PREFIX}/"):
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
        components.setdefault(name, copy.deepcopy(model_schema))  # each app fills in its own server limits
    text = repr(schema.get("paths", {}))
    for name in FASTAPI_VALIDATION_SCHEMAS:
        if f"#/components/schemas/{name}'" not in text:
            components.pop(name, None)
    return schema


def without_null(schema: dict[str, Any]) -> dict[str, Any]:
    """A parameter's schema without FastAPI's ``anyOf: [X, null]`` of an optional value: ``X`` with the outer keys
    (description, pattern …), and no ``null`` default."""
    branches = [branch for branch in schema.get("anyOf", []) if branch != NULL]
    if "anyOf" not in schema or len(branches) != 1:
        return schema
    outer = {key: value for key, value in schema.items() if key != "anyOf" and not (key == "default" and value is None)}
    return {**branches[0], **outer}


def fill_limits(node: Any, settings: object) -> None:
    """Replace every ``SERVER_LIMIT`` marker under ``node`` by the ``maximum`` it names: that setting's value."""
    if isinstance(node, dict):
        name = node.pop(SERVER_LIMIT, None)
        if name is not None:
            node["maximum"] = getattr(settings, name)
        for value in node.values():
            fill_limits(value, settings)
    elif isinstance(node, list):
        for value in node:
            fill_limits(value, settings)


def server_constraints(schema: dict[str, Any], settings: object) -> dict[str, Any]:
    """``schema`` with parameters that are never ``null`` and the limits of ``settings`` (``max_width`` …) filled
    in."""
    for item in schema.get("paths", {}).values():
        for operation in item.values():
            for parameter in operation.get("parameters", []) if isinstance(operation, dict) else []:
                parameter["schema"] = without_null(parameter.get("schema", {}))
    fill_limits(schema, settings)
    return schema


def install(app: FastAPI, settings: object, schemas: Mapping[str, dict[str, Any]] | None = None) -> None:
    """Make ``app.openapi()`` answer the documented-errors schema with the constraints of the server's
    ``settings`` (what ``SERVER_LIMIT`` markers name), built once, then cached like FastAPI's."""
    build: Callable[[], dict[str, Any]] = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            app.openapi_schema = server_constraints(document_errors(build(), schemas), settings)
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
