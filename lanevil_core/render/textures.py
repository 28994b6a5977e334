"""Procedural noise textures shared by every render (fixed seed, built once, with mip levels)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..typed import Float32Array

NOISE_SIZE = 256
FINE_TEXEL_M = 0.025  # asphalt grain
COARSE_TEXEL_M = 0.4  # stains, patchiness and puddle shapes


def _smooth_noise(rng: np.random.Generator, size: int, octaves: tuple[tuple[int, float], ...]) -> Float32Array:
    """Tileable value noise: sums of bilinearly upsampled random grids."""
    out = np.zeros((size, size))
    for cells, weight in octaves:
        grid = rng.standard_normal((cells, cells))
        coords = np.arange(size) * cells / size
        i0 = np.floor(coords).astype(int)
        f = coords - i0
        f = f * f * (3 - 2 * f)
        i1 = (i0 + 1) % cells
        rows = grid[i0][:, i0] * (1 - f)[None, :] + grid[i0][:, i1] * f[None, :]
        rows_b = grid[i1][:, i0] * (1 - f)[None, :] + grid[i1][:, i1] * f[None, :]
        out += weight * (rows * (1 - f)[:, None] + rows_b * f[:, None])
    out /= np.abs(out).max()
    return out.astype(np.float32)


def _mip_stack(base: Float32Array, levels: int) -> Float32Array:
    """(levels, n, n): level l is the 2^l box-filtered texture, upsampled back to n x n."""
    n = base.shape[0]
    stack = [base]
    level = base
    for _ in range(1, levels):
        m = level.shape[0] // 2
        level = level.reshape(m, 2, m, 2).mean(axis=(1, 3))
        stack.append(np.repeat(np.repeat(level, n // m, axis=0), n // m, axis=1))
    return np.ascontiguousarray(np.stack(stack), np.float32)


@lru_cache(maxsize=1)
def noise_textures() -> tuple[Float32Array, Float32Array]:
    """(fine, coarse): (8, 256, 256) float32 mip stacks of zero-mean noise in [-1, 1]."""
    rng = np.random.default_rng(20240601)
    fine = rng.standard_normal((NOISE_SIZE, NOISE_SIZE)) * 0.6
    fine = fine + _smooth_noise(rng, NOISE_SIZE, ((64, 0.6), (128, 0.4)))
    fine = (fine / np.abs(fine).max()).astype(np.float32)
    coarse = _smooth_noise(rng, NOISE_SIZE, ((4, 1.0), (8, 0.6), (16, 0.35), (32, 0.2), (64, 0.1)))
    return _mip_stack(fine, 8), _mip_stack(coarse, 8)
