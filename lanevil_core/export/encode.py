"""Image encoders: pixels to file bytes with no metadata: the same pixels give the same bytes."""

from __future__ import annotations

import io
import struct
import zlib
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any, Final

import numpy as np
from PIL import Image

from ..typed import UInt8Array

PNG_SIGNATURE: Final = b"\x89PNG\r\n\x1a\n"
PNG_SUB_FILTER: Final = 1  # PNG row filter "Sub": each byte minus the same channel of the pixel to its left
# zlib's RLE strategy (runs of one byte) at level 1, after the Sub filter on every row. Measured on stock 1280x720
# frames (bench/png_levels.py, every setting side by side in one run): about half the time of Pillow with the same
# zlib strategy after its adaptive per-row filter choice, for files ~9 % larger; that was itself 0.34x the time of
# zlib level 6 (the usual default) for 1.10x the size. The bytes depend on the pixels and zlib's version alone
# (the dataset manifest records it).
PNG_ZLIB: Final[Mapping[str, int]] = MappingProxyType({"level": 1, "strategy": zlib.Z_RLE})


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


def figure_png(fig: Any) -> bytes:
    """A matplotlib figure as PNG bytes without the "Software" stamp; the figure is closed."""
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata={"Software": None})
    plt.close(fig)
    return buffer.getvalue()
