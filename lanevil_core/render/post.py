"""Image-space steps after shading: mirror blur, silhouette antialiasing and tone mapping to sRGB bytes."""

from __future__ import annotations

import cv2
import numpy as np

from ..images import linear_to_srgb
from ._jit import kernel
from .bands import band_rows, run_bands

LUT_SIZE = 4096
WHITE_POINT = 4.0
CLAMP = 8.0  # bright highlights are clamped before edge blending so a sun glint does not bleed
# A lens's glare (the skirt of its point-spread function: scatter in the glass and off the barrel): light above
# GLARE_THRESHOLD times the exposure's white spreads in three Gaussian lobes, (sigma as a share of the image width,
# share of the light), so the sun's small disk and the lamps at night bloom as a camera shows them. Spread at
# 1 / GLARE_SCALE of the image size.
GLARE_THRESHOLD = 4.0
GLARE_LOBES = ((0.004, 0.05), (0.015, 0.02), (0.06, 0.01))
GLARE_SCALE = 4


def glare(hdr: np.ndarray, exposure: float) -> None:
    """Add, in place, the lens glare of the light in (H, W, 3) float32 linear ``hdr`` brighter than
    ``GLARE_THRESHOLD`` at ``exposure`` (no change when nothing is that bright)."""
    limit = GLARE_THRESHOLD / max(exposure, 1e-9)
    if float(hdr.max(initial=0.0)) <= limit:
        return
    height, width = hdr.shape[:2]
    small_size = (max(width // GLARE_SCALE, 1), max(height // GLARE_SCALE, 1))
    excess = cv2.resize(np.maximum(hdr - np.float32(limit), np.float32(0.0)), small_size,
                        interpolation=cv2.INTER_AREA)
    spread = np.zeros(excess.shape, np.float32)
    for sigma, share in GLARE_LOBES:
        spread += np.float32(share) * np.asarray(cv2.GaussianBlur(excess, (0, 0), max(sigma * small_size[0], 0.5)),
                                                 np.float32)
    hdr += np.asarray(cv2.resize(spread, (width, height), interpolation=cv2.INTER_LINEAR), np.float32)


def _srgb_lut() -> np.ndarray:
    srgb = linear_to_srgb(np.linspace(0.0, 1.0, LUT_SIZE))
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)


SRGB_LUT = _srgb_lut()


@kernel(inline="always")
def _lut_index(x: float, inv_w2: float, top: int) -> int:
    """Extended Reinhard curve, then the entry of the sRGB lookup table (``top`` + 1 entries) that encodes it."""
    x = max(x, 0.0)
    y = x * (1.0 + x * inv_w2) / (1.0 + x)
    return min(int(y * top + 0.5), top)


@kernel(inline="always")
def _differs(ids: np.ndarray, row: int, col: int, above: int, below: int, left: int, right: int) -> bool:
    """Whether the id at (row, col) differs from the one at any of the given neighbouring rows and columns."""
    here = ids[row, col]
    return (ids[row, right] != here) | (ids[row, left] != here) | (ids[below, col] != here) | (ids[above, col] != here)


@kernel(inline="always")
def row_edges(ids: np.ndarray, row: int, on_edge: np.ndarray) -> None:
    """Per column of ``row``: whether the pixel's object id differs from one of its 4-neighbours' (a neighbour
    off the image is the pixel itself). Branch-free inside the row, so that loop runs on whole vectors of columns."""
    height, width = ids.shape
    above, below = max(row - 1, 0), min(row + 1, height - 1)
    for col in range(1, width - 1):
        on_edge[col] = _differs(ids, row, col, above, below, col - 1, col + 1)
    on_edge[0] = _differs(ids, row, 0, above, below, 0, min(1, width - 1))
    on_edge[width - 1] = _differs(ids, row, width - 1, above, below, max(width - 2, 0), width - 1)


@kernel(inline="always")
def edge_blend(hdr: np.ndarray, row: int, col: int, c: int) -> float:
    """Half the pixel's clamped radiance plus half its 4-neighbourhood's mean."""
    height, width, _ = hdr.shape
    acc = 0.0
    cnt = 0.0
    if col + 1 < width:
        acc += min(hdr[row, col + 1, c], CLAMP)
        cnt += 1.0
    if col > 0:
        acc += min(hdr[row, col - 1, c], CLAMP)
        cnt += 1.0
    if row + 1 < height:
        acc += min(hdr[row + 1, col, c], CLAMP)
        cnt += 1.0
    if row > 0:
        acc += min(hdr[row - 1, col, c], CLAMP)
        cnt += 1.0
    return 0.5 * min(hdr[row, col, c], CLAMP) + 0.5 * acc / cnt


@kernel
def _finish_rows(hdr: np.ndarray, ids: np.ndarray, exposure: float, lut: np.ndarray, out: np.ndarray, band: int,
                 bands: int) -> None:
    """Tone-map the rows of one band: every channel's lookup-table index in one arithmetic sweep of the row (it
    vectorises), the table reads in a second; then the pixels on an object edge again, blended."""
    height, width, _ = hdr.shape
    inv_w2 = 1.0 / (WHITE_POINT * WHITE_POINT)
    top = lut.size - 1
    index = np.empty(width * 3, np.uint16)  # unsigned: the table reads need no check for negative indices
    on_edge = np.empty(width, np.bool_)
    for row in band_rows(height, band, bands):
        radiance = hdr[row].reshape(width * 3)
        for k in range(width * 3):
            index[k] = np.uint16(_lut_index(radiance[k] * exposure, inv_w2, top))
        encoded = out[row].reshape(width * 3)
        for k in range(width * 3):
            encoded[k] = lut[index[k]]
        row_edges(ids, row, on_edge)
        for col in range(width):
            if on_edge[col]:
                for c in range(3):
                    out[row, col, c] = lut[_lut_index(edge_blend(hdr, row, col, c) * exposure, inv_w2, top)]


def finish(hdr: np.ndarray, ids: np.ndarray, exposure: float, lut: np.ndarray, out: np.ndarray,
           threads: int = 1) -> None:
    """Tone-map (H, W, 3) linear radiance to sRGB bytes in ``out``; pixels on an object-id boundary are first
    blended with their 4-neighbourhood (a cheap silhouette antialias: the procedural road is already filtered,
    object edges are not)."""
    hdr = np.ascontiguousarray(hdr)
    run_bands(lambda band, bands: _finish_rows(hdr, ids, exposure, lut, out, band, bands), threads)


@kernel
def _blur_column_band(img: np.ndarray, depth: np.ndarray, radius: int, band: int, bands: int) -> None:
    """Running box sums down each column of one band: O(height) per column whatever the radius."""
    height, width, _ = img.shape
    column = np.empty((height, 3))
    for col in band_rows(width, band, bands):
        for row in range(height):
            for c in range(3):
                column[row, c] = img[row, col, c]
        acc0 = acc1 = acc2 = 0.0
        cnt = 0
        for row in range(min(radius, height)):  # the window of row -1: rows 0 .. radius - 1
            if depth[row, col] < np.inf:
                acc0 += column[row, 0]
                acc1 += column[row, 1]
                acc2 += column[row, 2]
                cnt += 1
        for row in range(height):
            enter, leave = row + radius, row - radius - 1
            if enter < height and depth[enter, col] < np.inf:
                acc0 += column[enter, 0]
                acc1 += column[enter, 1]
                acc2 += column[enter, 2]
                cnt += 1
            if leave >= 0 and depth[leave, col] < np.inf:
                acc0 -= column[leave, 0]
                acc1 -= column[leave, 1]
                acc2 -= column[leave, 2]
                cnt -= 1
            if depth[row, col] < np.inf:
                img[row, col, 0] = acc0 / cnt
                img[row, col, 1] = acc1 / cnt
                img[row, col, 2] = acc2 / cnt


def blur_columns(img: np.ndarray, depth: np.ndarray, radius: int, threads: int = 1) -> None:
    """Box-blur a mirror image along columns in place (wet roads smear reflections vertically); the bands of
    ``threads`` split the columns."""
    run_bands(lambda band, bands: _blur_column_band(img, depth, radius, band, bands), threads)
