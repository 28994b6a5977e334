"""Procedural road-surface textures in road coordinates: cracks, repair patches and sealant, tyre marks.

A texture's rows run along the road (s) and its columns across it (t); texels are ``texel`` metres square and
texel (i, j) has its centre at ``s_local = (i + 0.5) * texel``, ``t_local = (j + 0.5) * texel`` from the texture's
corner. Shapes are drawn from distance fields with box-filtered edges, so a crack thinner than a texel comes out
as partial coverage rather than as aliased stair steps.

Every generator returns ``(rgba, wet)`` (``crack_layers`` the same split into a stain and a crack layer):
``rgba`` (h, w, 4) float32 linear albedo plus straight (not premultiplied) coverage alpha, ``wet`` (h, w)
float32 puddle coverage or None. All randomness comes from the Generator passed in; each drawn item (a crack, a
patch, a mark) takes its own child generator, so raising a count adds items without changing the ones already
there.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit

from .typed import Float32Array, FloatArray

CrackKind = Literal["transverse", "longitudinal", "alligator"]
CRACK_KINDS: tuple[CrackKind, ...] = ("transverse", "longitudinal", "alligator")

Texture = tuple[Float32Array, Float32Array | None]

# Linear albedos (fresh asphalt 0.02-0.03, worn asphalt 0.05-0.08, tyre rubber 0.012-0.02).
CRACK_RGB = (0.010, 0.010, 0.011)
CRACK_HALO_RGB = (0.024, 0.024, 0.025)
FRESH_ASPHALT_RGB = (0.025, 0.025, 0.027)
SEALANT_DARK_RGB = (0.012, 0.012, 0.013)
SEALANT_BRIGHT_RGB = (0.30, 0.30, 0.29)  # weathered or sun-glossy crack filler, reads like faded paint
RUBBER_RGB = (0.015, 0.015, 0.016)  # tyre rubber laid on the asphalt

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


# ---------------------------------------------------------------------------------------------------------------
# Cracks


@dataclass(frozen=True)
class _Stroke:
    """One polyline: (n, 2) (s_local, t_local) points, (n,) half widths and (n,) strengths."""

    pts: FloatArray
    half_width: FloatArray
    value: FloatArray


def _crack(rng: np.random.Generator, start: FloatArray, heading: float, length: float, width: float,
           straightness: float, depth: int = 0) -> list[_Stroke]:
    """A meandering crack and its branches (up to two generations), as strokes."""
    step = 0.04
    n = max(int(length / step), 3)
    theta = heading + _meander(rng, n, step, 0.35 / straightness, 2.5 * straightness, 0.25)
    pts = _walk(start, theta, step)
    half_width = 0.5 * width * _taper(n) * _smooth_random(rng, n, 6, 0.75, 1.25)
    strokes = [_Stroke(pts, half_width, np.ones(n))]
    if depth >= 2:
        return strokes
    for _ in range(rng.poisson(0.45 * length / (depth + 1))):
        k = int(rng.integers(n // 8, n - 2))
        turn = rng.choice([-1.0, 1.0]) * rng.uniform(0.45, 1.2)
        strokes += _crack(rng, pts[k], float(theta[k] + turn), length * rng.uniform(0.12, 0.4),
                          2.0 * half_width[k] * 0.75, straightness * 0.7, depth + 1)
    return strokes


def _crack_strokes(rng: np.random.Generator, kind: CrackKind, size_m: tuple[float, float], width_m: float,
                   spot: float) -> list[_Stroke]:
    """Strokes of one transverse or longitudinal crack starting at s = ``spot * length_s``, anywhere across."""
    length_s, width_t = size_m
    if kind == "transverse":
        direction = rng.choice([-1.0, 1.0])
        t_start = rng.uniform(0.0, 0.25) * width_t if direction > 0 else width_t * (1 - rng.uniform(0.0, 0.25))
        start = np.array([spot * length_s, t_start])
        heading = direction * np.pi / 2 + rng.normal(0.0, 0.15)
        return _crack(rng, start, heading, width_t * rng.uniform(0.35, 1.0), width_m, 1.0)
    start = np.array([spot * length_s, rng.uniform(0.0, width_t)])
    heading = rng.choice([0.0, np.pi]) + rng.normal(0.0, 0.04)
    return _crack(rng, start, heading, rng.uniform(3.0, 15.0), width_m, 3.0)


def _along_strokes(rng: np.random.Generator, t_line: float, length_s: float, width_m: float,
                   spot: float) -> list[_Stroke]:
    """A long longitudinal crack hugging ``t_line`` (a paving joint beside a lane line), with short branches."""
    step = 0.04
    length = length_s * rng.uniform(0.45, 0.85)
    n = max(int(length / step), 3)
    s = spot * (length_s - length) + np.arange(n) * step
    wander = _smooth_random(rng, n, n // 50, -0.03, 0.03)  # a joint wanders a few cm either side of its line
    pts = np.stack([s, t_line + wander + rng.normal(0.0, 0.002, n)], axis=1)
    half_width = 0.65 * width_m * _taper(n, 0.03, 0.05) * _smooth_random(rng, n, n // 25, 0.75, 1.25)
    strokes = [_Stroke(pts, half_width, np.ones(n))]
    for _ in range(rng.poisson(0.15 * length)):
        k = int(rng.integers(1, n - 1))
        heading = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.2) + rng.choice([0.0, np.pi])
        strokes += _crack(rng, pts[k], float(heading), rng.uniform(0.3, 1.5), 1.5 * half_width[k], 0.7, 1)
    return strokes


def crack_network(rng: np.random.Generator, shape: tuple[int, int], texel: float, kind: CrackKind = "transverse",
                  density: float = 1.0, width_m: float = 0.015, darkness: float = 0.8,
                  along_t: Sequence[float] = (), wetness: float = 0.0) -> Texture:
    """Dark, thin, branching, meandering asphalt cracks with a slightly darker halo.

    Args:
        rng: the only randomness (a fixed number of values is drawn from it).
        shape: (h, w) texels, rows along s, columns across t.
        texel: texel size (m), 0.02-0.04.
        kind: ``transverse`` (across the road), ``longitudinal`` (along it) or ``alligator`` (patches of
            polygonal cells).
        density: cracks (alligator: patches) per 100 m^2.
        width_m: core width of a main crack (m); branches are thinner and every crack narrows to its tips.
        darkness: opacity of the core in [0, 1]; the halo gets ``HALO_OPACITY`` of it.
        along_t: t_local (m) of extra long longitudinal cracks, one each (paving joints beside lane lines).
        wetness: water held in the cracks on a wet road, in [0, 1] (0 = no wet map).

    Returns:
        rgba (h, w, 4) float32, wet (h, w) float32 or None.
    """
    if kind not in CRACK_KINDS:
        raise ValueError(f"kind must be one of {CRACK_KINDS}, got {kind!r}")
    return crack_mix(rng, shape, texel, {kind: density}, width_m, darkness, along_t, wetness)


def crack_mix(rng: np.random.Generator, shape: tuple[int, int], texel: float,
              densities: Mapping[CrackKind, float], width_m: float = 0.015, darkness: float = 0.8,
              along_t: Sequence[float] = (), wetness: float = 0.0) -> Texture:
    """Several crack kinds in one texture (one pass, one buffer): ``crack_network`` with a density per kind.

    ``crack_mix(rng, ..., {kind: d})`` draws exactly what ``crack_network(rng, ..., kind, d)`` draws; each kind
    has its own child seeds, so changing one kind's density leaves the others' cracks where they were.
    """
    layers = crack_layers(rng, shape, texel, densities, width_m, darkness, along_t, wetness)
    return composite(layers.cracks, layers.stains), layers.wet


@dataclass(frozen=True)
class CrackLayers:
    """A crack texture split by depth, each (h, w, 4) float32 straight-alpha rgba (``wet`` (h, w) or None).

    ``stains`` are the crushed, darkened and spalled rims beside the cracks, which lie under the paint;
    ``cracks`` are the open cracks themselves, which split a lane line's paint as they split the asphalt.
    """

    stains: Float32Array
    cracks: Float32Array
    wet: Float32Array | None


def crack_layers(rng: np.random.Generator, shape: tuple[int, int], texel: float,
                 densities: Mapping[CrackKind, float], width_m: float = 0.015, darkness: float = 0.8,
                 along_t: Sequence[float] = (), wetness: float = 0.0, *, joint_t: Sequence[float] = (),
                 spall: float = 0.0) -> CrackLayers:
    """``crack_mix``'s cracks as separate stain and crack layers, plus deteriorated joints and spalled edges.

    Args:
        rng, shape, texel, densities, width_m, darkness, along_t, wetness: as for ``crack_mix``.
        joint_t: t_local (m) of paving joints under lane lines that have failed into a band of fatigue
            (alligator) cracking strung along the line, one band each.
        spall: how far the crack edges have broken down, in [0, 1]: widens the stained rim (by up to 2x) and
            darkens it (by up to 2x); 0 = the plain rim of ``HALO_SCALE`` half widths at ``HALO_OPACITY``.
    """
    unknown = set(densities) - set(CRACK_KINDS)
    if unknown:
        raise ValueError(f"crack kinds must be among {CRACK_KINDS}, got {sorted(unknown)}")
    bases = _children(rng)
    size_m = (shape[0] * texel, shape[1] * texel)
    core, halo = np.zeros(shape, np.float32), np.zeros(shape, np.float32)
    filter_width = 1.25 * texel
    halo_scale = HALO_SCALE * (1.0 + spall)
    for index, kind in enumerate(CRACK_KINDS):
        for k in range(_count(densities.get(kind, 0.0), size_m[0] * size_m[1])):
            child, spot = _child(bases[index], k), _spot(bases[4 + index], k)
            if kind == "alligator":
                _alligator_patch(child, core, halo, size_m, width_m, texel, filter_width, spot, halo_scale)
                continue
            for stroke in _crack_strokes(child, kind, size_m, width_m, spot):
                _stamp_polyline(core, halo, stroke.pts, stroke.half_width, stroke.value, texel, filter_width,
                                halo_scale)
    for k, t_line in enumerate(along_t):
        for stroke in _along_strokes(_child(bases[3], k), float(t_line), size_m[0], width_m, _spot(bases[7], k)):
            _stamp_polyline(core, halo, stroke.pts, stroke.half_width, stroke.value, texel, filter_width, halo_scale)
    for k, t_line in enumerate(joint_t):
        _joint_band(_child(bases[3], JOINT_SEED_OFFSET + k), core, halo, size_m, float(t_line), width_m, texel,
                    filter_width, halo_scale)
    stains, cracks = _Canvas.empty(shape), _Canvas.empty(shape)
    stains.paint(CRACK_HALO_RGB, halo * min(HALO_OPACITY * (1.0 + spall) * darkness, 1.0))
    cracks.paint(CRACK_RGB, core * darkness)
    wet = (core * wetness).astype(np.float32) if wetness > 0.0 else None
    return CrackLayers(stains.rgba(), cracks.rgba(), wet)


def _alligator_patch(rng: np.random.Generator, core: np.ndarray, halo: np.ndarray, size_m: tuple[float, float],
                     width_m: float, texel: float, filter_width: float, spot: float,
                     halo_scale: float = HALO_SCALE) -> None:
    """One patch of fatigue (alligator) cracking: an ellipse of polygonal cells 0.2-0.5 m across."""
    radii = np.array([rng.uniform(0.8, 3.0), rng.uniform(0.6, 1.6)])
    center = np.array([spot * size_m[0], rng.uniform(0.0, size_m[1])])
    _stamp_alligator(core, halo, center, radii, rng.uniform(0.2, 0.5), ALLIGATOR_WIDTH * width_m,
                     rng.uniform(0.75, 0.95), texel, filter_width, ALLIGATOR_HALO * halo_scale / HALO_SCALE,
                     int(rng.integers(1, 2**31 - 1)))


def _joint_band(rng: np.random.Generator, core: np.ndarray, halo: np.ndarray, size_m: tuple[float, float],
                t_line: float, width_m: float, texel: float, filter_width: float, halo_scale: float) -> None:
    """Fatigue cracking along a failed paving joint at ``t_line``: overlapping alligator patches 2-7 m long and
    1.1-1.8 m wide strung along the line with short sound stretches between them, from the texture's start."""
    s = rng.uniform(-1.5, 0.5)
    while s < size_m[0]:
        half_s = rng.uniform(1.0, 3.5)
        center = np.array([s + half_s, t_line + rng.normal(0.0, 0.08)])
        radii = np.array([half_s, rng.uniform(0.55, 0.9)])
        _stamp_alligator(core, halo, center, radii, rng.uniform(0.2, 0.3), ALLIGATOR_WIDTH * width_m,
                         rng.uniform(0.9, 0.99), texel, filter_width, ALLIGATOR_HALO * halo_scale / HALO_SCALE,
                         int(rng.integers(1, 2**31 - 1)))
        s += 2.0 * half_s * rng.uniform(0.75, 0.95) + rng.uniform(0.0, 0.8)


