"""Image encoders: pixels to file bytes with no metadata: the same pixels give the same bytes."""

from __future__ import annotations

import io
from typing import Any

import numpy as np
from PIL import Image

from .typed import UInt8Array


def png_bytes(rgb: UInt8Array) -> bytes:
    """PNG encoding of an (H, W, 3) uint8 image, with no metadata (same pixels -> same bytes)."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), "RGB").save(buffer, format="PNG", compress_level=6)
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
