"""Request parameters shared by several routes: frame ranges, image sizes, versions, ETags, render options."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Annotated, Any

from fastapi import Depends, Query
from pydantic import ValidationError

from lanevil_core.case import Case, Sun
from lanevil_core.detect.catalog import detector_infos
from lanevil_core.images import ImageFormat as ImageFormat  # the format parameter of the image routes
from lanevil_core.pipeline.frames import parse_frame_range

from ..frames import apply_overrides
from ..settings import Settings
from .errors import ApiError, first_error
from .openapi import SERVER_LIMIT

MIN_SIZE = 64  # smallest rendered width or height (the case camera's lower bound)
# What ``frame_range`` reads, for the OpenAPI description: ``START:STOP`` (either end optional) or ``N``; whether the
# range lies in the case (and is not empty) depends on the case, so only the server can say.
FRAMES_PATTERN = r"^([0-9]{1,3}|[0-9]{0,3}:[0-9]{0,3})$"
# pydantic locations of the override fields in a case -> the query parameter that set them
OVERRIDE_FIELDS: dict[tuple[str, ...], str] = {("sun", "azimuth"): "sun_azimuth", ("sun", "altitude"): "sun_altitude",
                                               ("sun", "intensity"): "sun_intensity"}


def frame_range(text: str | None, frames: int, default: range, limit: int | None = None) -> range:
    """``A:B`` (half-open, either end optional: ``:10``, ``90:``) or a single frame ``N`` -> a range of frames
    of a case with ``frames`` frames; at most ``limit`` frames. Errors name ``frames``."""
    if text is None or not text.strip():
        chosen = default
    else:
        chosen = _parse_range(text.strip(), frames)
    if limit is not None and len(chosen) > limit:
        raise ApiError(422, f"at most {limit} frames per request (asked for {len(chosen)}: {chosen.start}:"
                            f"{chosen.stop})", "frames")
    return chosen


def _parse_range(text: str, frames: int) -> range:
    try:
        return parse_frame_range(text, frames, single=True)
    except ValueError as error:
        raise ApiError(422, str(error), "frames") from None


def image_size(width: int | None, height: int | None, case: Case, settings: Settings) -> tuple[int, int]:
    """The requested (width, height), each within 64..the server's max. Neither: the case camera's (capped); one
    alone: the other follows the camera's aspect ratio (within the same bounds)."""
    largest = {"width": settings.max_width, "height": settings.max_height}
    for name, value in (("width", width), ("height", height)):
        if value is not None and not MIN_SIZE <= value <= largest[name]:
            raise ApiError(422, f"{value} is outside {MIN_SIZE}..{largest[name]}", name)
    camera = case.camera
    if width is None:
        if height is None:
            return min(camera.width, settings.max_width), min(camera.height, settings.max_height)
        return _within(round(height * camera.width / camera.height), settings.max_width), height
    if height is None:
        return width, _within(round(width * camera.height / camera.width), settings.max_height)
    return width, height


def _within(value: int, largest: int) -> int:
    return max(MIN_SIZE, min(value, largest))


def check_frame(case: Case, frame: int) -> int:
    """``frame`` when the case has it; else a 404 naming ``frame`` (the frame asked for does not exist)."""
    if not 0 <= frame < case.ego.frames:
        raise ApiError(404, f"{frame} is outside 0..{case.ego.frames - 1} (the case has {case.ego.frames} "
                                    "frames)", "frame")
    return frame


MAX_VERSION_DIGITS = 18  # a version fits an int64; longer digit strings are refused before int() reads them
# What ``parse_version`` takes, for the OpenAPI description of ``If-Match``.
VERSION_PATTERN = rf'^\s*(\*|(W/)?"?[0-9]{{1,{MAX_VERSION_DIGITS}}}"?)\s*$'


def parse_version(text: str | None, field: str = "If-Match") -> int | None:
    """A version from ``If-Match`` (``"3"``, ``W/"3"``, ``3``; ``*`` = any version -> None)."""
    if text is None:
        return None
    value = text.strip()
    if value == "*":
        return None
    value = value.removeprefix("W/").strip('"')
    if not (value.isascii() and value.isdigit()) or len(value) > MAX_VERSION_DIGITS:
        shown = text if len(text) <= 40 else f"{text[:40]}..."
        raise ApiError(422, f"{shown!r} is not a case version (send the ETag of the case, e.g. \"3\"; at most "
                            f"{MAX_VERSION_DIGITS} digits)", field)
    return int(value)