# ---------------------------------------------------------------------------------------------------------------
# Repair patches and sealant strips


def _rounded_box_distance(ds: FloatArray, dt: FloatArray, half: tuple[float, float], radius: float) -> FloatArray:
    """Signed distance (m) to a box of half sizes ``half`` (s, t) with rounded corners, centred at 0."""
    qs = np.abs(ds) - (half[0] - radius)
    qt = np.abs(dt) - (half[1] - radius)
    outside = np.hypot(np.maximum(qs, 0.0), np.maximum(qt, 0.0))
    return outside + np.minimum(np.maximum(qs, qt), 0.0) - radius


def _blob_distance(rng: np.random.Generator, ds: FloatArray, dt: FloatArray, radii: tuple[float, float]) -> FloatArray:
    """Approximate signed distance (m) to an irregular blob (an ellipse whose radius wobbles with angle)."""
    rho = np.hypot(ds / radii[0], dt / radii[1])
    angle = np.arctan2(ds / radii[0], dt / radii[1])
    wobble = np.ones_like(angle)
    for k in range(2, 6):
        wobble += rng.uniform(0.03, 0.12) / (k - 1) * np.cos(k * angle + rng.uniform(0, 2 * np.pi))
    return (rho - wobble) * min(radii)


PatchKind = Literal["rectangle", "blob", "trench", "across"]


