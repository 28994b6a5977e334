"""The study's JSON API under ``/api/study``: organiser routes (bearer token) and participant routes.

Errors use the REST API's body ``{"detail": "<field>: <message>", "field": "<field>"}`` (``app.api.errors``):
401/403 for the token, 404 for an unknown study, item or participant, 409 for a study that is not ready, a
repeated rating or an unfinished session, 413 for an upload over ``max_upload_bytes``, 422 for anything else
malformed (a rating outside 1-5 included).
"""

from __future__ import annotations

import secrets
import sqlite3
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from fastapi import APIRouter, Request
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import FileResponse, JSONResponse, Response
from pydantic import ValidationError
from starlette.datastructures import UploadFile

from ...state import AppState
from ...study.auth import AdminDep
from ...study.bodies import (
    Completed,
    OpenStudy,
    ParticipantPlan,
    PublicStudy,
    RatingBody,
    StudyDetail,
    StudyResults,
    StudyRow,
)
from ...study.create import SpecError, create_study, items_folder
from ...study.db import connect, db_path
from ...study.deps import DbDep
from ...study.images import CheckedUpload, UploadError, check_upload
from ...study.order import participant_order
from ...study.records import (
    NotFound,
    Study,
    add_participant,
    add_rating,
    complete_participant,
    get_item,
    get_participant,
    get_study,
    image_url,
    list_studies,
    participant_ratings,
    study_items,
    study_participants,
    study_ratings,
)
from ...study.spec import ConsentIn, RatingIn, StudySpec
from ...study.stats import exclusions, summarize
from ...study.tables import raw_ratings_csv, summary_csv
from ..deps import StateDep
from ..errors import ApiError, ApiRoute, ErrorBody, first_error
from ..forms import read_form
from ..json_body import BodyError, check_json_type, is_json_type, parse_json

MAX_UPLOAD_FILES = 1000
FORM_TYPES = ("multipart/form-data", "application/x-www-form-urlencoded")


def _error(description: str) -> dict[str, Any]:
    return {"model": ErrorBody, "description": description}


ORGANISER: dict[int | str, dict[str, Any]] = {
    401: _error("missing or wrong organiser token (`Authorization: Bearer <token>`)"),
    403: _error("no organiser token is configured on the server (LANEVIL_ADMIN_TOKEN)"),
}
NO_STUDY: dict[int | str, dict[str, Any]] = {404: _error("no such study (or participant, or item): `field` says which")}
NOT_READY: dict[int | str, dict[str, Any]] = {409: _error("the study is not ready yet (still rendering, or failed)")}
router = APIRouter(prefix="/study", tags=["study"], route_class=ApiRoute,
                   responses={422: _error("invalid input; `field` names it")})

# ``POST /studies`` reads its body itself (a multipart form or JSON), so its request body is described here.
_SPEC_SCHEMA = StudySpec.model_json_schema(ref_template="#/components/schemas/{model}")
SCHEMAS: dict[str, dict[str, Any]] = {"StudySpec": {k: v for k, v in _SPEC_SCHEMA.items() if k != "$defs"},
                                      **_SPEC_SCHEMA.get("$defs", {})}
SPEC_EXAMPLE = {"title": "How natural do these road scenes look?", "viewing_seconds": 3, "width": 1280,
                "height": 720, "generated": {"cases": ["clean-00_straight_urban"], "frames": [0, 40]},
                "items": [{"case_id": "clean-01_bend_suburban", "role": "training"},
                          {"case_id": "clean-01_bend_suburban", "frame": 20, "role": "gold", "garble": True,
                           "expect": [1, 2]},
                          {"case_id": "clean-00_straight_urban", "frame": 60, "role": "trap", "answer": 2}]}
CREATE_BODY: dict[str, Any] = {"requestBody": {"required": True, "content": {
    "multipart/form-data": {
        "schema": {"type": "object", "required": ["spec"], "properties": {
            "spec": {"$ref": "#/components/schemas/StudySpec", "description": "the study spec, sent as JSON text",
                     "example": SPEC_EXAMPLE},
            "files": {"type": "array", "items": {"type": "string", "format": "binary"}, "default": [],
                      "description": "real images (PNG or JPEG); an item names one by its file name (`upload`)"}}},
        "encoding": {"spec": {"contentType": "application/json"}, "files": {"contentType": "image/png, image/jpeg"}}},
    "application/json": {"schema": {"$ref": "#/components/schemas/StudySpec"}, "example": SPEC_EXAMPLE},
}}}


def http_error(status: int, field: str, message: str) -> ApiError:
    return ApiError(status, message, field)


