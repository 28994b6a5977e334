"""The land beyond the road (numba): verges, fields and lawns of the ``grass`` road material, per pixel in road
coordinates and box-filtered over the pixel's footprint.

A photograph of the countryside shows a patchwork, not one lawn to the hills: the verge is its own band of longer,
paler and browner grass, worn dry along the road's edge with weeds in it; beyond it, fields of different crops with
straight boundaries (a strip of grass between them), drill rows, tramlines and mowing stripes, and darker damp
patches. Suburban grass is lawns: one per garden along the street, each its own green, mown in stripes, with weeds
along the kerb. Everything is keyed on the piece's road coordinates (s, u), u = |t| from the grass's inner edge,
through a hash of the plot's indices, so a frame is a pure function of the scene; every pattern is filtered over the
pixel's footprint (``dash_coverage``, ``box_overlap``), so far fields fade to their mean colour instead of aliasing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..typed import MATERIALS, FloatArray
from ._jit import kernel
from .surface import box_overlap, dash_coverage

if TYPE_CHECKING:
    from ..world.road_layout import RoadPiece

GRASS = MATERIALS.index("grass")
# ground_table columns, one row per road piece
INNER_M, LAND = range(2)
NO_LAND, LAWNS, FIELDS = 0.0, 1.0, 2.0
# Field crops, linear albedo r, g, b, then their patterns: drill rows (period m, contrast), broad stripes (mowing,
# swaths; period m, contrast), tramline spacing (m, 0: none), share of the fields (sums to 1). Season-neutral: a
# drive sees green and yellow-green crops, stubble, ploughed earth and hay side by side.
FIELD_LOOK = np.array([
    [0.068, 0.104, 0.040, 0.0, 0.0, 7.0, 0.07, 0.0, 0.28],  # pasture, mown in broad stripes
    [0.046, 0.082, 0.029, 0.16, 0.10, 0.0, 0.0, 20.0, 0.17],  # a dark green crop (wheat, barley in leaf)
    [0.112, 0.132, 0.048, 0.16, 0.08, 0.0, 0.0, 24.0, 0.18],  # a yellow-green crop (ripening cereal, rape)
    [0.205, 0.160, 0.083, 0.20, 0.14, 0.0, 0.0, 24.0, 0.13],  # ochre stubble
    [0.092, 0.066, 0.045, 0.40, 0.30, 0.0, 0.0, 0.0, 0.13],  # ploughed earth: furrows
    [0.150, 0.143, 0.074, 0.0, 0.0, 5.0, 0.12, 0.0, 0.11],  # hay meadow in swaths
])
ROWS_PERIOD, ROWS_CONTRAST, STRIPE_PERIOD, STRIPE_CONTRAST, TRAMLINES, SHARE = range(3, 9)
FIELD_SHARES = np.cumsum(FIELD_LOOK[:, SHARE])
SOIL = (0.085, 0.068, 0.048)  # bare earth in the tramlines' wheel tracks
TRACK_M = 0.45  # a tramline's wheel track, two of them TRACK_GAUGE_M apart
TRACK_GAUGE_M = 1.8
TRACK_SOIL = 0.65  # share of soil in a wheel track
VERGE = (0.104, 0.114, 0.058)  # longer, paler and browner grass than a lawn (linear albedo)
VERGE_M = (2.5, 2.0)  # the verge is 2.5-4.5 m wide (by the piece and side)
MARGIN = (0.082, 0.100, 0.048)  # the grass strip between fields
MARGIN_M = (0.8, 1.4)  # its half width, 0.8-2.2 m (by the band)
FIELD_DEPTH_M = (35.0, 60.0)  # a band of fields reaches 35-95 m away from the road (by the side)
FIELD_LENGTH_M = (40.0, 100.0)  # a field runs 40-140 m along it (by the band)
DRY = (0.150, 0.133, 0.088)  # the worn strip along the road's edge: dry grass, dust and grit
DRY_M = (0.35, 0.25)  # its width, wandering 0.1-0.6 m
WEEDS = (0.050, 0.088, 0.030)  # weeds in it (where the stain noise is high)
LAWN = (0.072, 0.108, 0.043)
LAWN_BROWN = (0.100, 0.104, 0.052)  # a dry, thin lawn
LAWN_LENGTH_M = (13.0, 10.0)  # one garden's lawn along the street: 13-23 m
LAWN_DEPTH_M = 28.0
BED = (0.060, 0.050, 0.036)  # the bed or path between two lawns, of half width BED_M
BED_M = 0.25
MOW_PERIOD_M = 1.3  # a mower's two passes
MOW_CONTRAST = 0.09
KERB_WEEDS_M = 0.22  # the weedy strip along the pavement's edge
PATCH_TEXEL_M = 5.0  # texel of the noise of colour variation inside a field and of damp patches
PATCH_TONE = 0.14
DAMP_DARKENING = 0.3  # a damp hollow's albedo is up to this much darker
WET_DARKENING = 0.35  # soaked ground (the weather's wetness 1) is this much darker
FIELD_TEXTURE = 0.7  # a field's crop is more even than grass: its clumps are this much weaker


def ground_table(pieces: list[RoadPiece]) -> FloatArray:
    """(pieces, 2) float64 per road piece: |t| where its outermost strip begins and the land there (``NO_LAND``
    unless that strip is grass; ``LAWNS`` when the grass stands raised behind a kerb and pavement, as gardens
    do; ``FIELDS`` when it lies level with or below the road, as the countryside does)."""
    table = np.zeros((max(len(pieces), 1), 2))
    for index, piece in enumerate(pieces):
        outer = piece.strips[-1]
        table[index, INNER_M] = piece.half_width + sum(strip.width for strip in piece.strips[:-1])
        if outer.material == "grass":
            table[index, LAND] = LAWNS if outer.height > 0.0 else FIELDS
    return table


@kernel(inline="always")
def fract(x: float) -> float:
    """The fractional part of x (in [0, 1))."""
    return x - np.floor(x)


@kernel(inline="always")
def plot_hash(a: float, b: float, c: float) -> float:
    """A number in [0, 1) fixed by the plot's indices (a, b, c): a hash of multiplies and fractions only (no sine:
    a grass pixel takes several)."""
    x, y, z = fract(a * 0.1031), fract(b * 0.1030), fract(c * 0.0973)
    d = x * (z + 31.32) + y * (y + 31.32) + z * (x + 31.32)
    x, y, z = x + d, y + d, z + d
    return fract((x + y) * z)


@kernel(inline="always")
def mix(rgb: tuple[float, float, float], other: tuple[float, float, float],
        w: float) -> tuple[float, float, float]:
    """``rgb`` moved towards ``other`` by ``w``."""
    return (rgb[0] + (other[0] - rgb[0]) * w, rgb[1] + (other[1] - rgb[1]) * w, rgb[2] + (other[2] - rgb[2]) * w)


@kernel(inline="always")
def stripes(x: float, foot: float, period: float, contrast: float) -> float:
    """Tone of alternating bands of half ``period`` each, +-``contrast``, box-filtered over ``foot``."""
    if period <= 0.0:
        return 1.0
    return 1.0 + contrast * (2.0 * dash_coverage(x, foot, 0.5 * period, period) - 1.0)


@kernel(inline="always")
def plot(s: float, u: float, fs: float, ft: float, depth: float, length: tuple[float, float],
         margin: tuple[float, float], salt: float) -> tuple[float, float, float, float, float]:
    """(band, index, inside, x, y) of the plot under (s, u) in bands of ``depth`` along the road, each band cut
    into plots of its own length (``length``: least, span) and offset: which plot, the share of the footprint
    inside it beyond its margin (``margin``: least, span; by the band), the pixel's place in it (x along the road,
    y away from it)."""
    band = np.floor(u / depth)
    size = length[0] + length[1] * plot_hash(band, salt, 1.0)
    shift = size * plot_hash(band, salt, 2.0)
    edge = margin[0] + margin[1] * plot_hash(band, salt, 4.0)
    index = np.floor((s + shift) / size)
    x = s + shift - index * size
    y = u - band * depth
    # the footprint no wider than half a plot, so far plots keep their own colour instead of the margin's
    inside = box_overlap(x, min(fs, 0.5 * size), edge, size - edge) \
        * box_overlap(y, min(ft, 0.5 * depth), edge, depth - edge)
    return band, index, inside, x, y


@kernel(inline="always")
def field(s: float, u: float, fs: float, ft: float, salt: float) -> tuple[float, float, float]:
    """Albedo of the fields at (s, u) (u from the first band's edge): each plot a crop of ``FIELD_LOOK`` in its
    own tone, its rows and tramlines along or across the road, the grass margin between plots."""
    depth = FIELD_DEPTH_M[0] + FIELD_DEPTH_M[1] * plot_hash(salt, 3.0, 0.0)
    band, index, inside, x, y = plot(s, u, fs, ft, depth, FIELD_LENGTH_M, MARGIN_M, salt)
    if inside <= 0.0:
        return MARGIN
    pick = plot_hash(band, index, salt)
    crop = 0
    while crop < FIELD_SHARES.size - 1 and pick > FIELD_SHARES[crop]:
        crop += 1
    look = FIELD_LOOK[crop]
    tone = 0.86 + 0.28 * plot_hash(index, band, salt + 5.0)
    along = plot_hash(index, salt, band + 6.0) < 0.6  # rows run along the road (varying across it) or across
    pos, foot = (y, ft) if along else (x, fs)
    tone *= stripes(pos, foot, look[ROWS_PERIOD], look[ROWS_CONTRAST])
    tone *= stripes(pos, foot, look[STRIPE_PERIOD], look[STRIPE_CONTRAST])
    rgb = (look[0] * tone, look[1] * tone, look[2] * tone)
    if look[TRAMLINES] > 0.0:
        spacing = look[TRAMLINES]
        track = dash_coverage(pos + 0.5 * (TRACK_GAUGE_M + TRACK_M), foot, TRACK_M, spacing) \
            + dash_coverage(pos - 0.5 * (TRACK_GAUGE_M - TRACK_M), foot, TRACK_M, spacing)
        rgb = mix(rgb, SOIL, TRACK_SOIL * track)
    return mix(MARGIN, rgb, inside)


@kernel(inline="always")
def lawn(s: float, u: float, fs: float, ft: float, salt: float) -> tuple[float, float, float]:
    """Albedo of the lawns at (s, u): one per garden along the street, each its own green (some dry and brown),
    mown in stripes along or across the street, a bed or path between two."""
    band, index, inside, x, y = plot(s, u, fs, ft, LAWN_DEPTH_M, LAWN_LENGTH_M, (BED_M, 0.0), salt)
    tone = 0.85 + 0.3 * plot_hash(index, band, salt + 7.0)
    rgb = mix(LAWN, LAWN_BROWN, 0.8 * plot_hash(band, index, salt + 8.0) ** 3)
    along = plot_hash(index, salt, band + 9.0) < 0.5
    tone *= stripes(y, ft, MOW_PERIOD_M, MOW_CONTRAST) if along else stripes(x, fs, MOW_PERIOD_M, MOW_CONTRAST)
    return mix(BED, (rgb[0] * tone, rgb[1] * tone, rgb[2] * tone), inside)


@kernel(inline="always")
def ground(table: np.ndarray, piece: int, s: float, t: float, fs: float, ft: float, patch: float, stain: float,
           wetness: float) -> tuple[float, float, float, float]:
    """(r, g, b, texture): the albedo of the grass at road point (s, t) of ``piece`` and a factor of its clumps'
    strength. ``patch`` is a noise sample (in [-1, 1], filtered) at ``PATCH_TEXEL_M`` (colour variation, damp
    patches, the straw in the verge and the worn strip's wandering edge); ``stain`` the material's stain noise
    (weeds in the worn strip)."""
    land = table[piece, LAND]
    side = 1.0 if t >= 0.0 else -1.0
    u = abs(t) - table[piece, INNER_M]
    salt = piece * 2.0 + side
    texture = 1.0
    if land == LAWNS:
        rgb = lawn(s, u, fs, ft, salt)
        edge = box_overlap(u, ft, -1.0, KERB_WEEDS_M * (1.0 + 0.5 * patch))
        rgb = mix(rgb, mix(DRY, WEEDS, min(max(2.0 * stain, 0.0), 1.0)), edge)
    else:
        verge = VERGE_M[0] + VERGE_M[1] * plot_hash(salt, 11.0, 0.0)
        in_verge = box_overlap(u, ft, -1.0, verge)
        rgb = VERGE
        if in_verge < 1.0:
            rgb = mix(field(s, u - verge, fs, ft, salt), VERGE, in_verge)
        rgb = mix(rgb, (0.13, 0.125, 0.065), 0.5 * in_verge * min(max(patch, 0.0), 1.0))  # straw in the verge
        dry = box_overlap(u, ft, -1.0, DRY_M[0] + DRY_M[1] * patch)
        rgb = mix(rgb, mix(DRY, WEEDS, min(max(2.0 * stain, 0.0), 1.0)), dry)
        texture = FIELD_TEXTURE + (1.0 - FIELD_TEXTURE) * in_verge
    tone = (1.0 + PATCH_TONE * patch) * (1.0 - DAMP_DARKENING * min(max(3.0 * (patch - 0.35), 0.0), 1.0)) \
        * (1.0 - WET_DARKENING * wetness)
    return rgb[0] * tone, rgb[1] * tone, rgb[2] * tone, texture
