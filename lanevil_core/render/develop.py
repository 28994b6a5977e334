"""Image-space steps of a real camera after shading: motion blur over the exposure, and the sensor kernel that
turns linear radiance into sRGB bytes (exposure, vignetting, white balance, shot and read noise, clipping,
saturation, the filmic curve). The numbers come from ``camera.sensor.development``; noise is a counter-based hash
of (seed, pixel, channel) shaped near-normal, so it is the same for any thread count and any run."""

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


@kernel(inline="always")
def _gaussian(seed: np.uint64, index: np.uint64) -> float:
    """A near-normal draw (mean 0, variance 1) for ``index`` of stream ``seed``: the sum of the four 16-bit
    uniforms of one hash (Irwin-Hall, tails cut at 3.5 sigma), no transcendental functions per pixel."""
    h = _hash(seed + index * np.uint64(0x9E3779B97F4A7C15))
    mask = np.uint64(0xFFFF)
    total = float(h & mask) + float((h >> np.uint64(16)) & mask) + float((h >> np.uint64(32)) & mask) + float(
        h >> np.uint64(48))
    return (total / 65536.0 - 2.0) * 1.7320508075688772


@kernel
def _develop_rows(hdr: np.ndarray, gain: float, channel_gain: np.ndarray, vignetting: float, cx: float, cy: float,
                  shot: float, read: float, saturation: float, seed: np.uint64, lut: np.ndarray, out: np.ndarray,
                  band: int, bands: int) -> None:
    height, width, _ = hdr.shape
    top = lut.size - 1
    inv_r2 = 1.0 / (cx * cx + cy * cy)
    g0, g1, g2 = channel_gain[0], channel_gain[1], channel_gain[2]
    x = np.empty(3)
    for row in band_rows(height, band, bands):
        dy = row + 0.5 - cy
        for col in range(width):
            dx = col + 0.5 - cx
            r2 = (dx * dx + dy * dy) * inv_r2
            fall = gain * (1.0 - vignetting * r2 * (1.2 - 0.2 * r2))
            x[0] = hdr[row, col, 0] * fall * g0
            x[1] = hdr[row, col, 1] * fall * g1
            x[2] = hdr[row, col, 2] * fall * g2
            base = np.uint64((row * width + col) * 3)
            for c in range(3):
                v = max(x[c], 0.0)
                sigma = math.sqrt(v * shot + read * read)
                v += sigma * _gaussian(seed, base + np.uint64(c))
                x[c] = min(max(v, 0.0), 1.0)
            y = 0.2126 * x[0] + 0.7152 * x[1] + 0.0722 * x[2]
            for c in range(3):
                v = min(max(y + saturation * (x[c] - y), 0.0), 1.0)
                out[row, col, c] = lut[int(math.sqrt(v) * top + 0.5)]


def develop(hdr: np.ndarray, gain: float, channel_gain: np.ndarray, vignetting: float, center: tuple[float, float],
            shot: float, read: float, saturation: float, seed: int, lut: np.ndarray, out: np.ndarray,
            threads: int = 1) -> None:
    """(H, W, 3) float32 linear radiance to sRGB bytes in ``out`` (H, W, 3) uint8; ``center`` is the optical
    centre (px) the vignetting falls off from."""
    hdr = np.ascontiguousarray(hdr)
    cg = np.asarray(channel_gain, np.float64)
    run_bands(lambda band, bands: _develop_rows(hdr, gain, cg, vignetting, center[0], center[1], shot, read,
                                                saturation, np.uint64(seed), lut, out, band, bands), threads)


@kernel
def _motion_blur_rows(src: np.ndarray, depth: np.ndarray, cx: float, cy: float, travel: float, out: np.ndarray,
                      band: int, bands: int) -> None:
    height, width, _ = src.shape
    for row in band_rows(height, band, bands):
        for col in range(width):
            z = depth[row, col]
            for c in range(3):
                out[row, col, c] = src[row, col, c]
            if not z < np.inf or z <= travel * 2.0:
                continue
            # Over the exposure the camera moves ``travel`` m forward: the pixel slides away from the centre of
            # expansion by (p - c) * travel / (z - travel); average the streak centred on the mid-exposure point.
            k = travel / (z - travel)
            fx = (col + 0.5 - cx) * k
            fy = (row + 0.5 - cy) * k
            length = math.sqrt(fx * fx + fy * fy)
            if length < 0.75:
                continue
            taps = min(int(length) + 2, 24)
            a0 = a1 = a2 = 0.0
            for i in range(taps):
                t = i / (taps - 1) - 0.5
                sc = min(max(int(col + t * fx + 0.5), 0), width - 1)
                sr = min(max(int(row + t * fy + 0.5), 0), height - 1)
                a0 += src[sr, sc, 0]
                a1 += src[sr, sc, 1]
                a2 += src[sr, sc, 2]
            out[row, col, 0] = a0 / taps
            out[row, col, 1] = a1 / taps
            out[row, col, 2] = a2 / taps


def motion_blur(hdr: np.ndarray, depth: np.ndarray, center: tuple[float, float], travel: float,
                threads: int = 1) -> np.ndarray:
    """(H, W, 3) float32 radiance blurred along each pixel's image motion while the camera moves ``travel`` m
    along its optical axis (a pinhole image; ``center`` is its principal point). Sky pixels stay sharp."""
    out = np.empty_like(hdr)
    run_bands(lambda band, bands: _motion_blur_rows(hdr, depth, center[0], center[1], travel, out, band, bands),
              threads)
    return out
