"""Shared drawing machinery of the surface textures: colours, a premultiplied canvas, distance-field
stamping kernels and seeded helpers."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit

from ...typed import Float32Array, FloatArray

CrackKind = Literal["transverse", "longitudinal", "alligator"]
CRACK_KINDS: tuple[CrackKind, ...] = ("transverse", "longitudinal", "alligator")

Texture = tuple[Float32Array, Float32Array | None]

# Linear albedos (fresh asphalt 0.02-0.03, worn asphalt 0.05-0.08, tire rubber 0.012-0.02).
CRACK_RGB = (0.010, 0.010, 0.011)
CRACK_HALO_RGB = (0.024, 0.024, 0.025)
FRESH_ASPHALT_RGB = (0.025, 0.025, 0.027)
SEALANT_DARK_RGB = (0.012, 0.012, 0.013)
SEALANT_BRIGHT_RGB = (0.30, 0.30, 0.29)  # weathered or sun-glossy crack filler, reads like faded paint
GROUND_OFF_RGB = (0.26, 0.26, 0.25)  # a marking ground off the asphalt: scoured stone and paint residue
RUBBER_RGB = (0.015, 0.015, 0.016)  # tire rubber laid on the asphalt

HALO_OPACITY = 0.4  # the crushed, stained rim either side of a crack, relative to its core
HALO_SCALE = 5.0  # halo radius in crack half widths
ALLIGATOR_WIDTH = 0.6  # an alligator crack's core width relative to a main crack's
ALLIGATOR_HALO = 3.0  # an alligator crack's halo radius in its half widths (before spalling)
JOINT_SEED_OFFSET = 1_000_000  # joint bands take child seeds of the along-line family from here on
GOLDEN_FRACTION = 0.6180339887498949
_SEEDS_PER_CALL = 8  # every generator draws exactly this many values from the caller's Generator


# ---------------------------------------------------------------------------------------------------------------
# Canvas and drawing kernels


@dataclass
class _Canvas:
    """Premultiplied colour (h, w, 3) and alpha (h, w) float32, painted back to front with ``over``."""

    premul: Float32Array
    alpha: Float32Array

    @classmethod
    def empty(cls, shape: tuple[int, int]) -> _Canvas:
        return cls(np.zeros((*shape, 3), np.float32), np.zeros(shape, np.float32))

    @classmethod
    def from_rgba(cls, rgba: Float32Array) -> _Canvas:
        alpha = np.ascontiguousarray(rgba[..., 3], dtype=np.float32)
        return cls((rgba[..., :3] * alpha[..., None]).astype(np.float32), alpha)

    def paint(self, color: Sequence[float] | np.ndarray, coverage: np.ndarray) -> None:
        """Lay ``color`` ((3,) or (h, w, 3)) over the canvas with per-texel ``coverage`` (h, w) in [0, 1]."""
        colors = np.broadcast_to(np.asarray(color, np.float32), self.premul.shape)
        _over(self.premul, self.alpha, colors, np.asarray(coverage, np.float32))

    def rgba(self) -> Float32Array:
        return _unpremultiply(self.premul, self.alpha)


@njit(cache=True)
def _over(premul: np.ndarray, alpha: np.ndarray, color: np.ndarray, coverage: np.ndarray) -> None:
    """In place: premul (h, w, 3), alpha (h, w) <- color (h, w, 3) over them with coverage (h, w)."""
    h, w = alpha.shape
    for i in range(h):
        for j in range(w):
            a = min(max(coverage[i, j], 0.0), 1.0)
            if a <= 0.0:
                continue
            for c in range(3):
                premul[i, j, c] = premul[i, j, c] * (1.0 - a) + a * color[i, j, c]
            alpha[i, j] = a + alpha[i, j] * (1.0 - a)


@njit(cache=True)
def _unpremultiply(premul: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """(h, w, 4) float32 straight-alpha rgba from premultiplied colour and alpha."""
    h, w = alpha.shape
    out = np.zeros((h, w, 4), np.float32)
    for i in range(h):
        for j in range(w):
            a = alpha[i, j]
            out[i, j, 3] = a
            if a > 1e-6:
                for c in range(3):
                    out[i, j, c] = premul[i, j, c] / a
    return out


def composite(top: Float32Array, bottom: Float32Array) -> Float32Array:
    """``top`` over ``bottom``: both (h, w, 4) float32 straight-alpha rgba of the same shape."""
    canvas = _Canvas.from_rgba(bottom)
    canvas.paint(top[..., :3], top[..., 3])
    return canvas.rgba()


@njit(cache=True)
def _box_cover(d: float, half_width: float, filter_width: float) -> float:
    """Fraction of a box filter ``filter_width`` wide, centred ``d`` from a band's axis, covered by the band."""
    lo = max(d - half_width, -0.5 * filter_width)
    hi = min(d + half_width, 0.5 * filter_width)
    return min(max((hi - lo) / filter_width, 0.0), 1.0)


