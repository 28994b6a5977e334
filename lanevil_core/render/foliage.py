"""How the sun lights a crown, a hedge or a forest edge: a volume of leaves, not a painted shell (numba, inlined).

A crown's faces stand for the outline of thousands of leaves facing every way, so shading them as one flat
surface each (Lambert's n.l) draws a dark, faceted blob: half of every tree in shade, black where the sun is
behind it. Two things a photograph of a tree shows instead:

- **Lit beyond the outline's terminator.** Leaves near the rim of a crown face the sun even where the outline
  turns away from it, so the lit share falls off as a wrapped cosine, (n.l + w) / (1 + w), rather than at n.l = 0
  (``LEAF_WRAP``; the shadow map still darkens what other crowns and buildings shade, and the crown's far side,
  which its own leaves shade).
- **Light through the leaves.** A leaf transmits about as much light as it reflects, greener (Jacquemoud & Baret's
  PROSPECT model; measured broadleaf transmittance 0.05-0.1 in green against reflectance 0.08-0.12), so a crown
  with the sun behind it glows at its thin rim instead of turning black: the faces turned away from the sun get
  ``LEAF_TRANSMIT`` of the sun through the outer leaves, more where they face straight away.

The sky reaches a crown's sides through its gaps as much as its top (``LEAF_SKY_FLOOR``, against 0.6 for a solid
wall). The ``LEAVES`` finish (``world.facade``) marks the faces lit this way; a reflection of a crown in a wet road
(``shading.shade_mirror``) is lit by the same terms, so it is never brighter than the crown above it.

**Clumps of leaves, not facets** (``leaf_clumps``). A crown's outline is a few dozen flat faces; a photograph shows
clumps of leaves (a few tenths of a metre) gathered in masses on the branches (a couple of metres), the outer ones
lit and yellower, the gaps between them dark with the crown's own shade. Two octaves of 3D value noise
(``textures.value_noise``) at the pixel's world point, ``LEAF_CLUMP_M`` and ``LEAF_MASS_M``, say how far out a
point lies in the crown: out, the albedo is brighter and yellower, in, darker (a linear swing about 1, so the mean
colour of a crown stays); the noise's gradient tilts the shading normal (a bump map), so the sun's side of every
clump and mass is lit and the flat tone of a face, and the edge between two faces, break up. The pattern is in world
space, continuous across the faces. Each octave fades to its mean as it shrinks under ``LEAF_RESOLVED_PX`` pixels of
the pixel's footprint (``resolved``): a far crown or a wooded ridge is its mean tone, never sparkle.
"""

from __future__ import annotations

import numpy as np

from ._jit import kernel
from .textures import value_noise

LEAF_WRAP = 0.4  # how far past the crown outline's terminator its leaves still face the sun (cosine offset)
LEAF_TRANSMIT = 0.45  # sunlight through the outer leaves, as a share of what they reflect facing the sun
LEAF_SKY_FLOOR = 0.85  # the skylight a crown's underside still gets, as a share of its top's (walls: 0.6)
LEAF_CLUMP_M = 0.45  # a clump of leaves (the noise's lattice step, m)
LEAF_MASS_M = 2.2  # a mass of clumps on a branch (m)
LEAF_MASS_SHARE = 0.5  # the masses' share of how far out a point lies, against the clumps' 1
LEAF_SHARPNESS = 2.2  # the clump noise pushed towards +-1: clumps with gaps between them, not a soft haze
LEAF_DEPTH = 0.45  # albedo swing of a point fully out (1 + LEAF_DEPTH) or fully in (1 - LEAF_DEPTH)
LEAF_YELLOW = 0.12  # and how much redder (and less blue) an outer clump is than the swing alone
LEAF_BUMP = 0.8  # how far the clumps' gradient (per lattice step) tilts the shading normal
LEAF_MASS_BUMP = 0.7  # ... and the masses'
LEAF_RESOLVED_PX = 2.0  # an octave whose lattice step spans fewer pixels than this is drawn as its mean
LEAF_MIN_COSINE = 0.05  # n.v under which a face's footprint along it no longer grows (a face seen edge-on)


