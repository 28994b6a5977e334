"""Tire marks: pairs of dark rubber tracks along straight, swerving and yawing paths."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

from ...typed import FloatArray
from ._canvas import (
    RUBBER_RGB,
    Texture,
    _Canvas,
    _child,
    _children,
    _smooth_random,
    _smoothstep,
    _spot,
    _stamp_polyline,
    _walk,
)

TireMarkKind = Literal["straight", "swerve", "yaw"]


def _mark_center_line(rng: np.random.Generator, kind: TireMarkKind, size_m: tuple[float, float], center_t: float,
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


def tire_marks(rng: np.random.Generator, shape: tuple[int, int], texel: float, *, straight: int = 1,
               swerve: int = 0, yaw: int = 0, center_t: Sequence[float] = (), swerve_m: float = 3.5,
               length_m: tuple[float, float] = (15.0, 35.0), darkness: float = 0.7, track_width_m: float = 0.2,
               gauge_m: tuple[float, float] = (1.5, 1.8), start_m: tuple[float, float] | None = None) -> Texture:
    """Pairs of dark rubber tire tracks along smooth curves, fading in and out at their ends.

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
        track_width_m: width of one tire track (m).
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
    kinds: list[tuple[TireMarkKind, int, int]] = (
        [("straight", bases[0], k) for k in range(straight)] + [("swerve", bases[1], k) for k in range(swerve)]
        + [("yaw", bases[2], k) for k in range(yaw)]
    )
    for index, (kind, base, k) in enumerate(kinds):
        child = _child(base, k)
        t_c = float(center_t[index % len(center_t)]) if center_t else child.uniform(1.0, size_m[1] - 1.0)
        sweep = swerve_m if k % 2 == 0 else -swerve_m
        if not 0.5 <= t_c + sweep <= size_m[1] - 0.5:
            sweep = -sweep
        path, theta = _mark_center_line(child, kind, size_m, t_c, sweep, length_m, _spot(base, k), start_m)
        _stamp_tracks(child, cover, path, theta, kind, texel, darkness, track_width_m, gauge_m)
    canvas = _Canvas.empty(shape)
    canvas.paint(RUBBER_RGB, cover)
    return canvas.rgba(), None


def _stamp_tracks(rng: np.random.Generator, cover: np.ndarray, path: FloatArray, theta: FloatArray,
                  kind: TireMarkKind, texel: float, darkness: float, track_width_m: float,
                  gauge_m: tuple[float, float]) -> None:
    """Stamp the two tire tracks either side of a centre path into ``cover`` (h, w)."""
    n = len(path)
    u = np.linspace(0.0, 1.0, n)
    gauge = rng.uniform(*gauge_m) * (1.0 + (0.3 * u if kind == "yaw" else 0.0))
    normal = np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    # Rubber builds up as the tire locks and fades where the vehicle stops or regains grip.
    onset = _smoothstep(u / rng.uniform(0.1, 0.25)) * _smoothstep((1.0 - u) / rng.uniform(0.05, 0.15))
    for side in (-1.0, 1.0):
        patchy = _smooth_random(rng, n, 16, 0.75, 1.0)
        pts = path + side * 0.5 * (gauge * np.ones(n))[:, None] * normal
        half_width = np.full(n, 0.5 * track_width_m * rng.uniform(0.9, 1.1))
        _stamp_polyline(cover, cover, pts, half_width, darkness * onset * patchy, texel,
                        max(1.25 * texel, 0.03), 0.0)
