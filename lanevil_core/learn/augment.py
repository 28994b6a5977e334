"""Training-time image augmentations: the geometric flip every run uses and the defences ``--augment`` names.

Each augmentation is a pure function of an image (``(H, W, 3)`` uint8 at the network's input size), a numpy
``Generator`` and, where it mixes images, a second image; labels are never changed by any of them (the flip,
which moves the lanes, is applied to labels by the dataset). The paper's comparison baselines:

- ``cutout``: one to three random rectangles filled with grey.
- ``mixup``: ``x' = lam * x + (1 - lam) * x2`` with ``lam`` in [0.6, 1], keeping ``x``'s labels.
- ``hsv``: random hue shift, saturation and value scaling.
- ``copy_paste``: a random rectangle of another training image pasted at a random place.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from ..typed import UInt8Array

Augment = Callable[[UInt8Array, np.random.Generator, UInt8Array], UInt8Array]


def _box(rng: np.random.Generator, width: int, height: int, lo: float, hi: float) -> tuple[int, int, int, int]:
    w = int(width * rng.uniform(lo, hi))
    h = int(height * rng.uniform(lo, hi))
    x0 = int(rng.integers(0, width - w + 1))
    y0 = int(rng.integers(0, height - h + 1))
    return x0, y0, w, h


def cutout(image: UInt8Array, rng: np.random.Generator, other: UInt8Array) -> UInt8Array:
    out = image.copy()
    height, width = out.shape[:2]
    for _ in range(int(rng.integers(1, 4))):
        x0, y0, w, h = _box(rng, width, height, 0.1, 0.3)
        out[y0:y0 + h, x0:x0 + w] = 128
    return out


def mixup(image: UInt8Array, rng: np.random.Generator, other: UInt8Array) -> UInt8Array:
    lam = rng.uniform(0.6, 1.0)
    return np.clip(lam * image + (1.0 - lam) * other + 0.5, 0, 255).astype(np.uint8)


def hsv(image: UInt8Array, rng: np.random.Generator, other: UInt8Array) -> UInt8Array:
    hsv_image = cv2.cvtColor(image, cv2.COLOR_RGB2HSV).astype(np.float32)
    hsv_image[..., 0] = (hsv_image[..., 0] + rng.uniform(-10, 10)) % 180.0  # OpenCV hue is 0..180
    hsv_image[..., 1] *= rng.uniform(0.6, 1.4)
    hsv_image[..., 2] *= rng.uniform(0.6, 1.4)
    return np.asarray(cv2.cvtColor(np.clip(hsv_image, 0, 255).astype(np.uint8), cv2.COLOR_HSV2RGB), np.uint8)


def copy_paste(image: UInt8Array, rng: np.random.Generator, other: UInt8Array) -> UInt8Array:
    out = image.copy()
    height, width = out.shape[:2]
    x0, y0, w, h = _box(rng, width, height, 0.15, 0.4)
    x1 = int(rng.integers(0, width - w + 1))
    y1 = int(rng.integers(0, height - h + 1))
    out[y1:y1 + h, x1:x1 + w] = other[y0:y0 + h, x0:x0 + w]
    return out


AUGMENTS: dict[str, Augment | None] = {
    "none": None, "cutout": cutout, "mixup": mixup, "hsv": hsv, "copy_paste": copy_paste,
}
AUGMENT_PROBABILITY = 0.5  # share of training images an augmentation touches
