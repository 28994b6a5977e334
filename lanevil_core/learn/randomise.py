"""Train-time domain randomisation: strong photometric changes and image-space randomisation of everything that
is not lane paint, so a detector learns the paint's shape rather than our renderer's colours and textures.

Each function is pure: an image ``(H, W, 3)`` uint8 at the network's input size and a numpy ``Generator`` (drawn
per seed, epoch and sample by ``learn.data``), and returns a new image; the labels never change. Two ingredients,
switched on apart so each can be measured (``lanevil train --photometric`` / ``--randomise``):

- ``photometric``: what different cameras and light do to one scene: brightness, contrast, saturation, hue and
  white-balance jitter, gamma, blur (defocus or motion), sensor noise (shot and read), JPEG at a random quality and
  random erasing. Always the same number of draws.
- ``randomise``: what different worlds do: the paint mask comes from the labels (``paint_mask``: each lane drawn at
  the width of a road marking, 15 cm of a 3.6 m lane, widened by ``PAINT_MARGIN``); the whole image is re-coloured
  by a smooth random colour field and mixed with a random procedural texture (value noise, stripes or blotches),
  and inside the mask the paint's detail over its blurred road is added back on the new road (``recolour``);
  then random cast shadows and light pools (soft polygons, across the paint too), and random occluders and
  distractors (boxes of vehicle-like size, kerb-like and crack-like strokes) that are not lanes.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..detect.lane_slots import LaneLine
from ..typed import UInt8Array

PAINT_TO_LANE = 0.15 / 3.6  # a marking's width over a lane's width
PAINT_MARGIN = 1.6  # the kept area is this many times the marking's width
DEFAULT_SPACING = 0.35  # a lane's width at the bottom row over the image width, where one lane alone is labelled
PHOTOMETRIC_DRAWS = 24
PAINT_BLUR = 9  # box filter (pixels at the input size) wide enough to take the paint out of the road around it


def _value_noise(rng: np.random.Generator, shape: tuple[int, int], cells: int, channels: int) -> np.ndarray:
    """(H, W, channels) float32 in [0, 1]: a ``cells``-wide random grid smoothly upsampled."""
    height, width = shape
    rows = max(2, int(round(cells * height / width)))
    grid = rng.random((rows, cells, channels)).astype(np.float32)
    field = cv2.resize(grid, (width, height), interpolation=cv2.INTER_CUBIC)
    return np.clip(field.reshape(height, width, channels), 0.0, 1.0)


def photometric(image: UInt8Array, rng: np.random.Generator) -> UInt8Array:
    """The image as another camera in other light would take it (``PHOTOMETRIC_DRAWS`` uniform draws)."""
    u = rng.random(PHOTOMETRIC_DRAWS)
    x = image.astype(np.float32) / 255.0
    gains = 0.8 + 0.4 * u[0:3]  # white balance
    x = x * gains * (0.55 + 0.9 * u[3])  # exposure
    grey = x.mean(axis=2, keepdims=True)
    x = grey + (x - grey) * (1.6 * u[4])  # saturation 0 (grey) .. 1.6
    mean = float(x.mean())
    x = mean + (x - mean) * (0.6 + 0.8 * u[5])  # contrast
    x = np.clip(x, 0.0, 1.0) ** (0.6 + 1.0 * u[6])  # gamma
    out = np.clip(x * 255.0 + 0.5, 0, 255).astype(np.uint8)
    if u[7] < 0.5:  # hue
        hsv = cv2.cvtColor(out, cv2.COLOR_RGB2HSV)
        hsv[..., 0] = ((hsv[..., 0].astype(np.int32) + int(round(16 * (u[8] - 0.5)))) % 180).astype(np.uint8)
        out = cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB)
    if u[9] < 0.3:  # defocus
        out = cv2.GaussianBlur(out, (0, 0), 0.3 + 1.2 * u[10])
    elif u[9] < 0.45:  # motion
        length = 3 + int(6 * u[10])
        streak = np.zeros((length, length), np.float32)
        streak[length // 2, :] = 1.0 / length
        rotation = cv2.getRotationMatrix2D(((length - 1) / 2, (length - 1) / 2), 180 * u[11], 1.0)
        kernel = np.asarray(cv2.warpAffine(streak, rotation, (length, length)), np.float32)
        out = cv2.filter2D(out, -1, kernel / max(float(kernel.sum()), 1e-6))
    if u[12] < 0.6:  # shot (signal-dependent) and read noise
        noise_rng = np.random.default_rng(int(u[13] * 2**31))
        level = out.astype(np.float32)
        sigma = np.sqrt(level * (0.05 + 0.5 * u[14]) + (1.0 + 8.0 * u[15]) ** 2)
        out = np.clip(level + noise_rng.standard_normal(out.shape).astype(np.float32) * sigma, 0, 255).astype(np.uint8)
    if u[16] < 0.4:  # compression
        ok, encoded = cv2.imencode(".jpg", out[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, int(15 + 75 * u[17])])
        decoded = cv2.imdecode(encoded, cv2.IMREAD_COLOR) if ok else None
        if decoded is not None:
            out = np.ascontiguousarray(decoded[..., ::-1])
    if u[18] < 0.3:  # random erasing
        height, width = out.shape[:2]
        h = max(1, int(height * (0.08 + 0.25 * u[19])))
        w = max(1, int(width * (0.08 + 0.25 * u[20])))
        y0 = int((height - h) * u[21])
        x0 = int((width - w) * u[22])
        out = out.copy()
        out[y0:y0 + h, x0:x0 + w] = np.uint8(255 * u[23])
    return np.ascontiguousarray(out, dtype=np.uint8)


def paint_mask(lines: list[LaneLine], size: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: where the labelled lanes' paint lies at an image of ``size`` (width, height), each lane drawn
    at ``PAINT_TO_LANE`` of the local lane spacing (the next labelled lane's distance, or ``DEFAULT_SPACING``
    scaled by the row's depth below the lanes' top), widened by ``PAINT_MARGIN``."""
    width, height = size
    mask = np.zeros((height, width), np.uint8)
    if not lines:
        return mask.astype(bool)
    top = min(float(line.points[:, 1].min()) for line in lines)
    rows = np.linspace(0.0, 1.0, max(8, height // 4))
    xs = np.stack([line.x_at(rows) for line in lines])  # (lanes, rows), NaN off a lane
    for index in range(len(lines)):
        spacing = np.full(len(rows), np.nan)
        others = np.delete(xs, index, axis=0)
        if len(others):
            gaps = np.abs(others - xs[index])
            spacing = np.nanmin(np.where(np.isnan(gaps), np.inf, gaps), axis=0)
            spacing[~np.isfinite(spacing)] = np.nan
        depth = np.clip((rows - top) / max(1.0 - top, 1e-6), 0.0, 1.0)
        spacing = np.where(np.isnan(spacing), DEFAULT_SPACING * depth, spacing)
        for k in range(len(rows) - 1):
            x0, x1 = xs[index, k], xs[index, k + 1]
            if np.isnan(x0) or np.isnan(x1):
                continue
            thickness = max(1, int(round(PAINT_MARGIN * PAINT_TO_LANE * spacing[k + 1] * width)))
            cv2.line(mask, (int(round(x0 * width)), int(round(rows[k] * height))),
                     (int(round(x1 * width)), int(round(rows[k + 1] * height))), 1, thickness)
    return mask.astype(bool)


def _texture(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """(H, W, 3) float32 in [0, 1]: one of value noise, stripes or blotches in random colours."""
    kind = int(rng.integers(3))
    a, b = rng.random(3).astype(np.float32), rng.random(3).astype(np.float32)
    height, width = shape
    if kind == 0:
        t = _value_noise(rng, shape, int(rng.integers(8, 64)), 1)
    elif kind == 1:
        angle, period = rng.uniform(0, np.pi), rng.uniform(4, 40)
        yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
        t = (0.5 + 0.5 * np.sin((xx * np.cos(angle) + yy * np.sin(angle)) * 2 * np.pi / period))[..., None]
    else:
        t = (_value_noise(rng, shape, int(rng.integers(4, 16)), 1) > rng.uniform(0.4, 0.6)).astype(np.float32)
        t = cv2.GaussianBlur(t, (0, 0), 1.5)[..., None]
    return a * t + b * (1.0 - t)


def _soft_polygon(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) float32 in [0, 1]: a random convex-ish polygon with a soft edge (a shadow or a light pool)."""
    height, width = shape
    centre = rng.uniform((0, height * 0.3), (width, height))
    radius = rng.uniform(0.1, 0.5) * width
    angles = np.sort(rng.uniform(0, 2 * np.pi, int(rng.integers(3, 8))))
    points = centre + np.stack([np.cos(angles), np.sin(angles) * 0.5], axis=1) * radius * rng.uniform(0.5, 1.0,
                                                                                                     (len(angles), 1))
    mask = np.zeros(shape, np.float32)
    cv2.fillPoly(mask, [np.round(points).astype(np.int32)], 1.0)
    return np.asarray(cv2.GaussianBlur(mask, (0, 0), rng.uniform(0.5, 4.0)), np.float32)


def _distractors(rng: np.random.Generator, image: np.ndarray) -> None:
    """Occluders (vehicle-sized boxes on the lower half) and strokes that are not lanes, drawn in place."""
    height, width = image.shape[:2]
    for _ in range(int(rng.integers(0, 3))):  # occluders
        w = int(width * rng.uniform(0.08, 0.3))
        h = int(w * rng.uniform(0.5, 1.0))
        x0 = int(rng.integers(0, max(1, width - w)))
        y0 = int(rng.uniform(0.45, 0.95) * height - h / 2)
        colour = rng.random(3) ** 1.5
        cv2.rectangle(image, (x0, y0), (x0 + w, y0 + h), colour.tolist(), -1)
        cv2.rectangle(image, (x0, y0 + h - max(1, h // 5)), (x0 + w, y0 + h), (colour * 0.2).tolist(), -1)
    for _ in range(int(rng.integers(0, 4))):  # kerb-, seam- and crack-like strokes
        points = [(float(rng.uniform(0, width)), float(rng.uniform(0.4, 1.0) * height))]
        for _ in range(int(rng.integers(1, 6))):
            x, y = points[-1]
            points.append((x + rng.normal(0, width * 0.08), y + rng.normal(0, height * 0.05)))
        polyline = np.round(np.array(points)).astype(np.int32)
        shade = float(rng.uniform(0.0, 1.0))
        cv2.polylines(image, [polyline], False, (shade, shade, shade), int(rng.integers(1, 4)))


def recolour(image: UInt8Array, keep: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) float32 in [0, 1]: ``image`` re-coloured by a smooth random colour field and mixed with a random
    texture; inside ``keep`` (``paint_mask``) the same is done to the image blurred past the paint, and the paint's
    own detail (the image less its blur) is added back, so the paint keeps its contrast on the new road and no seam
    marks the kept area."""
    height, width = image.shape[:2]
    x = image.astype(np.float32) / 255.0
    tint = 0.4 + 1.2 * _value_noise(rng, (height, width), int(rng.integers(2, 8)), 3)
    alpha = rng.uniform(0.0, 0.7)
    texture = _texture(rng, (height, width))

    def new_look(rgb: np.ndarray) -> np.ndarray:
        lightness = 0.5 + rgb.mean(axis=2, keepdims=True)
        return (1.0 - alpha) * np.clip(rgb * tint, 0.0, 1.0) + alpha * texture * lightness

    road = np.asarray(cv2.blur(x, (PAINT_BLUR, PAINT_BLUR)), np.float32)
    painted = new_look(road) + (x - road) * rng.uniform(0.7, 1.2)
    soft = np.asarray(cv2.GaussianBlur(keep.astype(np.float32), (0, 0), 1.0), np.float32)[..., None]
    out = soft * painted + (1.0 - soft) * new_look(x)
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def clutter(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Random cast shadows, a light pool, occluders and distractors over ``x`` ((H, W, 3) float32 in [0, 1])."""
    height, width = x.shape[:2]
    out = x.copy()
    for _ in range(int(rng.integers(0, 3))):  # cast shadows
        out *= 1.0 - rng.uniform(0.3, 0.75) * _soft_polygon(rng, (height, width))[..., None]
    if rng.random() < 0.3:  # a light pool or glare
        out += rng.uniform(0.2, 0.8) * _soft_polygon(rng, (height, width))[..., None] * rng.uniform(0.7, 1.0, 3)
    _distractors(rng, out)
    return out


def randomise(image: UInt8Array, keep: np.ndarray, rng: np.random.Generator) -> UInt8Array:
    """``image`` re-coloured outside the paint (``recolour``), then cluttered (``clutter``)."""
    out = clutter(recolour(image, keep, rng), rng)
    return np.clip(out * 255.0 + 0.5, 0, 255).astype(np.uint8)
