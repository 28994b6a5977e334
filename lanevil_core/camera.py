"""Pinhole camera: intrinsics, the ego camera pose of a frame, and projection.

Camera frame is OpenCV's: +X right, +Y down, +Z forward. Image coordinates are continuous with the origin at
the top-left corner of the top-left pixel; pixel (col, row) covers [col, col+1) x [row, row+1), so its centre
is at (col + 0.5, row + 0.5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .case import Camera, Case
from .road_layout import RoadNetwork
from .typed import FloatArray


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics in pixels."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_fov(cls, width: int, height: int, fov_deg: float) -> Intrinsics:
        """Square pixels, principal point at the image centre, horizontal FOV ``fov_deg``."""
        # Rounded so that 90 degrees gives exactly width / 2 (tan(pi/4) is not exactly 1 in floating point).
        fx = round(0.5 * width / float(np.tan(np.radians(fov_deg) / 2)), 9)
        return cls(width, height, fx, fx, width / 2.0, height / 2.0)

    @property
    def K(self) -> FloatArray:
        """(3, 3) float64 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class PinholeCamera:
    """Intrinsics plus pose ``T_world_camera`` (4, 4): maps camera-frame points to the world frame."""

    intrinsics: Intrinsics
    T_world_camera: FloatArray
    near: float = 0.1

    @property
    def R_world_camera(self) -> FloatArray:
        return self.T_world_camera[:3, :3]

    @property
    def p_world_camera(self) -> FloatArray:
        """(3,) camera centre in the world."""
        return self.T_world_camera[:3, 3]

    def world_to_camera(self, p_world: FloatArray) -> FloatArray:
        """(..., 3) world points to the camera frame."""
        return (np.asarray(p_world) - self.p_world_camera) @ self.R_world_camera

    def project(self, p_world: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Project world points.

        Returns:
            uv_image (..., 2) continuous pixel coordinates, depth (..., ) camera z (m; <= near is behind).
        """
        p_camera = self.world_to_camera(p_world)
        depth = p_camera[..., 2]
        safe = np.where(depth > 1e-9, depth, np.nan)
        k = self.intrinsics
        u = k.fx * p_camera[..., 0] / safe + k.cx
        v = k.fy * p_camera[..., 1] / safe + k.cy
        return np.stack([u, v], axis=-1), depth

    def ray_directions_camera(self) -> FloatArray:
        """(H, W, 3) float64 camera-frame rays through pixel centres, scaled to z = 1."""
        k = self.intrinsics
        cols = (np.arange(k.width) + 0.5 - k.cx) / k.fx
        rows = (np.arange(k.height) + 0.5 - k.cy) / k.fy
        x, y = np.meshgrid(cols, rows)
        return np.stack([x, y, np.ones_like(x)], axis=-1)

    def resized(self, width: int, height: int) -> PinholeCamera:
        """The same pose and horizontal FOV at another image size."""
        fov = 2 * np.degrees(np.arctan(0.5 * self.intrinsics.width / self.intrinsics.fx))
        return PinholeCamera(Intrinsics.from_fov(width, height, fov), self.T_world_camera, self.near)


def intrinsics_for(camera: Camera, size: tuple[int, int] | None = None) -> Intrinsics:
    """Intrinsics of a case camera, optionally at another output size (same horizontal FOV)."""
    width, height = size if size is not None else (camera.width, camera.height)
    return Intrinsics.from_fov(width, height, camera.fov)


def ego_camera(case: Case, network: RoadNetwork, frame: int, size: tuple[int, int] | None = None) -> PinholeCamera:
    """The ego camera of frame ``frame``: the vehicle sits on its lane centre, aligned with the road."""
    line = network.main.line
    s_ego = case.ego_s(frame)
    t_ego = network.lane_center_t(case.ego.lane)
    p_world_vehicle, forward, left = line.frame(s_ego)
    p_world_vehicle = p_world_vehicle + left * t_ego
    up = np.cross(forward, left)
    cam = case.camera
    p_world_camera = p_world_vehicle + cam.x * forward + cam.y * left + cam.z * up
    pitch = np.radians(cam.pitch)
    z_axis = np.cos(pitch) * forward - np.sin(pitch) * up  # optical axis, pitched down for pitch > 0
    y_axis = -(np.cos(pitch) * up + np.sin(pitch) * forward)  # image down
    x_axis = -left  # image right
    T_world_camera = np.eye(4)
    T_world_camera[:3, 0], T_world_camera[:3, 1], T_world_camera[:3, 2] = x_axis, y_axis, z_axis
    T_world_camera[:3, 3] = p_world_camera
    return PinholeCamera(intrinsics_for(cam, size), T_world_camera)
