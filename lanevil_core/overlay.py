"""Draw TuSimple-style lane labels onto an image, one colour per lane.

Visible points are filled dots joined by a polyline; points hidden by an object are hollow rings.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from .typed import UInt8Array

# Distinct, saturated colours (sRGB) in lane order, left to right.
LANE_COLORS: tuple[tuple[int, int, int], ...] = (
    (255, 64, 64),
    (64, 220, 64),
    (64, 140, 255),
    (255, 200, 0),
    (230, 64, 255),
    (0, 230, 230),
)


def lane_color(index: int) -> tuple[int, int, int]:
    """The overlay colour of lane ``index`` (cycling after six)."""
    return LANE_COLORS[index % len(LANE_COLORS)]


def _points(xs: Sequence[int], h_samples: Sequence[int]) -> list[tuple[float, float, int]]:
    """(x, y, j) pixel centres of a lane's valid points, j = index into h_samples."""
    return [(x + 0.5, y + 0.5, j) for j, (x, y) in enumerate(zip(xs, h_samples)) if x >= 0]


def draw_lanes(image: UInt8Array, record: dict[str, Any], radius: float | None = None) -> UInt8Array:
    """A copy of ``image`` (H, W, 3) uint8 with the lanes of a TuSimple ``record`` drawn on it.

    ``record`` needs ``lanes`` and ``h_samples``; an optional ``visibility`` (same shape as ``lanes``) marks
    occluded points, drawn hollow.
    """
    height = image.shape[0]
    r = radius if radius is not None else max(1.5, height / 240)
    canvas = Image.fromarray(np.ascontiguousarray(image[..., :3], dtype=np.uint8), "RGB")
    draw = ImageDraw.Draw(canvas)
    visibility = record.get("visibility")
    for index, xs in enumerate(record["lanes"]):
        color = lane_color(index)
        points = _points(xs, record["h_samples"])
        if len(points) >= 2:
            draw.line([(x, y) for x, y, _ in points], fill=color, width=max(1, int(r)))
        for x, y, j in points:
            seen = visibility is None or bool(visibility[index][j])
            box = (x - r, y - r, x + r, y + r)
            draw.ellipse(box, fill=color if seen else None, outline=color if seen else (255, 255, 255))
    return np.asarray(canvas, dtype=np.uint8).copy()