@contextmanager
def answers() -> Iterator[None]:
    """Turn the study's own errors into HTTP answers."""
    try:
        yield
    except NotFound as error:
        raise http_error(404, error.field, str(error)) from None
    except SpecError as error:
        raise http_error(422, error.field, str(error)) from None


# --- organiser ---------------------------------------------------------------------------------------------------

@router.post("/studies", status_code=201, summary="Create a study (organiser)", openapi_extra=CREATE_BODY,
             responses={201: {"model": StudyDetail,
                              "description": "the study, ready: `id`, `status`, `participant_url`, `items` (each "
                                             "with its `image_url`) and `job`: null"},
                        202: {"model": StudyDetail,
                              "description": "the study, still `rendering`, and its render `job`"},
                        **ORGANISER,
                        413: _error("an upload over `max_upload_bytes` (`field`: `files.<n>`), or the request over "
                                    "the server's body limit")})
async def post_study(request: Request, state: StateDep, _: AdminDep) -> JSONResponse:
    """Multipart form: ``spec`` (JSON, see ``StudySpec``) and any number of ``files`` (PNG/JPEG real images).
    A JSON body is accepted too (the spec alone, for studies of generated frames only).
    201 with the ready study, or 202 with the study and its render job when it renders in the background."""
    spec, uploads = await _read_create_request(request, state)
    db = connect(db_path(state.settings.data_dir))
    try:
        with answers():
            study, job = await run_in_threadpool(create_study, db, state.settings, state.store, state.frames,
                                                 state.jobs, spec, uploads)
        body = await run_in_threadpool(_study_detail, db, study)
    finally:
        db.close()
    body["job"] = job.to_dict() if job else None
    return JSONResponse(body, status_code=202 if job else 201)


async def _read_create_request(request: Request, state: AppState) -> tuple[StudySpec, dict[str, CheckedUpload]]:
    content_type = request.headers.get("content-type", "")
    if is_json_type(content_type):
        body = await request.body()
        if len(body) > state.settings.max_body_bytes:
            raise http_error(413, "spec", f"the spec is over {state.settings.max_body_bytes} bytes")
        return _parse_spec(body), {}
    if not content_type.startswith(FORM_TYPES):
        try:
            check_json_type(content_type)
        except BodyError as error:
            raise http_error(415, error.field, "send multipart/form-data (a 'spec' field and 'files') or "
                                               f"application/json (the spec alone), not {content_type or 'nothing'}"
                             ) from None
    form = await read_form(request, MAX_UPLOAD_FILES)
    part = form.get("spec")
    raw_spec: str | bytes | None
    if isinstance(part, UploadFile):  # a JSON part, as /docs and generated clients send it
        raw_spec = await part.read(state.settings.max_body_bytes + 1)
        if len(raw_spec) > state.settings.max_body_bytes:
            raise http_error(413, "spec", f"the spec is over {state.settings.max_body_bytes} bytes")
    else:
        raw_spec = part
    if not isinstance(raw_spec, str | bytes):
        raise http_error(422, "spec", "the form needs a field 'spec' holding the study spec as JSON")
    spec = _parse_spec(raw_spec)
    uploads: dict[str, CheckedUpload] = {}
    for index, upload in enumerate(form.getlist("files")):
        if upload == "":  # an empty file input, as browsers send it, is no upload
            continue
        if not isinstance(upload, UploadFile):
            raise http_error(422, f"files.{index}", "each 'files' part must be a file")
        name = upload.filename or f"upload-{index}"
        field = f"files.{index}"
        if name in uploads:
            raise http_error(422, field, f"two uploads are named {name!r}; give each file its own name")
        data = await upload.read(state.settings.max_upload_bytes + 1)
        if not data:  # an empty file part is no upload either
            continue
        if len(data) > state.settings.max_upload_bytes:
            raise http_error(413, field, f"{name} is over {state.settings.max_upload_bytes} bytes")
        try:
            uploads[name] = check_upload(data)
        except UploadError as error:
            raise http_error(422, field, f"{name} {error}") from None
    return spec, uploads


def _parse_spec(text: str | bytes) -> StudySpec:
    try:
        return StudySpec.model_validate(parse_json(text, field="spec"))
    except BodyError as error:
        raise http_error(error.status, error.field, str(error)) from None
    except ValidationError as error:
        raise http_error(422, *first_error(error.errors(), prefix="spec")) from None


