"""Image encoders: pixels to file bytes with no metadata: the same pixels give the same bytes."""

from __future__ import annotations

import io
import zlib
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any, Final

import numpy as np
from PIL import Image

from .typed import UInt8Array

# Pillow's PNG options: zlib's RLE strategy (runs of one byte; the level then makes no difference) after Pillow's
# adaptive row filters. On six stock 1280x720 frames (bench/png_levels.py, all settings side by side in one run) it
# encodes in 0.34x the time of zlib level 6 (the default) for files 1.10x as large; level 1 takes as long for 1.31x,
# level 4 takes 0.49x for 1.09x, and levels 8-9 save 6-8 % of the size for 5-9x the time. OpenCV's fixed "sub"
# filter with RLE is faster still (0.19x) but 1.19x as large, and would tie the bytes to a second library's build.
PNG_SAVE_OPTIONS: Final[Mapping[str, int]] = MappingProxyType({"compress_level": 1, "compress_type": zlib.Z_RLE})


def png_bytes(rgb: UInt8Array) -> bytes:
    """PNG encoding (``PNG_SAVE_OPTIONS``) of an (H, W, 3) uint8 image, with no metadata (same pixels -> same
    bytes)."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), "RGB").save(buffer, format="PNG", **PNG_SAVE_OPTIONS)
    return buffer.getvalue()


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
