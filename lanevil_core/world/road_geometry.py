"""Reference lines built from line / arc / clothoid pieces, with an elevation profile.

A reference line maps the road frame (s along the line, t to its left, both metres) to the world
frame (+X east, +Y north, +Z up). The line is sampled densely once; every other query interpolates
that one table, so labels and rendered geometry come from the same numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..typed import FloatArray

SAMPLE_STEP_M = 0.1
NEWTON_STEPS = 4  # refinements of a world point's station in ``road_coordinates``


@dataclass(frozen=True)
class Piece:
    """One planar piece: curvature varies linearly from ``k0`` to ``k1`` over ``length`` (1/m).

    k0 == k1 == 0 is a line, k0 == k1 != 0 an arc, otherwise a clothoid (OpenDRIVE ``spiral``).
    Positive curvature turns left.
    """

    length: float
    k0: float = 0.0
    k1: float = 0.0


@dataclass(frozen=True)
class GradeChange:
    """The grade (rise/run) eases from its previous value to ``grade`` over [s_start, s_start + length]."""

    s_start: float
    length: float
    grade: float


class ReferenceLine:
    """A sampled planar curve plus elevation.

    Attributes:
        s: (n,) float64 arc length at each sample.
        xy: (n, 2) float64 world position of each sample.
        heading: (n,) float64 heading (radians, counter-clockwise from +X).
        curvature: (n,) float64 (1/m).
        z: (n,) float64 elevation (m).
        grade: (n,) float64 dz/ds.
    """

    def __init__(
        self,
        pieces: list[Piece],
        origin_xy: tuple[float, float] = (0.0, 0.0),
        origin_heading: float = 0.0,
        origin_z: float = 0.0,
        grade_changes: tuple[GradeChange, ...] = (),
    ) -> None:
        self.pieces = list(pieces)
        self.length = float(sum(piece.length for piece in pieces))
        n = int(np.ceil(self.length / SAMPLE_STEP_M)) + 1
        self.s = np.linspace(0.0, self.length, n)
        self.curvature, self.heading = _curvature_heading(self.pieces, self.s, origin_heading)
        self.xy = _integrate_xy(self.s, self.heading, origin_xy)
        self.grade = _grade_profile(self.s, grade_changes)
        self.z = origin_z + _cumulative_trapezoid(self.s, self.grade)

    def _interp(self, values: FloatArray, s_road: FloatArray) -> FloatArray:
        return np.interp(s_road, self.s, values)

    def frame(self, s_road: FloatArray | float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Origin, tangent and left normal of the road frame at ``s_road``.

        Returns:
            p_world (..., 3), tangent_world (..., 3) (unit, along s, following the grade), left_world (..., 3)
            (unit, horizontal).
        """
        s_road = np.asarray(s_road, dtype=np.float64)
        x = self._interp(self.xy[:, 0], s_road)
        y = self._interp(self.xy[:, 1], s_road)
        z = self._interp(self.z, s_road)
        heading = self._interp(self.heading, s_road)
        grade = self._interp(self.grade, s_road)
        cos_h, sin_h = np.cos(heading), np.sin(heading)
        norm = np.sqrt(1.0 + grade**2)
        tangent = np.stack([cos_h / norm, sin_h / norm, grade / norm], axis=-1)
        left = np.stack([-sin_h, cos_h, np.zeros_like(cos_h)], axis=-1)
        return np.stack([x, y, z], axis=-1), tangent, left

    def to_world(
        self, s_road: FloatArray | float, t_road: FloatArray | float, h_road: FloatArray | float = 0.0,
    ) -> FloatArray:
        """World points (..., 3) of road-frame points: ``t_road`` to the left, ``h_road`` straight up."""
        s_road, t_road, h_road = np.broadcast_arrays(
            np.asarray(s_road, np.float64), np.asarray(t_road, np.float64), np.asarray(h_road, np.float64)
        )
        p_world, _, left = self.frame(s_road)
        return p_world + left * t_road[..., None] + np.array([0.0, 0.0, 1.0]) * h_road[..., None]

    def heading_at(self, s_road: FloatArray | float) -> FloatArray:
        """Heading (radians) at ``s_road``."""
        return self._interp(self.heading, np.asarray(s_road, np.float64))

    def grade_at(self, s_road: FloatArray | float) -> FloatArray:
        """Grade dz/ds at ``s_road``."""
        return self._interp(self.grade, np.asarray(s_road, np.float64))

    def z_at(self, s_road: FloatArray | float) -> FloatArray:
        """Elevation (m) of the reference line at ``s_road``."""
        return self._interp(self.z, np.asarray(s_road, np.float64))

    def station(self, p_world: FloatArray) -> tuple[float, float]:
        """Road-frame (s, t) of a world point (its x, y; (2,) or (3,)): the foot of the perpendicular on the line.

        The nearest sample is refined along its tangent (exact on lines, within micrometres on arcs), clamped to
        the line's ends.
        """
        xy = np.asarray(p_world, np.float64)[:2]
        nearest = int(np.argmin(np.sum((self.xy - xy) ** 2, axis=1)))
        heading = self.heading[nearest]
        along = float(np.dot(xy - self.xy[nearest], [np.cos(heading), np.sin(heading)]))
        s_road = float(np.clip(self.s[nearest] + along, 0.0, self.length))
        s_at = np.asarray(s_road)
        x, y = self._interp(self.xy[:, 0], s_at), self._interp(self.xy[:, 1], s_at)
        heading = self._interp(self.heading, s_at)
        t_road = float(np.dot(xy - [x, y], [-np.sin(heading), np.cos(heading)]))
        return s_road, t_road

    def road_coordinates(self, p_world: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """World points (n, 3) -> (s_road, t_road, h_road), each (n,), in this line's road frame.

        The nearest sample of the line seeds ``NEWTON_STEPS`` Newton steps along the horizontal tangent, so points
        within the bend radius of the line map back exactly (to ``to_world``'s own interpolation). ``station`` is
        the one-point form the renderer's path keeps (one refinement, no height).
        """
        p_world = np.atleast_2d(np.asarray(p_world, np.float64))
        d2 = ((p_world[:, None, :2] - self.xy[None, :, :]) ** 2).sum(-1)
        s_road = self.s[np.argmin(d2, axis=1)]
        for _ in range(NEWTON_STEPS):
            origin, tangent, _left = self.frame(s_road)
            flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
            s_road = np.clip(s_road + ((p_world[:, :2] - origin[:, :2]) * flat).sum(1), 0.0, self.length)
        origin, _tangent, left = self.frame(s_road)
        return s_road, ((p_world - origin) * left).sum(1), p_world[:, 2] - origin[:, 2]


def _curvature_heading(pieces: list[Piece], s: FloatArray, heading0: float) -> tuple[FloatArray, FloatArray]:
    curvature = np.zeros_like(s)
    heading = np.full_like(s, heading0)
    s_start, theta_start = 0.0, heading0
    for index, piece in enumerate(pieces):
        last = index == len(pieces) - 1
        s_end = s_start + piece.length
        inside = (s >= s_start) & ((s <= s_end) if last else (s < s_end))
        u = s[inside] - s_start
        rate = (piece.k1 - piece.k0) / piece.length
        curvature[inside] = piece.k0 + rate * u
        heading[inside] = theta_start + piece.k0 * u + 0.5 * rate * u**2
        theta_start += piece.k0 * piece.length + 0.5 * (piece.k1 - piece.k0) * piece.length
        s_start = s_end
    return curvature, heading


def _cumulative_trapezoid(s: FloatArray, f: FloatArray) -> FloatArray:
    out = np.zeros_like(s)
    out[1:] = np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))
    return out


def _integrate_xy(s: FloatArray, heading: FloatArray, origin_xy: tuple[float, float]) -> FloatArray:
    # The mid-point heading of each step is exact for arcs and second-order accurate for clothoids.
    ds = np.diff(s)
    mid = 0.5 * (heading[1:] + heading[:-1])
    xy = np.zeros((s.size, 2))
    xy[1:, 0] = np.cumsum(ds * np.cos(mid))
    xy[1:, 1] = np.cumsum(ds * np.sin(mid))
    return xy + np.asarray(origin_xy)


def _smoothstep(u: FloatArray) -> FloatArray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def _grade_profile(s: FloatArray, changes: tuple[GradeChange, ...]) -> FloatArray:
    grade = np.zeros_like(s)
    for change in sorted(changes, key=lambda c: c.s_start):
        blend = _smoothstep((s - change.s_start) / max(change.length, 1e-6))
        grade = grade + (change.grade - grade) * blend
    return grade
