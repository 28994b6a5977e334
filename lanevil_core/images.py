"""Pixels in and out: the sRGB transfer curve, image bytes by format, and image files read as RGB.

Encoders write no metadata, so the same pixels give the same bytes. Each caller of ``encode_image`` passes its JPEG
quality by name (``FILE_JPEG_QUALITY`` for the frames the command line and the dataset writer save).
"""

from __future__ import annotations

import io
import struct
import zlib
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Final, Literal

import cv2
import numpy as np
import numpy.typing as npt
from PIL import Image

from .typed import FloatArray, UInt8Array

ImageFormat = Literal["png", "jpg"]
IMAGE_FORMATS: tuple[ImageFormat, ...] = ("png", "jpg")
IMAGE_SUFFIXES: tuple[str, ...] = (".png", ".jpg", ".jpeg")  # image files read (``read_rgb``) and written
SUFFIX_FORMATS: Mapping[str, ImageFormat] = MappingProxyType({".png": "png", ".jpg": "jpg", ".jpeg": "jpg"})
FILE_JPEG_QUALITY: Final = 95  # frames saved by `lanevil render` and `lanevil dataset --format jpg`

PNG_SIGNATURE: Final = b"\x89PNG\r\n\x1a\n"
PNG_SUB_FILTER: Final = 1  # PNG row filter "Sub": each byte minus the same channel of the pixel to its left
# zlib's RLE strategy (runs of one byte) at level 1, after the Sub filter on every row. Measured on stock 1280x720
# frames (bench/png_levels.py, every setting side by side in one run): about half the time of Pillow with the same
# zlib strategy after its adaptive per-row filter choice, for files ~9 % larger; that was itself 0.34x the time of
# zlib level 6 (the usual default) for 1.10x the size. The bytes depend on the pixels and zlib's version alone
# (the dataset manifest records it).
PNG_ZLIB: Final[Mapping[str, int]] = MappingProxyType({"level": 1, "strategy": zlib.Z_RLE})

# The sRGB transfer curve (IEC 61966-2-1): a linear toe, then a 2.4 power.
_SRGB_LINEAR_LIMIT = 0.04045  # encoded value where the toe ends
_LINEAR_LIMIT = 0.0031308  # linear value where the toe ends
_TOE_SLOPE = 12.92
_GAMMA = 2.4


def srgb_to_linear(srgb: npt.ArrayLike) -> FloatArray:
    """Linear light of sRGB-encoded values in [0, 1], any shape (float64)."""
    c = np.asarray(srgb, np.float64)
    return np.where(c <= _SRGB_LINEAR_LIMIT, c / _TOE_SLOPE, ((c + 0.055) / 1.055) ** _GAMMA)


def linear_to_srgb(linear: npt.ArrayLike) -> FloatArray:
    """sRGB-encoded values in [0, 1] of linear light (clipped to [0, 1] first), any shape (float64)."""
    y = np.clip(np.asarray(linear, np.float64), 0.0, 1.0)
    return np.where(y <= _LINEAR_LIMIT, _TOE_SLOPE * y, 1.055 * np.power(y, 1 / _GAMMA) - 0.055)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_bytes(rgb: UInt8Array) -> bytes:
    """PNG of an (H, W, 3) uint8 image: 8-bit RGB, every row Sub-filtered, one zlib stream (``PNG_ZLIB``), no
    metadata chunks (same pixels -> same bytes)."""
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    height, width, channels = rgb.shape
    if channels != 3:
        raise ValueError(f"png_bytes: expected (H, W, 3) RGB, got shape {rgb.shape}")
    flat = rgb.reshape(height, width * 3)
    rows = np.empty((height, width * 3 + 1), np.uint8)
    rows[:, 0] = PNG_SUB_FILTER
    rows[:, 1:4] = flat[:, :3]
    np.subtract(flat[:, 3:], flat[:, :-3], out=rows[:, 4:])  # uint8 arithmetic wraps modulo 256, as PNG's does
    compressor = zlib.compressobj(PNG_ZLIB["level"], zlib.DEFLATED, 15, 8, PNG_ZLIB["strategy"])
    data = compressor.compress(rows.data) + compressor.flush()
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8 bits, truecolour, deflate, no interlace
    return PNG_SIGNATURE + _chunk(b"IHDR", header) + _chunk(b"IDAT", data) + _chunk(b"IEND", b"")


def jpeg_bytes(rgb: UInt8Array, quality: int) -> bytes:
    """Baseline JPEG (4:2:0) of an (H, W, 3) uint8 image, with no metadata (same pixels -> same bytes)."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), "RGB").save(
        buffer, format="JPEG", quality=quality, subsampling=2, optimize=False)
    return buffer.getvalue()


def encode_image(rgb: UInt8Array, image_format: str, jpeg_quality: int) -> bytes:
    """``png_bytes`` or ``jpeg_bytes`` (at ``jpeg_quality``) of an (H, W, 3) uint8 image; ``ValueError`` for a
    format not in ``IMAGE_FORMATS``."""
    if image_format == "png":
        return png_bytes(rgb)
    if image_format == "jpg":
        return jpeg_bytes(rgb, jpeg_quality)
    raise ValueError(f"unknown image format {image_format!r} (choose from {', '.join(IMAGE_FORMATS)})")


def frame_files(folders: tuple[Path, ...], max_frames: int) -> list[Path]:
    """The image files under ``folders`` (sorted), thinned evenly to ``max_frames``."""
    files = sorted(path for folder in folders for path in folder.rglob("*")
                   if path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES)
    if len(files) > max_frames:
        files = [files[int(i)] for i in np.linspace(0, len(files) - 1, max_frames).round()]
    return files


def read_rgb(path: Path, error: type[Exception] = ValueError) -> UInt8Array:
    """(H, W, 3) uint8 RGB pixels of an image file (alpha dropped, grey expanded); an unreadable file raises
    ``error`` (the caller's own error type) with the path in its message."""
    bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if bgr is None:
        raise error(f"{path}: cannot read the image")
    return np.ascontiguousarray(bgr[..., ::-1])
