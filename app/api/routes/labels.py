"""``GET /api/cases/{case_id}/labels``: lane ground truth of a frame range as TuSimple JSON lines or CULane text.

TuSimple records are those of an export's ``labels.json`` (1280x720 frames, ``raw_file`` = ``000000.png``, plus the
``visibility``, ``line_types`` and ``frame`` extensions); CULane lines are those of ``culane/000000.lines.txt``
(1640x590 frames). Labels need a render of their frame (hidden points are found from depth), so a request holds at
most ``MAX_LABEL_FRAMES`` frames.
"""

from __future__ import annotations

import json
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Query, Response

from lanevil_core.labels.lanes import CULANE_SIZE, TUSIMPLE_SIZE

from ..deps import RecordDep, StateDep
from ..errors import ERROR_RESPONSES, RENDER_BUSY, ApiRoute, ErrorBody
from ..params import FRAMES_PATTERN, frame_range

router = APIRouter(tags=["labels"], route_class=ApiRoute, responses={**ERROR_RESPONSES, **RENDER_BUSY})

MAX_LABEL_FRAMES = 50  # each frame is a 1280x720 (CULane: 1640x590) render: ~0.2-0.3 s
JSON_LINES = "application/x-ndjson"
LABEL_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"content": {JSON_LINES: {}, "application/json": {}},
          "description": "tusimple: one JSON record per line; culane: {format, size, lines: {frame: text}}"},
    404: {"model": ErrorBody, "description": "no case with that id"},
}


@router.get("/cases/{case_id}/labels", summary="Lane labels of a frame range", response_class=Response,
            responses=LABEL_RESPONSES)
def get_labels(
    record: RecordDep,
    state: StateDep,
    format: Annotated[Literal["tusimple", "culane"], Query(description="label format")] = "tusimple",  # noqa: A002
    frames: Annotated[str | None, Query(description=f"START:STOP (half-open) or N; default 0:1; at most "
                                                    f"{MAX_LABEL_FRAMES} frames",
                                        json_schema_extra={"pattern": FRAMES_PATTERN})] = None,
) -> Response:
    """TuSimple: JSON lines (``application/x-ndjson``), one record per frame. CULane: a JSON object
    ``{"format": "culane", "size": [1640, 590], "lines": {"0": "x1 y1 x2 y2 ...\\n...", ...}}`` keyed by frame."""
    case = record.case
    chosen = frame_range(frames, case.ego.frames, range(0, 1), MAX_LABEL_FRAMES)
    if format == "tusimple":
        records = [state.frames.frame(case, index, TUSIMPLE_SIZE).record for index in chosen]
        text = "".join(json.dumps(row) + "\n" for row in records)
        return Response(text, media_type=JSON_LINES)
    lines = {str(index): state.frames.culane_lines(case, index) for index in chosen}
    body = {"format": "culane", "size": list(CULANE_SIZE), "lines": lines}
    return Response(json.dumps(body), media_type="application/json")
