"""Draw TuSimple-style lanes onto an image: ground-truth labels one colour per lane, a detector's lanes in one colour.

Visible points are filled dots joined by a polyline; points hidden by an object are hollow rings. A detector's
lanes go through the same drawing as a wide ``DETECTION_COLOR`` band without dots (magenta, no lane's colour);
drawn under the labels, a detected lane that matches shows as a magenta band behind the label's dots and a wrong
one as a lone band.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from ..typed import UInt8Array

Color = tuple[int, int, int]

# Distinct, saturated colours (sRGB) of ground-truth lanes, in lane order, left to right.
LANE_COLORS: tuple[Color, ...] = (
    (255, 64, 64),
    (64, 220, 64),
    (64, 140, 255),
    (255, 200, 0),
    (255, 140, 0),
    (0, 230, 230),
)
# Every lane a detector found (no ground-truth lane has a magenta hue).
DETECTION_COLOR: Color = (255, 0, 255)


def lane_color(index: int) -> Color:
    """The overlay colour of lane ``index`` (cycling after six)."""
    return LANE_COLORS[index % len(LANE_COLORS)]


def _points(xs: Sequence[int], h_samples: Sequence[int]) -> list[tuple[float, float, int]]:
    """(x, y, j) pixel centres of a lane's valid points, j = index into h_samples."""
    return [(x + 0.5, y + 0.5, j) for j, (x, y) in enumerate(zip(xs, h_samples)) if x >= 0]


def draw_lanes(image: UInt8Array, record: dict[str, Any], radius: float | None = None,
               color: Color | None = None, band: bool = False) -> UInt8Array:
    """A copy of ``image`` (H, W, 3) uint8 with the lanes of a TuSimple ``record`` drawn on it.

    ``record`` needs ``lanes`` and ``h_samples``; an optional ``visibility`` (same shape as ``lanes``) marks
    occluded points, drawn hollow. ``color``: one colour for every lane (default: ``lane_color`` of each).
    ``band``: a line three dot radii wide and no dots (how detections are drawn).
    """
    height = image.shape[0]
    r = radius if radius is not None else max(1.5, height / 240)
    canvas = Image.fromarray(np.ascontiguousarray(image[..., :3], dtype=np.uint8), "RGB")
    draw = ImageDraw.Draw(canvas)
    visibility = record.get("visibility")
    for index, xs in enumerate(record["lanes"]):
        fill = color or lane_color(index)
        points = _points(xs, record["h_samples"])
        if len(points) >= 2:
            width = max(3, round(3 * r)) if band else max(1, int(r))
            draw.line([(x, y) for x, y, _ in points], fill=fill, width=width, joint="curve" if band else None)
        if band:
            continue
        for x, y, j in points:
            seen = visibility is None or bool(visibility[index][j])
            box = (x - r, y - r, x + r, y + r)
            draw.ellipse(box, fill=fill if seen else None, outline=fill if seen else (255, 255, 255))
    return np.asarray(canvas, dtype=np.uint8).copy()


def draw_detections(image: UInt8Array, lanes: Sequence[Sequence[int]], h_samples: Sequence[int],
                    radius: float | None = None) -> UInt8Array:
    """A copy of ``image`` with a detector's TuSimple ``lanes`` (x per row of ``h_samples``, -2 = none) drawn as
    ``DETECTION_COLOR`` bands (draw ground-truth labels after them, on top)."""
    return draw_lanes(image, {"lanes": lanes, "h_samples": h_samples}, radius, DETECTION_COLOR, band=True)
