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


@kernel(inline="always")
def lattice_value(i: int, j: int, k: int) -> float:
    """A repeatable value in [-1, 1] for the integer lattice point (i, j, k) (an integer hash: no tile, no
    period within the world)."""
    h = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791)
    h = (h ^ (h >> 13)) * 1274126177
    h = h ^ (h >> 16)
    return (h & 0xFFFF) / 32767.5 - 1.0


@kernel(inline="always")
def value_noise(x: float, y: float, z: float) -> tuple[float, float, float, float]:
    """(value, d/dx, d/dy, d/dz): 3D value noise at (x, y, z) in lattice units, the lattice's values blended by
    smoothstep weights (value in [-1, 1], mean 0; the gradient is exact, per lattice unit)."""
    x0, y0, z0 = np.floor(x), np.floor(y), np.floor(z)
    i, j, k = int(x0), int(y0), int(z0)
    fx, fy, fz = x - x0, y - y0, z - z0
    u, v, w = fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy), fz * fz * (3.0 - 2.0 * fz)
    du, dv, dw = 6.0 * fx * (1.0 - fx), 6.0 * fy * (1.0 - fy), 6.0 * fz * (1.0 - fz)
    c000, c100 = lattice_value(i, j, k), lattice_value(i + 1, j, k)
    c010, c110 = lattice_value(i, j + 1, k), lattice_value(i + 1, j + 1, k)
    c001, c101 = lattice_value(i, j, k + 1), lattice_value(i + 1, j, k + 1)
    c011, c111 = lattice_value(i, j + 1, k + 1), lattice_value(i + 1, j + 1, k + 1)
    k1, k2, k3 = c100 - c000, c010 - c000, c001 - c000
    k4, k5, k6 = c000 - c100 - c010 + c110, c000 - c010 - c001 + c011, c000 - c100 - c001 + c101
    k7 = -c000 + c100 + c010 - c110 + c001 - c101 - c011 + c111
    value = c000 + k1 * u + k2 * v + k3 * w + k4 * u * v + k5 * v * w + k6 * w * u + k7 * u * v * w
    return (value, du * (k1 + k4 * v + k6 * w + k7 * v * w), dv * (k2 + k4 * u + k5 * w + k7 * w * u),
            dw * (k3 + k5 * v + k6 * u + k7 * u * v))
