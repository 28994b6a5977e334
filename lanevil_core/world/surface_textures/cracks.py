"""Cracks: transverse, longitudinal and alligator networks, cracks along lane lines and failed joints."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ...typed import Float32Array, FloatArray
from ._canvas import (
    ALLIGATOR_HALO,
    ALLIGATOR_WIDTH,
    CRACK_HALO_RGB,
    CRACK_KINDS,
    CRACK_RGB,
    HALO_OPACITY,
    HALO_SCALE,
    JOINT_SEED_OFFSET,
    CrackKind,
    Texture,
    _Canvas,
    _child,
    _children,
    _count,
    _meander,
    _smooth_random,
    _spot,
    _stamp_alligator,
    _stamp_polyline,
    _Stroke,
    _taper,
    _walk,
    composite,
)


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
