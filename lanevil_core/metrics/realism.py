"""Image statistics that tell a rendered frame from a real dash-cam frame (``lanevil realism``).

Every statistic is a small function of one image at the common analysis size: the image is resized to
``ANALYSIS_WIDTH`` (1280) pixels wide keeping its aspect, so a 16:9 frame is analysed at 1280x720 whatever size it
was captured or rendered at (``INTER_AREA`` when shrinking, ``INTER_LINEAR`` when enlarging; enlarging softens
noise and edges, so compare footage of at least 1280 px width where you can). Grey is OpenCV's
``COLOR_RGB2GRAY`` (0.299 R + 0.587 G + 0.114 B) as uint8.

| statistic | method | unit |
|---|---|---|
| saturation | mean of OpenCV's HSV S channel (uint8 image) | 0..255 |
| edge_density | share of Canny edge pixels (thresholds 100/200) on the grey image | 0..1 |
| contrast | RMS contrast: standard deviation of grey / 255 | 0..0.5 |
| noise | sensor noise sigma, Immerkær's fast estimate over the flattest 90 % of pixels | grey levels |
| spectrum_slope | slope of log power vs log frequency (radial mean, Hann window, 0.02..0.2 cycles/px) | ≈ -2 natural |
| sharpness | variance of the 3x3 Laplacian of grey | grey levels² |
| brightness | mean grey | 0..255 |
| clipped | share of grey pixels >= 250 or <= 5 | 0..1 |
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import cv2
import numpy as np

from .. import images
from ..images import IMAGE_SUFFIXES
from ..typed import FloatArray, UInt8Array

ANALYSIS_WIDTH = 1280

CANNY_LOW, CANNY_HIGH = 100, 200
NOISE_FLAT_SHARE = 0.9  # Immerkær's estimate over the pixels whose Sobel gradient is below this quantile
SPECTRUM_BAND = (0.02, 0.2)  # cycles/pixel: above the frame's layout, below demosaicing and JPEG blocks
SPECTRUM_BINS = 24  # log-spaced frequency bins in the band, so the fit weighs every octave alike
CLIP_LOW, CLIP_HIGH = 5, 250


class RealismError(ValueError):
    """A folder or image that cannot be analysed; the message names it."""


@dataclass(frozen=True)
class FrameStatistics:
    """The statistics of one image (see the module table for each method and unit)."""

    saturation: float
    edge_density: float
    contrast: float
    noise: float
    spectrum_slope: float
    sharpness: float
    brightness: float
    clipped: float


STATISTICS: tuple[str, ...] = tuple(field.name for field in fields(FrameStatistics))


@dataclass(frozen=True)
class StatisticSummary:
    """Mean, median and (population) standard deviation of one statistic over a set of images."""

    mean: float
    median: float
    std: float


# ---------------------------------------------------------------------------------------------- preparation

def analysis_image(rgb: UInt8Array) -> UInt8Array:
    """(H, W, 3) uint8 RGB -> (round(H * 1280 / W), 1280, 3) uint8 RGB, the size every statistic is taken at."""
    height, width = rgb.shape[:2]
    if width == ANALYSIS_WIDTH:
        return rgb
    size = (ANALYSIS_WIDTH, max(1, round(height * ANALYSIS_WIDTH / width)))
    interpolation = cv2.INTER_AREA if width > ANALYSIS_WIDTH else cv2.INTER_LINEAR
    return np.asarray(cv2.resize(rgb, size, interpolation=interpolation), np.uint8)


def grey_image(rgb: UInt8Array) -> UInt8Array:
    """(H, W, 3) uint8 RGB -> (H, W) uint8 luma (OpenCV's RGB2GRAY weights)."""
    return np.asarray(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY), np.uint8)


# ---------------------------------------------------------------------------------------------- statistics

def colour_saturation(rgb: UInt8Array) -> float:
    """Mean S of OpenCV's 8-bit HSV (0 grey .. 255 pure colour) of (H, W, 3) uint8 RGB."""
    return float(cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV)[..., 1].mean())


def edge_density(grey: UInt8Array) -> float:
    """Share of pixels of (H, W) uint8 grey that Canny (100/200) marks as edges (no blur first: the figures of
    real footage we compare with are taken so)."""
    return float(np.count_nonzero(cv2.Canny(grey, CANNY_LOW, CANNY_HIGH))) / grey.size


def rms_contrast(grey: UInt8Array) -> float:
    """Standard deviation of (H, W) uint8 grey scaled to [0, 1]."""
    return float(np.std(grey.astype(np.float64))) / 255.0


def noise_sigma(grey: UInt8Array) -> float:
    """Sensor noise sigma (grey levels) of (H, W) uint8 grey by Immerkær's fast noise estimation (1996).

    The image is filtered with the difference of two Laplacians ``[[1, -2, 1], [-2, 4, -2], [1, -2, 1]]``, which
    cancels smooth shading; for white Gaussian noise ``sigma = sqrt(pi / 2) / 6 * mean |residual|``. Texture and
    edges also leave a residual, so the mean is taken over the flattest pixels only: those whose Sobel gradient
    magnitude is below its 90 % quantile (border pixels excluded).
    """
    image = grey.astype(np.float64)
    kernel = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float64)
    residual = np.abs(cv2.filter2D(image, cv2.CV_64F, kernel))[1:-1, 1:-1]
    gradient = np.hypot(cv2.Sobel(image, cv2.CV_64F, 1, 0), cv2.Sobel(image, cv2.CV_64F, 0, 1))[1:-1, 1:-1]
    flat = gradient <= np.quantile(gradient, NOISE_FLAT_SHARE)
    return float(math.sqrt(math.pi / 2.0) / 6.0 * residual[flat].mean())


