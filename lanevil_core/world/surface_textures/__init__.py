"""Procedural road-surface textures in road coordinates: cracks, repair patches and sealant, tire marks.

A texture's rows run along the road (s) and its columns across it (t); texels are ``texel`` metres square and
texel (i, j) has its centre at ``s_local = (i + 0.5) * texel``, ``t_local = (j + 0.5) * texel`` from the texture's
corner. Shapes are drawn from distance fields with box-filtered edges, so a crack thinner than a texel comes out
as partial coverage rather than as aliased stair steps.

Every generator returns ``(rgba, wet)`` (``crack_layers`` the same split into a stain and a crack layer):
``rgba`` (h, w, 4) float32 linear albedo plus straight (not premultiplied) coverage alpha, ``wet`` (h, w)
float32 puddle coverage or None. All randomness comes from the Generator passed in; each drawn item (a crack, a
patch, a mark) takes its own child generator, so raising a count adds items without changing the ones already
there.
"""

from __future__ import annotations

from ._canvas import (
    ALLIGATOR_HALO,
    ALLIGATOR_WIDTH,
    CRACK_HALO_RGB,
    CRACK_KINDS,
    CRACK_RGB,
    FRESH_ASPHALT_RGB,
    GOLDEN_FRACTION,
    HALO_OPACITY,
    HALO_SCALE,
    JOINT_SEED_OFFSET,
    RUBBER_RGB,
    SEALANT_BRIGHT_RGB,
    SEALANT_DARK_RGB,
    CrackKind,
    Texture,
    composite,
)
from .cracks import CrackLayers, crack_layers, crack_mix, crack_network
from .repairs import PatchKind, ghost_lines, patches
from .tire_marks import TireMarkKind, tire_marks
from .wear import worn_paint

__all__ = [
    "ALLIGATOR_HALO",
    "ALLIGATOR_WIDTH",
    "CRACK_HALO_RGB",
    "CRACK_KINDS",
    "CRACK_RGB",
    "CrackKind",
    "CrackLayers",
    "FRESH_ASPHALT_RGB",
    "GOLDEN_FRACTION",
    "HALO_OPACITY",
    "HALO_SCALE",
    "JOINT_SEED_OFFSET",
    "PatchKind",
    "RUBBER_RGB",
    "SEALANT_BRIGHT_RGB",
    "SEALANT_DARK_RGB",
    "Texture",
    "TireMarkKind",
    "composite",
    "crack_layers",
    "crack_mix",
    "crack_network",
    "ghost_lines",
    "patches",
    "tire_marks",
    "worn_paint",
]
