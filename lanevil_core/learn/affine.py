"""UFLD's geometric training augmentation (``lanevil train --affine``): a random rotation about the image centre and
a shift up or down and left or right, applied to the image and its lane lines together.

The published UFLD recipe rotates by up to 6 degrees and shifts by up to 100 px vertically and 200 px horizontally
on TuSimple's 1280x720 frames (``RandomRotate(6)``, ``RandomUDoffsetLABEL(100)``, ``RandomLROffsetLABEL(200)``);
here the shifts are the same shares of any frame. A row-anchor head that reads the whole frame through a fully
connected layer otherwise learns where lanes usually are (the training cameras' mount height, horizon and field of
view) instead of where the paint is; the shifts break that prior. The uncovered border is black, as there.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from ..detect.lane_slots import LaneLine
from ..typed import UInt8Array

ROTATION_DEG = 6.0
SHIFT_DOWN = 100.0 / 720.0  # share of the image height
SHIFT_ACROSS = 200.0 / 1280.0  # share of the image width
DRAWS = 3


def draw_affine(rng: np.random.Generator, size: tuple[int, int]) -> np.ndarray:
    """(2, 3) float64 map of continuous pixel coordinates (a pixel's centre at +0.5) of an image of ``size``
    (width, height) to the augmented image's, from ``DRAWS`` uniform draws of ``rng``."""
    width, height = size
    u = rng.uniform(-1.0, 1.0, DRAWS)
    angle = math.radians(ROTATION_DEG * u[0])
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s], [s, c]])
    centre = np.array([width / 2.0, height / 2.0])
    shift = np.array([SHIFT_ACROSS * width * u[1], SHIFT_DOWN * height * u[2]])
    return np.hstack([R, (centre - R @ centre + shift)[:, None]])


def warp_image(image: UInt8Array, M_out_in: np.ndarray) -> UInt8Array:
    """(H, W, 3) uint8 ``image`` moved by ``M_out_in`` (``draw_affine``), black where nothing maps."""
    height, width = image.shape[:2]
    # cv2 maps pixel indices (a centre at +0): p_index = p - 0.5 on both sides.
    M_index = M_out_in.copy()
    M_index[:, 2] += M_out_in[:, :2] @ np.array([0.5, 0.5]) - 0.5
    return np.asarray(cv2.warpAffine(image, M_index, (width, height), flags=cv2.INTER_LINEAR,
                                     borderMode=cv2.BORDER_CONSTANT, borderValue=(0, 0, 0)), np.uint8)


def warp_lines(lines: list[LaneLine], M_out_in: np.ndarray, size: tuple[int, int]) -> list[LaneLine]:
    """The lane lines (normalised coordinates) of the image ``warp_image`` makes: every point moved by
    ``M_out_in`` in pixels of ``size``, the points left above or below the image dropped, top to bottom; a line
    with fewer than 2 points left is gone."""
    width, height = size
    scale = np.array([width, height], np.float64)
    warped = []
    for line in lines:
        p_in = line.points * scale
        p_out = (p_in @ M_out_in[:, :2].T + M_out_in[:, 2]) / scale
        p_out = p_out[(p_out[:, 1] >= 0.0) & (p_out[:, 1] <= 1.0)]
        if len(p_out) >= 2:
            warped.append(LaneLine(p_out[np.argsort(p_out[:, 1], kind="stable")]))
    return warped


def ego_column(M_out_in: np.ndarray, size: tuple[int, int]) -> float:
    """x_norm of the bottom middle of the image (where the ego's lane starts, ``lane_slots.assign_slots``'s
    ``camera_x``) after ``M_out_in``: the lanes keep their places left and right of the ego."""
    width, height = size
    return float((M_out_in[0, :2] @ np.array([width / 2.0, float(height)]) + M_out_in[0, 2]) / width)