def radial_power_spectrum(grey: UInt8Array) -> tuple[FloatArray, FloatArray]:
    """(frequencies (B,) float64 cycles/pixel, mean power (B,) float64) of (H, W) uint8 grey in ``SPECTRUM_BINS``
    log-spaced bins over ``SPECTRUM_BAND``; the mean is removed and a 2D Hann window applied first (empty bins are
    left out)."""
    height, width = grey.shape
    image = grey.astype(np.float64)
    window = np.outer(np.hanning(height), np.hanning(width))
    power = np.abs(np.fft.fft2((image - image.mean()) * window)) ** 2
    radius = np.hypot(*np.meshgrid(np.fft.fftfreq(height), np.fft.fftfreq(width), indexing="ij"))
    edges = np.geomspace(*SPECTRUM_BAND, SPECTRUM_BINS + 1)
    index = np.digitize(radius.ravel(), edges) - 1
    inside = (index >= 0) & (index < SPECTRUM_BINS)
    counts = np.bincount(index[inside], minlength=SPECTRUM_BINS)
    sums = np.bincount(index[inside], weights=power.ravel()[inside], minlength=SPECTRUM_BINS)
    filled = counts > 0
    centres = np.sqrt(edges[:-1] * edges[1:])
    return centres[filled], sums[filled] / counts[filled]


def spectrum_slope(grey: UInt8Array) -> float:
    """Least-squares slope of log10 power vs log10 frequency over ``SPECTRUM_BAND`` of (H, W) uint8 grey.

    Natural images fall close to -2 (amplitude ~ 1/f); a steeper (more negative) slope means less fine detail,
    a flatter one more fine detail or noise. A flat image (no power) gives 0.
    """
    frequencies, power = radial_power_spectrum(grey)
    if len(power) < 2 or not np.all(power > 0):
        return 0.0
    slope, _ = np.polyfit(np.log10(frequencies), np.log10(power), 1)
    return float(slope)


def sharpness(grey: UInt8Array) -> float:
    """Variance of the 3x3 Laplacian (``cv2.Laplacian``, aperture 1) of (H, W) uint8 grey, in grey levels²."""
    return float(cv2.Laplacian(grey.astype(np.float64), cv2.CV_64F).var())


def brightness(grey: UInt8Array) -> float:
    """Mean of (H, W) uint8 grey, 0..255."""
    return float(grey.mean())


def clipped_share(grey: UInt8Array) -> float:
    """Share of (H, W) uint8 grey pixels at or beyond the ends of the range (>= 250 or <= 5)."""
    return float(np.count_nonzero((grey >= CLIP_HIGH) | (grey <= CLIP_LOW))) / grey.size


def frame_statistics(rgb: UInt8Array) -> FrameStatistics:
    """Every statistic of (H, W, 3) uint8 RGB, taken at the analysis size (``analysis_image``)."""
    rgb = analysis_image(np.ascontiguousarray(rgb, np.uint8))
    grey = grey_image(rgb)
    return FrameStatistics(saturation=colour_saturation(rgb), edge_density=edge_density(grey),
                           contrast=rms_contrast(grey), noise=noise_sigma(grey), spectrum_slope=spectrum_slope(grey),
                           sharpness=sharpness(grey), brightness=brightness(grey), clipped=clipped_share(grey))


# ---------------------------------------------------------------------------------------------- folders

def image_files(root: str | Path, limit: int | None = None) -> list[Path]:
    """The png/jpg/jpeg files under ``root`` (recursive, any case of suffix), sorted by relative path; the first
    ``limit`` of them when given. Raises ``RealismError`` for a missing folder or one without images."""
    root = Path(root)
    if not root.is_dir():
        raise RealismError(f"{root}: no such folder")
    found = sorted((path for path in root.rglob("*") if path.suffix.lower() in IMAGE_SUFFIXES and path.is_file()),
                   key=lambda path: path.relative_to(root).as_posix())
    if not found:
        raise RealismError(f"{root}: no {'/'.join(suffix[1:] for suffix in IMAGE_SUFFIXES)} images")
    return found[:limit] if limit is not None else found


def read_rgb(path: Path) -> UInt8Array:
    """(H, W, 3) uint8 RGB pixels of an image file (``images.read_rgb``); a ``RealismError`` if unreadable."""
    return images.read_rgb(path, error=RealismError)


def folder_statistics(root: str | Path, limit: int | None = None) -> list[FrameStatistics]:
    """``frame_statistics`` of every image of ``image_files(root, limit)``, in that order."""
    return [frame_statistics(read_rgb(path)) for path in image_files(root, limit)]


def summary(statistics: Sequence[FrameStatistics]) -> dict[str, StatisticSummary]:
    """Per statistic (``STATISTICS`` order): mean, median and std over the images."""
    if not statistics:
        raise RealismError("no images to summarize")
    table = np.array([[getattr(frame, name) for name in STATISTICS] for frame in statistics], np.float64)
    return {name: StatisticSummary(float(np.mean(column)), float(np.median(column)), float(np.std(column)))
            for name, column in zip(STATISTICS, table.T, strict=True)}


def summary_dict(summaries: dict[str, StatisticSummary]) -> dict[str, dict[str, float]]:
    """``summary`` as JSON-ready nested dicts."""
    return {name: asdict(value) for name, value in summaries.items()}