@kernel(inline="always")
def leaf_cosine(n_dot_l: float) -> float:
    """The share of the sun a crown's outline face gets at cosine ``n_dot_l`` (wrapped; 0 well past the rim)."""
    return max((n_dot_l + LEAF_WRAP) / (1.0 + LEAF_WRAP), 0.0)


@kernel(inline="always")
def leaf_transmission(n_dot_l: float) -> float:
    """The share of the sun that reaches the camera through the leaves of a face turned away from it."""
    return LEAF_TRANSMIT * max(-n_dot_l, 0.0)


@kernel(inline="always")
def leaf_sky(nz: float) -> float:
    """The skylight on a crown's face of upward normal component ``nz`` (1 on its top)."""
    return LEAF_SKY_FLOOR + (1.0 - LEAF_SKY_FLOOR) * 0.5 * (1.0 + nz)


@kernel(inline="always")
def leaf_footprint(dist: float, focal: float, n_dot_v: float) -> float:
    """The footprint (m) along a crown's face of a pixel at distance ``dist`` through a lens of ``focal`` pixels,
    the face at cosine ``n_dot_v`` to the view (an edge-on face's no wider than at ``LEAF_MIN_COSINE``)."""
    return dist / focal / max(n_dot_v, LEAF_MIN_COSINE)


@kernel(inline="always")
def resolved(step_m: float, foot_m: float) -> float:
    """The share of a pattern of lattice step ``step_m`` drawn at a pixel of footprint ``foot_m``: 1 where a step
    spans twice ``LEAF_RESOLVED_PX`` pixels or more, 0 (its mean) under ``LEAF_RESOLVED_PX``."""
    return min(max((step_m / max(foot_m, 1e-6) - LEAF_RESOLVED_PX) / LEAF_RESOLVED_PX, 0.0), 1.0)


@kernel(inline="always")
def leaf_clumps(px: float, py: float, pz: float, nx: float, ny: float, nz: float,
                foot_m: float) -> tuple[float, float, float, float, float, float]:
    """(red, green, blue albedo factors, shading normal x, y, z) of a crown's face of normal (nx, ny, nz) at world
    point (px, py, pz) seen over a footprint of ``foot_m`` metres: 1, 1, 1 and the face's normal where neither
    octave is resolved."""
    clump_w = resolved(LEAF_CLUMP_M, foot_m)
    mass_w = resolved(LEAF_MASS_M, foot_m) * LEAF_MASS_SHARE
    if mass_w <= 0.0:  # the masses are the coarser octave: nothing is resolved
        return 1.0, 1.0, 1.0, nx, ny, nz
    out = 0.0
    gx = gy = gz = 0.0
    if clump_w > 0.0:
        c, cx, cy, cz = value_noise(px / LEAF_CLUMP_M, py / LEAF_CLUMP_M, pz / LEAF_CLUMP_M)
        out = clump_w * min(max(LEAF_SHARPNESS * c, -1.0), 1.0)
        tilt = clump_w * LEAF_BUMP
        gx, gy, gz = tilt * cx, tilt * cy, tilt * cz
    m, mx, my, mz = value_noise(px / LEAF_MASS_M + 57.0, py / LEAF_MASS_M + 31.0, pz / LEAF_MASS_M)
    out += mass_w * m
    tilt = mass_w / LEAF_MASS_SHARE * LEAF_MASS_BUMP
    gx, gy, gz = gx + tilt * mx, gy + tilt * my, gz + tilt * mz
    along = gx * nx + gy * ny + gz * nz  # only the gradient across the face tilts it
    bx, by, bz = nx - (gx - along * nx), ny - (gy - along * ny), nz - (gz - along * nz)
    norm = 1.0 / np.sqrt(bx * bx + by * by + bz * bz)
    swing = LEAF_DEPTH * out
    yellow = LEAF_YELLOW * out
    return (max(1.0 + swing + yellow, 0.1), max(1.0 + swing, 0.1), max(1.0 + swing - yellow, 0.1), bx * norm,
            by * norm, bz * norm)
