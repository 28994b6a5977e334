"""Repair patches of fresh asphalt, sealant strips (some running along the lane lines) and the ghosts of old
lane markings ground off when the lanes were moved."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

from ...typed import FloatArray
from ._canvas import (
    FRESH_ASPHALT_RGB,
    GROUND_OFF_RGB,
    SEALANT_BRIGHT_RGB,
    SEALANT_DARK_RGB,
    Texture,
    _Canvas,
    _child,
    _children,
    _meander,
    _smooth_random,
    _spot,
    _stamp_polyline,
    _Stroke,
    _taper,
    _walk,
)


def _rounded_box_distance(ds: FloatArray, dt: FloatArray, half: tuple[float, float], radius: float) -> FloatArray:
    """Signed distance (m) to a box of half sizes ``half`` (s, t) with rounded corners, centred at 0."""
    qs = np.abs(ds) - (half[0] - radius)
    qt = np.abs(dt) - (half[1] - radius)
    outside = np.hypot(np.maximum(qs, 0.0), np.maximum(qt, 0.0))
    return outside + np.minimum(np.maximum(qs, qt), 0.0) - radius


def _blob_distance(rng: np.random.Generator, ds: np.ndarray, dt: np.ndarray, radii: tuple[float, float]) -> FloatArray:
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
        assert t_local is not None
        half = (0.5 * length_s * rng.uniform(0.35, 0.7), rng.uniform(0.3, 0.5) * size_scale)
        center = (half[0] + 0.1 * spot * (length_s - 2 * half[0]), float(t_local))
    elif kind == "across":
        assert t_local is not None
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
        angle = rng.normal(0.0, 0.02) * (kind != "trench")  # a trench runs parallel to its line, however long
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
    shapes: list[tuple[int, int, PatchKind, float | None]] = []
    shapes += [(bases[0], k, "rectangle", None) for k in range(rectangles)]
    shapes += [(bases[1], k, "blob", None) for k in range(blobs)]
    shapes += [(bases[4], k, "trench", float(t)) for k, t in enumerate(trench_t)]
    shapes += [(bases[5], k, "across", float(t)) for k, t in enumerate(across_t)]
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


GHOST_STEP_M = 0.25
GHOST_DASH_M = (3.0, 6.0)  # painted and gap length of the dashed lines the ghosts were


def ghost_lines(rng: np.random.Generator, shape: tuple[int, int], texel: float, t_local: Sequence[float], *,
                width_m: float = 0.15, opacity: float = 0.6, dashed_share: float = 0.5) -> Texture:
    """Ghost markings: old lane lines ground off when the lanes were moved (road works, re-laning), left as pale
    scoured stripes with paint residue, parallel to the lanes at ``t_local`` (m) over the texture's whole length.

    Grinding never removes a line evenly, so each ghost's opacity wanders between 45 % and 100 % of ``opacity``;
    a share ``dashed_share`` of them were dashed lines and keep their dashes.

    Returns:
        rgba (h, w, 4) float32, wet None.
    """
    base = _children(rng)[6]
    cover = np.zeros(shape, np.float32)
    length_s = shape[0] * texel
    s = np.arange(0.0, length_s + GHOST_STEP_M, GHOST_STEP_M)
    for k, t in enumerate(t_local):
        child = _child(base, k)
        pts = np.stack([s, t + _smooth_random(child, len(s), max(len(s) // 40, 2), -0.03, 0.03)], axis=1)
        value = opacity * _smooth_random(child, len(s), max(len(s) // 12, 2), 0.45, 1.0)
        if child.random() < dashed_share:
            painted, gap = GHOST_DASH_M
            value = value * (((s + child.uniform(0.0, painted + gap)) % (painted + gap)) < painted)
        _stamp_polyline(cover, cover, pts, np.full(len(s), 0.5 * width_m), value, texel, 1.25 * texel, 0.0)
    canvas = _Canvas.empty(shape)
    canvas.paint(GROUND_OFF_RGB, cover)
    return canvas.rgba(), None
