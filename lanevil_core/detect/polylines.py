"""Lane polylines in image pixels: what plug-in detectors answer, checked and turned into TuSimple lanes.

A plug-in detector (an HTTP server, an installed Python plug-in, an ONNX model with a standard head) answers the
lanes it sees as polylines ``[[x, y], ...]`` in the pixels of the image it was given: ``x`` the column and ``y``
the row, with ``(0, 0)`` the centre of the top-left pixel as in a TuSimple file (continuous image coordinates,
docs/conventions.md, are ``(x + 0.5, y + 0.5)``). Points may come in any order along the lane; a lane is read
between its highest and lowest point, linear between points, and absent above and below.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..metrics.formats import LaneFileError
from ..typed import FloatArray
from .common import lane_columns, sample_rows

MIN_POLYLINE_POINTS = 2


def checked_polylines(answer: Any, where: str) -> list[FloatArray]:
    """The lanes of a detector's JSON answer ``{"lanes": [[[x, y], ...], ...], "scores": [...]?}`` as (n, 2)
    float64 arrays; raises ``LaneFileError`` naming ``where`` and the first bad part."""
    if not isinstance(answer, dict) or "lanes" not in answer:
        raise LaneFileError(f"{where}: the answer is not an object with \"lanes\"")
    lanes = answer["lanes"]
    if not isinstance(lanes, list):
        raise LaneFileError(f"{where}: \"lanes\" is not a list")
    scores = answer.get("scores")
    if scores is not None and (not isinstance(scores, list) or len(scores) != len(lanes)
                               or not all(_is_number(score) for score in scores)):
        raise LaneFileError(f"{where}: \"scores\" is not a list of {len(lanes)} numbers")
    return [_checked_lane(lane, f"{where}: lanes[{index}]") for index, lane in enumerate(lanes)]


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _checked_lane(lane: Any, where: str) -> FloatArray:
    if not isinstance(lane, list):
        raise LaneFileError(f"{where} is not a list of [x, y] points")
    for index, point in enumerate(lane):
        if not (isinstance(point, list | tuple) and len(point) == 2 and all(_is_number(v) for v in point)):
            raise LaneFileError(f"{where}[{index}] is not a point [x, y] of two finite numbers")
    return np.asarray(lane, np.float64).reshape(-1, 2)


def scaled_polylines(polylines: Sequence[FloatArray], from_size: tuple[int, int],
                     to_size: tuple[int, int]) -> list[FloatArray]:
    """Polylines of an image of ``from_size`` (width, height) moved to the same view at ``to_size``."""
    if from_size == to_size:
        return [np.asarray(line, np.float64) for line in polylines]
    scale = np.array([to_size[0] / from_size[0], to_size[1] / from_size[1]])
    return [(np.asarray(line, np.float64) + 0.5) * scale - 0.5 for line in polylines]


def polyline_lanes(polylines: Sequence[FloatArray], h_samples: Sequence[int], width: int) -> list[list[int]]:
    """TuSimple lanes (x per row of ``h_samples``, -2 = none) of the polylines with at least two points on rows
    of an image ``width`` wide, in the polylines' order; lanes with fewer than two points on the rows are left out."""
    v_rows = sample_rows(list(h_samples))
    lanes = []
    for line in polylines:
        if len(line) < MIN_POLYLINE_POINTS:
            continue
        order = np.argsort(line[:, 1], kind="stable")
        v_line, u_line = line[order, 1] + 0.5, line[order, 0] + 0.5
        u_rows = np.where((v_rows >= v_line[0]) & (v_rows <= v_line[-1]), np.interp(v_rows, v_line, u_line), np.nan)
        lane = lane_columns(u_rows, width)
        if sum(x >= 0 for x in lane) >= MIN_POLYLINE_POINTS:
            lanes.append(lane)
    return lanes
