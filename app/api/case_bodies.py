"""JSON Schemas of the case routes' request bodies, as strict as the server: a case document (``Case``, no unknown
keys) or an envelope ``{"case": ..., "id"?, "version"?}`` (``POST``/``PUT /api/cases``, ``POST /api/render``), and
for ``PATCH`` a JSON merge patch of one (RFC 7396): every field of every object optional and nullable (``null``
resets it to its default), lists replaced whole, so their items are complete.

What a schema cannot say is left to the server's 422s: the rules across fields of a case (``Case`` validators: the
drive ends 60 m before the road does, one marking per lane boundary …), an envelope ``id`` that differs from the
URL's, a ``mesh_file`` that was never uploaded.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import Body
from pydantic import WithJsonSchema

from lanevil_core.case import Case

from ..store import ID_PATTERN

COMPONENTS = "#/components/schemas/"
PATCH_SUFFIX = "Patch"
NULL = {"type": "null"}


def envelope(case: dict[str, Any], with_id: bool) -> dict[str, Any]:
    """The envelope form of a body whose ``case`` is described by ``case`` (read-only fields are ignored). A write
    to ``/api/cases/{case_id}`` takes its id from the URL (the server takes an ``id`` only when equal to it)."""
    properties: dict[str, Any] = {
        "case": case,
        "version": {"type": "integer", "minimum": 1, "description": "the version the change is based on"},
        "created_at": {"type": "number", "description": "read-only, ignored"},
        "updated_at": {"type": "number", "description": "read-only, ignored"},
        "origin": {"anyOf": [{"type": "string"}, NULL], "description": "read-only, ignored"}}
    if with_id:
        properties["id"] = {"type": "string", "pattern": ID_PATTERN.pattern, "description": "the case id"}
    return {"type": "object", "required": ["case"], "additionalProperties": False, "properties": properties}


def document_or_envelope(case: dict[str, Any], description: str, with_id: bool = True) -> dict[str, Any]:
    return {"anyOf": [case, envelope(case, with_id)], "description": description}


def merge_patch_schemas(model: type[Case] = Case) -> dict[str, dict[str, Any]]:
    """Components ``<Name>Patch``: a merge patch of ``model`` and of every object it holds in a field."""
    schema = model.model_json_schema(ref_template=COMPONENTS + "{model}")
    objects = {**schema.pop("$defs", {}), model.__name__: schema}
    patches: dict[str, dict[str, Any]] = {}

    def patch_of(value: dict[str, Any]) -> dict[str, Any]:
        name = str(value.get("$ref", "")).removeprefix(COMPONENTS)
        if "properties" in objects.get(name, {}):
            if name + PATCH_SUFFIX not in patches:
                patches[name + PATCH_SUFFIX] = {}  # taken before recursing (a model may hold itself)
                patches[name + PATCH_SUFFIX] = patch_object(objects[name])
            return {**value, "$ref": COMPONENTS + name + PATCH_SUFFIX}
        if "anyOf" in value:
            return {**value, "anyOf": [patch_of(branch) for branch in value["anyOf"]]}
        return value

    def patch_object(source: dict[str, Any]) -> dict[str, Any]:
        properties = {key: {"anyOf": [patch_of(value), NULL]} for key, value in source["properties"].items()}
        return {"type": "object", "properties": properties, "additionalProperties": False,
                "description": f"a JSON merge patch of {source.get('title', 'an object')}: null resets a field"}

    patch_of({"$ref": COMPONENTS + model.__name__})
    return patches


CASE_BODY_SCHEMAS = merge_patch_schemas()
CASE_REF = {"$ref": f"{COMPONENTS}{Case.__name__}"}
PATCH_REF = {"$ref": f"{COMPONENTS}{Case.__name__}{PATCH_SUFFIX}"}
CASE_BODY = document_or_envelope(CASE_REF, "a case document, or an envelope {id?, version?, case}")
REPLACE_BODY = document_or_envelope(CASE_REF, "a case document, or an envelope {version?, case}", with_id=False)
PATCH_BODY = document_or_envelope(PATCH_REF, "a JSON merge patch of the case, or an envelope {version?, case: patch}",
                                  with_id=False)

CaseBody = Annotated[dict[str, Any], WithJsonSchema(CASE_BODY),
                     Body(openapi_examples={"case": {"value": {"title": "my case"}}})]
ReplaceBody = Annotated[dict[str, Any], WithJsonSchema(REPLACE_BODY),
                        Body(openapi_examples={"case": {"value": {"title": "my case"}}})]
PatchBody = Annotated[dict[str, Any], WithJsonSchema(PATCH_BODY),
                      Body(openapi_examples={"patch": {"value": {"sun": {"altitude": 20.0}}}})]
