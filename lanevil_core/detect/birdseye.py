"""Bird's-eye baseline: warp the road to a top view, threshold white and yellow paint, follow each line with
sliding windows, fit ``x = poly(z)`` on the ground and project it back to the image rows.

The top view comes from the known camera (``GroundCamera``: intrinsics, mount height, pitch) and a flat road,
so no calibration points are guessed. Ground coordinates: ``x_ground`` metres right of the camera,
``z_ground`` metres ahead.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..labels.lanes import MAX_LANES, RANGE_M
from ..typed import BoolArray, FloatArray, IndexArray, UInt8Array
from .common import GroundCamera, lane_columns, sample_rows, useful_lanes


@dataclass(frozen=True)
class BirdseyeParams:
    """Top-view grid and detection thresholds (metres unless named otherwise)."""

    x_half_m: float = 12.0  # lateral half-width of the top view
    z_far_m: float = 50.0  # far edge of the top view
    m_per_px_x: float = 0.05
    m_per_px_z: float = 0.2
    tophat_m: float = 0.6  # paint is narrower than this (white top-hat kernel width)
    min_contrast: float = 0.22  # top-hat / local background brightness of paint
    min_tophat: float = 12.0  # absolute top-hat floor (0-255)
    yellow_hue: tuple[int, int] = (12, 40)  # OpenCV hue (0-180)
    yellow_min_saturation: int = 70
    white_max_saturation: int = 60
    base_range_m: float = 25.0  # the histogram of line positions uses the top view up to this far
    min_peak_fraction: float = 0.12  # a line covers at least this fraction of that range
    min_spacing_m: float = 2.2  # two lines closer than this are one
    window_half_m: float = 0.5
    windows: int = 20
    min_window_pixels: int = 3
    min_lane_pixels: int = 25


def z_near_m(camera: GroundCamera) -> float:
    """Ground distance seen at the bottom image edge."""
    return float(camera.ground_z_of_row(np.array([camera.size[1]]))[0])


def topview_H(camera: GroundCamera, params: BirdseyeParams) -> tuple[FloatArray, tuple[int, int]]:
    """(3, 3) homography top-view pixel -> image pixel, and the top-view size (width, height).

    Top-view column c covers x_ground = -x_half + (c + 0.5) * m_per_px_x; row 0 is the far edge.
    """
    z_near = z_near_m(camera)
    width = int(round(2 * params.x_half_m / params.m_per_px_x))
    height = int(round((params.z_far_m - z_near) / params.m_per_px_z))
    # top-view pixel (c, r) -> ground (x, z): x = -x_half + c * dx, z = z_far - r * dz (corner convention)
    T_ground_topview = np.array([[params.m_per_px_x, 0.0, -params.x_half_m],
                                 [0.0, -params.m_per_px_z, params.z_far_m],
                                 [0.0, 0.0, 1.0]])
    return camera.H_image_ground() @ T_ground_topview, (width, height)


def paint_mask(rgb_topview: UInt8Array, params: BirdseyeParams) -> BoolArray:
    """(h, w) bool: white or yellow paint, brighter than the road around it by a relative margin."""
    rgb = rgb_topview.astype(np.float32)
    brightness = 0.5 * (rgb[..., 0] + rgb[..., 1])  # yellow and white paint are both bright in R and G
    kernel = np.ones((1, max(3, int(round(params.tophat_m / params.m_per_px_x))) | 1), np.uint8)
    background = cv2.morphologyEx(brightness, cv2.MORPH_OPEN, kernel)
    tophat = brightness - background
    contrast = (tophat > params.min_tophat) & (tophat > params.min_contrast * (background + 10.0))
    hls = cv2.cvtColor(rgb_topview, cv2.COLOR_RGB2HLS)
    hue, saturation = hls[..., 0], hls[..., 2]
    low, high = params.yellow_hue
    yellow = (hue >= low) & (hue <= high) & (saturation >= params.yellow_min_saturation)
    white = saturation <= params.white_max_saturation
    return contrast & (white | yellow)


def base_columns(mask: BoolArray, params: BirdseyeParams, rows_near: slice) -> list[int]:
    """Top-view columns where lines start: peaks of the paint histogram of the near rows, strongest first."""
    hist = mask[rows_near].sum(axis=0).astype(np.float64)
    width_px = max(3, int(round(0.3 / params.m_per_px_x)) | 1)
    hist = np.convolve(hist, np.ones(width_px) / width_px * 3, mode="same")
    rows = rows_near.stop - rows_near.start
    spacing = int(round(params.min_spacing_m / params.m_per_px_x))
    peaks: list[int] = []
    for col in np.argsort(-hist, kind="stable"):
        if hist[col] < params.min_peak_fraction * rows:
            break
        if all(abs(int(col) - other) >= spacing for other in peaks):
            peaks.append(int(col))
    return peaks


def follow_line(pixels: tuple[IndexArray, ...], size: tuple[int, int], start_col: int, params: BirdseyeParams
                ) -> tuple[FloatArray, FloatArray]:
    """Sliding windows from the near edge outwards over the paint ``pixels`` (rows, cols) of a top view of
    ``size`` (width, height); returns the (cols, rows) of the pixels along the line."""
    width, height = size
    ys, xs = pixels
    half = int(round(params.window_half_m / params.m_per_px_x))
    step = height / params.windows
    col, drift = float(start_col), 0.0
    keep = np.zeros(len(xs), bool)
    for i in range(params.windows):
        top, bottom = height - (i + 1) * step, height - i * step
        inside = (ys >= top) & (ys < bottom) & (np.abs(xs - col) <= half)
        if inside.sum() >= params.min_window_pixels:
            new_col = float(xs[inside].mean())
            drift = 0.5 * drift + 0.5 * (new_col - col) if i else 0.0
            col = new_col
            keep |= inside
        else:
            col += drift  # carry on through dash gaps along the line's current direction
        if not 0 <= col < width:
            break
    return xs[keep].astype(np.float64), ys[keep].astype(np.float64)


def fit_ground_lane(cols: FloatArray, rows: FloatArray, params: BirdseyeParams) -> FloatArray:
    """Polynomial coefficients of x_ground(z_ground): quadratic when the line is seen over 20 m, else linear."""
    x_ground = -params.x_half_m + (cols + 0.5) * params.m_per_px_x
    z_ground = params.z_far_m - (rows + 0.5) * params.m_per_px_z
    degree = 2 if np.ptp(z_ground) > 20.0 else 1
    return np.polyfit(z_ground, x_ground, degree)


def detect_birdseye(rgb: UInt8Array, h_samples: list[int], camera: GroundCamera | None = None,
                    params: BirdseyeParams = BirdseyeParams()) -> list[list[int]]:
    """TuSimple lanes (one x per h_sample, -2 = none), left to right, of an (H, W, 3) uint8 RGB frame."""
    height, width = rgb.shape[:2]
    camera = camera or GroundCamera.default((width, height))
    H_image_topview, size = topview_H(camera, params)
    topview = np.asarray(cv2.warpPerspective(rgb, H_image_topview, size, flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP),
                         np.uint8)
    mask = paint_mask(topview, params)
    near_rows = int(round((params.base_range_m - z_near_m(camera)) / params.m_per_px_z))
    starts = base_columns(mask, params, slice(size[1] - max(near_rows, 1), size[1]))
    v_image = sample_rows(h_samples)
    z_rows = camera.ground_z_of_row(v_image)
    usable_rows = np.isfinite(z_rows) & (z_rows <= RANGE_M)
    pixels = np.nonzero(mask)
    lanes = []
    for start in starts[:MAX_LANES]:
        cols, rows = follow_line(pixels, size, start, params)
        if len(cols) < params.min_lane_pixels:
            continue
        x_rows = np.asarray(np.polyval(fit_ground_lane(cols, rows, params), np.where(usable_rows, z_rows, 0.0)),
                            np.float64)
        uv_image = camera.project_ground(x_rows, np.where(usable_rows, z_rows, 1.0))
        lanes.append(lane_columns(np.where(usable_rows, uv_image[:, 0], np.nan), width))
    return useful_lanes(lanes)