def _patch_coverage(rng: np.random.Generator, shape: tuple[int, int], texel: float, size_scale: float,
                    kind: PatchKind, spot: float, t_local: float | None = None
                    ) -> tuple[np.ndarray, np.ndarray, tuple[slice, slice]]:
    """Fill and seal-rim coverage of one patch, over the sub-window (slices) of the texture it touches.

    A patch is a saw-cut ``rectangle`` or an irregular ``blob`` anywhere across the texture, a long narrow
    ``trench`` reinstatement centred on ``t_local`` with its edges parallel to the lanes, starting in the
    texture's first tenth, or a saw-cut patch laid ``across`` a lane line at ``t_local`` (within 0.3 m of its
    centre, so it covers the line) in the texture's first half.
    """
    length_s, width_t = shape[0] * texel, shape[1] * texel
    if kind == "trench":
        half = (0.5 * length_s * rng.uniform(0.35, 0.7), rng.uniform(0.3, 0.5) * size_scale)
        center = (half[0] + 0.1 * spot * (length_s - 2 * half[0]), float(t_local))
    elif kind == "across":
        half = (rng.uniform(0.6, 2.0) * size_scale, rng.uniform(0.5, 1.2) * size_scale)
        center = (0.5 * spot * length_s, float(t_local) + rng.uniform(-0.3, 0.3))
    else:
        half = (rng.uniform(0.5, 2.2) * size_scale, rng.uniform(0.4, 1.6) * size_scale)
        center = (spot * length_s, rng.uniform(0.0, width_t))
    reach = max(half) * 1.4 + 0.1
    rows = slice(max(int((center[0] - reach) / texel), 0), min(int((center[0] + reach) / texel) + 1, shape[0]))
    cols = slice(max(int((center[1] - reach) / texel), 0), min(int((center[1] + reach) / texel) + 1, shape[1]))
    ds = ((np.arange(rows.start, rows.stop) + 0.5) * texel - center[0])[:, None]
    dt = ((np.arange(cols.start, cols.stop) + 0.5) * texel - center[1])[None, :]
    if kind == "blob":
        sd = _blob_distance(rng, ds, dt, half)
    else:
        angle = rng.normal(0.0, 0.02)
        ca, sa = np.cos(angle), np.sin(angle)
        radius = min(rng.uniform(0.02, 0.15), 0.5 * min(half))
        sd = _rounded_box_distance(ca * ds - sa * dt, sa * ds + ca * dt, half, radius)
    sd = sd + 0.015 * np.sin(ds * 9.0 + dt * 4.0 + rng.uniform(0, 6.3))  # a hand-cut edge is never straight
    fill = np.clip(0.5 - sd / texel, 0.0, 1.0)
    rim_hw = rng.uniform(0.015, 0.04)
    rim = np.clip((np.minimum(np.abs(sd) + rim_hw, 0.5 * texel) - np.maximum(np.abs(sd) - rim_hw, -0.5 * texel))
                  / texel, 0.0, 1.0)
    return fill, rim, (rows, cols)


