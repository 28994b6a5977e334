"""Lens distortion: OpenCV's Brown-Conrady model (k1, k2, p1, p2, k3) on normalised image coordinates.

A distorted camera renders through a pinhole ``cover`` camera that sees every ray of the distorted image, then
resamples it (``undistort_maps``); labels go through ``distort``, the same model, so they stay on the paint.
"""

from __future__ import annotations

import numpy as np

from ..case import LENS_VALID_MARGIN as VALID_MARGIN
from ..case import lens_covers as covers  # noqa: F401  # which lenses a case may hold: the case model's check
from ..typed import FloatArray

Distortion = tuple[float, float, float, float, float]
NO_DISTORTION: Distortion = (0.0, 0.0, 0.0, 0.0, 0.0)
UNDISTORT_ITERATIONS = 20


def is_pinhole(distortion: Distortion) -> bool:
    """Whether every coefficient is zero."""
    return not any(distortion)


def distort(x: FloatArray, y: FloatArray, distortion: Distortion) -> tuple[FloatArray, FloatArray]:
    """Ideal normalised coordinates (x, y) (any shape) to distorted normalised coordinates."""
    k1, k2, p1, p2, k3 = distortion
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    x_d = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    y_d = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    return x_d, y_d


def valid_radius2(distortion: Distortion, corner_r2: float) -> float:
    """Largest squared ideal radius the lens model may map: a margin past the image's corners (``corner_r2``), and
    never past the radius where the polynomial turns back (beyond it, points far outside the view would fold
    back into the image)."""
    k1, k2, _, _, k3 = distortion
    r2 = np.linspace(0.0, 4.0 * max(corner_r2, 1e-6), 4001)
    slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2**2 + 7.0 * k3 * r2**3  # d(r * radial(r)) / dr
    turning = r2[np.argmax(slope <= 0.05)] if np.any(slope <= 0.05) else np.inf
    return float(min(VALID_MARGIN**2 * corner_r2, turning))


def undistort(x_d: FloatArray, y_d: FloatArray, distortion: Distortion) -> tuple[FloatArray, FloatArray]:
    """Distorted normalised coordinates back to ideal ones (fixed-point iteration, as OpenCV's
    ``undistortPoints``; converges for the mild lenses the case model allows)."""
    k1, k2, p1, p2, k3 = distortion
    x, y = np.array(x_d, np.float64), np.array(y_d, np.float64)
    for _ in range(UNDISTORT_ITERATIONS):
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        dx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
        dy = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
        x, y = (x_d - dx) / radial, (y_d - dy) / radial
    return x, y
