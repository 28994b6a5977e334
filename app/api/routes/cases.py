"""``/api/cases``: list, create, read, replace, merge-patch and delete stored cases, with optimistic versioning.

Request bodies of POST, PUT and PATCH take one of two forms:

* a bare case document (PATCH: a JSON merge patch of one), which for PUT/PATCH may carry a top-level
  ``"version"`` (taken out before the case is validated), or
* an envelope ``{"case": {...}, "id": ..., "version": ...}`` — the shape ``GET`` returns, so a client can send back
  what it read (``created_at``, ``updated_at`` and ``origin`` are read-only and ignored).

A write names the version it was based on with ``If-Match: "<version>"`` (the ETag of ``GET``) or the body's
``version``; a stale one is a 409 that says the current version. A write naming no version applies unconditionally.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Header, Query, Request, Response
from fastapi.responses import JSONResponse
from pydantic import BaseModel, Field, ValidationError

from lanevil_core.case import Case
from lanevil_core.illusions import CATEGORIES, REGISTRY, MeshFileError
from lanevil_core.library.benchmark_layout import MIXED_CATEGORY
from lanevil_core.pipeline.compile import check_mesh_files

from ...state import AppState
from ...store import CaseRecord, InvalidId, VersionConflict, check_id
from ..case_bodies import PATCH_BODY, CaseBody, PatchBody, ReplaceBody
from ..deps import CaseIdPath, RecordDep, StateDep
from ..errors import ERROR_RESPONSES, ApiError, ApiRoute, ErrorBody, first_error
from ..params import VERSION_PATTERN, etag_matches, parse_version

router = APIRouter(prefix="/cases", tags=["cases"], route_class=ApiRoute, responses=ERROR_RESPONSES)

LISTING_CATEGORIES = ("clean", *CATEGORIES, MIXED_CATEGORY)
ENVELOPE_KEYS = frozenset({"id", "version", "case", "created_at", "updated_at", "origin"})
CONFLICT: dict[int | str, dict[str, Any]] = {
    409: {"model": ErrorBody, "description": "stale version (the message says the current one)"}}
NOT_FOUND: dict[int | str, dict[str, Any]] = {404: {"model": ErrorBody, "description": "no case with that id"}}



class CaseSummary(BaseModel):
    """One row of the case listing (``CaseRecord.summary``)."""

    id: str
    title: str
    category: str = Field(description=f"one of {', '.join(LISTING_CATEGORIES)}")
    type: str | None = Field(description="the first illusion's type (a stock original: its folder's), or null")
    severity: int = Field(description="highest severity among the illusions, 0 for none")
    version: int
    road: str = Field(description="road type, e.g. bend")
    frames: int
    illusions: int = Field(description="number of illusions")
    updated_at: float = Field(description="seconds since the epoch")


class CaseList(BaseModel):
    data: list[CaseSummary]
    count: int


class CaseEnvelope(BaseModel):
    """A stored case with its bookkeeping: what ``GET /api/cases/{id}`` answers and every write returns."""

    id: str
    version: int = Field(description="increases by one with every write; also the ETag")
    created_at: float = Field(description="seconds since the epoch")
    updated_at: float = Field(description="seconds since the epoch")
    origin: str | None = Field(description="the stock file a seeded case came from, or null")
    case: Case


def envelope_response(description: str) -> dict[str, Any]:
    """An OpenAPI response of ``CaseEnvelope`` with its ``ETag`` header."""
    return {"model": CaseEnvelope, "description": description,
            "headers": {"ETag": {"description": 'the version, e.g. "3"', "schema": {"type": "string"}}}}


IfMatch = Annotated[str | None, Header(alias="If-Match", description='the version the change is based on: "3"',
                                       json_schema_extra={"pattern": VERSION_PATTERN})]


def record_response(record: CaseRecord, status_code: int = 200, headers: dict[str, str] | None = None) -> JSONResponse:
    """The envelope of ``record`` with its version as ETag."""
    return JSONResponse(record.envelope(), status_code=status_code, headers={"ETag": f'"{record.version}"',
                                                                              **(headers or {})})


def split_body(body: dict[str, Any], allow_version: bool) -> tuple[dict[str, Any], str | None, int | None]:
    """(case document, id, version) of a request body in either form (see the module docstring)."""
    if "case" in body:
        unknown = sorted(set(body) - ENVELOPE_KEYS)
        if unknown:
            raise ApiError(422, f"unknown envelope key (allowed: {', '.join(sorted(ENVELOPE_KEYS))})", unknown[0])
        document, case_id, version = body["case"], body.get("id"), body.get("version")
        prefix = "case"
    else:
        document = dict(body)
        version = document.pop("version", None) if allow_version else None
        case_id, prefix = None, ""
    if not isinstance(document, dict):
        raise ApiError(422, "must be a JSON object (a case document)", prefix or "body")
    if case_id is not None and not isinstance(case_id, str):
        raise ApiError(422, "must be a string", "id")
    if version is not None and (isinstance(version, bool) or not isinstance(version, int) or version < 1):
        raise ApiError(422, f"{version!r} is not a case version (a positive integer)", "version")
    return document, case_id, version


def validate_case(document: dict[str, Any], prefix: str, state: AppState) -> Case:
    """A ``Case`` from a JSON document whose mesh files are uploaded; a 422 naming the first bad field (under
    ``prefix``) otherwise."""
    try:
        case = Case.model_validate(document)
        check_mesh_files(case, state.meshes_dir)
    except ValidationError as error:
        field, message = first_error(error.errors(), prefix)
        raise ApiError(422, message, field) from None
    except MeshFileError as error:
        raise ApiError(422, error.message, f"{prefix}.{error.field}" if prefix else error.field) from None
    return case


def expected_version(if_match: str | None, body_version: int | None) -> int | None:
    header_version = parse_version(if_match)
    if header_version is not None and body_version is not None and header_version != body_version:
        raise ApiError(422, f"If-Match says version {header_version} but the body says {body_version}", "version")
    return header_version if header_version is not None else body_version


def merge_patch(target: Any, patch: Any) -> Any:
    """RFC 7396 JSON merge patch: objects merge recursively, ``null`` removes a key, anything else replaces."""
    if not isinstance(patch, dict):
        return patch
    merged = dict(target) if isinstance(target, dict) else {}
    for key, value in patch.items():
        if value is None:
            merged.pop(key, None)
        else:
            merged[key] = merge_patch(merged.get(key), value)
    return merged


@router.get("", summary="List cases")
def list_cases(
    state: StateDep,
    category: Annotated[str | None, Query(description=f"one of {', '.join(LISTING_CATEGORIES)}",
                                          json_schema_extra={"enum": list(LISTING_CATEGORIES)})] = None,
    type: Annotated[str | None, Query(description="an illusion type, e.g. fence_shadow",  # noqa: A002
                                      json_schema_extra={"enum": list(REGISTRY)})] = None,
) -> CaseList:
    """Summaries of the stored cases (sorted by id), optionally of one category and/or illusion type (an empty
    value is no filter)."""
    category, type = category or None, type or None  # noqa: A001 - ``?category=`` as a form sends "no filter"
    if category is not None and category not in LISTING_CATEGORIES:
        raise ApiError(422, f"unknown category {category!r} (choose from {', '.join(LISTING_CATEGORIES)})",
                       "category")
    if type is not None and type not in REGISTRY:
        raise ApiError(422, f"unknown illusion type {type!r} (see GET /api/illusions)", "type")
    rows = [record.summary() for record in state.store.list(category, type)]
    return CaseList.model_validate({"data": rows, "count": len(rows)})


@router.post("", status_code=201, summary="Create a case",
             responses={201: envelope_response("the stored case"), 409: {"model": ErrorBody}})
def create_case(body: CaseBody, state: StateDep, request: Request) -> JSONResponse:
    """Store a new case at version 1; its id is the envelope's ``id`` or one derived from the title."""
    document, case_id, _ = split_body(body, allow_version=False)
    case = validate_case(document, "case" if "case" in body else "", state)
    if case_id is not None:
        try:
            check_id(case_id)
        except InvalidId as error:
            raise ApiError(422, str(error), "id") from None
    record = state.store.create(case, case_id=case_id)
    return record_response(record, 201, {"Location": str(request.url_for("get_case", case_id=record.id))})


