"""Lane detectors: ``GET /api/detectors`` and ``GET /api/cases/{case_id}/frames/{frame}/detections``.

A detection runs a detector (``lanevil_core.detect.registry``: learned ONNX models, classical OpenCV baselines, and
the plug-ins the server is configured with: HTTP servers, ONNX models with a sidecar, installed Python plug-ins;
docs/detectors.md) on the rendered frame and scores it against the frame's ground truth with the official TuSimple
metric (``lanevil_core.detect.frame_detection``); the frame service caches it next to the frame. Unknown or unavailable
detectors, and a plug-in that fails (its server down, an answer that is not lanes), are a 422 naming ``detector``.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Annotated, Any

from fastapi import APIRouter, Query
from pydantic import BaseModel, Field

from lanevil_core.detect.catalog import available_detector, detector_infos
from lanevil_core.detect.registry import ready_detector
from lanevil_core.detect.split import METHODS
from lanevil_core.metrics.formats import LaneFileError

from ..deps import FramePath, RecordDep, StateDep
from ..errors import ERROR_RESPONSES, RENDER_BUSY, ApiError, ApiRoute, ErrorBody
from ..params import ScrubQueryDep, check_frame, detector_enum, image_size

router = APIRouter(tags=["detectors"], route_class=ApiRoute, responses=ERROR_RESPONSES)

DETECTOR_HELP = (f"a detector name of `GET /api/detectors`: built-in {', '.join(METHODS)}, or a plug-in "
                 "configured on the server")


@contextmanager
def detector_errors() -> Iterator[None]:
    """Turn the core's detector errors (unknown, unavailable, a model that fails) into a 422 naming ``detector``."""
    try:
        yield
    except LaneFileError as error:
        raise ApiError(422, str(error).removeprefix("detector: "), "detector") from None


def checked_detector(name: str | None, ready: bool = False) -> str | None:
    """``name`` when it is a detector that can run here (None stays None); else a 422 naming ``detector``. With
    ``ready``, an HTTP plug-in is asked once (``detect.registry.ready_detector``), for a job that runs later."""
    if name is not None:
        with detector_errors():
            available_detector(name)
            if ready:
                ready_detector(name, sources=False)
    return name


class DetectorEntry(BaseModel):
    """A detector of ``GET /api/detectors``."""

    name: str = Field(description="the value of `detector=`")
    kind: str = Field(description="`learned` (a shipped ONNX network), `classical` (OpenCV), or a plug-in: `http` (a "
                                  "detector server), `onnx` (a model with a sidecar), `plugin` (a Python plug-in)")
    available: bool = Field(description="whether it can run on this server")
    reason: str | None = Field(None, description="why it is not available")
    model: dict[str, Any] | None = Field(None, description="a learned detector's model: `input_size`, `backbone`, "
                                                           "`width`, and from its training.json `val_accuracy`, "
                                                           "`epochs`, `train_frames`, `val_frames`, `data`, "
                                                           "`augment`")
    source: str | None = Field(None, description="a plug-in's URL, `onnx:PATH` or entry point")
    real_trained: bool = Field(False, description="trained on real roads (reported in the Real -> LanEvil table)")


class DetectorList(BaseModel):
    data: list[DetectorEntry]
    count: int


class FrameDetectionBody(BaseModel):
    """A detector's lanes on one frame and their TuSimple score against the frame's ground truth."""

    case_id: str
    frame: int
    detector: str
    width: int = Field(description="frame width, pixels")
    height: int = Field(description="frame height, pixels")
    h_samples: list[int] = Field(description="rows of the lanes, frame pixels")
    lanes: list[list[int]] = Field(description="detected lanes: x per row, -2 = none")
    gt_lanes: list[list[int]] = Field(description="ground-truth lanes at the same rows")
    accuracy: float = Field(description="official TuSimple per-image accuracy, 0..1 (scored at 1280x720)")
    fp: float = Field(description="false-positive rate")
    fn: float = Field(description="false-negative rate")
    run_time_ms: float = Field(description="wall-clock time of the detection on this server (not scored)")


@router.get("/detectors", summary="The lane detectors and whether they can run here", response_model=DetectorList)
def get_detectors() -> dict[str, Any]:
    """Every detector name, its kind (learned / classical / a plug-in), whether it is available (a learned one needs
    its shipped model), for learned ones the model's summary (`val_accuracy`, `input_size`, ...), for plug-ins their
    source and whether they were trained on real roads. A malformed plug-in configuration is a 422."""
    with detector_errors():
        data = [info.as_dict() for info in detector_infos()]
    return {"data": data, "count": len(data)}


@router.get("/cases/{case_id}/frames/{frame}/detections", summary="A detector's lanes on a frame, scored",
            response_model=FrameDetectionBody,
            responses={404: {"model": ErrorBody, "description": "no such case or frame"}, **RENDER_BUSY})
def get_detections(
    record: RecordDep,
    frame: FramePath,
    state: StateDep,
    query: ScrubQueryDep,
    detector: Annotated[str, Query(max_length=40, description=DETECTOR_HELP, json_schema_extra=detector_enum())],
) -> dict[str, Any]:
    """Run `detector` on frame `frame` (same size and override parameters as the frame image) and score its lanes
    against the frame's TuSimple labels: `accuracy`, `fp`, `fn` are the official per-image values, computed on the
    1280x720 grid whatever the frame's size; the metric's 200 ms run-time rule is not applied."""
    check_frame(record.case, frame)
    checked_detector(detector)
    size = image_size(query.width, query.height, record.case, state.settings)
    case = query.apply(record.case)
    with detector_errors():
        found = state.frames.detection(case, frame, size, detector)
    return {"case_id": record.id, "frame": frame, **found.as_dict()}