def _strip_stroke(rng: np.random.Generator, size_m: tuple[float, float], width_m: float,
                  t_line: float | None, spot: float) -> _Stroke:
    """A crack-sealing strip: free-running (crack-following) or parallel to the lanes at ``t_line``."""
    length_s, width_t = size_m
    step = 0.05
    if t_line is None:
        heading = rng.choice([0.0, np.pi / 2, np.pi / 4, -np.pi / 4, np.pi]) + rng.normal(0.0, 0.1)
        length = rng.uniform(2.0, 10.0)
        start = np.array([spot * length_s, rng.uniform(0.0, width_t)])
        theta = heading + _meander(rng, max(int(length / step), 3), step, 0.2, 3.0, 0.05)
    else:
        length = length_s * rng.uniform(0.5, 0.9)
        start = np.array([spot * (length_s - length), t_line])
        theta = rng.normal(0.0, 0.003) + _meander(rng, max(int(length / step), 3), step, 0.01, 15.0, 0.005)
    pts = _walk(start, theta, step)
    n = len(pts)
    half_width = 0.5 * width_m * _smooth_random(rng, n, 8, 0.85, 1.15)
    return _Stroke(pts, half_width, _smooth_random(rng, n, 12, 0.8, 1.0) * _taper(n, 0.01, 0.01))


