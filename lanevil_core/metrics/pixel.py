"""The pixel lane-line metric: IoU and F1 of a lane-line mask against the labelled lanes drawn as lines.

Segmentation detectors (BDD100K style) predict a lane-line mask, not lane instances, so matching lanes (TuSimple,
CULane) scores them through their clustering as much as through what they see. This metric scores pixels instead.

The ground-truth mask of an image is its TuSimple lanes drawn as lines ``width`` pixels wide: a pixel belongs to it
when its centre is within ``width / 2`` of the polyline through the lane's consecutive labelled points (points
``(x, h)`` in pixel indices, as the TuSimple file writes them; a row without a point breaks the line, a point with
no labelled neighbour is a disc). ``width`` is ``line_width`` pixels at 720 rows (default ``LINE_WIDTH_720``),
scaled with the image's height. A prediction is either a TuSimple file (its lanes drawn the same way) or a folder of
mask images named after the GT's ``raw_file`` with ``.png`` (any non-zero pixel is lane line).

Over all images, with TP, FP, FN the summed pixel counts: ``IoU = TP / (TP + FP + FN)``, ``precision = TP / (TP +
FP)``, ``recall = TP / (TP + FN)``, ``F1 = 2 TP / (2 TP + FP + FN)`` (pixel-summed, so a large image weighs more).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..labels.lanes import IMAGE_SIZE_FIELD, TUSIMPLE_SIZE
from ..typed import BoolArray
from .formats import LaneFileError, LaneRecord, pair_records, read_tusimple

LINE_WIDTH_720 = 8.0  # lane-line width in pixels at 720 image rows


def line_width_px(line_width_720: float, height: int) -> float:
    """The line width in pixels of an image ``height`` rows tall."""
    return line_width_720 * height / TUSIMPLE_SIZE[1]


def lane_segments(lanes: Sequence[Sequence[float]], h_samples: Sequence[float]) -> list[tuple[float, ...]]:
    """``(x0, y0, x1, y1)`` of every pair of consecutive labelled points of every lane (a lone point: x0 = x1)."""
    segments: list[tuple[float, ...]] = []
    for lane in lanes:
        points = [(float(x), float(h)) if x >= 0 else None for x, h in zip(lane, h_samples, strict=True)]
        for index, point in enumerate(points):
            if point is None:
                continue
            following = points[index + 1] if index + 1 < len(points) else None
            before = points[index - 1] if index > 0 else None
            if following is not None:
                segments.append((*point, *following))
            elif before is None:
                segments.append((*point, *point))
    return segments


def lane_mask(lanes: Sequence[Sequence[float]], h_samples: Sequence[float], size: tuple[int, int],
              width: float) -> BoolArray:
    """(H, W) bool: pixels whose centre lies within ``width / 2`` of a lane's polyline."""
    image_width, image_height = size
    mask = np.zeros((image_height, image_width), bool)
    radius = width / 2.0
    for x0, y0, x1, y1 in lane_segments(lanes, h_samples):
        c_lo = max(0, int(np.floor(min(x0, x1) - radius)))
        c_hi = min(image_width, int(np.ceil(max(x0, x1) + radius)) + 1)
        r_lo = max(0, int(np.floor(min(y0, y1) - radius)))
        r_hi = min(image_height, int(np.ceil(max(y0, y1) + radius)) + 1)
        if c_lo >= c_hi or r_lo >= r_hi:
            continue
        cols, rows = np.meshgrid(np.arange(c_lo, c_hi, dtype=np.float64), np.arange(r_lo, r_hi, dtype=np.float64))
        dx, dy = x1 - x0, y1 - y0
        length2 = dx * dx + dy * dy
        t = np.clip(((cols - x0) * dx + (rows - y0) * dy) / length2, 0.0, 1.0) if length2 > 0 else 0.0
        distance2 = (cols - x0 - t * dx) ** 2 + (rows - y0 - t * dy) ** 2
        mask[r_lo:r_hi, c_lo:c_hi] |= distance2 <= radius * radius
    return mask


