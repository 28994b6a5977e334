"""Stimulus images: checking uploads, scrambling gold items, writing the trap banner.

All functions are pure over ``(H, W, 3) uint8`` RGB arrays (pixel origin top-left); randomness comes only from
``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw, ImageFont, UnidentifiedImageError

from .spec import ACR_LABELS

UPLOAD_FORMATS: dict[str, tuple[str, str]] = {"PNG": ("image/png", ".png"), "JPEG": ("image/jpeg", ".jpg")}
GARBLE_TILES = 8  # tiles per side of the scrambled grid
BANNER_GRAY = (32, 32, 32)
OBJECT_REPR = re.compile(r"\s*<[^<>]* at 0x[0-9a-fA-F]+>")


class UploadError(ValueError):
    """An upload that is not a decodable PNG or JPEG image."""


@dataclass(frozen=True)
class CheckedUpload:
    """An uploaded image that decodes: its bytes, Pillow format name, media type and file suffix."""

    data: bytes
    format: str
    media_type: str
    suffix: str
    size: tuple[int, int]


def check_upload(data: bytes) -> CheckedUpload:
    """Decode ``data`` fully with Pillow; raise ``UploadError`` unless it is a PNG or JPEG image."""
    try:
        with Image.open(io.BytesIO(data)) as image:
            image_format = image.format or ""
            if image_format not in UPLOAD_FORMATS:
                raise UploadError(f"is a {image_format or 'unknown'} file; upload PNG or JPEG images")
            image.load()  # verify() misses truncated data; a full decode does not
            size = image.size
    except UploadError:
        raise
    except UnidentifiedImageError:
        raise UploadError("is not an image file; upload PNG or JPEG images") from None
    except Image.DecompressionBombError:
        raise UploadError(f"has more than {Image.MAX_IMAGE_PIXELS} pixels; upload a smaller image") from None
    except (OSError, SyntaxError, ValueError) as error:
        raise UploadError(f"does not decode as a PNG or JPEG image ({_reason(error)})") from None
    media_type, suffix = UPLOAD_FORMATS[image_format]
    return CheckedUpload(data, image_format, media_type, suffix, size)


def _reason(error: Exception) -> str:
    """Pillow's message without object reprs (``<_io.BytesIO object at 0x…>``), which mean nothing to a user."""
    return OBJECT_REPR.sub("", str(error)).strip(" :()") or type(error).__name__


def decode_rgb(data: bytes) -> np.ndarray:
    """(H, W, 3) uint8 RGB pixels of encoded image bytes."""
    with Image.open(io.BytesIO(data)) as image:
        return np.asarray(image.convert("RGB"), dtype=np.uint8)


def garble(rgb: np.ndarray, seed: int) -> np.ndarray:
    """An obviously broken version of ``rgb``: tiles shuffled, colour channels rotated, heavy noise.

    rgb: (H, W, 3) uint8 -> (H, W, 3) uint8 of the same shape."""
    rng = np.random.default_rng(seed)
    height, width = rgb.shape[:2]
    tile_h, tile_w = max(height // GARBLE_TILES, 1), max(width // GARBLE_TILES, 1)
    rows, cols = height // tile_h, width // tile_w
    out = rgb.copy()
    grid = rgb[: rows * tile_h, : cols * tile_w].reshape(rows, tile_h, cols, tile_w, 3).swapaxes(1, 2)
    tiles = grid.reshape(rows * cols, tile_h, tile_w, 3)[rng.permutation(rows * cols)]
    out[: rows * tile_h, : cols * tile_w] = (tiles.reshape(rows, cols, tile_h, tile_w, 3).swapaxes(1, 2)
                                             .reshape(rows * tile_h, cols * tile_w, 3))
    out = out[..., [2, 0, 1]].astype(np.int16) + rng.normal(0.0, 60.0, out.shape).astype(np.int16)
    return np.clip(out, 0, 255).astype(np.uint8)


def trap_banner(rgb: np.ndarray, answer: int) -> np.ndarray:
    """``rgb`` with a dark band across its middle saying which rating to give (the trapping question).

    rgb: (H, W, 3) uint8 -> (H, W, 3) uint8 of the same shape."""
    image = Image.fromarray(np.ascontiguousarray(rgb), "RGB")
    width, height = image.size
    lines = ["Attention check", f"Please rate this image {answer} ({ACR_LABELS[answer]})"]
    size = max(height // 12, 8)
    font = ImageFont.load_default(size=size)
    while size > 8 and ImageDraw.Draw(image).textlength(lines[1], font=font) > 0.9 * width:
        size -= 1
        font = ImageFont.load_default(size=size)
    band_h = int(size * 3.4)
    top = (height - band_h) // 2
    draw = ImageDraw.Draw(image)
    draw.rectangle([0, top, width, top + band_h], fill=BANNER_GRAY)
    for row, text in enumerate(lines):
        y_px = top + size * 0.5 + row * size * 1.4
        x_px = (width - draw.textlength(text, font=font)) / 2
        draw.text((x_px, y_px), text, fill=(245, 245, 245), font=font)
    return np.asarray(image, dtype=np.uint8)
