"""Lane slots and the two learned output encodings (row anchors, lane masks), in numpy so inference needs no torch.

A learned detector predicts a fixed number of *lane slots* ordered by their place relative to the camera:
``slots = 6`` means ``[left 3, left 2, left 1, right 1, right 2, right 3]``, "left 1" being the first boundary
left of the camera. Ground truth (TuSimple records, any image size) is turned into slots by where each lane meets
the bottom of the image.

Coordinates are *normalised image coordinates*: ``x_norm = u_image / width`` and ``y_norm = v_image / height`` with
the continuous image coordinates of docs/conventions.md (a TuSimple row ``h`` is ``v_image = h + 0.5``, a column
``x`` is ``u_image = x + 0.5``), so one encoding serves every image size.

Row anchors (Ultra Fast Lane Detection): the target of a slot is, per anchor row, one of ``grid`` column cells or
``grid`` itself for "no lane at this row". Lane masks (SCNN-like segmentation): per pixel of a low-resolution
map, 0 for background or ``slot + 1``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ..labels.lanes import NO_POINT, TUSIMPLE_H_SAMPLES, TUSIMPLE_SIZE
from ..typed import FloatArray, Int64Array

BOTTOM_FIT_POINTS = 8  # lowest points of a lane fitted to find where it meets the image bottom
MIN_LANE_POINTS = 2
MAX_GAP = 0.12  # normalised rows: a longer stretch without points is not bridged


@dataclass(frozen=True)
class LaneLine:
    """One lane in normalised image coordinates: ``(n, 2)`` float64 points ``(x_norm, y_norm)``, top to bottom."""

    points: FloatArray

    @property
    def bottom_x(self) -> float:
        """x_norm where a line fitted to the lowest points meets the image bottom (y_norm = 1)."""
        tail = self.points[-BOTTOM_FIT_POINTS:]
        if len(tail) < 2 or np.ptp(tail[:, 1]) < 1e-9:
            return float(tail[-1, 0])
        slope, intercept = np.polyfit(tail[:, 1], tail[:, 0], 1)
        return float(slope + intercept)

    def x_at(self, y_norm: FloatArray, reach: float = 0.0) -> FloatArray:
        """(r,) x_norm at rows ``y_norm``, linear between points, NaN outside the lane's rows widened by ``reach``.

        Between two points farther apart than ``MAX_GAP`` (a hidden stretch) there is no lane either.
        """
        y = np.asarray(y_norm, np.float64)
        ys, xs = self.points[:, 1], self.points[:, 0]
        x = np.interp(y, ys, xs)
        if len(ys) >= 2:  # linear extension by at most ``reach`` beyond both ends
            top_slope = (xs[1] - xs[0]) / max(ys[1] - ys[0], 1e-9)
            bottom_slope = (xs[-1] - xs[-2]) / max(ys[-1] - ys[-2], 1e-9)
            x = np.where(y < ys[0], xs[0] + (y - ys[0]) * top_slope, x)
            x = np.where(y > ys[-1], xs[-1] + (y - ys[-1]) * bottom_slope, x)
        inside = (y >= ys[0] - reach) & (y <= ys[-1] + reach)
        gap_after = np.searchsorted(ys, y)  # index of the first point at or below each row
        gaps = np.diff(ys) > MAX_GAP
        in_gap = np.zeros(y.shape, bool)
        between = (gap_after > 0) & (gap_after < len(ys))
        in_gap[between] = gaps[gap_after[between] - 1]
        return np.where(inside & ~in_gap, x, np.nan)


def lane_lines(lanes: Sequence[Sequence[float]], h_samples: Sequence[float], size: tuple[int, int]) -> list[LaneLine]:
    """TuSimple lanes (pixel columns per row, -2 = none) of an image of ``size`` as lane lines (>= 2 points)."""
    width, height = size
    y_norm = (np.asarray(h_samples, np.float64) + 0.5) / height
    lines = []
    for lane in lanes:
        x = np.asarray(lane, np.float64)
        valid = x >= 0
        if int(valid.sum()) < MIN_LANE_POINTS:
            continue
        points = np.stack([(x[valid] + 0.5) / width, y_norm[valid]], axis=1)
        lines.append(LaneLine(points[np.argsort(points[:, 1])]))
    return lines


def assign_slots(lines: list[LaneLine], slots: int, camera_x: float = 0.5) -> list[LaneLine | None]:
    """The lanes in ``slots`` places: nearest left of ``camera_x`` at ``slots // 2 - 1`` going outwards, nearest
    right at ``slots // 2``; lanes beyond the slots are dropped."""
    half = slots // 2
    left = sorted((line for line in lines if line.bottom_x < camera_x), key=lambda line: -line.bottom_x)
    right = sorted((line for line in lines if line.bottom_x >= camera_x), key=lambda line: line.bottom_x)
    placed: list[LaneLine | None] = [None] * slots
    for k, line in enumerate(left[:half]):
        placed[half - 1 - k] = line
    for k, line in enumerate(right[:half]):
        placed[half + k] = line
    return placed


