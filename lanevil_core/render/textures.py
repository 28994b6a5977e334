"""Procedural noise textures shared by every render (fixed seed, built once, with mip levels)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..typed import Float32Array
from ._jit import kernel

NOISE_SIZE = 256  # texels along each side of the tile (a power of two)
NOISE_LEVELS = 8
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


@kernel(inline="always")
def level_offset(level: int) -> int:
    """Index of the first texel of mip level ``level`` in a flat pyramid of a NOISE_SIZE tile: the levels before
    it hold n^2 (1 + 1/4 + ...) = 4/3 (n^2 - side^2) texels, side = n >> level."""
    side = NOISE_SIZE >> level
    return (NOISE_SIZE * NOISE_SIZE - side * side) * 4 // 3


def _mip_pyramid(base: Float32Array, levels: int) -> Float32Array:
    """The mip levels of ``base`` (n, n) one after the other, flat, row-major: level l is the 2^l box-filtered
    texture, (n >> l)^2 texels from ``level_offset(l)``. A sixth of the memory of levels upsampled to n x n, so
    the five lookups of a photographed road pixel stay in cache."""
    out = [base.ravel()]
    level = base
    for _ in range(1, levels):
        m = level.shape[0] // 2
        level = level.reshape(m, 2, m, 2).mean(axis=(1, 3))
        out.append(level.ravel())
    return np.ascontiguousarray(np.concatenate(out), np.float32)


@lru_cache(maxsize=1)
def noise_textures() -> tuple[Float32Array, Float32Array]:
    """(fine, coarse): flat float32 mip pyramids (``_mip_pyramid``, NOISE_LEVELS levels of a NOISE_SIZE tile) of
    zero-mean noise in [-1, 1]."""
    rng = np.random.default_rng(20240601)
    fine = rng.standard_normal((NOISE_SIZE, NOISE_SIZE)) * 0.6
    fine = fine + _smooth_noise(rng, NOISE_SIZE, ((64, 0.6), (128, 0.4)))
    fine = (fine / np.abs(fine).max()).astype(np.float32)
    coarse = _smooth_noise(rng, NOISE_SIZE, ((4, 1.0), (8, 0.6), (16, 0.35), (32, 0.2), (64, 0.1)))
    return _mip_pyramid(fine, NOISE_LEVELS), _mip_pyramid(coarse, NOISE_LEVELS)
