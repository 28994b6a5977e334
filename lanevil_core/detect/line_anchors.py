"""LaneATT's line anchors and their encoding, in numpy (inference needs no torch).

An anchor is a straight line entering the image at a start point on its left, right or bottom border at a fixed
angle (LaneATT's angle sets). A lane is predicted relative to an anchor: an x offset at each row of
``spec.anchor_rows`` plus the lane's bottom row and length (rows). Training marks the anchors near a ground-truth
lane positive (mean horizontal distance over the lane's rows); decoding keeps confident anchors and suppresses
lanes that lie within ``NMS_DISTANCE`` of a stronger one (LaneATT's lane NMS).

Coordinates are normalised image coordinates (see ``lane_slots``); an angle is in degrees from the image's
+x axis, measured upwards (90 = vertical), in pixels of an image of the given aspect.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..typed import BoolArray, FloatArray
from .lane_slots import LaneLine

SIDE_ANGLES = (72.0, 60.0, 49.0, 39.0, 30.0, 22.0)  # left border; the right border mirrors them
BOTTOM_ANGLES = (165.0, 150.0, 141.0, 131.0, 120.0, 108.0, 100.0, 90.0, 80.0, 72.0, 60.0, 49.0, 39.0, 30.0, 15.0)
SIDE_STARTS = 10  # start points on each side border, evenly over y_norm SIDE_TOP ... 1
SIDE_TOP = 0.45
BOTTOM_STARTS = 20  # start points on the bottom border, evenly over x_norm 0 ... 1
POSITIVE_DISTANCE = 0.05  # normalised mean horizontal distance below which an anchor is a lane's
NEGATIVE_DISTANCE = 0.08  # ... above which it is background (between: ignored by the classifier)
UNCOVERED_DISTANCE = 0.5  # distance counted at a lane row below the anchor's start
NMS_DISTANCE = 0.03
# LaneATT's TuSimple setting is 0.2 (focal-loss scores stay low); with the score loss weighted 10x as in LaneATT,
# the anchors guessed from the road's layout still reach 0.2-0.4, and 0.5 is where accuracy on held-out
# drawn-camera training frames peaks (65.2 % against 33.7 % at 0.2).
SCORE_THRESHOLD = 0.5
IGNORE = -1


def line_anchors() -> FloatArray:
    """(A, 3) float64 anchors ``(x0_norm, y0_norm, angle_deg)``: left, right, then bottom border."""
    side_y = np.linspace(SIDE_TOP, 1.0, SIDE_STARTS, endpoint=False)
    left = [(0.0, y, a) for y in side_y for a in SIDE_ANGLES]
    right = [(1.0, y, 180.0 - a) for y in side_y for a in SIDE_ANGLES]
    bottom = [(x, 1.0, a) for x in np.linspace(0.0, 1.0, BOTTOM_STARTS) for a in BOTTOM_ANGLES]
    return np.array(left + right + bottom, np.float64)


def anchor_xs(anchors: FloatArray, rows: FloatArray, aspect: float) -> FloatArray:
    """(A, R) x_norm of each anchor line at rows ``rows`` (y_norm), extended past its start; ``aspect`` = W / H."""
    x0, y0, angle = anchors[:, :1], anchors[:, 1:2], np.radians(anchors[:, 2:])
    return x0 + (y0 - np.asarray(rows)[None]) / (aspect * np.tan(angle))


def anchor_covers(anchors: FloatArray, rows: FloatArray) -> BoolArray:
    """(A, R) bool: the rows at or above each anchor's start (the part of the line inside the image's rows)."""
    return np.asarray(rows)[None] <= anchors[:, 1:2] + 1e-9


@dataclass(frozen=True)
class AnchorTargets:
    """Training targets of one frame: ``labels`` (A,) int64 1 lane / 0 background / -1 ignored; ``regression``
    (A, 2 + R) float32 ``[bottom row / (R - 1), length / R, x offsets per row]``; ``row_mask`` (A, R) float32
    the rows whose offset is learnt (a positive anchor's lane rows)."""

    labels: np.ndarray
    regression: np.ndarray
    row_mask: np.ndarray


def encode_anchors(placed: list[LaneLine | None], anchors: FloatArray, rows: FloatArray,
                   aspect: float) -> AnchorTargets:
    """The anchor targets of the lanes ``placed`` (slots; None = empty)."""
    xs = anchor_xs(anchors, rows, aspect)
    covers = anchor_covers(anchors, rows)
    count, n_rows = xs.shape
    labels = np.zeros(count, np.int64)
    regression = np.zeros((count, 2 + n_rows), np.float32)
    row_mask = np.zeros((count, n_rows), np.float32)
    lanes = [line.x_at(rows) for line in placed if line is not None]
    lanes = [x for x in lanes if int(np.isfinite(x).sum()) >= 2]
    if not lanes:
        return AnchorTargets(labels, regression, row_mask)
    distance = np.stack([_distances(x, xs, covers) for x in lanes], axis=1)  # (A, lanes)
    nearest = np.argmin(distance, axis=1)
    best = distance[np.arange(count), nearest]
    labels[(best >= POSITIVE_DISTANCE) & (best < NEGATIVE_DISTANCE)] = IGNORE
    positive = best < POSITIVE_DISTANCE
    for lane in range(len(lanes)):  # every lane gets at least its nearest anchor
        anchor = int(np.argmin(distance[:, lane]))
        positive[anchor], nearest[anchor] = True, lane
    labels[positive] = 1
    for index in np.flatnonzero(positive):
        anchor = int(index)
        x = lanes[nearest[anchor]]
        present = np.flatnonzero(np.isfinite(x))
        top, bottom = int(present[0]), int(present[-1])
        regression[anchor, 0] = bottom / max(n_rows - 1, 1)
        regression[anchor, 1] = (bottom - top + 1) / n_rows
        regression[anchor, 2:][present] = x[present] - xs[anchor, present]
        row_mask[anchor, present] = 1.0
    return AnchorTargets(labels, regression, row_mask)


def _distances(lane_x: FloatArray, xs: FloatArray, covers: BoolArray) -> FloatArray:
    """(A,) mean horizontal distance of every anchor to a lane over the lane's rows (rows below an anchor's start
    count ``UNCOVERED_DISTANCE``)."""
    present = np.isfinite(lane_x)
    gap = np.abs(xs[:, present] - lane_x[present][None])
    gap = np.where(covers[:, present], gap, UNCOVERED_DISTANCE)
    return np.asarray(gap.mean(axis=1))


def anchor_lanes(regression: FloatArray, anchor_x: FloatArray) -> tuple[np.ndarray, np.ndarray]:
    """(K, R) x_norm of the lanes of ``regression`` (K, 2 + R) on anchors at ``anchor_x`` (K, R), and (K, R) bool
    the rows each lane covers (its bottom row and length, rounded to rows)."""
    n_rows = anchor_x.shape[1]
    bottom = np.clip(np.rint(regression[:, 0] * (n_rows - 1)), 0, n_rows - 1)
    length = np.clip(np.rint(regression[:, 1] * n_rows), 1, n_rows)
    index = np.arange(n_rows)[None]
    covered = (index <= bottom[:, None]) & (index > (bottom - length)[:, None])
    return anchor_x + regression[:, 2:], covered


def lane_distance(x_a: FloatArray, covered_a: BoolArray, x_b: FloatArray, covered_b: BoolArray) -> float:
    """Mean horizontal distance of two lanes over their common rows (infinite when they share fewer than 2)."""
    common = covered_a & covered_b
    if int(common.sum()) < 2:
        return float("inf")
    return float(np.abs(x_a[common] - x_b[common]).mean())


def decode_anchors(scores: FloatArray, regression: FloatArray, anchors: FloatArray, rows: FloatArray, aspect: float,
                   max_lanes: int, threshold: float = SCORE_THRESHOLD,
                   nms_distance: float = NMS_DISTANCE) -> list[LaneLine | None]:
    """Lane lines from ``scores`` (A,) lane probabilities and ``regression`` (A, 2 + R): confident anchors in
    score order, each dropped when within ``nms_distance`` of a kept one, at most ``max_lanes``."""
    keep = np.flatnonzero(scores > threshold)
    keep = keep[np.argsort(-scores[keep], kind="stable")]
    xs, covered = anchor_lanes(regression[keep], anchor_xs(anchors[keep], rows, aspect))
    kept: list[int] = []
    for k in range(len(keep)):
        if int(covered[k].sum()) < 2:
            continue
        if all(lane_distance(xs[k], covered[k], xs[j], covered[j]) >= nms_distance for j in kept):
            kept.append(k)
        if len(kept) == max_lanes:
            break
    return [LaneLine(np.stack([xs[k][covered[k]], np.asarray(rows)[covered[k]]], axis=1)) for k in kept]
