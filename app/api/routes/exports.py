"""Zipped exports in the benchmark layout ``<Category>/<Type>/<case>/000000.png … labels.json case.json``.

``GET /api/cases/{case_id}/export.zip`` answers a few frames (``SYNC_EXPORT_FRAMES``) at once; a longer range
becomes a background job (202 + ``Location``), as does ``POST /api/exports``. Jobs are polled at
``GET /api/exports/{job_id}``, cancelled with ``DELETE``, and their zip fetched from ``/download`` once ``status``
is ``done`` (409 before).

An export of the same case content and frames as a queued, running or finished job answers that job; a full queue
or a client with ``JobManager.max_per_client`` unfinished jobs gets 429 with ``Retry-After``.
"""

from __future__ import annotations

import uuid
from pathlib import Path, PurePosixPath
from typing import Annotated, Any

from fastapi import APIRouter, Query, Request, Response
from fastapi.responses import FileResponse, JSONResponse
from pydantic import BaseModel, Field

from lanevil_core.library.benchmark_layout import case_folder
from lanevil_core.pipeline.compile import check_mesh_files

from ...frames import case_hash
from ...jobs import Job, export_zip
from ...state import AppState
from ...store import ID_PATTERN, CaseRecord
from ..deps import RecordDep, StateDep
from ..errors import ERROR_RESPONSES, TOO_MANY, ApiError, ApiRoute, ErrorBody
from ..job_bodies import JobBody
from ..params import FRAMES_PATTERN, frame_range

router = APIRouter(tags=["exports"], route_class=ApiRoute, responses=ERROR_RESPONSES)

SYNC_EXPORT_FRAMES = 10  # more frames than this (~0.2 s each at 1280x720) go to a background job
ZIP = "application/zip"


class ExportJob(JobBody):
    case_id: str
    case_version: int
    frames: str = Field(description="START:STOP, half-open")
    folder: str = Field(description="Category/Type/<case id> inside the zip")


JOB_ACCEPTED: dict[int | str, dict[str, Any]] = {
    202: {"model": ExportJob,
          "description": "export queued as a job (or the job of an identical export): poll the Location "
                        "(GET /api/exports/{job_id})",
          "headers": {"Location": {"description": "the job's URL", "schema": {"type": "string"}}}},
    **TOO_MANY,
}
NO_CASE: dict[int | str, dict[str, Any]] = {404: {"model": ErrorBody, "description": "no case with that id"}}


class ExportRequest(BaseModel):
    """Body of ``POST /api/exports``."""

    case_id: str = Field(description="id of a stored case", json_schema_extra={"pattern": ID_PATTERN.pattern})
    frames: str | None = Field(None, description="START:STOP (half-open) or N; default: every frame",
                               json_schema_extra={"pattern": FRAMES_PATTERN})


def zip_name(record: CaseRecord) -> str:
    return f"{record.id}.zip"


def export_folder(record: CaseRecord) -> PurePosixPath:
    """``Category/Type/<case id>`` (``Clean/<id>`` for clean cases) inside the zip."""
    return case_folder(record.case, record.id, record.illusion_type)


def job_body(job: Job, request: Request) -> dict[str, Any]:
    """A job's state plus the URLs to poll and download it."""
    return {**job.to_dict(), "links": {"self": str(request.url_for("get_export", job_id=job.id)),
                                       "download": str(request.url_for("download_export", job_id=job.id))}}


def submit_export(state: AppState, record: CaseRecord, frames: range, request: Request) -> JSONResponse:
    """Queue an export job of ``frames`` (or find the job of the same export); answer 202 with the job and its URL."""
    case, folder = record.case, export_folder(record)
    check_mesh_files(case, state.meshes_dir)  # a stored case whose mesh is gone: 422 now, not a failed job
    meta = {"case_id": record.id, "case_version": record.version, "frames": f"{frames.start}:{frames.stop}",
            "folder": folder.as_posix()}
    key = f"export:{folder.as_posix()}:{case_hash(case)}:{frames.start}:{frames.stop}"
    client = request.client.host if request.client else "unknown"
    job = state.jobs.submit("export", len(frames), lambda job, progress: export_zip(
        case, folder, frames, state.jobs.result_path(job.id), progress, state.meshes_dir), meta, key=key, client=client)
    body = job_body(job, request)
    return JSONResponse(body, status_code=202, headers={"Location": body["links"]["self"]})