@njit(cache=True)
def _stamp_polyline(core: np.ndarray, halo: np.ndarray, pts: np.ndarray, half_width: np.ndarray,
                    value: np.ndarray, texel: float, filter_width: float, halo_scale: float) -> None:
    """Max-composite a variable-width polyline into ``core`` and its soft surround into ``halo``.

    Args:
        core, halo: (h, w) float32 coverage, updated in place.
        pts: (n, 2) float64 (s_local, t_local) vertices (m); half_width, value: (n,) float64 per vertex.
        filter_width: box-filter width across the line (m, at least a texel: antialiasing).
        halo_scale: halo radius as a multiple of the half width (0 = no halo).
    """
    h, w = core.shape
    for k in range(pts.shape[0] - 1):
        s0, t0, s1, t1 = pts[k, 0], pts[k, 1], pts[k + 1, 0], pts[k + 1, 1]
        hw0, hw1, v0, v1 = half_width[k], half_width[k + 1], value[k], value[k + 1]
        reach = max(hw0, hw1) * max(halo_scale, 1.0) + filter_width + texel
        i0 = max(int((min(s0, s1) - reach) / texel), 0)
        i1 = min(int((max(s0, s1) + reach) / texel) + 1, h)
        j0 = max(int((min(t0, t1) - reach) / texel), 0)
        j1 = min(int((max(t0, t1) + reach) / texel) + 1, w)
        ds, dt = s1 - s0, t1 - t0
        length2 = ds * ds + dt * dt
        for i in range(i0, i1):
            s = (i + 0.5) * texel
            for j in range(j0, j1):
                t = (j + 0.5) * texel
                u = 0.0 if length2 <= 0.0 else min(max(((s - s0) * ds + (t - t0) * dt) / length2, 0.0), 1.0)
                d = np.hypot(s - s0 - u * ds, t - t0 - u * dt)
                hw = hw0 + u * (hw1 - hw0)
                v = v0 + u * (v1 - v0)
                c = _box_cover(d, hw, filter_width) * v
                if c > core[i, j]:
                    core[i, j] = c
                if halo_scale > 0.0:
                    r = hw * halo_scale + 0.5 * texel
                    if d < r:
                        q = (1.0 - d / r) ** 2 * v
                        if q > halo[i, j]:
                            halo[i, j] = q


@njit(cache=True)
def _hash01(a: int, b: int, c: int, seed: int) -> float:
    """A reproducible pseudo-random number in [0, 1) for integer coordinates."""
    x = (a * 73856093) ^ (b * 19349663) ^ (c * 83492791) ^ seed
    x = (x ^ (x >> 13)) * 1274126177
    x = x ^ (x >> 16)
    x = (x ^ (x >> 11)) * 2246822519
    return ((x >> 7) & 0xFFFFFF) / 16777216.0


@njit(cache=True)
def _site(ci: int, cj: int, cell: float, seed: int) -> tuple[float, float]:
    """Jittered-grid Voronoi site of cell (ci, cj) (m)."""
    return ((ci + 0.05 + 0.9 * _hash01(ci, cj, 1, seed)) * cell, (cj + 0.05 + 0.9 * _hash01(ci, cj, 2, seed)) * cell)


@njit(cache=True)
def _stamp_alligator(core: np.ndarray, halo: np.ndarray, center: np.ndarray, radii: np.ndarray, cell: float,
                     half_width: float, keep: float, texel: float, filter_width: float, halo_scale: float,
                     seed: int) -> None:
    """Max-composite a patch of polygonal (jittered Voronoi) crack cells into ``core`` and ``halo``.

    The patch is an ellipse with semi-axes ``radii`` (s, t) around ``center`` (s_local, t_local); a ``keep``
    share of the cell edges is cracked, each with its own width; the network fades out towards the rim.
    """
    h, w = core.shape
    i0 = max(int((center[0] - radii[0]) / texel), 0)
    i1 = min(int((center[0] + radii[0]) / texel) + 1, h)
    j0 = max(int((center[1] - radii[1]) / texel), 0)
    j1 = min(int((center[1] + radii[1]) / texel) + 1, w)
    phase = _hash01(seed, 7, 7, 1) * 6.283
    for i in range(i0, i1):
        s = (i + 0.5) * texel
        for j in range(j0, j1):
            t = (j + 0.5) * texel
            rim = ((s - center[0]) / radii[0]) ** 2 + ((t - center[1]) / radii[1]) ** 2
            wobble = 0.12 * np.sin(5.0 * np.arctan2(s - center[0], t - center[1]) + phase)
            fade = min(max((1.0 + wobble - np.sqrt(rim)) / 0.3, 0.0), 1.0)
            if fade <= 0.0:
                continue
            # A gentle warp bends the straight Voronoi edges into meandering ones.
            ws = s + 0.12 * cell * np.sin(t / cell * 2.1 + phase)
            wt = t + 0.12 * cell * np.sin(s / cell * 1.7 - phase)
            ci, cj = int(np.floor(ws / cell)), int(np.floor(wt / cell))
            best, bi, bj = 1e30, 0, 0
            for di in range(-2, 3):
                for dj in range(-2, 3):
                    ps, pt = _site(ci + di, cj + dj, cell, seed)
                    d2 = (ws - ps) ** 2 + (wt - pt) ** 2
                    if d2 < best:
                        best, bi, bj = d2, ci + di, cj + dj
            as_, at = _site(bi, bj, cell, seed)
            edge, edge_hw = 1e30, half_width
            for di in range(-2, 3):
                for dj in range(-2, 3):
                    oi, oj = ci + di, cj + dj
                    if oi == bi and oj == bj:
                        continue
                    first = bi < oi or (bi == oi and bj < oj)
                    lo_i, lo_j, hi_i, hi_j = (bi, bj, oi, oj) if first else (oi, oj, bi, bj)
                    pick = _hash01(lo_i * 131 + lo_j, hi_i * 131 + hi_j, 3, seed)
                    if pick > keep:
                        continue
                    ps, pt = _site(oi, oj, cell, seed)
                    gap = np.hypot(ps - as_, pt - at)
                    d = ((ws - ps) ** 2 + (wt - pt) ** 2 - best) / (2.0 * gap)
                    if d < edge:
                        edge = d
                        edge_hw = half_width * (0.55 + 0.9 * _hash01(lo_i, hi_j, 4, seed + lo_j + hi_i))
            if edge > 1e29:
                continue
            c = _box_cover(edge, edge_hw, filter_width) * fade
            if c > core[i, j]:
                core[i, j] = c
            r = edge_hw * halo_scale + 0.5 * texel
            if halo_scale > 0.0 and edge < r:
                q = (1.0 - edge / r) ** 2 * fade
                if q > halo[i, j]:
                    halo[i, j] = q


