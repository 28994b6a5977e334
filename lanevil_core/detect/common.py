"""What both classical detectors share: the camera's ground geometry, row sampling and TuSimple lane output.

Image coordinates follow docs/conventions.md: continuous, origin at the top-left corner, pixel (col, row)
centred at (col + 0.5, row + 0.5). A TuSimple row ``h`` is sampled at ``v_image = h + 0.5`` and a lane point is
written as ``floor(u_image)``, -2 where the lane is absent or outside the image, like the ground truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..camera import Intrinsics, intrinsics_for
from ..case import Camera
from ..labels.lanes import NO_POINT
from ..typed import FloatArray


@dataclass(frozen=True)
class GroundCamera:
    """A pinhole camera above a flat road: intrinsics, mount height (m) and pitch (radians, positive down).

    Ground coordinates: ``x_ground`` metres to the right of the camera, ``z_ground`` metres ahead of it.
    """

    intrinsics: Intrinsics
    height_m: float
    pitch: float

    @classmethod
    def default(cls, size: tuple[int, int]) -> GroundCamera:
        """The LanEvil camera (case defaults: 90 deg HFOV, 3 m up, pitch 0) at image ``size``."""
        camera = Camera()
        return cls(intrinsics_for(camera, size), camera.z, math.radians(camera.pitch))

    @property
    def size(self) -> tuple[int, int]:
        return self.intrinsics.width, self.intrinsics.height

    @property
    def horizon_row(self) -> float:
        """Continuous image row of the horizon of the flat road."""
        k = self.intrinsics
        return k.cy - k.fy * math.tan(self.pitch)

    def H_image_ground(self) -> FloatArray:
        """(3, 3) homography: ground (x_ground, z_ground, 1) -> homogeneous image (u, v, 1)."""
        s, c, h = math.sin(self.pitch), math.cos(self.pitch), self.height_m
        # Columns: camera-frame images of the ground x axis, the ground z axis and the ground origin.
        R_camera_ground = np.array([[1.0, 0.0, 0.0], [0.0, -s, h * c], [0.0, c, h * s]])
        return self.intrinsics.K @ R_camera_ground

    def ground_z_of_row(self, v_image: FloatArray) -> FloatArray:
        """(r,) distance ahead (m) of the flat road seen at image rows ``v_image`` (NaN at/above the horizon)."""
        k = self.intrinsics
        angle = np.arctan((np.asarray(v_image, np.float64) - k.cy) / k.fy) + self.pitch  # below the horizontal
        with np.errstate(divide="ignore", invalid="ignore"):
            z_ray = self.height_m / np.tan(angle)  # horizontal distance to where the ray meets the road
        return np.where(angle > 1e-6, z_ray, np.nan)

    def project_ground(self, x_ground: FloatArray, z_ground: FloatArray) -> FloatArray:
        """(r, 2) continuous image points of ground points."""
        p = self.H_image_ground() @ np.stack([x_ground, z_ground, np.ones_like(x_ground)])
        return (p[:2] / p[2]).T


def sample_rows(h_samples: list[int]) -> FloatArray:
    """(r,) continuous rows of TuSimple h_samples (their pixel centres)."""
    return np.asarray(h_samples, np.float64) + 0.5


def lane_columns(u_image: FloatArray, width: int) -> list[int]:
    """TuSimple x per row: ``floor(u)`` inside the image, -2 where NaN or outside."""
    u = np.asarray(u_image, np.float64)
    inside = np.isfinite(u) & (u >= 0) & (u < width)
    return np.where(inside, np.floor(np.where(inside, u, 0.0)), NO_POINT).astype(int).tolist()


def useful_lanes(lanes: list[list[int]], min_points: int = 2) -> list[list[int]]:
    """Lanes with at least ``min_points`` points, ordered left to right by their lowest point."""
    kept = [lane for lane in lanes if sum(x >= 0 for x in lane) >= min_points]

    def bottom_x(lane: list[int]) -> int:
        return next(x for x in reversed(lane) if x >= 0)

    return sorted(kept, key=bottom_x)
