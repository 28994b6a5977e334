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
"""

from __future__ import annotations

from ._jit import kernel

LEAF_WRAP = 0.4  # how far past the crown outline's terminator its leaves still face the sun (cosine offset)
LEAF_TRANSMIT = 0.45  # sunlight through the outer leaves, as a share of what they reflect facing the sun
LEAF_SKY_FLOOR = 0.85  # the skylight a crown's underside still gets, as a share of its top's (walls: 0.6)


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
