"""BezierLaneNet's lane curves: each lane a cubic Bézier curve of 4 control points, in numpy.

A ground-truth lane is fitted by least squares with its end points fixed (chord-length parameters), so a curve
spans exactly the lane's rows; training compares curves by points sampled at the same parameters; decoding
samples each existing query's curve densely and reads it as a lane line. Coordinates are normalised image
coordinates (see ``lane_slots``).
"""

from __future__ import annotations

import numpy as np

from ..typed import FloatArray
from .lane_slots import LaneLine

CONTROL_POINTS = 4
DECODE_SAMPLES = 100
# Training weights a matched query's existence as all unmatched ones together (``learn.losses``): about 4.4 to 1 on
# the train split (20 queries, 3.7 lanes a frame), so a predicted 0.5 means a real chance of about 1 in 5.4 and
# 0.8 ~ 4.4 / 5.4 is the real even chance. At 0.5 the shipped model kept the lanes it guessed from the road's layout
# (55 % TuSimple accuracy without paint; 33 % at 0.8, the originals 88.5 -> 87.6 %).
EXIST_THRESHOLD = 0.8


def bernstein(t: FloatArray) -> FloatArray:
    """(T, 4) cubic Bernstein weights at parameters ``t`` (T,) in 0..1."""
    t = np.asarray(t, np.float64)[:, None]
    k = np.arange(CONTROL_POINTS)[None]
    binomial = np.array([1.0, 3.0, 3.0, 1.0])[None]
    return np.asarray(binomial * t ** k * (1.0 - t) ** (CONTROL_POINTS - 1 - k))


def fit_bezier(points: FloatArray) -> FloatArray:
    """(4, 2) control points of the cubic through the first and last of ``points`` (n, 2) closest to the rest."""
    points = np.asarray(points, np.float64)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    t = chord / max(chord[-1], 1e-12)
    weights = bernstein(t)
    start, end = points[0], points[-1]
    rest = points - np.outer(weights[:, 0], start) - np.outer(weights[:, 3], end)
    inner, *_ = np.linalg.lstsq(weights[:, 1:3], rest, rcond=None)
    return np.stack([start, inner[0], inner[1], end])


def sample_bezier(control: FloatArray, count: int) -> FloatArray:
    """(..., count, 2) points of curves ``control`` (..., 4, 2) at ``count`` evenly spaced parameters."""
    weights = bernstein(np.linspace(0.0, 1.0, count))
    return np.asarray(np.einsum("tk,...kd->...td", weights, control))


def encode_curves(placed: list[LaneLine | None]) -> tuple[np.ndarray, np.ndarray]:
    """(slots, 4, 2) float32 control points of the lanes ``placed`` and (slots,) float32 1 where a lane is."""
    control = np.zeros((len(placed), CONTROL_POINTS, 2), np.float32)
    valid = np.zeros(len(placed), np.float32)
    for slot, line in enumerate(placed):
        if line is not None and len(line.points) >= 2:
            control[slot] = fit_bezier(line.points)
            valid[slot] = 1.0
    return control, valid


def decode_curves(exist: FloatArray, control: FloatArray, threshold: float = EXIST_THRESHOLD,
                  samples: int = DECODE_SAMPLES) -> list[LaneLine | None]:
    """Lane lines of the queries whose existence ``exist`` (Q,) passes ``threshold``, from ``control``
    (Q, 4, 2): each curve sampled at ``samples`` parameters, points ordered top to bottom."""
    lines: list[LaneLine | None] = []
    for query in np.flatnonzero(exist > threshold):
        points = sample_bezier(control[query].astype(np.float64), samples)
        points = points[np.argsort(points[:, 1], kind="stable")]
        if np.ptp(points[:, 1]) > 1e-6:
            lines.append(LaneLine(points))
    return lines
