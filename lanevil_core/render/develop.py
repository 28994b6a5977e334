"""Image-space steps of a real camera after shading: motion blur over the exposure, and the sensor kernel that
turns linear radiance into sRGB bytes (exposure, vignetting, white balance, shot and read noise, clipping,
saturation, the filmic curve). The numbers come from ``camera.sensor.development``; noise is a counter-based hash
of (seed, pixel) that picks each channel's draw from a fixed table of normal deviates, so it is the same for any
thread count and any run. Through a plain pinhole the sensor kernel also blurs and antialiases object edges as it
reads each pixel, so the frame's radiance is read once and never copied."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..typed import Float32Array
from ._jit import kernel
from .bands import band_rows, run_bands
from .post import edge_blend, row_edges


@kernel(inline="always")
def _hash(x: np.uint64) -> np.uint64:
    """SplitMix64's finaliser: a well-mixed 64-bit hash."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


NOISE_TABLE_BITS = 12
# Standard normal deviates (float64, fixed seed) the sensor noise draws from: 4,096 of them fit the first-level
# cache, and 12 bits of one pixel's hash pick each channel's, so a pixel costs one hash instead of one per channel.
NOISE_TABLE = np.random.default_rng(0x5E45).standard_normal(1 << NOISE_TABLE_BITS)


class Streaks(NamedTuple):
    """Motion blur of a pinhole image while the camera moves ``travel`` m along its optical axis: the image's depth
    (H, W) and its principal point (px). ``travel`` 0: none."""

    depth: Float32Array
    cx: float
    cy: float
    travel: float


NO_STREAKS = Streaks(np.full((1, 1), np.inf, np.float32), 0.0, 0.0, 0.0)
# Pixels whose streak is shorter stay sharp: the nearest-texel taps of a streak under a pixel long all land on the
# pixel itself, so blurring it would only cost time (and skip the edge blend).
MIN_STREAK_PX = 1.0
MAX_STREAK_TAPS = 24


@kernel(inline="always")
def _streak_row(depth: np.ndarray, cx: float, cy: float, travel: float, row: int, taps: np.ndarray,
                start_x: np.ndarray, start_y: np.ndarray, step_x: np.ndarray, step_y: np.ndarray) -> None:
    """Each pixel's streak in ``row``: its tap count (0 when the streak is shorter than MIN_STREAK_PX and the
    pixel stays sharp), its first tap and the step between taps (px).

    Over the exposure the camera moves ``travel`` m forward: a point at depth z slides away from the centre of
    expansion by (p - c) * travel / (z - travel); the streak is centred on the mid-exposure point. Arithmetic
    only, without branches, so it runs on whole vectors of pixels."""
    for col in range(depth.shape[1]):
        z = depth[row, col]
        moving = (z < np.inf) & (z > travel * 2.0)
        k = travel / (z - travel) if moving else 0.0
        fx = (col + 0.5 - cx) * k
        fy = (row + 0.5 - cy) * k
        length2 = fx * fx + fy * fy
        n = min(int(math.sqrt(length2)) + 2, MAX_STREAK_TAPS) if length2 >= MIN_STREAK_PX * MIN_STREAK_PX else 0
        taps[col] = n
        step_x[col] = fx / max(n - 1, 1)
        step_y[col] = fy / max(n - 1, 1)
        start_x[col] = col + 0.5 - 0.5 * fx
        start_y[col] = row + 0.5 - 0.5 * fy


