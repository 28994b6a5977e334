"""What road materials and objects are made of (numba helpers inlined into ``shading``): the material table
(``surface_table``: albedo, roughness, Fresnel, whether it holds a water film), each material's albedo toned by
its grain and stains, concrete slabs and their sealed joints, the photographic clumps of surfaces and objects,
puddles, and a surface under water."""

from __future__ import annotations

import numpy as np

from ..typed import MATERIALS, FloatArray
from ..world.paint import MATERIAL_ALBEDO
from ._jit import kernel
from .facades import cell_hash
from .surface import dash_coverage

ASPHALT = MATERIALS.index("asphalt")
SLAB = MATERIALS.index("slab")
CONCRETE = MATERIALS.index("concrete")  # footways: paving flags
KERB = MATERIALS.index("kerb")
PAVED = ("asphalt", "concrete", "kerb", "slab")  # hold a water film; grass, gravel and dirt soak it up
# surface_table columns; its rows are the road MATERIALS, then one for every object
ALBEDO_R, ALBEDO_G, ALBEDO_B, ROUGHNESS, F0, HOLDS_WATER, MIRROR_F0, GRAIN = range(8)
FLAG_GRAIN = 0.4  # paving flags and kerb stones are smoother than asphalt: this share of its grain and stains
OBJECT_ROW = len(MATERIALS)
STANDING_WATER_ROUGHNESS = 0.03
PUDDLE_RAGGED = 0.3  # share of the puddle noise that is a finer octave: ragged shores
PUDDLE_SHORE_TEXEL_M = 0.12  # texel of that octave (m)
PUDDLE_SHORE_SLOPE = 4.0  # standing water deepens from its shore over 1 / PUDDLE_SHORE_SLOPE of the noise
CLUMP_TEXEL_M = 0.1  # photographic texture: texel of the clumps (leaves, tufts, stains; ~4 texels across) (m)
MID_TEXEL_M = 0.03  # ... and of its grain (m)
CLUMP_SHARPNESS = 4.0  # the clump noise is scaled and clipped to +-1: sharp-edged patches
CLUMP_DEPTH = 0.6
GRAIN_DEPTH = 0.35
# Jointed plain concrete pavement (FHWA TA 5040.30: transverse joints at most about 15 ft apart; longitudinal
# joints along the lane lines): sawn joints filled with dark sealant, a wider band of sealant smeared over them
# (the "tar seams" of concrete roads and bridge decks), slabs whose concrete weathered slightly differently.
JOINT_SPACING_M = 4.5
JOINT_WIDTH_M = 0.012
SEAM_WIDTH_M = 0.07
SEAM_OPACITY = 0.6
SEALANT_ALBEDO = 0.03
SLAB_TONE = 0.08  # each slab's albedo differs from the pavement's by up to this share
DRIP_HALF_WIDTH_M = 0.35  # the oil-drip stain down the middle of every lane (engines and gearboxes leak there)
DRIP_DARKENING = 0.22


def surface_table(albedo: np.ndarray = MATERIAL_ALBEDO) -> FloatArray:
    """(materials + 1, 8) float64 per road material, then for objects: albedo r, g, b (objects: their faces'),
    roughness, Fresnel f0 of highlights, holds a water film (0/1), Fresnel f0 of the mirror image, the share of
    asphalt's grain and stains it shows."""
    table = np.zeros((OBJECT_ROW + 1, 8))
    table[:, GRAIN] = 1.0
    table[[CONCRETE, KERB], GRAIN] = FLAG_GRAIN
    table[:OBJECT_ROW, ALBEDO_R:ALBEDO_B + 1] = albedo
    table[:, ROUGHNESS], table[:, F0], table[:, MIRROR_F0] = 0.35, 0.04, 0.02
    table[ASPHALT, ROUGHNESS], table[ASPHALT, F0] = 0.55, 0.02
    table[SLAB, ROUGHNESS], table[SLAB, F0] = 0.6, 0.03
    table[[MATERIALS.index(name) for name in PAVED], HOLDS_WATER] = 1.0
    table[OBJECT_ROW, ROUGHNESS], table[OBJECT_ROW, MIRROR_F0] = 0.25, 0.05  # glossy paint
    return table