def patches(rng: np.random.Generator, shape: tuple[int, int], texel: float, *, rectangles: int = 3,
            blobs: int = 2, strips: int = 0, parallel_t: Sequence[float] = (), trench_t: Sequence[float] = (),
            across_t: Sequence[float] = (), size_scale: float = 1.0, contrast: float = 0.7,
            strip_width_m: float = 0.08, bright_share: float = 0.3) -> Texture:
    """Repair patches of fresher asphalt and strips of crack sealant.

    Args:
        shape: (h, w) texels, rows along s; texel: texel size (m).
        rectangles: saw-cut rectangular patches (0.8-4.4 m by 0.6-3.2 m at ``size_scale`` 1) with a sealed rim.
        blobs: irregular pothole fills.
        strips: free-running sealant strips (2-10 m, following cracks across or along the road).
        parallel_t: t_local (m) of long straight strips running parallel to the lanes, one each.
        trench_t: t_local (m) of long narrow trench patches (0.6-1 m wide at ``size_scale`` 1) along the lanes,
            starting in the texture's first tenth.
        across_t: t_local (m) of lane lines, one saw-cut patch (1.2-4 m by 1-2.4 m at ``size_scale`` 1) laid
            across each, in the texture's first half.
        size_scale: multiplies patch sizes.
        contrast: how much darker and more opaque the fresh asphalt is, in [0, 1].
        strip_width_m: sealant strip width (m).
        bright_share: share of strips in weathered bright filler (the rest black).

    Returns:
        rgba (h, w, 4) float32, wet None.
    """
    bases = _children(rng)
    size_m = (shape[0] * texel, shape[1] * texel)
    canvas = _Canvas.empty(shape)
    fill_alpha = 0.35 + 0.6 * contrast
    shapes: list[tuple[int, int, PatchKind, float | None]] = (
        [(bases[0], k, "rectangle", None) for k in range(rectangles)]
        + [(bases[1], k, "blob", None) for k in range(blobs)]
        + [(bases[4], k, "trench", float(t)) for k, t in enumerate(trench_t)]
        + [(bases[5], k, "across", float(t)) for k, t in enumerate(across_t)])
    for base, k, kind, t_local in shapes:
        child = _child(base, k)
        fill, rim, window = _patch_coverage(child, shape, texel, size_scale, kind, _spot(base, k), t_local)
        tone = np.asarray(FRESH_ASPHALT_RGB) * child.uniform(0.85, 1.25)
        _paint_window(canvas, window, tone, fill * fill_alpha)
        _paint_window(canvas, window, SEALANT_DARK_RGB, rim * (0.3 + 0.5 * contrast))
    lines: list[tuple[int, int, float | None]] = [(bases[2], k, None) for k in range(strips)]
    lines += [(bases[3], k, float(t)) for k, t in enumerate(parallel_t)]
    dark, bright = np.zeros(shape, np.float32), np.zeros(shape, np.float32)
    for base, k, t_line in lines:
        child = _child(base, k)
        cover = bright if child.random() < bright_share else dark
        stroke = _strip_stroke(child, size_m, strip_width_m, t_line, _spot(base, k))
        _stamp_polyline(cover, cover, stroke.pts, stroke.half_width, stroke.value * (0.55 + 0.45 * contrast),
                        texel, 1.25 * texel, 0.0)
    canvas.paint(SEALANT_DARK_RGB, dark)
    canvas.paint(SEALANT_BRIGHT_RGB, bright)
    return canvas.rgba(), None


