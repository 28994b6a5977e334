"""Where a camera's straight-road lines meet: the vanishing point from lane labels of a few of its frames.

A user who has labelled frames of their own camera (TuSimple JSON lines, e.g. the training labels of their
real-trained detector) on straight, level road gets the camera's horizon from them: each lane's lower part
(``LOWER_SHARE`` of its labelled rows, nearest the camera, where a gentle bend has not yet turned it) is fitted by a
straight line ``u = a v + b``; the frame's vanishing point is the least-squares meeting point of its lines, and
the camera's is the median over frames. Coordinates are continuous image coordinates (docs/conventions.md): a
label ``(x, h)`` is the point ``(x + 0.5, h + 0.5)``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..typed import FloatArray

LOWER_SHARE = 0.6
MIN_LANE_POINTS = 4
MIN_SLOPE_SPREAD = 0.05  # lines nearly parallel in the image meet nowhere useful


def lane_line(lane: Sequence[float], h_samples: Sequence[float]) -> FloatArray | None:
    """(a, b) of ``u = a v + b`` fitted to the lower part of a labelled lane, or None with too few points."""
    points = [(x + 0.5, h + 0.5) for x, h in zip(lane, h_samples, strict=True) if x >= 0]
    if len(points) < MIN_LANE_POINTS:
        return None
    points.sort(key=lambda point: point[1])
    lower = np.asarray(points[int(len(points) * (1.0 - LOWER_SHARE)):], np.float64)
    if len(lower) < 2 or np.ptp(lower[:, 1]) == 0:
        return None
    return np.polyfit(lower[:, 1], lower[:, 0], 1)


def meeting_point(lines: Sequence[FloatArray]) -> tuple[float, float] | None:
    """The least-squares meeting point (u, v) of lines ``u = a v + b``, or None when they are near parallel."""
    if len(lines) < 2 or np.ptp([line[0] for line in lines]) < MIN_SLOPE_SPREAD:
        return None
    # each line: u - a v - b = 0, normalised so every line weighs its distance in pixels
    normals = np.array([[1.0, -a] for a, _ in lines]) / np.hypot(1.0, np.array([a for a, _ in lines]))[:, None]
    offsets = np.array([b for _, b in lines]) / np.hypot(1.0, np.array([a for a, _ in lines]))
    u, v = np.linalg.lstsq(normals, offsets, rcond=None)[0]
    return float(u), float(v)


def vanishing_point(records: Sequence[tuple[Sequence[Sequence[float]], Sequence[float]]]) -> tuple[float, float]:
    """The median vanishing point (u, v) over frames given as (lanes, h_samples); raises ValueError when no frame
    has two lanes that meet."""
    found = [point for lanes, rows in records
             if (point := meeting_point([line for lane in lanes if (line := lane_line(lane, rows)) is not None]))
             is not None]
    if not found:
        raise ValueError("no frame of the labels has two lanes that meet (label straight-road frames)")
    u, v = np.median(np.asarray(found), axis=0)
    return float(u), float(v)
