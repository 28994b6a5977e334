"""Decoders of the common lane-detection output kinds, for ONNX models brought by users (``onnx_detector``).

Each decoder takes one image's outputs (batch axis removed) and answers polylines as (n, 2) float64 arrays of
``(x_norm, y_norm)``: normalised coordinates of the network input, ``x_norm = u / width`` with continuous image
coordinates (docs/conventions.md). The expected tensors, with the batch axis:

- ``row_anchors`` (Ultra Fast Lane Detection): one output ``(1, grid + 1, rows, lanes)``, per lane and row anchor
  the scores of ``grid`` column cells over the input width and, last, "no lane". The rows are the sidecar's
  ``row_anchors`` (input pixels). Scores are softmaxed when ``logits`` is true. A lane's x at a row is the
  expectation over the cells near the best one (``lane_slots.decode_row_anchors``).
- ``mask`` (lane-line segmentation, BDD100K style): one output ``(1, 1, h, w)`` lane-line probability (a sigmoid
  is applied when ``logits`` is true), ``(1, 2, h, w)`` background/lane scores (softmax, channel 1 is the lane) or
  ``(1, h, w)``; any ``h, w`` (the map covers the whole input). Pixels above ``threshold`` are cut into runs per
  map row, runs are chained bottom-up into lanes (the nearest run within ``cluster_px`` map pixels of where a lane
  is heading, across gaps up to ``max_gap`` of the map's height, so dashes join), and each lane with enough rows
  is fitted by ``x(y)``: a parabola when it spans a quarter of the map's height or more, else a line.
- ``polynomial`` (LSTR): ``(1, Q, C)`` class scores (softmax; a query is a lane where class ``lane_class`` wins) and
  ``(1, Q, 8)`` curves ``[y_lower, y_upper, k, f, m, n, b, b']`` in normalised input coordinates:
  ``x = k / (y - f)^2 + m / (y - f) + n + b * y - b'`` for ``y`` from ``y_lower`` to ``y_upper``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..typed import FloatArray
from .lane_slots import decode_row_anchors

HEADS = ("row_anchors", "mask", "polynomial")
CURVE_SAMPLES = 50
MIN_MASK_ROWS = 4  # map rows a mask lane must cover
MAX_FIT_DEGREE = 2
CURVED_SPAN = 0.25  # share of the map's height a lane must span to be fitted by a parabola rather than a line


def softmax(scores: FloatArray, axis: int) -> FloatArray:
    shifted = np.exp(scores - scores.max(axis=axis, keepdims=True))
    return shifted / shifted.sum(axis=axis, keepdims=True)


def sigmoid(scores: FloatArray) -> FloatArray:
    return 1.0 / (1.0 + np.exp(-np.clip(scores, -60.0, 60.0)))


def decode_row_anchor_head(scores: FloatArray, rows_norm: FloatArray, logits: bool = True) -> list[FloatArray]:
    """Polylines from UFLD scores ``(grid + 1, rows, lanes)`` at ``rows_norm`` (rows,) normalised input rows."""
    if scores.ndim != 3 or scores.shape[1] != len(rows_norm):
        raise ValueError(f"row_anchors: expected (grid + 1, {len(rows_norm)}, lanes) scores, got {scores.shape}")
    probs = softmax(scores, 0) if logits else scores
    lines = decode_row_anchors(np.ascontiguousarray(probs.transpose(2, 1, 0)), rows_norm)
    return [line.points for line in lines if line is not None]


def lane_probability(mask: FloatArray, logits: bool) -> FloatArray:
    """(h, w) lane-line probability of a mask output ``(1, h, w)``, ``(2, h, w)`` or ``(h, w)``."""
    if mask.ndim == 3 and mask.shape[0] == 2:
        return softmax(mask, 0)[1] if logits else mask[1]
    if mask.ndim == 3 and mask.shape[0] == 1:
        mask = mask[0]
    if mask.ndim != 2:
        raise ValueError(f"mask: expected (1, h, w), (2, h, w) or (h, w), got {mask.shape}")
    return sigmoid(mask) if logits else mask


def row_runs(row: np.ndarray) -> list[float]:
    """Centres of the runs of True in one boolean row, continuous coordinates (columns ``[start, end)`` span
    ``start .. end``)."""
    padded = np.concatenate([[False], row, [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    return [(start + end) / 2.0 for start, end in zip(edges[::2], edges[1::2], strict=True)]


@dataclass
class _Chain:
    points: list[tuple[float, float]] = field(default_factory=list)  # (u_map, v_map), bottom to top

    def heading(self, v_map: float) -> float:
        """Where the chain is expected at row ``v_map``: its last point moved along its recent slope."""
        (u1, v1) = self.points[-1]
        if len(self.points) < 3:
            return u1
        (u0, v0) = self.points[max(0, len(self.points) - 6)]
        return u1 + (u1 - u0) / (v1 - v0) * (v_map - v1) if v1 != v0 else u1


def cluster_mask(on: np.ndarray, cluster_px: float, max_gap_rows: int) -> list[list[tuple[float, float]]]:
    """Chains of run centres ``(u_map, v_map)`` (continuous map coordinates) of a boolean (h, w) mask, bottom up."""
    chains: list[_Chain] = []
    for row in range(on.shape[0] - 1, -1, -1):
        v_map = row + 0.5
        live = [chain for chain in chains if chain.points[-1][1] - v_map <= max_gap_rows + 1]
        taken: set[int] = set()
        for u_map in row_runs(on[row]):
            best, best_distance = None, cluster_px
            for index, chain in enumerate(live):
                distance = abs(chain.heading(v_map) - u_map)
                if index not in taken and distance <= best_distance:
                    best, best_distance = index, distance
            if best is None:
                chains.append(_Chain([(u_map, v_map)]))
            else:
                taken.add(best)
                live[best].points.append((u_map, v_map))
    return [chain.points for chain in chains]


def fitted_chain(points: Sequence[tuple[float, float]], size: tuple[int, int]) -> FloatArray:
    """(n, 2) normalised polyline of a chain of map points fitted by ``x(y)`` (a parabola for a long chain, else a
    line), one point per row."""
    width, height = size
    u_map, v_map = np.asarray(points, np.float64).T
    # a short chain bends wherever its few rows lead a parabola: only a long one may curve
    curved = np.ptp(v_map) >= CURVED_SPAN * height
    degree = min(MAX_FIT_DEGREE if curved else 1, len(np.unique(v_map)) - 1)
    coeffs = np.polyfit(v_map, u_map, degree)
    v_rows = np.sort(np.unique(v_map))
    return np.stack([np.polyval(coeffs, v_rows) / width, v_rows / height], axis=1)


def decode_mask_head(mask: FloatArray, logits: bool = False, threshold: float = 0.5, cluster_px: float = 0.0,
                     max_gap: float = 0.1) -> list[FloatArray]:
    """Polylines of a lane-line mask output (see the module docstring); ``cluster_px`` 0 = 2 % of the map width
    but at least 2 map pixels."""
    probability = lane_probability(np.asarray(mask, np.float64), logits)
    height, width = probability.shape
    reach = cluster_px or max(2.0, 0.02 * width)
    chains = cluster_mask(probability > threshold, reach, max(1, round(max_gap * height)))
    return [fitted_chain(chain, (width, height)) for chain in chains
            if len({v for _, v in chain}) >= MIN_MASK_ROWS]


def decode_polynomial_head(scores: FloatArray, curves: FloatArray, lane_class: int = 1) -> list[FloatArray]:
    """Polylines of LSTR outputs: ``scores`` (Q, C) class logits, ``curves`` (Q, 8) (see the module docstring)."""
    if scores.ndim != 2 or curves.ndim != 2 or curves.shape[1] != 8 or len(scores) != len(curves):
        raise ValueError(f"polynomial: expected (Q, C) scores and (Q, 8) curves, got {scores.shape} and "
                         f"{curves.shape}")
    is_lane = np.argmax(scores, axis=1) == lane_class
    lines = []
    for lower, upper, k, f, m, n, b, b_shift in curves[is_lane]:
        y = np.linspace(min(lower, upper), max(lower, upper), CURVE_SAMPLES)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = k / (y - f) ** 2 + m / (y - f) + n + b * y - b_shift
        keep = np.isfinite(x)
        if int(keep.sum()) >= 2:
            lines.append(np.stack([x[keep], y[keep]], axis=1))
    return lines