def _paint_window(canvas: _Canvas, window: tuple[slice, slice], color: Sequence[float] | np.ndarray,
                  coverage: np.ndarray) -> None:
    """``_Canvas.paint`` restricted to a (rows, cols) window (the views write through to the canvas)."""
    _Canvas(canvas.premul[window], canvas.alpha[window]).paint(color, coverage)


# ---------------------------------------------------------------------------------------------------------------
# Tyre marks

SkidKind = Literal["straight", "swerve", "yaw"]


def _skid_centerline(rng: np.random.Generator, kind: SkidKind, size_m: tuple[float, float], center_t: float,
                     swerve_m: float, length_m: tuple[float, float], spot: float,
                     start_m: tuple[float, float] | None = None) -> tuple[FloatArray, FloatArray]:
    """(n, 2) (s, t) centre path of a vehicle's skid and (n,) its heading, sampled every 0.1 m. The path starts
    ``spot`` (a fraction) of the way through ``start_m`` (s range, m) or, when None, the room left along the
    texture; a start never leaves the mark running past the texture's end."""
    length = min(rng.uniform(*length_m), 0.95 * size_m[0])
    step = 0.1
    n = max(int(length / step), 3)
    u = np.arange(n) * step
    if kind == "straight":
        theta = rng.normal(0.0, 0.01) + 0.015 * np.sin(2 * np.pi * u / rng.uniform(15, 40) + rng.uniform(0, 6.3))
    elif kind == "swerve":
        # A lane change: the lateral offset follows a raised cosine of amplitude swerve_m over the mark.
        lateral = np.gradient(0.5 * swerve_m * (1 - np.cos(np.pi * u / u[-1])), u)
        theta = np.arctan(lateral)
    else:
        curvature = rng.choice([-1.0, 1.0]) / rng.uniform(25.0, 60.0)
        theta = rng.normal(0.0, 0.05) + curvature * u
    lo, hi = (0.0, size_m[0]) if start_m is None else start_m
    hi = max(min(hi, size_m[0] - length), lo)
    start = np.array([lo + spot * (hi - lo), center_t])
    return _walk(start, theta, step), theta