@dataclass(frozen=True)
class PixelCounts:
    """Lane-line pixels of one image or summed: true positives, false positives, false negatives."""

    tp: int
    fp: int
    fn: int


def count_pixels(pred: BoolArray, gt: BoolArray) -> PixelCounts:
    return PixelCounts(int(np.count_nonzero(pred & gt)), int(np.count_nonzero(pred & ~gt)),
                       int(np.count_nonzero(~pred & gt)))


@dataclass(frozen=True)
class PixelSummary:
    """The metric over images (module docstring); ``line_width`` is the width at 720 rows."""

    images: int
    line_width: float
    tp: int
    fp: int
    fn: int
    iou: float
    precision: float
    recall: float
    f1: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def _ratio(top: int, bottom: int) -> float:
    return top / bottom if bottom else 0.0


def summarize_pixels(counts: Iterable[PixelCounts], line_width: float = LINE_WIDTH_720) -> PixelSummary:
    listed = list(counts)
    tp, fp, fn = (sum(getattr(c, name) for c in listed) for name in ("tp", "fp", "fn"))
    if tp + fp + fn == 0:  # no lane line anywhere on either side: an empty road found empty
        return PixelSummary(len(listed), line_width, 0, 0, 0, 1.0, 1.0, 1.0, 1.0)
    return PixelSummary(len(listed), line_width, tp, fp, fn, _ratio(tp, tp + fp + fn), _ratio(tp, tp + fp),
                        _ratio(tp, tp + fn), _ratio(2 * tp, 2 * tp + fp + fn))


def record_size(gt: LaneRecord) -> tuple[int, int]:
    """(width, height) of a GT record's image: its ``image_size``, else 1280x720."""
    size = gt.extra.get(IMAGE_SIZE_FIELD)
    return (int(size[0]), int(size[1])) if size else TUSIMPLE_SIZE


def read_mask(path: Path, size: tuple[int, int]) -> BoolArray:
    """(H, W) bool of a mask image (non-zero = lane line); raises ``LaneFileError`` if missing or of another size."""
    image = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if image is None:
        raise LaneFileError(f"{path}: no mask image (the prediction folder needs one PNG per GT image)")
    if image.shape[::-1] != size:
        raise LaneFileError(f"{path}: a {image.shape[1]}x{image.shape[0]} mask for a {size[0]}x{size[1]} image")
    return image > 0


def mask_file(pred_root: Path, raw_file: str) -> Path:
    """The mask of GT image ``raw_file`` in a prediction folder: the same relative path with ``.png``."""
    return (pred_root / raw_file).with_suffix(".png")


def score_pixel_files(gt_path: Path, pred_path: Path, line_width: float = LINE_WIDTH_720) -> PixelSummary:
    """The pixel metric of a TuSimple GT file against a TuSimple prediction file or a folder of mask PNGs."""
    if not line_width > 0:
        raise LaneFileError(f"--line-width {line_width}: must be positive")
    gt = read_tusimple(gt_path, "gt")
    counts = []
    if pred_path.is_dir():
        for record in gt:
            size = record_size(record)
            width = line_width_px(line_width, size[1])
            counts.append(count_pixels(read_mask(mask_file(pred_path, record.raw_file), size),
                                       lane_mask(record.lanes, record.h_samples, size, width)))
    else:
        pairs = pair_records(gt, read_tusimple(pred_path, "pred"), str(gt_path), str(pred_path),
                             require_run_time=False)
        for g, p in pairs:
            size = record_size(g)
            width = line_width_px(line_width, size[1])
            counts.append(count_pixels(lane_mask(p.lanes, g.h_samples, size, width),
                                       lane_mask(g.lanes, g.h_samples, size, width)))
    return summarize_pixels(counts, line_width)
