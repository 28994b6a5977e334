"""What building walls and windows are made of: the finishes the renderer draws per pixel, their palettes.

A face's finish (``Mesh.finish``, an index into ``FINISHES``) tells the renderer which structure to draw over its
albedo in facade coordinates (``Mesh.uv``, metres: along the wall and up it, or across a pane from its centre and up
from its foot): brick courses and mortar, soft stains and streaks of a rendered (plastered) wall, the joints of
precast concrete panels, the frame bars of a window and the Fresnel mirror of glass (``render/shading.py``
``facade``). Structure smaller than a pixel is box-filtered over the pixel's footprint, so it fades to the
material's mean colour at distance.

Colours are linear albedo, chosen calmer than saturated primaries: measured facades lie between about 0.1 (dark
brick) and 0.55 (white render); a drawn jitter per building keeps a street from repeating one colour.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..typed import FloatArray

Finish = Literal["plain", "brick", "render", "panels", "tiles", "leaves", "glass", "shop_glass"]
FINISHES: tuple[Finish, ...] = ("plain", "brick", "render", "panels", "tiles", "leaves", "glass", "shop_glass")
PLAIN, BRICK, RENDER, PANELS, TILES, LEAVES, GLASS, SHOP_GLASS = range(len(FINISHES))  # the glass finishes last
# ``TILES`` is a pitched roof's covering (u along the eaves, v up the slope from them). ``LEAVES`` is not a building
# at all: it marks the faces of a crown, hedge or forest edge, which the renderer lights as a volume of leaves
# (``render/foliage.py``) and draws no structure over.

PANE_HEIGHT_M = 1.6  # a window pane's height; its transom bar lies TRANSOM_M above its foot
TRANSOM_M = 1.12

# Wall colours by finish (linear albedo): red, brown, buff and blue-grey engineering brick; white, cream, pale ochre,
# pale pink and light grey render; pale and darker grey precast concrete.
BRICK_COLORS = ((0.26, 0.095, 0.055), (0.20, 0.085, 0.05), (0.32, 0.22, 0.13), (0.15, 0.10, 0.08),
                (0.30, 0.13, 0.075))
RENDER_COLORS = ((0.55, 0.53, 0.48), (0.50, 0.44, 0.33), (0.46, 0.36, 0.22), (0.50, 0.40, 0.36),
                 (0.40, 0.40, 0.39))
PANEL_COLORS = ((0.36, 0.35, 0.33), (0.27, 0.27, 0.27), (0.42, 0.40, 0.36))
WALL_FINISHES = (BRICK, RENDER, PANELS)
WALL_SHARES = (0.4, 0.4, 0.2)  # of urban blocks; houses are brick or render
COLOR_JITTER = 0.08  # each building's wall colour differs from its palette entry by up to this share

# Shops: the fascia (sign band) over the window in a trade's colour, the awning cloth.
FASCIA_COLORS = ((0.02, 0.12, 0.06), (0.20, 0.02, 0.03), (0.02, 0.04, 0.16), (0.02, 0.02, 0.02),
                 (0.50, 0.48, 0.43), (0.32, 0.14, 0.03))
AWNING_COLORS = ((0.35, 0.03, 0.02), (0.03, 0.15, 0.05), (0.03, 0.05, 0.2), (0.5, 0.45, 0.35))
SHOP_AWNING_SHARE = 0.5
BALCONY_SHARE = 0.5  # of the residential blocks (those without shops), balconies on every other window column


def wall_finish(rng: np.random.Generator, choices: tuple[int, ...] = WALL_FINISHES,
                shares: tuple[float, ...] = WALL_SHARES) -> tuple[int, FloatArray]:
    """(finish, (3,) linear albedo) of one building's walls, drawn from ``choices`` in ``shares``."""
    p = np.asarray(shares, np.float64)
    finish = int(choices[int(rng.choice(len(choices), p=p / p.sum()))])
    palette = {BRICK: BRICK_COLORS, RENDER: RENDER_COLORS, PANELS: PANEL_COLORS}[finish]
    color = np.asarray(palette[int(rng.integers(len(palette)))], np.float64)
    return finish, color * (1.0 + COLOR_JITTER * rng.uniform(-1.0, 1.0))
