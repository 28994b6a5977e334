"""Closed-loop drives as background jobs: ``POST /api/drives`` starts one, ``GET /api/drives/{job_id}`` polls it
(with the summary once done), ``DELETE`` cancels it, ``GET /api/drives/{job_id}/files/{name}`` serves its files
(``trace.csv``, ``summary.json``, ``trace.png``, ``path.png``, ``drive.mp4`` or ``drive.gif``).

The drive itself is ``lanevil_core.drive`` (docs/drive.md): the renderer in the loop, a detector, a lane estimate,
a lateral controller and a kinematic bicycle model.
"""

from __future__ import annotations

import json
from typing import Any, Literal

from fastapi import APIRouter, Request
from fastapi.responses import FileResponse, JSONResponse
from pydantic import BaseModel, Field

from lanevil_core.case import Case
from lanevil_core.drive.detectors import DRIVE_DETECTORS, GROUND_TRUTH
from lanevil_core.drive.loop import DriveSettings
from lanevil_core.drive.outputs import PATH_PLOT_FILE, SUMMARY_FILE, TRACE_FILE, TRACE_PLOT_FILE
from lanevil_core.pipeline.compile import check_mesh_files

from ...frames import case_hash
from ...jobs import Job, drive_job
from ...settings import Settings
from ...store import ID_PATTERN
from ..deps import StateDep
from ..errors import ERROR_RESPONSES, TOO_MANY, ApiError, ApiRoute, ErrorBody
from ..job_bodies import JobBody
from ..params import HEIGHT_HELP, WIDTH_HELP, detector_enum, image_size, size_schema
from .detectors import checked_detector

router = APIRouter(tags=["drives"], route_class=ApiRoute, responses=ERROR_RESPONSES)

DRIVE_SIZE = (640, 360)  # the drive camera's default width and height
MEDIA_TYPES = {TRACE_FILE: "text/csv", SUMMARY_FILE: "application/json", TRACE_PLOT_FILE: "image/png",
               PATH_PLOT_FILE: "image/png", "drive.mp4": "video/mp4", "drive.gif": "image/gif"}
JOB_NOT_FOUND: dict[int | str, dict[str, Any]] = {404: {"model": ErrorBody, "description": "no such drive job"}}


class DriveJob(JobBody):
    case_id: str
    detector: str
    controller: str
    files: dict[str, str] | None = Field(None, description="once done: file name -> URL")
    summary: dict[str, Any] | None = Field(None, description="once done: summary.json (the ASR criterion, "
                                                              "max deviation, departures)")


DRIVE_JOB: dict[int | str, dict[str, Any]] = {200: {"model": DriveJob}, **JOB_NOT_FOUND}


class DriveRequest(BaseModel):
    """Body of ``POST /api/drives``."""

    case_id: str = Field(description="id of a stored case", json_schema_extra={"pattern": ID_PATTERN.pattern})
    detector: str = Field(GROUND_TRUTH, description=f"one of {', '.join(DRIVE_DETECTORS)} (gt = the projected "
                                                    "ground truth, the reference) that can run here",
                          json_schema_extra=detector_enum(GROUND_TRUTH))
    controller: Literal["pure_pursuit", "stanley"] = Field("pure_pursuit", description="lateral controller")
    seconds: float | None = Field(None, gt=0, le=60, description="how long to drive; default the case's drive")
    width: int | None = Field(None, description=f"{WIDTH_HELP}; default {DRIVE_SIZE[0]}x{DRIVE_SIZE[1]} (at most "
                                                "the server's largest)", json_schema_extra=size_schema("max_width"))
    height: int | None = Field(None, description=HEIGHT_HELP, json_schema_extra=size_schema("max_height"))

    def size(self, case: Case, settings: Settings) -> tuple[int, int]:
        """The camera size: ``width``/``height`` as a frame's (``image_size``), or ``DRIVE_SIZE`` within the
        server's largest."""
        if self.width is None and self.height is None:
            return min(DRIVE_SIZE[0], settings.max_width), min(DRIVE_SIZE[1], settings.max_height)
        return image_size(self.width, self.height, case, settings)


def _files(job: Job) -> list[str]:
    if job.status != "done" or job.result is None:
        return []
    return sorted(path.name for path in job.result.iterdir() if path.name in MEDIA_TYPES)