@router.get("/{case_id}", summary="Read a case", responses={200: envelope_response("the stored case"), **NOT_FOUND,
                                                            304: {"description": "not modified"}})
def get_case(record: RecordDep, if_none_match: Annotated[str | None, Header(alias="If-None-Match")] = None
             ) -> Response:
    """The stored envelope ``{id, version, created_at, updated_at, origin, case}``; ``ETag`` is the version."""
    if etag_matches(if_none_match, str(record.version)):
        return Response(status_code=304, headers={"ETag": f'"{record.version}"'})
    return record_response(record)


@router.put("/{case_id}", summary="Replace a case",
            responses={200: envelope_response("the case at its new version"), **NOT_FOUND, **CONFLICT})
def put_case(case_id: CaseIdPath, body: ReplaceBody, state: StateDep, if_match: IfMatch = None) -> JSONResponse:
    """Replace the case; ``If-Match`` or the body's ``version`` guards against overwriting someone else's change."""
    document, body_id, body_version = split_body(body, allow_version=True)
    if body_id is not None and body_id != case_id:
        raise ApiError(422, f"{body_id!r} differs from the id in the URL ({case_id!r})", "id")
    version = expected_version(if_match, body_version)
    state.store.get(case_id)  # 404 before 422 for an unknown case
    case = validate_case(document, "case" if "case" in body else "", state)
    return record_response(state.store.update(case_id, case, expected_version=version))