@kernel(inline="always")
def _streak_buffers(width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A row's worth of ``_streak_row`` output: tap counts (all 0, so every pixel starts sharp), first taps and
    steps."""
    return np.zeros(width, np.int64), np.empty(width), np.empty(width), np.empty(width), np.empty(width)


@kernel(inline="always")
def _streak_mean(src: np.ndarray, taps: int, x: float, y: float, step_x: float,
                 step_y: float) -> tuple[np.float32, np.float32, np.float32]:
    """The mean of ``src`` (H, W, 3) over ``taps`` (at least 1) nearest-pixel taps from (x, y) by (step_x,
    step_y)."""
    height, width, _ = src.shape
    a0 = a1 = a2 = np.float32(0.0)  # the image's own precision: no conversion per tap
    for _ in range(taps):
        sc = min(max(int(x), 0), width - 1)
        sr = min(max(int(y), 0), height - 1)
        a0 += src[sr, sc, 0]
        a1 += src[sr, sc, 1]
        a2 += src[sr, sc, 2]
        x += step_x
        y += step_y
    inv = np.float32(1.0 / taps)
    return a0 * inv, a1 * inv, a2 * inv


@kernel
def _motion_blur_rows(src: np.ndarray, depth: np.ndarray, cx: float, cy: float, travel: float, out: np.ndarray,
                      band: int, bands: int) -> None:
    """The rows of one band of ``out``: each pixel's streak mean, or its own value when the streak is shorter
    than MIN_STREAK_PX."""
    height, width, _ = src.shape
    taps, start_x, start_y, step_x, step_y = _streak_buffers(width)
    for row in band_rows(height, band, bands):
        _streak_row(depth, cx, cy, travel, row, taps, start_x, start_y, step_x, step_y)
        for col in range(width):
            if taps[col] > 0:
                r, g, b = _streak_mean(src, taps[col], start_x[col], start_y[col], step_x[col], step_y[col])
                out[row, col, 0] = r
                out[row, col, 1] = g
                out[row, col, 2] = b
            else:
                out[row, col, 0] = src[row, col, 0]
                out[row, col, 1] = src[row, col, 1]
                out[row, col, 2] = src[row, col, 2]


def motion_blur(hdr: np.ndarray, depth: np.ndarray, center: tuple[float, float], travel: float,
                threads: int = 1) -> np.ndarray:
    """(H, W, 3) float32 radiance blurred along each pixel's image motion while the camera moves ``travel`` m
    along its optical axis (a pinhole image; ``center`` is its principal point). Sky pixels stay sharp."""
    out = np.empty_like(hdr)
    run_bands(lambda band, bands: _motion_blur_rows(hdr, depth, center[0], center[1], travel, out, band, bands),
              threads)
    return out


@kernel
def _develop_rows(hdr: np.ndarray, ids: np.ndarray, streaks: Streaks, gain: float, channel_gain: np.ndarray,
                  vignetting: float, cx: float, cy: float, shot: float, read: float, saturation: float,
                  seed: np.uint64, lut: np.ndarray, normals: np.ndarray, out: np.ndarray, band: int,
                  bands: int) -> None:
    """Develops the rows of one band in five sweeps of a row: each pixel's streak (``_streak_row``, on whole
    vectors of pixels); its radiance (its streak's mean, else blended with its neighbours on an object edge, else
    its own); its noise deviates (none drawn when ``shot`` and ``read`` are both 0: the deviates stay 0, so the
    frame carries exactly no noise); the sensor's arithmetic, on whole vectors of pixels; the tone curve's table
    reads."""
    height, width, _ = hdr.shape
    depth, blur_cx, blur_cy, travel = streaks
    top = lut.size - 1
    inv_r2 = 1.0 / (cx * cx + cy * cy)
    g0, g1, g2 = channel_gain[0], channel_gain[1], channel_gain[2]
    read2 = read * read
    mask = np.uint64(normals.size - 1)
    bits = np.uint64(NOISE_TABLE_BITS)
    radiance = np.empty(width * 3, np.float64)
    noise = np.zeros(width * 3, np.float64)
    drawn = width if shot > 0.0 or read > 0.0 else 0  # columns whose deviates are drawn: none without noise
    index = np.empty(width * 3, np.uint16)  # unsigned: the table reads need no check for negative indices
    on_edge = np.zeros(width, np.bool_)
    taps, start_x, start_y, step_x, step_y = _streak_buffers(width)  # no streaks: every pixel stays sharp
    for row in band_rows(height, band, bands):
        if ids.shape[0] == height:
            row_edges(ids, row, on_edge)
        if travel > 0.0:
            _streak_row(depth, blur_cx, blur_cy, travel, row, taps, start_x, start_y, step_x, step_y)
        for col in range(width):
            if taps[col] > 0:
                r, g, b = _streak_mean(hdr, taps[col], start_x[col], start_y[col], step_x[col], step_y[col])
            elif on_edge[col]:
                r, g, b = edge_blend(hdr, row, col, 0), edge_blend(hdr, row, col, 1), edge_blend(hdr, row, col, 2)
            else:
                r, g, b = hdr[row, col, 0], hdr[row, col, 1], hdr[row, col, 2]
            radiance[3 * col] = r
            radiance[3 * col + 1] = g
            radiance[3 * col + 2] = b
        pixel = np.uint64(row * width)
        for col in range(drawn):  # three table reads per pixel from one hash
            h = _hash(seed + (pixel + np.uint64(col)) * np.uint64(0x9E3779B97F4A7C15))
            noise[3 * col] = normals[h & mask]
            noise[3 * col + 1] = normals[(h >> bits) & mask]
            noise[3 * col + 2] = normals[(h >> (bits + bits)) & mask]
        dy = row + 0.5 - cy
        for col in range(width):  # arithmetic only: it runs on whole vectors of pixels
            dx = col + 0.5 - cx
            r2 = (dx * dx + dy * dy) * inv_r2
            fall = gain * (1.0 - vignetting * r2 * (1.2 - 0.2 * r2))
            x0 = max(radiance[3 * col] * fall * g0, 0.0)
            x1 = max(radiance[3 * col + 1] * fall * g1, 0.0)
            x2 = max(radiance[3 * col + 2] * fall * g2, 0.0)
            x0 = min(max(x0 + math.sqrt(x0 * shot + read2) * noise[3 * col], 0.0), 1.0)
            x1 = min(max(x1 + math.sqrt(x1 * shot + read2) * noise[3 * col + 1], 0.0), 1.0)
            x2 = min(max(x2 + math.sqrt(x2 * shot + read2) * noise[3 * col + 2], 0.0), 1.0)
            y = 0.2126 * x0 + 0.7152 * x1 + 0.0722 * x2
            index[3 * col] = np.uint16(min(max(y + saturation * (x0 - y), 0.0), 1.0) * top + 0.5)
            index[3 * col + 1] = np.uint16(min(max(y + saturation * (x1 - y), 0.0), 1.0) * top + 0.5)
            index[3 * col + 2] = np.uint16(min(max(y + saturation * (x2 - y), 0.0), 1.0) * top + 0.5)
        encoded = out[row].reshape(width * 3)
        for k in range(width * 3):
            encoded[k] = lut[index[k]]


def develop(hdr: np.ndarray, gain: float, channel_gain: np.ndarray, vignetting: float, center: tuple[float, float],
            shot: float, read: float, saturation: float, seed: int, lut: np.ndarray, out: np.ndarray,
            threads: int = 1, ids: np.ndarray | None = None, streaks: Streaks = NO_STREAKS) -> None:
    """(H, W, 3) float32 linear radiance to sRGB bytes in ``out`` (H, W, 3) uint8; ``center`` is the optical
    centre (px) the vignetting falls off from. With the object ids ``ids`` (H, W), pixels on an object's edge are
    first blended with their neighbours (as ``post.finish`` does); with ``streaks``, pixels are first blurred
    along their motion (``motion_blur`` in the same pass)."""
    hdr = np.ascontiguousarray(hdr)
    cg = np.asarray(channel_gain, np.float64)
    id_map = np.zeros((0, 0), np.int32) if ids is None else ids
    run_bands(lambda band, bands: _develop_rows(hdr, id_map, streaks, gain, cg, vignetting, center[0], center[1],
                                                shot, read, saturation, np.uint64(seed), lut, NOISE_TABLE, out,
                                                band, bands), threads)
