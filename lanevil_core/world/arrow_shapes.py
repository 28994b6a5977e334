"""Lane-use arrows painted on the road: straight, left and right heads and their combinations, as convex parts.

An arrow is drawn in its own frame: x forward (the way its lane's traffic goes), y to the driver's left, metres;
the straight head's tip at x = 0 and the stem's tail at x = -length. Its proportions are those of the elongated
arrows of the Vienna-convention manuals (the German RMS' Richtungspfeile, the Chinese 导向箭头), which the MUTCD's
lane-use arrows share: a narrow stem, a head about a third of the arrow's length, turn heads that bend off the stem
on a short arc and point across the lane. Every part is a convex polygon of three or four corners, counter-clockwise,
overlapping its neighbours a little so that the painted union has no seam.
"""

from __future__ import annotations

from collections.abc import Collection

import numpy as np

from ..typed import FloatArray

# Shares of the arrow's length (the German 5 m Richtungspfeil: 1.5 m head, 1.0 m across it, a 0.35 m stem).
HEAD_LENGTH = 0.30
HEAD_HALF_WIDTH = 0.10
STEM_HALF_WIDTH = 0.035
TURN_HEAD_LENGTH = 0.19  # a turn head is smaller: it lies across a lane of about 3.5 m
TURN_HEAD_HALF_WIDTH = 0.08
TURN_RADIUS = 0.12  # centre-line radius of the stem's bend into a turn head
TURN_FROM = 0.55  # a turn branch leaves the stem this share of the length behind the tip (alone: TURN_ALONE_FROM)
TURN_ALONE_FROM = 0.42
ARC_STEPS = 6
OVERLAP = 0.5  # each stem part runs on this share of the stem's half width into the next

Heads = Collection[str]  # a subset of {"left", "straight", "right"}


def counter_clockwise(points: FloatArray) -> FloatArray:
    """``points`` (k, 2) counter-clockwise in (x, y)."""
    x, y = points[:, 0], points[:, 1]
    area = float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    return points if area >= 0 else points[::-1].copy()


def _head(base: FloatArray, direction: FloatArray, length: float, half_width: float) -> FloatArray:
    """(3, 2) the triangle of a head whose base is centred on ``base``, pointing along the unit ``direction``."""
    across = np.array([-direction[1], direction[0]])
    corners = np.array([base + across * half_width, base - across * half_width, base + direction * length])
    return counter_clockwise(corners)


def _stem(path: FloatArray, half_width: float) -> list[FloatArray]:
    """(4, 2) quads along the polyline ``path`` (k, 2), each run OVERLAP of the half width past both its ends."""
    quads = []
    for a, b in zip(path[:-1], path[1:], strict=True):
        direction = (b - a) / np.linalg.norm(b - a)
        across = np.array([-direction[1], direction[0]]) * half_width
        a, b = a - direction * OVERLAP * half_width, b + direction * OVERLAP * half_width
        quads.append(counter_clockwise(np.array([a - across, b - across, b + across, a + across])))
    return quads


def _turn_path(x_from: float, side: float, length: float) -> FloatArray:
    """(k, 2) centre line of a turn branch: a quarter arc off the stem at x = ``x_from``, towards ``side`` (+1 left,
    -1 right), ending across the lane."""
    radius = TURN_RADIUS * length
    angle = np.linspace(0.0, np.pi / 2, ARC_STEPS + 1)
    return np.stack([x_from + radius * np.sin(angle), side * radius * (1.0 - np.cos(angle))], axis=1)


def arrow_parts(heads: Heads, length: float) -> list[FloatArray]:
    """The convex parts ((3 or 4, 2) float, counter-clockwise, in the arrow's frame) of an arrow ``length`` m long
    with ``heads`` (any of "left", "straight", "right"; at least one)."""
    if not heads or not set(heads) <= {"left", "straight", "right"}:
        raise ValueError(f"an arrow needs heads among left, straight, right, not {sorted(heads)}")
    stem = STEM_HALF_WIDTH * length
    straight = "straight" in heads
    turn_from = -(TURN_FROM if straight else TURN_ALONE_FROM) * length
    tip_base = -HEAD_LENGTH * length
    stem_end = tip_base if straight else turn_from
    parts = _stem(np.array([[-length, 0.0], [stem_end, 0.0]]), stem)
    if straight:
        parts.append(_head(np.array([tip_base, 0.0]), np.array([1.0, 0.0]), HEAD_LENGTH * length,
                           HEAD_HALF_WIDTH * length))
    for side, name in ((1.0, "left"), (-1.0, "right")):
        if name in heads:
            path = _turn_path(turn_from, side, length)
            parts += _stem(path, stem)
            parts.append(_head(path[-1], np.array([0.0, side]), TURN_HEAD_LENGTH * length,
                               TURN_HEAD_HALF_WIDTH * length))
    return parts


def lane_heads(moves: Heads, lane: int, lanes: int) -> frozenset[str]:
    """The heads of the arrow in approach lane ``lane`` (0: next to the centre line) of ``lanes``, where the
    junction allows ``moves``: every lane goes straight where that is allowed, the inner lane also turns left and
    the outer lane right (a lane that cannot go straight takes the turn on its side, or the only one left)."""
    heads = {"straight"} & set(moves)
    if lane == 0 and "left" in moves:
        heads.add("left")
    if lane == lanes - 1 and "right" in moves:
        heads.add("right")
    if not heads:
        heads.add("left" if "left" in moves and (lane < lanes / 2 or "right" not in moves) else "right")
    return frozenset(heads)
