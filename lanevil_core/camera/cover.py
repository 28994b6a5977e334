"""Rendering through a distorted lens: a pinhole ``cover`` camera that sees every ray of the distorted image, and
the per-pixel maps that resample its frame into the distorted one."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..typed import FloatArray
from .lens import Distortion, undistort
from .pinhole import Intrinsics, PinholeCamera

COVER_MARGIN_PX = 2


def _ideal(intrinsics: Intrinsics, distortion: Distortion, u: FloatArray, v: FloatArray) -> tuple[FloatArray,
                                                                                                  FloatArray]:
    k = intrinsics
    return undistort((u - k.cx) / k.fx, (v - k.cy) / k.fy, distortion)


@lru_cache(maxsize=8)
def _cover(intrinsics: Intrinsics, distortion: Distortion) -> tuple[Intrinsics, np.ndarray, np.ndarray]:
    k = intrinsics
    cols = np.arange(k.width) + 0.5
    rows = np.arange(k.height) + 0.5
    u, v = np.meshgrid(cols, rows)
    x, y = _ideal(k, distortion, u, v)
    # The cover keeps the distorted image's sampling at its centre (same focal length) and spans every ray.
    fx, fy = k.fx, k.fy
    x0, x1, y0, y1 = float(x.min()), float(x.max()), float(y.min()), float(y.max())
    width = int(np.ceil((x1 - x0) * fx)) + 2 * COVER_MARGIN_PX
    height = int(np.ceil((y1 - y0) * fy)) + 2 * COVER_MARGIN_PX
    cx, cy = -x0 * fx + COVER_MARGIN_PX, -y0 * fy + COVER_MARGIN_PX
    cover = Intrinsics(width, height, fx, fy, cx, cy)
    # Continuous cover-image coordinates of each distorted pixel centre, minus 0.5: OpenCV's remap convention.
    map_u = (fx * x + cx - 0.5).astype(np.float32)
    map_v = (fy * y + cy - 0.5).astype(np.float32)
    map_u.setflags(write=False)
    map_v.setflags(write=False)
    return cover, map_u, map_v


def cover_camera(camera: PinholeCamera) -> PinholeCamera:
    """The pinhole camera (same pose) whose image holds every ray of ``camera``'s distorted image."""
    cover, _, _ = _cover(camera.intrinsics, camera.distortion)
    return PinholeCamera(cover, camera.T_world_camera, camera.near)


def cover_maps(camera: PinholeCamera) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) float32 each: where each pixel of ``camera``'s distorted image samples ``cover_camera``'s image
    (OpenCV ``remap`` coordinates: pixel centres at integers)."""
    _, map_u, map_v = _cover(camera.intrinsics, camera.distortion)
    return map_u, map_v
