"""The ego line match: does a detector find the two lines of the lane the car drives in?

A stricter, simpler question than TuSimple's accuracy, for a user's own labelled real frames:

- The **ego lines** of a ground-truth image are the labelled lane lines nearest the image centre at the bottom row,
  one left of the centre and one right of it. Each line's x at the bottom row comes from a least-squares line
  ``x = k * y + b`` through its labelled points (its only x when it has one), so a line labelled only part way
  down is still placed where it would meet the bottom row.
- A ground-truth ego line is **matched** when one predicted lane is within ``EGO_PIXEL_THRESH`` (20 px, inclusive)
  at no less than ``EGO_MATCH_SHARE`` (85 %) of the line's labelled rows (x >= 0); a row the prediction does not
  cover counts as a miss. Its **point accuracy** is that share for its best prediction.
- An image scores its ego lines (0, 1 or 2 of them); a set of images scores the share of all ego lines matched
  and their mean point accuracy.
- Everything is in the frame's own pixels: 20 px of a 960x540 frame are 20 of its pixels, not 20 px of the
  1280x720 grid TuSimple's accuracy is scored on.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .formats import LaneRecord

EGO_PIXEL_THRESH = 20.0
EGO_MATCH_SHARE = 0.85

Side = Literal["left", "right"]


@dataclass(frozen=True)
class EgoLineScore:
    """One ground-truth ego line: its side, index in the record's lanes, best point accuracy and match."""

    side: Side
    lane: int
    point_accuracy: float
    matched: bool


@dataclass(frozen=True)
class EgoSummary:
    """Over a set of images: how many ego lines there were, the share matched and the mean point accuracy."""

    images: int
    ego_lines: int
    matched: int
    match_share: float
    point_accuracy: float

    def as_dict(self) -> dict[str, float | int]:
        return {"images": self.images, "ego_lines": self.ego_lines, "matched": self.matched,
                "match_share": self.match_share, "point_accuracy": self.point_accuracy,
                "pixel_thresh": EGO_PIXEL_THRESH, "match_share_thresh": EGO_MATCH_SHARE}


def bottom_x(lane: Sequence[float], h_samples: Sequence[float]) -> float | None:
    """x where a lane meets the bottom row (largest h_sample), from the least-squares line through its labelled
    points; None for a lane without labelled points."""
    x = np.asarray(lane, np.float64)
    y = np.asarray(h_samples, np.float64)
    valid = x >= 0
    if not valid.any():
        return None
    if valid.sum() == 1:
        return float(x[valid][0])
    k, b = np.polyfit(y[valid], x[valid], 1)
    return float(k * y.max() + b)


def ego_lanes(gt: LaneRecord, image_width: float) -> dict[Side, int]:
    """Index in ``gt.lanes`` of the ego line on each side of the image centre (a side without lines is absent)."""
    centre = image_width / 2.0
    left: tuple[float, int] | None = None
    right: tuple[float, int] | None = None
    for index, lane in enumerate(gt.lanes):
        x = bottom_x(lane, gt.h_samples)
        if x is None:
            continue
        distance = abs(x - centre)
        if x < centre and (left is None or distance < left[0]):
            left = (distance, index)
        elif x >= centre and (right is None or distance < right[0]):
            right = (distance, index)
    chosen: dict[Side, int] = {}
    if left is not None:
        chosen["left"] = left[1]
    if right is not None:
        chosen["right"] = right[1]
    return chosen


def point_accuracy(pred: Sequence[float], gt: Sequence[float]) -> float:
    """Share of the GT lane's labelled rows (x >= 0) where ``pred`` has a point within 20 px (0 with no rows)."""
    g = np.asarray(gt, np.float64)
    p = np.asarray(pred, np.float64)
    labelled = g >= 0
    if not labelled.any():
        return 0.0
    close = labelled & (p >= 0) & (np.abs(p - g) <= EGO_PIXEL_THRESH)
    return float(close.sum() / labelled.sum())


def ego_line_match(gt: LaneRecord, pred: LaneRecord, image_width: float = 1280.0) -> list[EgoLineScore]:
    """The ego lines of ``gt`` (left first), each with its best prediction's point accuracy and match.

    ``image_width``: the width of the pixel frame both records are in (its centre separates left from right).
    """
    scores = []
    for side, index in ego_lanes(gt, image_width).items():
        best = max((point_accuracy(lane, gt.lanes[index]) for lane in pred.lanes), default=0.0)
        scores.append(EgoLineScore(side, index, best, best >= EGO_MATCH_SHARE))
    return scores


def summarize_ego(images: Iterable[list[EgoLineScore]]) -> EgoSummary:
    """Pooled over every ego line of every image (an image without ego lines adds none)."""
    per_image = list(images)
    lines = [score for scores in per_image for score in scores]
    matched = sum(score.matched for score in lines)
    share = matched / len(lines) if lines else 0.0
    accuracy = float(np.mean([score.point_accuracy for score in lines])) if lines else 0.0
    return EgoSummary(len(per_image), len(lines), matched, share, accuracy)
