"""Report figures as PNG bytes; the image encoders live in ``lanevil_core.images`` (re-exported here)."""

from __future__ import annotations

import io
from typing import Any

from ..images import PNG_SIGNATURE, PNG_SUB_FILTER, PNG_ZLIB, jpeg_bytes, png_bytes

__all__ = ["PNG_SIGNATURE", "PNG_SUB_FILTER", "PNG_ZLIB", "figure_png", "jpeg_bytes", "png_bytes"]


def figure_png(fig: Any) -> bytes:
    """A matplotlib figure as PNG bytes without the "Software" stamp; the figure is closed."""
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata={"Software": None})
    plt.close(fig)
    return buffer.getvalue()