# ---------------------------------------------------------------------------------------------------------------
# Shared helpers


def _children(rng: np.random.Generator) -> list[int]:
    """The fixed draw every generator takes from the caller's Generator: one base seed per item family."""
    return [int(x) for x in rng.integers(0, 2**63 - 1, size=_SEEDS_PER_CALL)]


def _child(base: int, k: int) -> np.random.Generator:
    return np.random.default_rng([base, k])


def _spot(base: int, k: int) -> float:
    """Where item ``k`` of a family lies along s, as a fraction in [0, 1): a golden-ratio sequence, so items
    spread evenly along the road whatever their count (and adding items never moves the earlier ones). The
    first item lies in the first tenth, where a camera at the texture's start sees it."""
    return float((0.1 * (base % 1_000_003) / 1_000_003 + k * GOLDEN_FRACTION) % 1.0)


def _count(density: float, area_m2: float) -> int:
    """Items for ``density`` per 100 m^2 over ``area_m2`` (rounded, never negative)."""
    return max(int(np.floor(density * area_m2 / 100.0 + 0.5)), 0)


def _smooth_random(rng: np.random.Generator, n: int, knots: int, lo: float = 0.0, hi: float = 1.0) -> FloatArray:
    """(n,) values in [lo, hi] varying smoothly: ``knots`` random values linearly interpolated along n samples."""
    knots = max(knots, 2)
    return np.interp(np.arange(n), np.linspace(0, n - 1, knots), rng.uniform(lo, hi, knots))


def _smoothstep(u: FloatArray) -> FloatArray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def _meander(rng: np.random.Generator, n: int, step: float, amplitude: float, wavelength: float,
             jitter: float) -> FloatArray:
    """(n,) heading offsets (radians): a few slow sine waves plus per-step jitter (the jagged edge of a crack)."""
    u = np.arange(n) * step
    offsets = rng.normal(0.0, jitter, n)
    for octave in range(3):
        lam = wavelength * 0.5**octave * rng.uniform(0.7, 1.3)
        offsets += amplitude / (octave + 1) * np.sin(2 * np.pi * u / lam + rng.uniform(0, 2 * np.pi))
    return offsets


def _walk(start: FloatArray, heading: FloatArray, step: float) -> FloatArray:
    """(n, 2) points of a path that leaves ``start`` (s, t) and turns to ``heading`` (n,) (0 = along +s)."""
    steps = step * np.stack([np.cos(heading[:-1]), np.sin(heading[:-1])], axis=1)
    return np.asarray(start, np.float64) + np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def _taper(n: int, head: float = 0.12, tail: float = 0.2) -> FloatArray:
    """(n,) width profile of a crack: full in the middle, narrowing to a fifth over the ``head`` and ``tail``
    fractions of its length."""
    u = np.linspace(0.0, 1.0, n)
    return np.sqrt(np.clip(np.minimum(u / head, (1.0 - u) / tail), 0.0, 1.0)) * 0.8 + 0.2


@dataclass(frozen=True)
class _Stroke:
    """One polyline: (n, 2) (s_local, t_local) points, (n,) half widths and (n,) strengths."""

    pts: FloatArray
    half_width: FloatArray
    value: FloatArray