@kernel(inline="always")
def albedo(surface: np.ndarray, material: int, grain: float, blotch: float,
           detail: float) -> tuple[float, float, float]:
    """(r, g, b): the road material's colour toned by its grain and stains (noise samples in [-1, 1]), as much as
    the material shows (``GRAIN``); ``detail`` (0 = the ideal render) deepens both as a photograph shows them."""
    share = surface[material, GRAIN]
    tone = (1.0 + 0.35 * share * (1.0 + detail) * grain) * (1.0 + 0.18 * share * (1.0 + 1.5 * detail) * blotch)
    return surface[material, ALBEDO_R] * tone, surface[material, ALBEDO_G] * tone, surface[material, ALBEDO_B] * tone


@kernel(inline="always")
def slab_joints(s: float, t: float, fs: float, ft: float, lane_width: float, stain: float, r: float, g: float,
                b: float) -> tuple[float, float, float]:
    """(r, g, b) of concrete slabs: each slab's own tone and the oil-drip stain down its lane's middle, then the
    sealed joints (transverse every ``JOINT_SPACING_M``, longitudinal on the lane boundaries) and their sealant
    bands, box-filtered over the pixel's footprint (fs, ft); ``stain`` (noise in [-1, 1]) varies the smeared
    sealant and the drip."""
    i, j = np.floor(s / JOINT_SPACING_M), np.floor(t / lane_width)
    fade = max(1.0 - 2.0 * max(fs, ft) / JOINT_SPACING_M, 0.0)  # far away a pixel spans many slabs
    tone = 1.0 + SLAB_TONE * fade * cell_hash(i, j)
    across = (t / lane_width - j - 0.5) * lane_width / DRIP_HALF_WIDTH_M
    spread = min(ft / lane_width, 1.0)  # a footprint across the lane sees the drip's lane-wide mean
    drip = np.exp(-across * across) * (1.0 - spread) + np.sqrt(np.pi) * DRIP_HALF_WIDTH_M / lane_width * spread
    tone *= 1.0 - DRIP_DARKENING * (0.6 + 0.4 * stain) * drip
    joint = max(dash_coverage(s + 0.5 * JOINT_WIDTH_M, fs, JOINT_WIDTH_M, JOINT_SPACING_M),
                dash_coverage(t + 0.5 * JOINT_WIDTH_M, ft, JOINT_WIDTH_M, lane_width))
    seam = max(dash_coverage(s + 0.5 * SEAM_WIDTH_M, fs, SEAM_WIDTH_M, JOINT_SPACING_M),
               dash_coverage(t + 0.5 * SEAM_WIDTH_M, ft, SEAM_WIDTH_M, lane_width))
    cover = max(joint, SEAM_OPACITY * (0.5 + 0.5 * stain) * seam)
    keep = tone * (1.0 - cover)
    sealant = SEALANT_ALBEDO * cover
    return r * keep + sealant, g * keep + sealant, b * keep + sealant


@kernel(inline="always")
def clumps(strength: float, mid: float, fine: float) -> float:
    """Albedo factor of the photographic texture: sharp-edged clumps (the mid-scale noise pushed towards +-1) and
    grain, both scaled by ``strength`` (0 = none); never below 0.1."""
    clump = min(max(CLUMP_SHARPNESS * mid, -1.0), 1.0)
    return max(1.0 + strength * (CLUMP_DEPTH * clump + GRAIN_DEPTH * fine), 0.1)


@kernel(inline="always")
def puddle_depth(shape: float, puddles: float) -> float:
    """Standing water in [0, 1] where the puddle noise is ``shape``, for the weather's puddle coverage."""
    return min(max((shape - (0.55 - 1.2 * puddles)) * PUDDLE_SHORE_SLOPE, 0.0), 1.0)


@kernel(inline="always")
def wet_surface(r: float, g: float, b: float, roughness: float, surface_wet: float,
                standing: float) -> tuple[float, float, float, float]:
    """(r, g, b, roughness) of a surface under a water film ``surface_wet`` (darker, smoother; mirror-smooth
    where ``standing`` water is deep)."""
    if surface_wet <= 0.0:
        return r, g, b, roughness
    darken = 1.0 - 0.5 * surface_wet
    roughness = roughness * (1.0 - surface_wet) + 0.09 * surface_wet
    if standing > 0.5:
        roughness = STANDING_WATER_ROUGHNESS
    return r * darken, g * darken, b * darken, roughness