def drive_body(job: Job, request: Request) -> dict[str, Any]:
    """A drive job's state, its links, and once done its summary and file URLs."""
    body: dict[str, Any] = {**job.to_dict(), "links": {"self": str(request.url_for("get_drive", job_id=job.id))}}
    files = _files(job)
    if files and job.result is not None:
        body["files"] = {name: str(request.url_for("drive_file", job_id=job.id, name=name)) for name in files}
        body["summary"] = json.loads((job.result / SUMMARY_FILE).read_text(encoding="utf-8"))
    return body


def _drive_job(state: StateDep, job_id: str) -> Job:
    job = state.jobs.get(job_id)
    if job.kind != "drive":
        raise ApiError(404, f"no drive job with id {job_id!r}", "job_id")
    return job


@router.post("/drives", status_code=202, summary="Start a closed-loop drive",
             responses={202: {"model": DriveJob,
                              "description": "drive queued: poll the Location (GET /api/drives/{job_id})"},
                        404: {"model": ErrorBody, "description": "no case with that id"}, **TOO_MANY})
def create_drive(body: DriveRequest, state: StateDep, request: Request) -> JSONResponse:
    """Drive a stored case with a detector in the loop; poll the returned job for its summary and files."""
    record = state.store.get(body.case_id)
    if body.detector != GROUND_TRUTH:
        checked_detector(body.detector, ready=True)  # a plug-in server that is down: 422 now, not a failed job
    size = body.size(record.case, state.settings)
    check_mesh_files(record.case, state.meshes_dir)
    settings = DriveSettings(detector=body.detector, controller=body.controller, seconds=body.seconds, size=size)
    meta = {"case_id": record.id, "case_version": record.version, "detector": body.detector,
            "controller": body.controller}
    key = (f"drive:{case_hash(record.case)}:{body.detector}:{body.controller}:{body.seconds}:"
           f"{size[0]}x{size[1]}")
    client = request.client.host if request.client else "unknown"
    job = drive_job(state.jobs, record.case, settings, meta, key=key, client=client, meshes_dir=state.meshes_dir)
    payload = drive_body(job, request)
    return JSONResponse(payload, status_code=202, headers={"Location": payload["links"]["self"]})


@router.get("/drives/{job_id}", summary="State of a drive job", response_model=None, responses=DRIVE_JOB)
def get_drive(job_id: str, state: StateDep, request: Request) -> dict[str, Any]:
    """``status``, ``done``/``total`` steps; once ``done`` also ``summary`` (the ASR criterion, max deviation,
    departures) and ``files``."""
    return drive_body(_drive_job(state, job_id), request)


@router.delete("/drives/{job_id}", summary="Cancel a drive job", response_model=None, responses=DRIVE_JOB)
def cancel_drive(job_id: str, state: StateDep, request: Request) -> dict[str, Any]:
    """Stop a queued or running drive (it ends as ``cancelled`` after its current step)."""
    _drive_job(state, job_id)
    return drive_body(state.jobs.cancel(job_id), request)


@router.get("/drives/{job_id}/files/{name}", summary="A file of a finished drive", response_class=FileResponse,
            responses={200: {"content": {media: {} for media in sorted(set(MEDIA_TYPES.values()))}},
                       404: {"model": ErrorBody}, 409: {"model": ErrorBody, "description": "not done (yet)"}})
def drive_file(job_id: str, name: str, state: StateDep) -> FileResponse:
    """One of the drive's files: ``trace.csv``, ``summary.json``, ``trace.png``, ``path.png``, ``drive.mp4``."""
    job = _drive_job(state, job_id)
    if name not in MEDIA_TYPES:
        raise ApiError(404, f"no file {name!r}: choose from {', '.join(MEDIA_TYPES)}", "name")
    if job.status != "done" or job.result is None:
        reason = f"failed: {job.error}" if job.status == "failed" else f"is {job.status} ({job.done}/{job.total})"
        raise ApiError(409, f"drive {job_id} {reason}", "job_id")
    path = job.result / name
    if not path.is_file():
        raise ApiError(404, f"drive {job_id} has no {name}", "name")
    return FileResponse(path, media_type=MEDIA_TYPES[name], filename=name)