@router.patch("/{case_id}", summary="Merge-patch a case (RFC 7396)",
              responses={200: envelope_response("the case at its new version"), **NOT_FOUND, **CONFLICT},
              openapi_extra={"requestBody": {"content": {"application/merge-patch+json": {"schema": PATCH_BODY}}}})
def patch_case(case_id: CaseIdPath, body: PatchBody, state: StateDep, if_match: IfMatch = None) -> JSONResponse:
    """Merge a JSON merge patch into the case (``null`` resets a field to its default, lists are replaced)."""
    patch, body_id, body_version = split_body(body, allow_version=True)
    if body_id is not None and body_id != case_id:
        raise ApiError(422, f"{body_id!r} differs from the id in the URL ({case_id!r})", "id")
    version = expected_version(if_match, body_version)
    current = state.store.get(case_id)
    if version is not None and version != current.version:
        raise VersionConflict(case_id, version, current.version)
    patch = lane_count_patch(patch, current.case.road.lanes_per_direction)
    merged = merge_patch(current.case.model_dump(mode="json"), patch)
    case = validate_case(merged, "case" if "case" in body else "", state)
    # the patch applies to ``current``: only write if nobody changed the case since it was read
    return record_response(state.store.update(case_id, case, expected_version=current.version))


def lane_count_patch(patch: Any, lanes_per_direction: int) -> Any:
    """``patch``, resetting the road's markings to the new lane count's defaults when it changes
    ``road.lanes_per_direction`` without giving ``road.markings`` (the old markings have the wrong count)."""
    road = patch.get("road") if isinstance(patch, dict) else None
    if not isinstance(road, dict) or road.get("lanes_per_direction", lanes_per_direction) == lanes_per_direction:
        return patch
    if "markings" in road:
        return patch
    return {**patch, "road": {**road, "markings": None}}


@router.delete("/{case_id}", status_code=204, summary="Delete a case", responses={**NOT_FOUND, **CONFLICT})
def delete_case(case_id: CaseIdPath, state: StateDep, if_match: IfMatch = None) -> Response:
    """Remove the case (only if it is still at the ``If-Match`` version, when given)."""
    state.store.delete(case_id, expected_version=parse_version(if_match))
    return Response(status_code=204)