def _study_detail(db: sqlite3.Connection, study: Study) -> dict[str, Any]:
    items = study_items(db, study.id)
    return study.to_dict() | {
        "participant_url": f"/study/{study.id}",
        "results_url": f"/study/admin#{study.id}",
        "items": [item.to_dict() for item in items],
        "participants": len(study_participants(db, study.id)),
    }


@router.get("/studies", summary="List studies (organiser)", response_model=None,
            responses={200: {"model": list[StudyRow]}, **ORGANISER})
def get_studies(db: DbDep, _: AdminDep) -> list[dict[str, Any]]:
    return [study.to_dict() | {"participants": len(study_participants(db, study.id))} for study in list_studies(db)]


@router.get("/studies/{study_id}", summary="A study with its items (organiser)", response_model=None,
            responses={200: {"model": StudyDetail}, **ORGANISER, **NO_STUDY})
def get_study_detail(study_id: str, db: DbDep, state: StateDep, _: AdminDep) -> dict[str, Any]:
    with answers():
        study = get_study(db, study_id)
    body = _study_detail(db, study)
    body["job"] = _job(state, study.job_id)
    return body


def _job(state: AppState, job_id: str | None) -> dict[str, Any] | None:
    if job_id is None:
        return None
    try:
        return state.jobs.get(job_id).to_dict()
    except LookupError:  # jobs live in memory; after a restart only the study's status remains
        return None


def _results(db: sqlite3.Connection, study_id: str) -> tuple[Study, dict[str, Any]]:
    with answers():
        study = get_study(db, study_id)
    items = study_items(db, study_id)
    return study, summarize(items, study_participants(db, study_id), study_ratings(db, study_id))


@router.get("/studies/{study_id}/results", summary="MOS with 95% CI and rater screening (organiser)",
            response_model=None, responses={200: {"model": StudyResults}, **ORGANISER, **NO_STUDY})
def get_results(study_id: str, db: DbDep, _: AdminDep) -> dict[str, Any]:
    study, summary = _results(db, study_id)
    return {"study": study.to_dict()} | summary


@router.get("/studies/{study_id}/ratings.csv", summary="Raw ratings as CSV (organiser)", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}, **ORGANISER, **NO_STUDY})
def get_ratings_csv(study_id: str, db: DbDep, _: AdminDep) -> Response:
    with answers():
        study = get_study(db, study_id)
    items, participants, ratings = study_items(db, study_id), study_participants(db, study_id), \
        study_ratings(db, study_id)
    text = raw_ratings_csv(items, ratings, exclusions(items, participants, ratings))
    return _csv_response(text, f"study-{study.id}-ratings.csv")


@router.get("/studies/{study_id}/summary.csv", summary="MOS summary as CSV (organiser)", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}, **ORGANISER, **NO_STUDY})
def get_summary_csv(study_id: str, db: DbDep, _: AdminDep) -> Response:
    study, summary = _results(db, study_id)
    return _csv_response(summary_csv(summary["groups"]), f"study-{study.id}-summary.csv")


def _csv_response(text: str, filename: str) -> Response:
    return Response(text, media_type="text/csv; charset=utf-8",
                    headers={"Content-Disposition": f'attachment; filename="{filename}"'})


# --- participants --------------------------------------------------------------------------------------------------

def _counts(db: sqlite3.Connection, study_id: str) -> dict[str, int]:
    items = study_items(db, study_id)
    return {"training_items": sum(item.role == "training" for item in items),
            "rated_items": sum(item.scored for item in items)}


@router.get("/open", summary="Studies open to participants (for the /study page)", response_model=None,
            responses={200: {"model": list[OpenStudy]}})
def get_open_studies(db: DbDep) -> list[dict[str, Any]]:
    """Every study that is ready, newest first: what the ``/study`` page lists for people who want to take part."""
    ready = [study for study in reversed(list_studies(db)) if study.status == "ready"]
    return [{"id": study.id, "title": study.title, "question": study.question, "viewing_ms": study.viewing_ms,
             "participant_url": f"/study/{study.id}", **_counts(db, study.id)} for study in ready]


@router.get("/studies/{study_id}/public", summary="What a participant sees before consenting", response_model=None,
            responses={200: {"model": PublicStudy}, **NO_STUDY})
def get_public(study_id: str, db: DbDep, state: StateDep) -> dict[str, Any]:
    """Also ``preparing`` (``{"done", "total"}`` images) while the study's images are still being rendered."""
    with answers():
        study = get_study(db, study_id)
    job = _job(state, study.job_id) if study.status == "rendering" else None
    return {"id": study.id, "title": study.title, "question": study.question, "consent_text": study.consent_text,
            "instructions": study.instructions, "viewing_ms": study.viewing_ms, "width": study.width,
            "height": study.height, "status": study.status, **_counts(db, study_id),
            "preparing": {"done": job["done"], "total": job["total"]} if job else None}


