"""Hough baseline: Canny edges of thin bright structures below the horizon, probabilistic Hough segments,
segments grouped into lanes by their slope, one least-squares line ``x = k * y + b`` per lane.

Lanes on a flat road all pass through the vanishing point, and a lane at lateral offset X (m) has slope
``k = dx/dy = X / camera height`` in the image (pitch 0), so the slope alone separates the lanes (its sign
separates left from right).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..labels.lanes import MAX_LANES, RANGE_M
from ..typed import FloatArray, UInt8Array
from .common import GroundCamera, lane_columns, sample_rows, useful_lanes

WORK_WIDTH = 640  # wider frames are shrunk to this width first (the edges and segments need no more)


@dataclass(frozen=True)
class HoughParams:
    """Thresholds at a 640 px wide image; pixel lengths scale with the image width."""

    blur: int = 5
    canny_low: int = 40
    canny_high: int = 120
    tophat_px: int = 25  # paint is narrower than this
    min_tophat: int = 12
    horizon_margin: float = 0.03  # of the image height, below the horizon
    hough_threshold: int = 12
    min_length_px: float = 12.0
    max_gap_px: float = 12.0
    max_abs_slope: float = 4.0  # |dx/dy|: flatter segments are not lanes (lateral offset > 4 camera heights)
    vanishing_tolerance: float = 0.2  # of the image width: segments must pass this close to the vanishing point
    slope_gap: float = 0.25  # sorted slopes further apart than this start a new lane
    min_support_px: float = 40.0  # total segment length of a lane


def paint_edges(rgb: UInt8Array, horizon_row: float, params: HoughParams, scale: float) -> UInt8Array:
    """(H, W) uint8 Canny edges of bright thin structures (white top-hat) below the horizon."""
    gray = (0.5 * (rgb[..., 0].astype(np.float32) + rgb[..., 1])).astype(np.uint8)
    blur = max(3, int(round(params.blur * min(scale, 2.0))) | 1)
    gray = np.asarray(cv2.GaussianBlur(gray, (blur, blur), 0), np.uint8)
    kernel = np.ones((1, max(3, int(round(params.tophat_px * scale)) | 1)), np.uint8)
    tophat = cv2.morphologyEx(gray, cv2.MORPH_TOPHAT, kernel)
    edges = np.asarray(cv2.Canny(gray, params.canny_low, params.canny_high), np.uint8)
    near_paint = cv2.dilate((tophat > params.min_tophat).astype(np.uint8), np.ones((3, 3), np.uint8))
    edges[near_paint == 0] = 0
    top = int(math.ceil(horizon_row + params.horizon_margin * rgb.shape[0]))
    edges[: max(top, 0)] = 0
    return edges


def lane_segments(edges: UInt8Array, horizon_row: float, params: HoughParams, scale: float) -> FloatArray:
    """(n, 4) float64 Hough segments (x1, y1, x2, y2) that may be lanes: steep enough, through the vanishing point."""
    found = cv2.HoughLinesP(edges, 1, np.pi / 180, params.hough_threshold,
                            minLineLength=params.min_length_px * scale, maxLineGap=params.max_gap_px * scale)
    if found is None:
        return np.zeros((0, 4))
    seg = found.reshape(-1, 4).astype(np.float64)
    dy = seg[:, 3] - seg[:, 1]
    steep = np.abs(dy) > 1e-6
    seg, dy = seg[steep], dy[steep]
    k = (seg[:, 2] - seg[:, 0]) / dy
    x_horizon = seg[:, 0] + k * (horizon_row - seg[:, 1])
    width = edges.shape[1]
    keep = (np.abs(k) <= params.max_abs_slope) & (np.abs(x_horizon - 0.5 * width) <= params.vanishing_tolerance * width)
    return seg[keep]


def group_by_slope(seg: FloatArray, params: HoughParams) -> list[FloatArray]:
    """Segments split into lanes where their sorted slopes jump by more than ``slope_gap``."""
    if len(seg) == 0:
        return []
    k = (seg[:, 2] - seg[:, 0]) / (seg[:, 3] - seg[:, 1])
    order = np.argsort(k, kind="stable")
    breaks = np.nonzero(np.diff(k[order]) > params.slope_gap)[0] + 1
    return [seg[group] for group in np.split(order, breaks)]


def fit_line(seg: FloatArray) -> tuple[float, float, float]:
    """Length-weighted least-squares ``x = k * y + b`` through the segments' end points; returns (k, b, support)."""
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    x = np.concatenate([seg[:, 0], seg[:, 2]])
    y = np.concatenate([seg[:, 1], seg[:, 3]])
    w = np.concatenate([length, length])
    k, b = np.polyfit(y, x, 1, w=np.sqrt(w))
    return float(k), float(b), float(length.sum())


def detect_hough(rgb: UInt8Array, h_samples: list[int], camera: GroundCamera | None = None,
                 params: HoughParams = HoughParams()) -> list[list[int]]:
    """TuSimple lanes (one x per h_sample, -2 = none), left to right, of an (H, W, 3) uint8 RGB frame."""
    height, width = rgb.shape[:2]
    camera = camera or GroundCamera.default((width, height))
    # Larger frames are processed at WORK_WIDTH: continuous coordinates scale by `shrink` (corner origin).
    shrink = min(1.0, WORK_WIDTH / width)
    small = (round(width * shrink), round(height * shrink))
    work = rgb if shrink == 1.0 else np.asarray(cv2.resize(rgb, small, interpolation=cv2.INTER_AREA), np.uint8)
    scale = work.shape[1] / 640.0
    horizon_work = camera.horizon_row * shrink
    seg = lane_segments(paint_edges(work, horizon_work, params, scale), horizon_work, params, scale)
    lines = [fit_line(group) for group in group_by_slope(seg, params)]
    lines = [line for line in lines if line[2] >= params.min_support_px * scale]
    lines.sort(key=lambda line: -line[2])
    v_image = sample_rows(h_samples)
    z_rows = camera.ground_z_of_row(v_image)
    usable_rows = np.isfinite(z_rows) & (z_rows <= RANGE_M)
    lanes = []
    for k, b_work, _ in lines[:MAX_LANES]:
        u_image = k * v_image + b_work / shrink  # x = k y + b in work pixels -> the same line in image pixels
        lanes.append(lane_columns(np.where(usable_rows, u_image, np.nan), width))
    return useful_lanes(lanes)