def etag_matches(if_none_match: str | None, etag: str) -> bool:
    """Whether an ``If-None-Match`` header names ``etag`` (quoted or not, weak or strong) or is ``*``."""
    if not if_none_match:
        return False
    tags = [tag.strip().removeprefix("W/").strip('"') for tag in if_none_match.split(",")]
    return "*" in tags or etag in tags


@dataclass(frozen=True)
class RenderQuery:
    """The query parameters of an image request (a detections request: the same without overlay and detector)."""

    overlay: bool
    width: int | None
    height: int | None
    severity: int | None
    sun_azimuth: float | None
    sun_altitude: float | None
    sun_intensity: float | None
    detector: str | None = None

    def apply(self, case: Case) -> Case:
        """``case`` with the overrides applied; an out-of-range override is a 422 naming its query parameter."""
        if (self.severity, self.sun_azimuth, self.sun_altitude, self.sun_intensity) == (None, None, None, None):
            return case
        try:
            return apply_overrides(case, self.severity, self.sun_azimuth, self.sun_altitude, self.sun_intensity)
        except ValidationError as error:
            loc = tuple(str(part) for part in error.errors()[0].get("loc", ()))
            field, message = first_error(error.errors())
            name = OVERRIDE_FIELDS.get(loc, "severity" if "severity" in loc else field)
            raise ApiError(422, message, name) from None


def sun_bounds(name: str) -> dict[str, Any]:
    """The ``minimum``/``maximum`` of the case schema's ``sun.<name>``, for the override's OpenAPI description."""
    schema = Sun.model_json_schema()["properties"][name]
    return {key: schema[key] for key in ("minimum", "maximum") if key in schema}


def size_schema(limit: str) -> dict[str, Any]:
    """OpenAPI bounds of an image width or height: ``MIN_SIZE`` up to the setting ``limit`` (``max_width`` …),
    filled in from the server's settings when the description is built (``openapi.SERVER_LIMIT``)."""
    return {"minimum": MIN_SIZE, SERVER_LIMIT: limit}


def available_detectors() -> list[str]:
    """The detector names that can run on this server (``GET /api/detectors`` with ``available``)."""
    return [info.name for info in detector_infos() if info.available]


def detector_enum(*also: str) -> Callable[[dict[str, Any]], None]:
    """``json_schema_extra`` listing ``also`` and the available detectors, when the OpenAPI document is built."""

    def extra(schema: dict[str, Any]) -> None:
        schema["enum"] = [*also, *available_detectors()]

    return extra


WIDTH_HELP = "image width, 64 up to the server's largest (alone: the height follows the case camera's aspect ratio)"
HEIGHT_HELP = "image height, 64 up to the server's largest (alone: the width follows the case camera's aspect ratio)"


def scrub_query(
    width: Annotated[int | None, Query(description=f"{WIDTH_HELP}; default: the case camera's",
                                       json_schema_extra=size_schema("max_width"))] = None,
    height: Annotated[int | None, Query(description=HEIGHT_HELP, json_schema_extra=size_schema("max_height"))] = None,
    severity: Annotated[int | None, Query(ge=1, le=5, description="render every illusion at this level")] = None,
    sun_azimuth: Annotated[float | None, Query(description="sun azimuth override (degrees)",
                                               json_schema_extra=sun_bounds("azimuth"))] = None,
    sun_altitude: Annotated[float | None, Query(description="sun altitude override (degrees)",
                                                json_schema_extra=sun_bounds("altitude"))] = None,
    sun_intensity: Annotated[float | None, Query(description="sun intensity override",
                                                 json_schema_extra=sun_bounds("intensity"))] = None,
) -> RenderQuery:
    """Size and overrides: what picks the rendered frame."""
    return RenderQuery(False, width, height, severity, sun_azimuth, sun_altitude, sun_intensity)


ScrubQueryDep = Annotated[RenderQuery, Depends(scrub_query)]


def render_query(
    scrub: ScrubQueryDep,
    overlay: Annotated[bool, Query(description="draw the TuSimple lane labels on the image")] = False,
    detector: Annotated[str | None, Query(max_length=40, description="draw this detector's lanes (magenta): a "
                                          "name of `GET /api/detectors`; empty = none",
                                          json_schema_extra=detector_enum(""))] = None,
) -> RenderQuery:
    return replace(scrub, overlay=overlay, detector=detector or None)


RenderQueryDep = Annotated[RenderQuery, Depends(render_query)]