def mirror_slots(placed: list[LaneLine | None]) -> list[LaneLine | None]:
    """The slots of the horizontally flipped image (x_norm -> 1 - x_norm, slot order reversed)."""
    flipped = [None if line is None else LaneLine(np.stack([1.0 - line.points[:, 0], line.points[:, 1]], axis=1))
               for line in placed]
    return flipped[::-1]


# ---------------------------------------------------------------------------------------------- row anchors


def anchor_rows(count: int) -> FloatArray:
    """(count,) y_norm of the row anchors: evenly over the TuSimple rows 160 ... 710 of a 720-row image."""
    first, last = TUSIMPLE_H_SAMPLES[0] + 0.5, TUSIMPLE_H_SAMPLES[-1] + 0.5
    return np.linspace(first, last, count) / TUSIMPLE_SIZE[1]


# Row-anchor location: the expectation over this many column cells either side of the most likely one. UFLD took it
# over the whole row, which pulls an uncertain lane towards the image's middle (on real frames the lines bent
# inwards near the bottom); UFLDv2 keeps a local window. 3 of 56 cells scored best on a held-out drawn-camera split
# (docs/learning.md).
LOCATION_WINDOW = 3


def encode_row_anchors(placed: list[LaneLine | None], anchors: FloatArray, grid: int) -> Int64Array:
    """(slots, anchors) int64 class targets: the column cell ``floor(x_norm * grid)``, ``grid`` where no lane."""
    target = np.full((len(placed), len(anchors)), grid, np.int64)
    for slot, line in enumerate(placed):
        if line is None:
            continue
        x = line.x_at(anchors)
        inside = np.isfinite(x) & (x >= 0.0) & (x < 1.0)
        target[slot, inside] = np.floor(x[inside] * grid).astype(np.int64)
    return target


def decode_row_anchors(probs: FloatArray, anchors: FloatArray, min_points: int = 3,
                       window: int = LOCATION_WINDOW) -> list[LaneLine | None]:
    """Lane lines from ``(slots, anchors, grid + 1)`` softmax probabilities.

    At an anchor the lane is absent when the "no lane" class wins; otherwise its x is the expectation over the
    column cells within ``window`` cells of the most likely one (UFLDv2's local location), so the position is finer
    than one cell. Slots with fewer than ``min_points`` present anchors are empty.
    """
    grid = probs.shape[-1] - 1
    centres = (np.arange(grid) + 0.5) / grid
    lines: list[LaneLine | None] = []
    for slot_probs in probs:
        present = np.argmax(slot_probs, axis=-1) < grid
        cells = slot_probs[:, :grid]
        peak = np.argmax(cells, axis=-1)
        cells = np.where(np.abs(np.arange(grid) - peak[:, None]) <= window, cells, 0.0)
        x = (cells @ centres) / np.maximum(cells.sum(axis=-1), 1e-12)
        if int(present.sum()) < min_points:
            lines.append(None)
            continue
        lines.append(LaneLine(np.stack([x[present], anchors[present]], axis=1)))
    return lines


# ---------------------------------------------------------------------------------------------- lane masks