@router.get("/cases/{case_id}/export.zip", summary="Export frames and labels as a zip",
            response_class=Response, responses={200: {"content": {ZIP: {}}}, **JOB_ACCEPTED, **NO_CASE})
def export_case_zip(
    record: RecordDep,
    state: StateDep,
    request: Request,
    frames: Annotated[str | None, Query(description="START:STOP (half-open) or N; default: every frame",
                                        json_schema_extra={"pattern": FRAMES_PATTERN})] = None,
) -> Response:
    """The zip itself for up to ``SYNC_EXPORT_FRAMES`` frames; otherwise 202 with a job to poll."""
    chosen = frame_range(frames, record.case.ego.frames, range(record.case.ego.frames))
    if len(chosen) > SYNC_EXPORT_FRAMES:
        return submit_export(state, record, chosen, request)
    target = state.jobs.folder / f".direct-{uuid.uuid4().hex}.zip"
    try:
        export_zip(record.case, export_folder(record), chosen, target, meshes_dir=state.meshes_dir)
        data = target.read_bytes()
    finally:
        Path(target).unlink(missing_ok=True)
    return Response(data, media_type=ZIP,
                    headers={"Content-Disposition": f'attachment; filename="{zip_name(record)}"'})


@router.post("/exports", status_code=202, summary="Start an export job", responses={**JOB_ACCEPTED, **NO_CASE})
def create_export(body: ExportRequest, state: StateDep, request: Request) -> JSONResponse:
    """Queue an export of ``frames`` of a stored case; poll the returned job."""
    record = state.store.get(body.case_id)
    chosen = frame_range(body.frames, record.case.ego.frames, range(record.case.ego.frames))
    return submit_export(state, record, chosen, request)


@router.get("/exports/{job_id}", summary="State of an export job", response_model=None,
            responses={200: {"model": ExportJob}, 404: {"model": ErrorBody, "description": "no such job"}})
def get_export(job_id: str, state: StateDep, request: Request) -> dict[str, Any]:
    """``status`` (queued, running, done, failed, cancelled), ``done``/``total`` frames, ``progress`` 0..1 and links."""
    return job_body(state.jobs.get(job_id), request)


@router.delete("/exports/{job_id}", summary="Cancel an export job", response_model=None,
               responses={200: {"model": ExportJob}, 404: {"model": ErrorBody, "description": "no such job"}})
def cancel_export(job_id: str, state: StateDep, request: Request) -> dict[str, Any]:
    """Stop a queued or running export (it ends as ``cancelled`` after its current frame); a finished job is
    left as it is."""
    return job_body(state.jobs.cancel(job_id), request)


@router.get("/exports/{job_id}/download", summary="Download a finished export", response_class=FileResponse,
            responses={200: {"content": {ZIP: {}}}, 404: {"model": ErrorBody},
                       409: {"model": ErrorBody, "description": "the job is not done (yet)"}})
def download_export(job_id: str, state: StateDep) -> FileResponse:
    """The job's zip once its ``status`` is ``done``."""
    job = state.jobs.get(job_id)
    if job.status != "done" or job.result is None:
        reason = f"failed: {job.error}" if job.status == "failed" else f"is {job.status} ({job.done}/{job.total})"
        raise ApiError(409, f"export {job_id} {reason}", "job_id")
    name = f"{job.meta.get('case_id', job_id)}.zip"
    return FileResponse(job.result, media_type=ZIP, filename=name)
