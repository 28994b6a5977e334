"""The ego lane's centre line in the vehicle frame, estimated from a detector's lanes in the image.

Detected lane points (TuSimple columns at ``h_samples``) are cast back through the case camera mounted on the
vehicle (``camera.mounted_camera``, the model the labels project with) onto the flat ground plane under the
vehicle. Each lane becomes a quadratic ``y = a + b x + c x^2`` in the vehicle frame (+X forward, +Y left, metres);
the nearest lane on each side of the vehicle bounds the ego lane and the centre line lies midway. With only one
side found, the centre lies half the last measured lane width from it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..camera import PinholeCamera
from ..labels.lanes import NO_POINT
from ..typed import FloatArray

FIT_RANGE_M = (3.0, 30.0)  # lane points used, metres ahead of the vehicle origin
REFERENCE_X_M = 10.0  # lanes are told apart by their offset this far ahead
# (degree, (fewest points, shortest span along x in m)): the highest degree the points support is fitted
DEGREES: tuple[tuple[int, tuple[int, float]], ...] = ((3, (8, 12.0)), (2, (3, 4.0)), (1, (2, 0.5)))
LANE_WIDTH_RANGE_M = (2.4, 5.2)
DEFAULT_LANE_WIDTH_M = 3.5


@dataclass(frozen=True)
class LanePath:
    """A path in the vehicle frame: ``y = sum(coeffs[i] * x^i)`` (metres, +X forward, +Y left)."""

    coeffs: tuple[float, ...]

    def y_at(self, x_vehicle: FloatArray | float) -> FloatArray:
        return np.asarray(np.polynomial.polynomial.polyval(np.asarray(x_vehicle, np.float64), self.coeffs), np.float64)

    def slope_at(self, x_vehicle: float) -> float:
        return float(np.polynomial.polynomial.polyval(x_vehicle, np.polynomial.polynomial.polyder(self.coeffs)))

    def shifted(self, dy: float) -> LanePath:
        return LanePath((self.coeffs[0] + dy, *self.coeffs[1:]))

    def points(self, x_vehicle: FloatArray) -> FloatArray:
        """(n, 2) vehicle-frame points of the path at ``x_vehicle`` (n,)."""
        return np.stack([x_vehicle, self.y_at(x_vehicle)], axis=-1)


def mean_path(first: LanePath, second: LanePath) -> LanePath:
    """The path midway between two paths."""
    size = max(len(first.coeffs), len(second.coeffs))
    a = np.pad(first.coeffs, (0, size - len(first.coeffs)))
    b = np.pad(second.coeffs, (0, size - len(second.coeffs)))
    return LanePath(tuple(float(c) for c in 0.5 * (a + b)))


@dataclass(frozen=True)
class LaneEstimate:
    """The ego lane: its centre line, width (m) and which of its two boundaries were seen."""

    center: LanePath
    width: float
    left_seen: bool
    right_seen: bool

    @property
    def lateral_offset(self) -> float:
        """Vehicle origin's offset from the centre line (m, positive = vehicle left of the centre)."""
        return -float(self.center.y_at(0.0))

    @property
    def heading_error(self) -> float:
        """Vehicle heading minus the centre line's at the origin (radians, positive = turned left of it)."""
        return -float(np.arctan(self.center.slope_at(0.0)))


def ground_points(camera_vehicle: PinholeCamera, xs: Sequence[int], h_samples: Sequence[int]) -> FloatArray:
    """(n, 2) vehicle-frame ground points (x ahead, y left) of one TuSimple lane; rows that miss the ground are
    dropped. ``camera_vehicle``: the camera with ``T_world_camera`` = ``T_vehicle_camera``."""
    cols = np.asarray(xs, np.float64)
    rows = np.asarray(h_samples, np.float64)
    keep = cols != NO_POINT
    k = camera_vehicle.intrinsics
    rays_camera = np.stack([(cols[keep] + 0.5 - k.cx) / k.fx, (rows[keep] + 0.5 - k.cy) / k.fy,
                            np.ones(int(keep.sum()))], axis=-1)
    rays_vehicle = rays_camera @ camera_vehicle.R_world_camera.T
    p_vehicle_camera = camera_vehicle.p_world_camera
    down = rays_vehicle[:, 2] < -1e-6
    scale = -p_vehicle_camera[2] / np.where(down, rays_vehicle[:, 2], -1.0)
    p_vehicle = p_vehicle_camera + rays_vehicle * scale[:, None]
    return p_vehicle[down, :2]


def fit_path(p_vehicle: FloatArray) -> LanePath | None:
    """Least-squares polynomial through (n, 2) ground points inside ``FIT_RANGE_M``: a cubic (clothoids) where the
    points reach far enough, else a quadratic, else a line."""
    x, y = p_vehicle[:, 0], p_vehicle[:, 1]
    inside = (x >= FIT_RANGE_M[0]) & (x <= FIT_RANGE_M[1])
    x, y = x[inside], y[inside]
    span = float(np.ptp(x)) if x.size else 0.0
    degree = next((d for d, (points, reach) in DEGREES if x.size >= points and span >= reach), None)
    if degree is None:
        return None
    return LanePath(tuple(float(c) for c in np.polynomial.polynomial.polyfit(x, y, degree)))


def ego_boundaries(paths: list[LanePath]) -> tuple[LanePath | None, LanePath | None]:
    """The nearest lane left of the vehicle and the nearest right of it (offsets at ``REFERENCE_X_M``)."""
    offsets = [float(path.y_at(REFERENCE_X_M)) for path in paths]
    left = [(y, path) for y, path in zip(offsets, paths) if y > 0]
    right = [(y, path) for y, path in zip(offsets, paths) if y <= 0]
    nearest_left = min(left, key=lambda item: item[0])[1] if left else None
    nearest_right = max(right, key=lambda item: item[0])[1] if right else None
    return nearest_left, nearest_right


def estimate_lane(lanes: Sequence[Sequence[int]], h_samples: Sequence[int], camera_vehicle: PinholeCamera,
                  last_width: float = DEFAULT_LANE_WIDTH_M) -> LaneEstimate | None:
    """The ego lane from a detector's TuSimple lanes, or None when no lane was usable."""
    paths = [path for path in (fit_path(ground_points(camera_vehicle, xs, h_samples)) for xs in lanes)
             if path is not None]
    left, right = ego_boundaries(paths)
    if left is not None and right is not None:
        width = float(left.y_at(REFERENCE_X_M) - right.y_at(REFERENCE_X_M))
        if LANE_WIDTH_RANGE_M[0] <= width <= LANE_WIDTH_RANGE_M[1]:
            return LaneEstimate(mean_path(left, right), width, True, True)
        # Not a lane's width apart: keep the side nearer to where a boundary should be.
        if abs(abs(float(left.y_at(REFERENCE_X_M))) - 0.5 * last_width) <= \
                abs(abs(float(right.y_at(REFERENCE_X_M))) - 0.5 * last_width):
            right = None
        else:
            left = None
    if left is not None:
        return LaneEstimate(left.shifted(-0.5 * last_width), last_width, True, False)
    if right is not None:
        return LaneEstimate(right.shifted(0.5 * last_width), last_width, False, True)
    return None