def encode_lane_mask(placed: list[LaneLine | None], size: tuple[int, int], thickness: int = 2) -> Int64Array:
    """(height, width) int64 mask: ``slot + 1`` on each slot's lane drawn ``thickness`` map pixels wide, else 0."""
    width, height = size
    mask = np.zeros((height, width), np.uint8)
    for slot, line in enumerate(placed):
        if line is None:
            continue
        # cv2 draws on pixel centres at integer coordinates: shift by half a pixel, 4 fractional bits.
        points = np.round((line.points * (width, height) - 0.5) * 16).astype(np.int32)
        cv2.polylines(mask, [points.reshape(-1, 1, 2)], False, slot + 1, thickness, cv2.LINE_8, shift=4)
    return mask.astype(np.int64)


def _run_centre(profile: FloatArray, peak: int, floor: float) -> float:
    """Probability-weighted centre of the run of columns around ``peak`` whose value stays above ``floor``.

    A lane crossing a row at a shallow angle covers many columns, so the whole run, not a fixed window, is the
    lane's crossing of that row."""
    lo = peak
    while lo > 0 and profile[lo - 1] > floor:
        lo -= 1
    hi = peak
    while hi < len(profile) - 1 and profile[hi + 1] > floor:
        hi += 1
    weights = profile[lo:hi + 1]
    return float(weights @ np.arange(lo, hi + 1) / max(float(weights.sum()), 1e-12))


def decode_lane_masks(probs: FloatArray, exist: FloatArray, rows: FloatArray, threshold: float = 0.3,
                      exist_threshold: float = 0.5, min_points: int = 3) -> list[LaneLine | None]:
    """Lane lines from ``(slots + 1, H, W)`` softmax probabilities and ``(slots,)`` existence probabilities.

    Per row ``rows`` (y_norm) a slot's probability profile is read (linear between map rows); its peak above
    ``threshold`` gives the point, refined to the centre of the run of columns above half the peak.
    """
    _, height, width = probs.shape
    rows = np.asarray(rows, np.float64)
    v_map = np.clip(rows * height - 0.5, 0.0, height - 1.0)
    r0 = np.floor(v_map).astype(np.intp)
    r1 = np.minimum(r0 + 1, height - 1)
    a = (v_map - r0)[:, None]
    lines: list[LaneLine | None] = []
    for slot in range(probs.shape[0] - 1):
        if exist[slot] < exist_threshold:
            lines.append(None)
            continue
        channel = probs[slot + 1]
        profile = channel[r0] * (1.0 - a) + channel[r1] * a  # (r, W)
        peak = np.argmax(profile, axis=1)
        peak_value = profile[np.arange(len(rows)), peak]
        keep = np.flatnonzero(peak_value > threshold)
        if len(keep) < min_points:
            lines.append(None)
            continue
        centre = [_run_centre(profile[i], int(peak[i]), 0.5 * float(peak_value[i])) for i in keep]
        x_norm = (np.asarray(centre) + 0.5) / width
        lines.append(LaneLine(np.stack([x_norm, rows[keep]], axis=1)))
    return lines

# ---------------------------------------------------------------------------------------------- output


def tusimple_lanes(lines: Sequence[LaneLine | None], h_samples: Sequence[float], size: tuple[int, int],
                   reach: float = 0.0) -> list[list[int]]:
    """TuSimple lanes (``floor(u_image)`` per row, -2 where none) of the non-empty lines, left to right.

    ``reach`` (normalised rows) lets a line extend that far beyond its first and last point (half the anchor
    spacing for row anchors, so the rows between anchors and at the ends are covered).
    """
    width, height = size
    y_norm = (np.asarray(h_samples, np.float64) + 0.5) / height
    lanes = []
    for line in lines:
        if line is None:
            continue
        u_image = line.x_at(y_norm, reach) * width
        inside = np.isfinite(u_image) & (u_image >= 0) & (u_image < width)
        if int(inside.sum()) < MIN_LANE_POINTS:
            continue
        lanes.append(np.where(inside, np.floor(np.where(inside, u_image, 0.0)), NO_POINT).astype(int).tolist())
    return lanes


def anchor_reach(anchors: FloatArray) -> float:
    """A bit more than half the spacing of the anchor rows (normalised): how far a row-anchor lane may extend past
    its ends."""
    return 0.6 * float(np.diff(anchors).mean()) if len(anchors) > 1 else 0.0