def skid_marks(rng: np.random.Generator, shape: tuple[int, int], texel: float, *, straight: int = 1,
               swerve: int = 0, yaw: int = 0, center_t: Sequence[float] = (), swerve_m: float = 3.5,
               length_m: tuple[float, float] = (15.0, 35.0), darkness: float = 0.7, track_width_m: float = 0.2,
               gauge_m: tuple[float, float] = (1.5, 1.8), start_m: tuple[float, float] | None = None) -> Texture:
    """Pairs of dark rubber tyre tracks along smooth curves, fading in and out at their ends.

    Args:
        shape: (h, w) texels, rows along s; texel: texel size (m).
        straight: braking marks running along s.
        swerve: lane-change marks whose lateral offset sweeps ``swerve_m`` (crossing a lane line), alternately
            to +t and -t (turned back when the sweep would leave the texture).
        yaw: curved sideways-sliding marks whose track gauge widens.
        center_t: t_local (m) where each mark's vehicle starts, in the order straight, swerve, yaw; cycled
            (empty = anywhere across the texture).
        swerve_m: lateral sweep of a swerve (m).
        length_m: range of mark lengths (m).
        darkness: peak opacity of the rubber in [0, 1].
        track_width_m: width of one tyre track (m).
        gauge_m: range of track spacing, centre to centre (m).
        start_m: (lo, hi) s (m from the texture's start) over which the marks' starts spread, so the marks of
            one incident bunch together; lo < 0 lets a mark begin before the texture (only the rest is drawn).
            None = spread over the whole texture.

    Returns:
        rgba (h, w, 4) float32, wet None.
    """
    bases = _children(rng)
    size_m = (shape[0] * texel, shape[1] * texel)
    cover = np.zeros(shape, np.float32)
    kinds: list[tuple[SkidKind, int, int]] = (
        [("straight", bases[0], k) for k in range(straight)] + [("swerve", bases[1], k) for k in range(swerve)]
        + [("yaw", bases[2], k) for k in range(yaw)]
    )
    for index, (kind, base, k) in enumerate(kinds):
        child = _child(base, k)
        t_c = float(center_t[index % len(center_t)]) if center_t else child.uniform(1.0, size_m[1] - 1.0)
        sweep = swerve_m if k % 2 == 0 else -swerve_m
        if not 0.5 <= t_c + sweep <= size_m[1] - 0.5:
            sweep = -sweep
        path, theta = _skid_centerline(child, kind, size_m, t_c, sweep, length_m, _spot(base, k), start_m)
        _stamp_tracks(child, cover, path, theta, kind, texel, darkness, track_width_m, gauge_m)
    canvas = _Canvas.empty(shape)
    canvas.paint(RUBBER_RGB, cover)
    return canvas.rgba(), None


def _stamp_tracks(rng: np.random.Generator, cover: np.ndarray, path: FloatArray, theta: FloatArray,
                  kind: SkidKind, texel: float, darkness: float, track_width_m: float,
                  gauge_m: tuple[float, float]) -> None:
    """Stamp the two tyre tracks either side of a centre path into ``cover`` (h, w)."""
    n = len(path)
    u = np.linspace(0.0, 1.0, n)
    gauge = rng.uniform(*gauge_m) * (1.0 + (0.3 * u if kind == "yaw" else 0.0))
    normal = np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    # Rubber builds up as the tyre locks and fades where the vehicle stops or regains grip.
    onset = _smoothstep(u / rng.uniform(0.1, 0.25)) * _smoothstep((1.0 - u) / rng.uniform(0.05, 0.15))
    for side in (-1.0, 1.0):
        patchy = _smooth_random(rng, n, 16, 0.75, 1.0)
        pts = path + side * 0.5 * (gauge * np.ones(n))[:, None] * normal
        half_width = np.full(n, 0.5 * track_width_m * rng.uniform(0.9, 1.1))
        _stamp_polyline(cover, cover, pts, half_width, darkness * onset * patchy, texel,
                        max(1.25 * texel, 0.03), 0.0)
