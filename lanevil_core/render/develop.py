"""Image-space steps of a real camera after shading: motion blur over the exposure, and the sensor kernel that
turns linear radiance into sRGB bytes (exposure, vignetting, white balance, shot and read noise, clipping,
saturation, the filmic curve). The numbers come from ``camera.sensor.development``; noise is a counter-based hash
of (seed, pixel) that picks each channel's draw from a fixed table of normal deviates, so it is the same for any
thread count and any run."""

from __future__ import annotations

import math

import numpy as np

from ._jit import kernel
from .bands import band_rows, run_bands


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


@kernel
def _develop_rows(hdr: np.ndarray, gain: float, channel_gain: np.ndarray, vignetting: float, cx: float, cy: float,
                  shot: float, read: float, saturation: float, seed: np.uint64, lut: np.ndarray, normals: np.ndarray,
                  out: np.ndarray, band: int, bands: int) -> None:
    height, width, _ = hdr.shape
    top = lut.size - 1
    inv_r2 = 1.0 / (cx * cx + cy * cy)
    g0, g1, g2 = channel_gain[0], channel_gain[1], channel_gain[2]
    read2 = read * read
    mask = np.uint64(normals.size - 1)
    bits = np.uint64(NOISE_TABLE_BITS)
    for row in band_rows(height, band, bands):
        dy = row + 0.5 - cy
        for col in range(width):
            dx = col + 0.5 - cx
            r2 = (dx * dx + dy * dy) * inv_r2
            fall = gain * (1.0 - vignetting * r2 * (1.2 - 0.2 * r2))
            h = _hash(seed + np.uint64(row * width + col) * np.uint64(0x9E3779B97F4A7C15))
            x0 = max(hdr[row, col, 0] * fall * g0, 0.0)
            x1 = max(hdr[row, col, 1] * fall * g1, 0.0)
            x2 = max(hdr[row, col, 2] * fall * g2, 0.0)
            x0 = min(max(x0 + math.sqrt(x0 * shot + read2) * normals[h & mask], 0.0), 1.0)
            x1 = min(max(x1 + math.sqrt(x1 * shot + read2) * normals[(h >> bits) & mask], 0.0), 1.0)
            x2 = min(max(x2 + math.sqrt(x2 * shot + read2) * normals[(h >> (bits + bits)) & mask], 0.0), 1.0)
            y = 0.2126 * x0 + 0.7152 * x1 + 0.0722 * x2
            v = min(max(y + saturation * (x0 - y), 0.0), 1.0)
            out[row, col, 0] = lut[int(v * top + 0.5)]
            v = min(max(y + saturation * (x1 - y), 0.0), 1.0)
            out[row, col, 1] = lut[int(v * top + 0.5)]
            v = min(max(y + saturation * (x2 - y), 0.0), 1.0)
            out[row, col, 2] = lut[int(v * top + 0.5)]


def develop(hdr: np.ndarray, gain: float, channel_gain: np.ndarray, vignetting: float, center: tuple[float, float],
            shot: float, read: float, saturation: float, seed: int, lut: np.ndarray, out: np.ndarray,
            threads: int = 1) -> None:
    """(H, W, 3) float32 linear radiance to sRGB bytes in ``out`` (H, W, 3) uint8; ``center`` is the optical
    centre (px) the vignetting falls off from."""
    hdr = np.ascontiguousarray(hdr)
    cg = np.asarray(channel_gain, np.float64)
    run_bands(lambda band, bands: _develop_rows(hdr, gain, cg, vignetting, center[0], center[1], shot, read,
                                                saturation, np.uint64(seed), lut, NOISE_TABLE, out, band, bands),
              threads)


@kernel
def _motion_blur_rows(src: np.ndarray, depth: np.ndarray, cx: float, cy: float, travel: float, out: np.ndarray,
                      band: int, bands: int) -> None:
    """Blurs into ``out`` (a copy of ``src``) the pixels whose streak is at least 0.75 px long."""
    height, width, _ = src.shape
    for row in band_rows(height, band, bands):
        py = row + 0.5 - cy
        for col in range(width):
            z = depth[row, col]
            if not z < np.inf or z <= travel * 2.0:
                continue
            # Over the exposure the camera moves ``travel`` m forward: the pixel slides away from the centre of
            # expansion by (p - c) * travel / (z - travel); average the streak centred on the mid-exposure point.
            k = travel / (z - travel)
            fx = (col + 0.5 - cx) * k
            fy = py * k
            length2 = fx * fx + fy * fy
            if length2 < 0.5625:
                continue
            taps = min(int(math.sqrt(length2)) + 2, 24)
            step_x, step_y = fx / (taps - 1), fy / (taps - 1)
            x, y = col + 0.5 - 0.5 * fx, row + 0.5 - 0.5 * fy
            a0 = a1 = a2 = 0.0
            for _ in range(taps):
                sc = min(max(int(x), 0), width - 1)
                sr = min(max(int(y), 0), height - 1)
                a0 += src[sr, sc, 0]
                a1 += src[sr, sc, 1]
                a2 += src[sr, sc, 2]
                x += step_x
                y += step_y
            out[row, col, 0] = a0 / taps
            out[row, col, 1] = a1 / taps
            out[row, col, 2] = a2 / taps


def motion_blur(hdr: np.ndarray, depth: np.ndarray, center: tuple[float, float], travel: float,
                threads: int = 1) -> np.ndarray:
    """(H, W, 3) float32 radiance blurred along each pixel's image motion while the camera moves ``travel`` m
    along its optical axis (a pinhole image; ``center`` is its principal point). Sky pixels stay sharp."""
    out = hdr.copy()
    run_bands(lambda band, bands: _motion_blur_rows(hdr, depth, center[0], center[1], travel, out, band, bands),
              threads)
    return out
