"""The CULane lane metric: F1 of one-to-one lane matches at IoU > 0.5, pooled over all images.

As in the widely used Python port of the official evaluator (``culane_metric.py``, "official" discrete IoU):
- each lane (>= 2 points) is interpolated with a parametric interpolating spline (``scipy.interpolate.splprep``,
  s = 0, degree min(3, #points - 1)), sampled at 5 * (#points - 1) + 1 parameter values evenly spaced over
  [0, 1] (the parameter is the normalised chord length, so samples are not tied to the original points);
- the interpolated points are truncated to integers and drawn as a 30 px wide polyline (``cv2.line``) on an
  image-sized canvas (1640x590 for CULane files);
- IoU of every (prediction, GT) pair of masks; one-to-one assignment maximising the summed IoU
  (``scipy.optimize.linear_sum_assignment`` on 1 - IoU); a pair is a TP when its IoU exceeds 0.5;
- FP = #pred - TP, FN = #GT - TP per image; precision, recall and F1 from the sums over all images.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.interpolate import splev, splprep
from scipy.optimize import linear_sum_assignment

from ..typed import BoolArray, FloatArray
from .formats import Points

LANE_WIDTH_PX = 30
IOU_THRESHOLD = 0.5
SAMPLES_PER_SEGMENT = 5


class LaneInterpolationError(ValueError):
    """A lane the spline cannot pass through (e.g. repeated points)."""


@dataclass(frozen=True)
class MatchCounts:
    """True positives, false positives and false negatives (lanes)."""

    tp: int
    fp: int
    fn: int

    def __add__(self, other: MatchCounts) -> MatchCounts:
        return MatchCounts(self.tp + other.tp, self.fp + other.fp, self.fn + other.fn)


@dataclass(frozen=True)
class CulaneSummary:
    """Pooled counts and their precision, recall and F1."""

    tp: int
    fp: int
    fn: int
    precision: float
    recall: float
    f1: float
    images: int

    def as_dict(self) -> dict[str, float | int]:
        return {"tp": self.tp, "fp": self.fp, "fn": self.fn, "precision": self.precision, "recall": self.recall,
                "f1": self.f1, "images": self.images}


def interpolate_lane(points: Points, samples_per_segment: int = SAMPLES_PER_SEGMENT) -> FloatArray:
    """(m, 2) float64 points of the interpolating spline through ``points`` (n >= 2), m = 5 (n - 1) + 1."""
    xy = np.asarray(points, np.float64)
    try:
        tck, u = splprep([xy[:, 0], xy[:, 1]], s=0, k=min(3, len(xy) - 1))
    except (ValueError, TypeError) as error:
        raise LaneInterpolationError(f"lane cannot be interpolated ({error})") from None
    u_fine = np.linspace(0.0, 1.0, num=(len(u) - 1) * samples_per_segment + 1)
    return np.array(splev(u_fine, tck)).T


def lane_mask(points_image: FloatArray, size: tuple[int, int], width: int = LANE_WIDTH_PX) -> BoolArray:
    """(H, W) bool: the polyline through ``points_image`` (m, 2) (truncated to int), ``width`` px thick."""
    canvas = np.zeros((size[1], size[0]), np.uint8)
    pixels = points_image.astype(np.int32)
    for p1, p2 in zip(pixels[:-1], pixels[1:]):
        cv2.line(canvas, (int(p1[0]), int(p1[1])), (int(p2[0]), int(p2[1])), color=255, thickness=width)
    return canvas > 0


def iou_matrix(pred: Sequence[Points], gt: Sequence[Points], size: tuple[int, int],
               width: int = LANE_WIDTH_PX) -> FloatArray:
    """(#pred, #gt) float64 mask IoU of every pair of interpolated lanes."""
    pred_masks = [lane_mask(interpolate_lane(lane), size, width) for lane in pred]
    gt_masks = [lane_mask(interpolate_lane(lane), size, width) for lane in gt]
    ious = np.zeros((len(pred_masks), len(gt_masks)))
    for i, p in enumerate(pred_masks):
        for j, g in enumerate(gt_masks):
            union = int(np.count_nonzero(p | g))
            ious[i, j] = np.count_nonzero(p & g) / union if union else 0.0
    return ious


def match_image(pred: Sequence[Points], gt: Sequence[Points], size: tuple[int, int],
                width: int = LANE_WIDTH_PX, iou_threshold: float = IOU_THRESHOLD) -> MatchCounts:
    """One-to-one matching of one image's lanes; TP where the assigned pair's IoU exceeds ``iou_threshold``."""
    ious = iou_matrix(pred, gt, size, width)
    rows, cols = linear_sum_assignment(1.0 - ious)
    tp = int((ious[rows, cols] > iou_threshold).sum())
    return MatchCounts(tp, len(pred) - tp, len(gt) - tp)


def summarize(counts: Iterable[MatchCounts]) -> CulaneSummary:
    """Pooled precision = TP / (TP + FP), recall = TP / (TP + FN), F1 (0 where a denominator is 0)."""
    total = MatchCounts(0, 0, 0)
    images = 0
    for item in counts:
        total = total + item
        images += 1
    precision = total.tp / (total.tp + total.fp) if total.tp + total.fp else 0.0
    recall = total.tp / (total.tp + total.fn) if total.tp + total.fn else 0.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    return CulaneSummary(total.tp, total.fp, total.fn, precision, recall, f1, images)
