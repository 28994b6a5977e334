"""Camera projection properties."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.camera import Intrinsics, PinholeCamera, ego_camera
from lanevil_core.case import Case
from lanevil_core.world.road_layout import build_network

finite = st.floats(-50, 50, allow_nan=False)


def _camera(yaw: float, pitch: float, position: tuple[float, float, float]) -> PinholeCamera:
    cy, sy, cp, sp = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
    forward = np.array([cy * cp, sy * cp, -sp])
    left = np.array([-sy, cy, 0.0])
    up = np.cross(forward, left)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = -left, -up, forward, position
    return PinholeCamera(Intrinsics.from_fov(1280, 720, 90.0), T)


def test_reference_intrinsics() -> None:
    k = Intrinsics.from_fov(1280, 720, 90.0)
    assert (k.fx, k.fy, k.cx, k.cy) == (640.0, 640.0, 640.0, 360.0)
    vfov = 2 * np.degrees(np.arctan(k.cy / k.fy))
    assert abs(vfov - 58.72) < 0.01
    culane = Intrinsics.from_fov(1640, 590, 90.0)
    assert culane.fx == 820.0


@settings(max_examples=60, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-0.5, 0.5), st.tuples(finite, finite, st.floats(0.5, 10)),
       st.floats(-0.9, 0.9), st.floats(-0.5, 0.5), st.floats(1.0, 300.0))
def test_project_inverts_ray(yaw: float, pitch: float, position: tuple[float, float, float], x_n: float, y_n: float,
                             depth: float) -> None:
    """A point at depth d along a pixel's ray projects back onto that pixel, with depth d."""
    camera = _camera(yaw, pitch, position)
    k = camera.intrinsics
    p_camera = np.array([x_n * depth, y_n * depth, depth])
    p_world = camera.T_world_camera[:3, :3] @ p_camera + camera.T_world_camera[:3, 3]
    uv, d = camera.project(p_world)
    assert abs(d - depth) < 1e-6 * max(1.0, depth)
    assert np.allclose(uv, [k.fx * x_n + k.cx, k.fy * y_n + k.cy], atol=1e-6)


@settings(max_examples=40, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-0.3, 0.3), st.tuples(finite, finite, st.floats(0.5, 10)))
def test_pose_is_rigid(yaw: float, pitch: float, position: tuple[float, float, float]) -> None:
    R = _camera(yaw, pitch, position).R_world_camera
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert abs(np.linalg.det(R) - 1.0) < 1e-12


@settings(max_examples=30, deadline=None)
@given(st.floats(1.0, 200.0), st.floats(-0.2, 0.2))
def test_points_ahead_on_the_road_fall_below_the_horizon(distance: float, lateral: float) -> None:
    case = Case()
    network = build_network(case.road, case.scene.kind)
    camera = ego_camera(case, network, 0)
    s = case.ego_s(0) + case.camera.x + distance
    uv, depth = camera.project(network.main.line.to_world(s, network.lane_center_t(case.ego.lane) + lateral))
    assert depth > 0
    assert uv[1] > camera.intrinsics.cy  # the road lies below the horizon row of a level camera
    assert abs(uv[0] - camera.intrinsics.cx) < 1.0 + 640 * 0.2 / distance


def test_ego_camera_follows_the_lane_through_a_bend() -> None:
    case = Case.model_validate({"road": {"type": "bend", "radius": 80.0}, "ego": {"start_s": 60.0}})
    network = build_network(case.road, case.scene.kind)
    camera = ego_camera(case, network, 30)
    heading = network.main.line.heading_at(case.ego_s(30))
    forward = camera.R_world_camera[:, 2]
    assert abs(np.arctan2(forward[1], forward[0]) - heading) < 1e-6
    assert abs(camera.p_world_camera[2] - case.camera.z) < 1e-6
