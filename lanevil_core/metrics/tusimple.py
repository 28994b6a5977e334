"""The TuSimple lane metric (Accuracy, FP, FN) exactly as the official ``lane.py`` computes it, plus F1.

Per image (``score_image``):
- Each GT lane gets a tolerance of ``20 px / cos(theta)``, theta = arctan(k) from a least-squares fit
  ``x = k * y + b`` over its valid points (theta = 0 with fewer than two).
- ``line_accuracy(pred, gt)`` = fraction of *all* h_samples where ``|x_pred - x_gt| < tolerance``, with every
  negative x replaced by -100 first (so a row missing in both counts as a hit).
- Each GT lane takes its best prediction (not a one-to-one assignment); it is matched when that best score is
  at least 0.85.
- accuracy = sum of best scores / max(min(4, #GT), 1), the lowest score dropped when #GT > 4;
  FP = (#pred - #matched GT lanes) / #pred (0 without predictions; negative when two GT lanes match the same
  prediction, as in the official script); FN = #unmatched / max(min(#GT, 4), 1), one fewer unmatched when
  #GT > 4.
- An image with more than #GT + 2 predictions or a run time over 200 ms scores accuracy 0, FP 0, FN 1.
Dataset scores are per-image means. F1 has no official definition; ``F1_VARIANTS`` holds the two in use.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from .formats import LaneRecord

PIXEL_THRESH = 20.0
MATCH_THRESH = 0.85
MAX_RUN_TIME_MS = 200.0
EXTRA_PREDICTIONS = 2  # more than #GT + this many predictions scores the image 0
MAX_SCORED_LANES = 4
MISSING_X = -100.0


@dataclass(frozen=True)
class ImageScore:
    """Official per-image accuracy, FP and FN."""

    accuracy: float
    fp: float
    fn: float


@dataclass(frozen=True)
class TusimpleSummary:
    """Dataset means and the F1 of one variant."""

    accuracy: float
    fp: float
    fn: float
    f1: float
    f1_variant: str
    images: int

    def as_dict(self) -> dict[str, float | int | str]:
        return {"accuracy": self.accuracy, "fp": self.fp, "fn": self.fn, "f1": self.f1,
                "f1_variant": self.f1_variant, "images": self.images}


def lane_angle(xs: Sequence[float], h_samples: Sequence[float]) -> float:
    """theta (radians) of the least-squares line ``x = k * y + b`` through the valid (x >= 0) points."""
    x = np.asarray(xs, np.float64)
    y = np.asarray(h_samples, np.float64)
    valid = x >= 0
    x, y = x[valid], y[valid]
    if len(x) <= 1:
        return 0.0
    dy = y - y.mean()
    k = float(np.dot(dy, x - x.mean()) / np.dot(dy, dy))
    return math.atan(k)


def lane_tolerance(xs: Sequence[float], h_samples: Sequence[float]) -> float:
    """Pixel tolerance of a GT lane: ``20 / cos(theta)``."""
    return PIXEL_THRESH / math.cos(lane_angle(xs, h_samples))


def line_accuracy(pred: Sequence[float], gt: Sequence[float], tolerance: float) -> float:
    """Fraction of all rows where the two lanes agree within ``tolerance`` (missing x -> -100 in both)."""
    p = np.asarray(pred, np.float64)
    g = np.asarray(gt, np.float64)
    p = np.where(p >= 0, p, MISSING_X)
    g = np.where(g >= 0, g, MISSING_X)
    return float(np.sum(np.abs(p - g) < tolerance)) / len(g)


def score_image(pred_lanes: Sequence[Sequence[float]], gt_lanes: Sequence[Sequence[float]],
                h_samples: Sequence[float], run_time_ms: float) -> ImageScore:
    """Official accuracy, FP and FN of one image (lanes already checked to have one x per h_sample)."""
    if run_time_ms > MAX_RUN_TIME_MS or len(pred_lanes) > len(gt_lanes) + EXTRA_PREDICTIONS:
        return ImageScore(0.0, 0.0, 1.0)
    best_scores = []
    unmatched = 0
    for gt in gt_lanes:
        tolerance = lane_tolerance(gt, h_samples)
        best = max((line_accuracy(pred, gt, tolerance) for pred in pred_lanes), default=0.0)
        unmatched += best < MATCH_THRESH
        best_scores.append(best)
    matched = len(gt_lanes) - unmatched
    if len(gt_lanes) > MAX_SCORED_LANES and unmatched > 0:
        unmatched -= 1
    total = sum(best_scores)
    if len(gt_lanes) > MAX_SCORED_LANES:
        total -= min(best_scores)
    scored = max(min(MAX_SCORED_LANES, len(gt_lanes)), 1)
    fp = (len(pred_lanes) - matched) / len(pred_lanes) if pred_lanes else 0.0
    return ImageScore(total / scored, fp, unmatched / scored)


# ---------------------------------------------------------------------------------------------- F1

def _ratio(numerator: float, denominator: float) -> float:
    return numerator / denominator if denominator else 0.0


def _harmonic(precision: float, recall: float) -> float:
    return _ratio(2 * precision * recall, precision + recall)


def f1_ganet(fp: float, fn: float) -> float:
    """CondLaneNet / GANet / UFLD-v2: precision = 1 - FP, recall = 1 - FN."""
    return _harmonic(1.0 - fp, 1.0 - fn)


def f1_clrnet(fp: float, fn: float) -> float:
    """CLRNet: tp = 1 - FP, precision = tp / (tp + FP), recall = tp / (tp + FN) (0 where a denominator is 0)."""
    tp = 1.0 - fp
    return _harmonic(_ratio(tp, tp + fp), _ratio(tp, tp + fn))


F1_VARIANTS: dict[str, Callable[[float, float], float]] = {"ganet": f1_ganet, "clrnet": f1_clrnet}


def summarize(scores: Iterable[ImageScore], f1_variant: str = "ganet") -> TusimpleSummary:
    """Per-image means of accuracy, FP and FN and the F1 of ``f1_variant`` computed from the mean FP and FN."""
    chosen = list(scores)
    if not chosen:
        raise ValueError("no images to summarize")
    accuracy = fp = fn = 0.0
    for score in chosen:  # a plain running sum, as the official script accumulates (sum() compensates on 3.12+)
        accuracy += score.accuracy
        fp += score.fp
        fn += score.fn
    accuracy, fp, fn = accuracy / len(chosen), fp / len(chosen), fn / len(chosen)
    return TusimpleSummary(accuracy, fp, fn, F1_VARIANTS[f1_variant](fp, fn), f1_variant, len(chosen))


def score_pairs(pairs: Iterable[tuple[LaneRecord, LaneRecord]]) -> list[ImageScore]:
    """``score_image`` of every (gt, pred) pair from ``formats.pair_records``."""
    return [score_image(pred.lanes, gt.lanes, gt.h_samples, pred.run_time or 0.0) for gt, pred in pairs]
