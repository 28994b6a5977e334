"""Cascaded orthographic shadow maps along the sun direction.

Light frame: +Z points from the sun into the scene (``-sun_dir_world``); X and Y span the map. A cascade covers
the ground part of one slice of the camera frustum, snapped to whole texels so shadows do not crawl as the ego moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..camera import PinholeCamera
from ..typed import Float32Array, FloatArray
from .lighting import COARSE_SHIFT, min_pool
from .packed import PackedScene
from .raster import depth_orthographic

CASCADE_FAR_M = (18.0, 55.0, 220.0)
CASCADE_SIZE = 1024  # at 1280 pixels wide
GROUND_BAND_M = (-4.0, 14.0)  # heights around the camera's ground that receive shadows worth mapping


@dataclass(frozen=True)
class ShadowMaps:
    """Attributes:
    depth: (C, S, S) float32 light-frame depth of the nearest caster, inf where none.
    params: (C, 3) float64 per cascade: u0, v0, texels per metre.
    R_light_world: (3, 3) float64 rows = light-frame axes in world coordinates.
    """

    depth: Float32Array
    coarse: Float32Array  # (C, S/8, S/8) nearest caster depth per 8x8 texels, for a quick "fully lit" test
    params: FloatArray
    R_light_world: FloatArray


def light_rotation(sun_dir_world: FloatArray) -> FloatArray:
    """(3, 3) rotation whose rows are the light frame's X, Y, Z axes in the world."""
    z_axis = -np.asarray(sun_dir_world, np.float64)
    z_axis /= np.linalg.norm(z_axis)
    helper = np.array([0.0, 0.0, 1.0]) if abs(z_axis[2]) < 0.95 else np.array([1.0, 0.0, 0.0])
    x_axis = np.cross(helper, z_axis)
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(z_axis, x_axis)
    return np.stack([x_axis, y_axis, z_axis])


def _slice_points_world(camera: PinholeCamera, near: float, far: float) -> FloatArray:
    """World points bounding the ground band of the frustum between depths ``near`` and ``far``."""
    k = camera.intrinsics
    corners = np.array([[0, 0], [k.width, 0], [0, k.height], [k.width, k.height]], np.float64)
    rays_camera = np.stack([(corners[:, 0] - k.cx) / k.fx, (corners[:, 1] - k.cy) / k.fy, np.ones(4)], axis=-1)
    points = [camera.p_world_camera + (rays_camera * d) @ camera.R_world_camera.T for d in (near, far)]
    p_world = np.concatenate(points)
    ground = camera.p_world_camera[2] - 3.0
    p_world[:, 2] = np.clip(p_world[:, 2], ground + GROUND_BAND_M[0], ground + GROUND_BAND_M[1])
    return p_world


def cascade_size(image_width: int) -> int:
    """Texels per cascade side for an image width: shadow detail follows pixel size (1024 at 1280 wide)."""
    return int(min(max(2 ** round(np.log2(image_width * CASCADE_SIZE / 1280)), 256), 2048))


def build_shadow_maps(packed: PackedScene, camera: PinholeCamera, sun_dir_world: FloatArray,
                      size: int | None = None) -> ShadowMaps:
    """Rasterize every shadow-casting face into each cascade (``size`` texels a side; default from the image)."""
    size = size if size is not None else cascade_size(camera.intrinsics.width)
    R_light_world = light_rotation(sun_dir_world)
    v_light = packed.vertices @ R_light_world.T
    depth = np.empty((len(CASCADE_FAR_M), size, size), np.float32)
    params = np.zeros((len(CASCADE_FAR_M), 3))
    near = 0.1
    for c, far in enumerate(CASCADE_FAR_M):
        p_light = _slice_points_world(camera, near, far) @ R_light_world.T
        lo, hi = p_light[:, :2].min(axis=0), p_light[:, :2].max(axis=0)
        extent = float(max(hi - lo)) * 1.05 + 1.0
        texel = 2.0 ** np.ceil(np.log2(extent / size))  # power-of-two texels keep snapping stable
        u0 = np.floor((0.5 * (lo[0] + hi[0]) - 0.5 * size * texel) / texel) * texel
        v0 = np.floor((0.5 * (lo[1] + hi[1]) - 0.5 * size * texel) / texel) * texel
        depth[c] = depth_orthographic(v_light, packed.faces, packed.shadow_faces, (size, size), 1.0 / texel, u0, v0)
        params[c] = (u0, v0, 1.0 / texel)
        near = far * 0.9
    return ShadowMaps(depth, min_pool(depth, COARSE_SHIFT), params, R_light_world)
