"""The ego camera: intrinsics, lens distortion, the camera pose of a frame, and projection.

Camera frame is OpenCV's: +X right, +Y down, +Z forward. Image coordinates are continuous with the origin at
the top-left corner of the top-left pixel; pixel (col, row) covers [col, col+1) x [row, row+1), so its centre
is at (col + 0.5, row + 0.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..case import Camera, Case
from ..typed import FloatArray
from ..world.road_geometry import ReferenceLine
from ..world.road_layout import RoadNetwork
from .lens import NO_DISTORTION, Distortion, distort, is_pinhole, undistort, valid_radius2


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

    def scaled(self, width: int, height: int) -> Intrinsics:
        """The same lens on an image of another size (focal length and principal point scaled per axis)."""
        sx, sy = width / self.width, height / self.height
        return Intrinsics(width, height, self.fx * sx, self.fy * sy, self.cx * sx, self.cy * sy)

    @property
    def K(self) -> FloatArray:
        """(3, 3) float64 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class PinholeCamera:
    """Intrinsics, lens distortion and pose ``T_world_camera`` (4, 4): maps camera-frame points to the world frame.

    ``distortion`` is OpenCV's (k1, k2, p1, p2, k3) on normalised coordinates; all zero (the default) is a pinhole.
    """

    intrinsics: Intrinsics
    T_world_camera: FloatArray
    near: float = 0.1
    distortion: Distortion = NO_DISTORTION

    @property
    def pinhole(self) -> bool:
        """Whether the lens has no distortion."""
        return is_pinhole(self.distortion)

    @property
    def valid_radius2(self) -> float:
        """Squared ideal (undistorted) radius up to which ``project`` maps points through the lens."""
        return _valid_radius2(self.intrinsics, self.distortion)

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
        x_norm, y_norm = p_camera[..., 0] / safe, p_camera[..., 1] / safe
        if not self.pinhole:
            outside = x_norm**2 + y_norm**2 > self.valid_radius2  # where the lens model stops holding
            x_norm, y_norm = distort(x_norm, y_norm, self.distortion)
            x_norm, y_norm = np.where(outside, np.nan, x_norm), np.where(outside, np.nan, y_norm)
        return np.stack([k.fx * x_norm + k.cx, k.fy * y_norm + k.cy], axis=-1), depth

    def ray_directions_camera(self) -> FloatArray:
        """(H, W, 3) float64 camera-frame rays through pixel centres, scaled to z = 1."""
        k = self.intrinsics
        cols = (np.arange(k.width) + 0.5 - k.cx) / k.fx
        rows = (np.arange(k.height) + 0.5 - k.cy) / k.fy
        x, y = np.meshgrid(cols, rows)
        return np.stack([x, y, np.ones_like(x)], axis=-1)

    def resized(self, width: int, height: int) -> PinholeCamera:
        """The same pose and lens at another image size."""
        k = self.intrinsics
        if self.pinhole and k.cx == k.width / 2 and k.cy == k.height / 2 and k.fx == k.fy:
            fov = 2 * np.degrees(np.arctan(0.5 * k.width / k.fx))
            return PinholeCamera(Intrinsics.from_fov(width, height, fov), self.T_world_camera, self.near)
        return PinholeCamera(k.scaled(width, height), self.T_world_camera, self.near, self.distortion)


@lru_cache(maxsize=64)
def _valid_radius2(intrinsics: Intrinsics, distortion: Distortion) -> float:
    k = intrinsics
    u = np.array([0.0, k.width, 0.0, k.width])
    v = np.array([0.0, 0.0, k.height, k.height])
    x, y = undistort((u - k.cx) / k.fx, (v - k.cy) / k.fy, distortion)
    return valid_radius2(distortion, float(np.max(x * x + y * y)))


def _is_centred_fov(camera: Camera) -> bool:
    return camera.focal is None and camera.cx is None and camera.cy is None


def intrinsics_for(camera: Camera, size: tuple[int, int] | None = None) -> Intrinsics:
    """Intrinsics of a case camera, optionally at another output size (the same lens scaled)."""
    width, height = size if size is not None else (camera.width, camera.height)
    if _is_centred_fov(camera):
        return Intrinsics.from_fov(width, height, camera.fov)
    cx = camera.cx if camera.cx is not None else camera.width / 2.0
    cy = camera.cy if camera.cy is not None else camera.height / 2.0
    native = Intrinsics(camera.width, camera.height, camera.focal_px, camera.focal_px, cx, cy)
    return native if (width, height) == (camera.width, camera.height) else native.scaled(width, height)


