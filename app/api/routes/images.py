"""Rendered frames: ``GET /api/cases/{case_id}/frames/{frame}.png|jpg`` and ``POST /api/render`` (unsaved cases).

Images come from the shared ``FrameService`` (content-addressed caches), so the ETag is known before anything is
rendered and a revalidation (``If-None-Match``) costs no render. Query overrides (severity, sun) render a variant
of the case without saving it, for scrubbing sliders; ``detector=`` draws a detector's lanes on the frame.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Header, Query, Response

from lanevil_core.case import Case, Ego

from ...state import AppState
from ..case_bodies import CaseBody
from ..deps import FramePath, RecordDep, StateDep
from ..errors import ERROR_RESPONSES, RENDER_BUSY, ApiRoute, ErrorBody
from ..params import ImageFormat, RenderQuery, RenderQueryDep, check_frame, etag_matches, image_size
from .cases import split_body, validate_case
from .detectors import checked_detector, detector_errors

router = APIRouter(tags=["frames"], route_class=ApiRoute, responses=ERROR_RESPONSES)

# Stored cases change under the same URL: caches may keep the image but must revalidate it (cheap: ETag -> 304).
FRAME_CACHE_CONTROL = "no-cache"
IMAGE_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"content": {"image/png": {}, "image/jpeg": {}}, "description": "the rendered frame"},
    304: {"description": "not modified (If-None-Match matched the ETag)"},
    404: {"model": ErrorBody, "description": "no such case or frame"},
    **RENDER_BUSY,
}
MAX_FRAMES = Ego.model_json_schema()["properties"]["frames"]["maximum"]  # frames of the longest case
IfNoneMatch = Annotated[str | None, Header(alias="If-None-Match")]


def image_response(state: AppState, case: Case, frame: int, query: RenderQuery, fmt: ImageFormat,
                   if_none_match: str | None, cache_control: str) -> Response:
    """The encoded frame (or a 304), with ETag and Cache-Control."""
    size = image_size(query.width, query.height, case, state.settings)
    detector = checked_detector(query.detector)
    case = query.apply(case)
    with detector_errors():
        etag = state.frames.image_etag(case, frame, size, query.overlay, fmt, detector)
        headers = {"ETag": f'"{etag}"', "Cache-Control": cache_control}
        if etag_matches(if_none_match, etag):
            return Response(status_code=304, headers=headers)
        image = state.frames.image(case, frame, size, query.overlay, fmt, detector)
    return Response(image.data, media_type=image.media_type, headers=headers)


@router.get("/cases/{case_id}/frames/{frame}.{fmt}", summary="Render a frame of a stored case",
            response_class=Response, responses=IMAGE_RESPONSES)
def get_frame(record: RecordDep, frame: FramePath, fmt: ImageFormat, state: StateDep, query: RenderQueryDep,
              if_none_match: IfNoneMatch = None) -> Response:
    """Frame ``frame`` as PNG or JPEG at the case camera's size or ``width``x``height``, optionally with the lane
    overlay (ground truth, one colour per lane), a detector's lanes (``detector=``, magenta) and severity/sun
    overrides (not saved)."""
    check_frame(record.case, frame)
    return image_response(state, record.case, frame, query, fmt, if_none_match, FRAME_CACHE_CONTROL)


@router.post("/render", summary="Render a frame of a case given in the body", response_class=Response,
             responses=IMAGE_RESPONSES)
def render_case(
    body: CaseBody,
    state: StateDep,
    query: RenderQueryDep,
    frame: Annotated[int, Query(description="frame index, below the case's `ego.frames`",
                                json_schema_extra={"minimum": 0, "maximum": MAX_FRAMES - 1})] = 0,
    fmt: Annotated[ImageFormat, Query(alias="format", description="png or jpg")] = "png",
    if_none_match: IfNoneMatch = None,
) -> Response:
    """Render an unsaved case (e.g. the editor's working copy); same query parameters as the frame route."""
    document, _, _ = split_body(body, allow_version=True)
    case = validate_case(document, "case" if "case" in body else "", state)
    check_frame(case, frame)
    # the ETag is a content hash: an equal case renders the same bytes, so clients may cache by it
    return image_response(state, case, frame, query, fmt, if_none_match, "private, max-age=3600")
