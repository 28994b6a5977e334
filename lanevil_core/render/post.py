"""Image-space steps after shading: mirror blur, silhouette antialiasing and tone mapping to sRGB bytes."""

from __future__ import annotations

import numpy as np

from ._jit import kernel

LUT_SIZE = 4096
WHITE_POINT = 4.0
CLAMP = 8.0  # bright highlights are clamped before edge blending so a sun glint does not bleed


def _srgb_lut() -> np.ndarray:
    y = np.linspace(0.0, 1.0, LUT_SIZE)
    srgb = np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1 / 2.4) - 0.055)
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)


SRGB_LUT = _srgb_lut()


@kernel(inline="always")
def _encode(x: float, inv_w2: float, lut: np.ndarray) -> np.uint8:
    """Extended Reinhard curve, then sRGB encoding through a lookup table."""
    x = max(x, 0.0)
    y = x * (1.0 + x * inv_w2) / (1.0 + x)
    top = lut.size - 1
    return lut[min(int(y * top + 0.5), top)]


@kernel
def _encode_all(hdr: np.ndarray, exposure: float, lut: np.ndarray, out: np.ndarray) -> None:
    inv_w2 = 1.0 / (WHITE_POINT * WHITE_POINT)
    flat_in = hdr.reshape(-1)
    flat_out = out.reshape(-1)
    for i in range(flat_in.size):
        flat_out[i] = _encode(flat_in[i] * exposure, inv_w2, lut)


@kernel
def _smooth_edges(hdr: np.ndarray, edges: np.ndarray, exposure: float, lut: np.ndarray, out: np.ndarray) -> None:
    height, width, _ = hdr.shape
    inv_w2 = 1.0 / (WHITE_POINT * WHITE_POINT)
    for k in range(edges.size):
        row = edges[k] // width
        col = edges[k] % width
        for c in range(3):
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
            x = 0.5 * min(hdr[row, col, c], CLAMP) + 0.5 * acc / cnt
            out[row, col, c] = _encode(x * exposure, inv_w2, lut)


def finish(hdr: np.ndarray, ids: np.ndarray, exposure: float, lut: np.ndarray, out: np.ndarray) -> None:
    """Tone-map (H, W, 3) linear radiance to sRGB bytes in ``out``; pixels on an object-id boundary are first
    blended with their 4-neighbourhood (a cheap silhouette antialias: the procedural road is already filtered,
    object edges are not)."""
    _encode_all(np.ascontiguousarray(hdr), exposure, lut, out)
    edge = np.zeros(ids.shape, bool)
    across = ids[:, 1:] != ids[:, :-1]
    down = ids[1:, :] != ids[:-1, :]
    edge[:, 1:] |= across
    edge[:, :-1] |= across
    edge[1:, :] |= down
    edge[:-1, :] |= down
    _smooth_edges(hdr, np.flatnonzero(edge), exposure, lut, out)


@kernel
def blur_columns(img: np.ndarray, depth: np.ndarray, radius: int) -> None:
    """Box-blur a mirror image along columns in place (wet roads smear reflections vertically)."""
    height, width, _ = img.shape
    column = np.empty((height, 3))
    for col in range(width):
        for row in range(height):
            for c in range(3):
                column[row, c] = img[row, col, c]
        for row in range(height):
            if depth[row, col] == np.inf:
                continue
            lo = max(row - radius, 0)
            hi = min(row + radius, height - 1)
            for c in range(3):
                acc = 0.0
                cnt = 0
                for r in range(lo, hi + 1):
                    if depth[r, col] < np.inf:
                        acc += column[r, c]
                        cnt += 1
                img[row, col, c] = acc / cnt