def _ready(study: Study) -> None:
    if study.status != "ready":
        raise http_error(409, "study_id", f"study {study.id!r} is not open yet (status {study.status!r})")


def _plan(db: sqlite3.Connection, study: Study, participant_id: str) -> dict[str, Any]:
    participant = get_participant(db, study.id, participant_id)
    items = {item.id: item for item in study_items(db, study.id)}
    order = participant_order(list(items.values()), study.id, participant_id)
    rated = [rating.item_id for rating in participant_ratings(db, participant_id)]
    return {"participant_id": participant.id, "study_id": study.id, "viewing_ms": study.viewing_ms,
            "question": study.question, "completed": participant.completed_at is not None, "rated": rated,
            "items": [{"item_id": item_id, "training": items[item_id].role == "training",
                       "image_url": image_url(study.id, item_id)} for item_id in order]}


@router.post("/studies/{study_id}/participants", status_code=201, summary="Consent and join a study",
             response_model=None, responses={201: {"model": ParticipantPlan}, **NO_STUDY, **NOT_READY})
def post_participant(study_id: str, consent: ConsentIn, db: DbDep) -> dict[str, Any]:
    """Creates the participant (a random id) only when ``consent`` is true; returns the item order."""
    with answers():
        study = get_study(db, study_id)
        _ready(study)
        if not consent.consent:
            raise http_error(422, "consent", "nothing is recorded without consent; send {\"consent\": true}")
        participant = add_participant(db, study.id, secrets.token_hex(16))
        return _plan(db, study, participant.id)


@router.get("/studies/{study_id}/participants/{participant_id}", summary="A participant's order and progress",
            response_model=None, responses={200: {"model": ParticipantPlan}, **NO_STUDY})
def get_participant_plan(study_id: str, participant_id: str, db: DbDep) -> dict[str, Any]:
    with answers():
        return _plan(db, get_study(db, study_id), participant_id)


@router.post("/studies/{study_id}/participants/{participant_id}/ratings", status_code=201,
             summary="Rate one item (once; a second rating of the same item is refused with 409)",
             response_model=None, responses={201: {"model": RatingBody}, **NO_STUDY, 409: _error(
                 "this participant rated the item already (`field`: `item_id`)")})
def post_rating(study_id: str, participant_id: str, rating: RatingIn, db: DbDep) -> dict[str, Any]:
    with answers():
        study = get_study(db, study_id)
        participant = get_participant(db, study.id, participant_id)
        item = get_item(db, study.id, rating.item_id)
    try:
        stored = add_rating(db, participant.id, item.id, rating.rating, rating.response_ms)
    except sqlite3.IntegrityError:
        raise http_error(409, "item_id", f"item {item.id} is already rated by this participant; ratings are "
                                         "final") from None
    return {"id": stored.id, "item_id": item.id, "rating": stored.rating}


@router.post("/studies/{study_id}/participants/{participant_id}/complete", summary="Finish the session",
             response_model=None, responses={200: {"model": Completed}, **NO_STUDY,
                                             409: _error("items are still unrated (`field`: `ratings`)")})
def post_complete(study_id: str, participant_id: str, db: DbDep) -> dict[str, Any]:
    """409 while any item is unrated; otherwise marks the participant complete (idempotent)."""
    with answers():
        study = get_study(db, study_id)
        participant = get_participant(db, study.id, participant_id)
    rated = {rating.item_id for rating in participant_ratings(db, participant.id)}
    missing = [item.id for item in study_items(db, study.id) if item.id not in rated]
    if missing:
        raise http_error(409, "ratings", f"{len(missing)} item(s) are not rated yet (first: {missing[0]})")
    complete_participant(db, participant.id)
    return {"participant_id": participant.id, "completed": True}


@router.get("/studies/{study_id}/items/{item_id}/image", summary="An item's image, as stored at creation",
            response_class=FileResponse,
            responses={200: {"content": {"image/png": {}, "image/jpeg": {}}}, **NO_STUDY, **NOT_READY})
def get_item_image(study_id: str, item_id: int, db: DbDep, state: StateDep) -> FileResponse:
    with answers():
        study = get_study(db, study_id)
        item = get_item(db, study.id, item_id)
    _ready(study)
    path = items_folder(state.settings.data_dir, study.id) / item.file
    return FileResponse(path, media_type=item.media_type, headers={"Cache-Control": "private, max-age=86400"})
