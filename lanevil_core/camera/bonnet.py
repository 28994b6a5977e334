"""The ego's bonnet in view: its front edge projected through the frame's camera (lens included), and the pixels
below that edge painted as the bonnet (body colour lit by sky and sun, and a blurred mirror of the scene above).

Bonnet frame: the vehicle's (x forward, y left, z up), with the front edge ``reach`` m ahead of the camera and
``drop`` m below it, its corners ``crown`` m lower than its middle; beyond its width the edge falls away (the
wings), so the sides of the image below the edge show road.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..case import Bonnet, Camera
from ..typed import FloatArray
from .pinhole import PinholeCamera, mounted_camera

EDGE_SAMPLES = 241


def T_vehicle_camera(mount: Camera) -> FloatArray:
    """(4, 4) the camera's pose in the vehicle frame (the mount's position, pitch, yaw and roll)."""
    return mounted_camera(mount, np.eye(4)).T_world_camera


def edge_vehicle(mount: Camera, bonnet: Bonnet) -> FloatArray:
    """(EDGE_SAMPLES, 3) float64 the bonnet's front edge in the vehicle frame, right wing to left wing."""
    half = bonnet.width / 2
    y = np.linspace(-half - 0.6, half + 0.6, EDGE_SAMPLES)
    inside = np.clip(np.abs(y) / half, 0.0, 1.0)
    z = mount.z - bonnet.drop - bonnet.crown * inside**2
    wing = np.clip(np.abs(y) - half, 0.0, None) / 0.6  # 0 .. 1 over the wing
    z = z - wing * (z - 0.3)  # the wing falls to the wheel arch
    x = mount.x + bonnet.reach - 0.35 * inside**4 - 0.9 * wing
    return np.stack([x, mount.y + y, z], axis=1)


def edge_rows(camera: PinholeCamera, mount: Camera, bonnet: Bonnet) -> FloatArray:
    """(W,) float64 per image column: the continuous row where the bonnet starts (inf where none is in view)."""
    k = camera.intrinsics
    T_world_vehicle = camera.T_world_camera @ np.linalg.inv(T_vehicle_camera(mount))
    p_vehicle = edge_vehicle(mount, bonnet)
    p_world = p_vehicle @ T_world_vehicle[:3, :3].T + T_world_vehicle[:3, 3]
    uv_image, depth = camera.project(p_world)
    ok = np.isfinite(uv_image).all(axis=1) & (depth > 0.05)
    u, v = uv_image[ok, 0], uv_image[ok, 1]
    rows = np.full(k.width, np.inf)
    if u.size < 2:
        return rows
    order = np.argsort(u)
    u, v = u[order], v[order]
    cols = np.arange(k.width) + 0.5
    covered = (cols >= u[0]) & (cols <= u[-1])
    rows[covered] = np.interp(cols[covered], u, v)
    return rows


def bonnet_mask(camera: PinholeCamera, mount: Camera, bonnet: Bonnet) -> np.ndarray:
    """(H, W) bool: pixels whose centre lies on the bonnet."""
    k = camera.intrinsics
    rows = edge_rows(camera, mount, bonnet)
    return (np.arange(k.height)[:, None] + 0.5) >= rows[None, :]


def paint_bonnet(hdr: np.ndarray, mask: np.ndarray, bonnet: Bonnet, sky: FloatArray, sun: float) -> None:
    """Paint the bonnet pixels of (H, W, 3) float32 linear radiance in place: diffuse body colour under the sky
    (``sky``, (3,) irradiance) and the sun (``sun``, its irradiance on the bonnet), plus ``gloss`` times the scene
    above the edge mirrored in the paint and blurred by the bonnet's curve."""
    if not mask.any():
        return
    height, width, _ = hdr.shape
    first = np.where(mask.any(axis=0), mask.argmax(axis=0), height)  # (W,) first bonnet row per column
    top = int(first.min())
    rows = np.arange(top, height)[:, None]
    mirrored = np.clip(2 * first[None, :] - rows - 1, 0, height - 1)  # mirror about the edge
    cols = np.broadcast_to(np.arange(width)[None, :], mirrored.shape)
    blur_px = max(3, width // 160)
    reflection = cv2.blur(np.ascontiguousarray(hdr[mirrored, cols]), (blur_px, 3))
    depth_in = np.clip((rows - first[None, :]) / max(height * 0.25, 1.0), 0.0, 1.0)[..., None]
    body = np.asarray(bonnet.color, np.float32) * (np.asarray(sky, np.float32) + np.float32(sun))
    painted = body[None, None, :] + bonnet.gloss * (1.0 - 0.6 * depth_in) * reflection
    band = mask[top:]
    hdr[top:][band] = painted[band].astype(np.float32)
