"""Worn lane paint: markings on failing pavement lose their paint in flakes and chips (raveling), so the line
fades and breaks up where the asphalt under it cracks."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ._canvas import Texture, _Canvas, _child, _children, _smooth_random

WEAR_BAND_M = 0.5  # across a line: wide enough for a double line (2 x 0.12 m and its gap) and some wander
CHIP_M = 1.2  # along a line: the scale over which the paint's loss comes and goes


def worn_paint(rng: np.random.Generator, shape: tuple[int, int], texel: float, t_local: Sequence[float],
               wear: float, asphalt_rgb: Sequence[float]) -> Texture:
    """Bare asphalt (``asphalt_rgb``, the road's own) laid over the paint of the lines at ``t_local`` (m): an
    over-paint layer.

    ``wear`` in [0, 1] is the mean share of the paint gone: the loss varies along the line over about ``CHIP_M``
    (long flaked stretches next to nearly intact ones) and texel by texel (grain), so a worn line reads as
    faded and broken, not as a line drawn in grey.

    Returns:
        rgba (h, w, 4) float32, wet None.
    """
    base = _children(rng)[0]
    rows, cols = shape
    cover = np.zeros(shape, np.float32)
    half_band = int(np.ceil(0.5 * WEAR_BAND_M / texel))
    for k, t in enumerate(t_local):
        child = _child(base, k)
        centre = int(t / texel)
        lo, hi = max(centre - half_band, 0), min(centre + half_band + 1, cols)
        if hi <= lo:
            continue
        along = _smooth_random(child, rows, max(int(rows * texel / CHIP_M), 2), 0.0, 2.0)
        grain = child.random((rows, hi - lo))
        cover[:, lo:hi] = np.clip(wear * along[:, None] + 0.8 * (grain - 0.5), 0.0, 1.0)
    canvas = _Canvas.empty(shape)
    canvas.paint(asphalt_rgb, cover)
    return canvas.rgba(), None