@dataclass(frozen=True)
class VehiclePose:
    """The ego vehicle on the road: world position of its origin (m) and heading (radians, counter-clockwise
    from world +X). Height and pitch follow the road under it."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class EgoPath:
    """The case's scripted drive, resolved against its road: the camera mount, and the ego on its lane centre of
    the main road, aligned with it, moving at constant speed. Compiled into the scene, so the renderer and the
    labels place the camera without the case."""

    mount: Camera  # where the camera sits on the vehicle, its field of view and image size
    line: ReferenceLine  # the main road's reference line
    t_road: float  # the ego lane's centre (m, + left of the reference line)
    start_s: float  # station of frame 0 (m)
    speed: float  # m/s
    fps: float
    frames: int
    seed: int = 0  # the case's seed: a sensor's noise in each frame is drawn from it and the frame index

    def s_road(self, frame: int) -> float:
        """Station (m along the main road) of the ego at frame ``frame``."""
        return self.start_s + self.speed * (frame / self.fps)

    def vehicle_transform(self, frame: int) -> FloatArray:
        """(4, 4) ``T_world_vehicle`` of frame ``frame``. Vehicle frame: +X forward (along the grade), +Y left
        (horizontal), +Z up."""
        p_world, forward, left = self.line.frame(self.s_road(frame))
        return _transform(p_world + left * self.t_road, forward, left)

    def camera(self, frame: int, size: tuple[int, int] | None = None) -> PinholeCamera:
        """The ego camera of frame ``frame``, optionally at another image size."""
        return mounted_camera(self.mount, self.vehicle_transform(frame), size)


def ego_path(case: Case, network: RoadNetwork) -> EgoPath:
    """The case's scripted drive on ``network`` (its main road)."""
    return EgoPath(mount=case.camera, line=network.main.line, t_road=network.lane_center_t(case.ego.lane),
                   start_s=case.ego.start_s, speed=case.ego.speed, fps=case.ego.fps, frames=case.ego.frames,
                   seed=case.seed)


def scripted_vehicle_transform(case: Case, network: RoadNetwork, frame: int) -> FloatArray:
    """(4, 4) ``T_world_vehicle`` of frame ``frame`` of the case's scripted drive: on its lane centre, aligned with
    the road. Vehicle frame: +X forward (along the grade), +Y left (horizontal), +Z up."""
    return ego_path(case, network).vehicle_transform(frame)


def vehicle_transform(network: RoadNetwork, pose: VehiclePose) -> FloatArray:
    """(4, 4) ``T_world_vehicle`` of a vehicle at ``pose`` standing on the main road's surface: its height is the
    road's at its station, its pitch the road's slope along its heading (no roll)."""
    line = network.main.line
    s_road, _ = line.station(np.array([pose.x, pose.y]))
    z = float(line.z_at(s_road))
    slope = float(line.grade_at(s_road)) * float(np.cos(pose.yaw - line.heading_at(s_road)))
    forward = np.array([np.cos(pose.yaw), np.sin(pose.yaw), slope]) / np.sqrt(1.0 + slope**2)
    left = np.array([-np.sin(pose.yaw), np.cos(pose.yaw), 0.0])
    return _transform(np.array([pose.x, pose.y, z]), forward, left)


def _transform(p_world: FloatArray, forward: FloatArray, left: FloatArray) -> FloatArray:
    T_world_vehicle = np.eye(4)
    T_world_vehicle[:3, 0], T_world_vehicle[:3, 1] = forward, left
    T_world_vehicle[:3, 2], T_world_vehicle[:3, 3] = np.cross(forward, left), p_world
    return T_world_vehicle


def mounted_camera(cam: Camera, T_world_vehicle: FloatArray, size: tuple[int, int] | None = None) -> PinholeCamera:
    """The case camera mounted on a vehicle at ``T_world_vehicle`` (4, 4), optionally at another image size."""
    forward, left, up = (T_world_vehicle[:3, i] for i in range(3))
    p_world_camera = T_world_vehicle[:3, 3] + cam.x * forward + cam.y * left + cam.z * up
    if cam.yaw:  # turn the mount about the vehicle's up axis
        yaw = np.radians(cam.yaw)
        forward, left = np.cos(yaw) * forward + np.sin(yaw) * left, np.cos(yaw) * left - np.sin(yaw) * forward
    pitch = np.radians(cam.pitch)
    z_axis = np.cos(pitch) * forward - np.sin(pitch) * up  # optical axis, pitched down for pitch > 0
    y_axis = -(np.cos(pitch) * up + np.sin(pitch) * forward)  # image down
    x_axis = -left  # image right
    if cam.roll:  # turn the image clockwise: its right axis tips down
        roll = np.radians(cam.roll)
        x_axis, y_axis = np.cos(roll) * x_axis + np.sin(roll) * y_axis, np.cos(roll) * y_axis - np.sin(roll) * x_axis
    T_world_camera = np.eye(4)
    T_world_camera[:3, 0], T_world_camera[:3, 1], T_world_camera[:3, 2] = x_axis, y_axis, z_axis
    T_world_camera[:3, 3] = p_world_camera
    return PinholeCamera(intrinsics_for(cam, size), T_world_camera, distortion=cam.lens.coefficients)


def ego_camera(case: Case, network: RoadNetwork, frame: int, size: tuple[int, int] | None = None) -> PinholeCamera:
    """The ego camera of frame ``frame``: the vehicle sits on its lane centre, aligned with the road."""
    return ego_path(case, network).camera(frame, size)


def pose_camera(case: Case, network: RoadNetwork, pose: VehiclePose,
                size: tuple[int, int] | None = None) -> PinholeCamera:
    """The ego camera of a vehicle at an arbitrary ``pose`` (closed-loop driving)."""
    return mounted_camera(case.camera, vehicle_transform(network, pose), size)
