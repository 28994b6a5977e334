"""Per-pixel structure of building walls, windows and pavements (numba helpers inlined into ``shading``).

Building faces carry a finish (``world.facade.FINISHES``) and facade coordinates (u along the wall, v up it, m);
footways and kerbs are addressed in road coordinates (s, t). Every line, joint and bar is box-filtered over the
pixel's footprint (``lines``, ``band_coverage``), and every per-unit tone (a brick, a panel, a flag) fades
to its mean as the footprint grows past the unit, so a wall far away is its mean colour and never aliases.

Numbers, from building practice: bricks 215 x 65 mm laid in 10 mm mortar (courses of 75 mm, stretchers 225 mm,
stretcher bond: each course shifted half a brick); precast panels 2.4 m wide and half a storey high with 20 mm
sealed joints; paving flags 600 x 600 mm with sand joints that dirt widens to 15 mm; kerb stones 915 mm long;
interlocking concrete roof tiles about 420 x 330 mm laid at a 345 mm gauge (about 300 mm cover across), broken bond.
"""

from __future__ import annotations

import numpy as np

from ..world.facade import BRICK, GLASS, PANE_HEIGHT_M, PANELS, SHOP_GLASS, TILES, TRANSOM_M
from ._jit import kernel
from .surface import dash_coverage

COURSE_M = 0.075
BRICK_M = 0.225
MORTAR_M = 0.010
MORTAR_ALBEDO = (0.30, 0.29, 0.27)
BRICK_TONE = 0.16  # each brick's albedo differs from the wall's by up to this share (burnt darker, paler)
PANEL_WIDTH_M = 2.4
PANEL_HEIGHT_M = 1.6
PANEL_JOINT_M = 0.02
PANEL_TONE = 0.06
JOINT_DARKENING = 0.4  # a sealed panel joint or a flag's sand joint keeps this share of the albedo
STAIN_DEPTH = 0.10  # broad weathering of a wall (noise in [-1, 1])
STREAK_DEPTH = 0.22  # dirt washed down a wall from its sills: darker vertical runs under each storey's windows
STOREY_M = 3.2
SILL_ABOVE_FLOOR_M = 0.9  # a storey's window sills lie this far above its floor; streaks run down from them
SPLASH_DEPTH = 0.18  # the grime rain splashes up the foot of a wall, fading over SPLASH_M
SPLASH_M = 0.45
BAR_M = 0.06  # a window's mullion and transom
BAR_ALBEDO = (0.30, 0.30, 0.29)
SHOP_BAY_M = 1.8  # a shop window's glazing bars stand this far apart
SHOP_BAR_M = 0.08
SHOP_TRANSOM_M = 2.25
SHOP_RISER_M = 0.35  # the stall riser under a shop window
RISER_ALBEDO = (0.05, 0.05, 0.055)
LINTEL_SHADE_M = 0.12  # the top of a pane lies in the shadow of the window's reveal
LINTEL_DARKENING = 0.5
FLAG_M = 0.6
FLAG_JOINT_M = 0.015
FLAG_TONE = 0.09
KERB_STONE_M = 0.915
KERB_JOINT_M = 0.008
TILE_GAUGE_M = 0.345  # a roof's courses up the slope
TILE_COVER_M = 0.30  # a tile's width across the slope; each course shifted half a tile
TILE_BUTT_M = 0.035  # the shadow a course's butt (lower edge) casts on the course below
TILE_SIDE_M = 0.01  # the interlock between neighbours in a course
TILE_SHADE = 0.35  # the butt's shadow and the interlock keep this share of the tile's albedo
TILE_TONE = 0.14  # each tile's albedo differs by up to this share (weathered, replaced)
ROOF_STAIN_DEPTH = 0.25  # moss and lichen in broad patches (noise in [-1, 1]), deeper than on a wall


@kernel(inline="always")
def cell_hash(i: float, j: float) -> float:
    """A repeatable value in [-1, 1) for the integer cell (i, j) (a brick, a panel, a slab)."""
    hashed = np.sin(i * 12.9898 + j * 78.233) * 43758.5453
    return 2.0 * (hashed - np.floor(hashed)) - 1.0


@kernel(inline="always")
def band_coverage(x: float, width: float, lo: float, hi: float) -> float:
    """Share of [x - width/2, x + width/2] inside [lo, hi]."""
    return max(min(x + 0.5 * width, hi) - max(x - 0.5 * width, lo), 0.0) / width


@kernel(inline="always")
def lines(x: float, foot: float, width: float, period: float) -> float:
    """Share of the footprint [x - foot/2, x + foot/2] on lines ``width`` wide every ``period`` (the first from x = 0
    on), faded to their mean share as the footprint passes a quarter of the period: a box filter alone leaves moire
    where lines come a few pixels apart."""
    fade = min(max(4.0 * foot / period - 1.0, 0.0), 1.0)
    return dash_coverage(x, foot, width, period) * (1.0 - fade) + width / period * fade


@kernel(inline="always")
def joints_over(r: float, g: float, b: float, joint: float, tone: float, jr: float, jg: float,
                jb: float) -> tuple[float, float, float]:
    """(r, g, b) toned by ``tone`` with a share ``joint`` covered by the joint colour (jr, jg, jb)."""
    keep = tone * (1.0 - joint)
    return r * keep + jr * joint, g * keep + jg * joint, b * keep + jb * joint


@kernel(inline="always")
def brick_wall(u: float, v: float, fu: float, fv: float, r: float, g: float,
               b: float) -> tuple[float, float, float]:
    """Stretcher-bond brickwork of colour (r, g, b) in facade coordinates, footprint (fu, fv)."""
    course = np.floor(v / COURSE_M)
    across = u + 0.5 * BRICK_M * (course - 2.0 * np.floor(0.5 * course))
    bed = lines(v + 0.5 * MORTAR_M, fv, MORTAR_M, COURSE_M)
    head = lines(across + 0.5 * MORTAR_M, fu, MORTAR_M, BRICK_M)
    blur = min(fv / COURSE_M, 1.0)  # a footprint over several courses sees their head joints' mean
    head = head * (1.0 - blur) + MORTAR_M / BRICK_M * blur
    fade = max(1.0 - 2.0 * fv / COURSE_M, 0.0) * max(1.0 - fu / BRICK_M, 0.0)
    tone = 1.0 + BRICK_TONE * fade * cell_hash(course, np.floor(across / BRICK_M))
    return joints_over(r, g, b, bed + (1.0 - bed) * head, tone, MORTAR_ALBEDO[0], MORTAR_ALBEDO[1], MORTAR_ALBEDO[2])


@kernel(inline="always")
def panel_wall(u: float, v: float, fu: float, fv: float, r: float, g: float,
               b: float) -> tuple[float, float, float]:
    """Precast concrete panels with sealed joints."""
    joint = max(lines(u + 0.5 * PANEL_JOINT_M, fu, PANEL_JOINT_M, PANEL_WIDTH_M),
                lines(v + 0.5 * PANEL_JOINT_M, fv, PANEL_JOINT_M, PANEL_HEIGHT_M))
    fade = max(1.0 - max(fu, fv) / PANEL_HEIGHT_M, 0.0)
    tone = 1.0 + PANEL_TONE * fade * cell_hash(np.floor(u / PANEL_WIDTH_M), np.floor(v / PANEL_HEIGHT_M))
    dark = JOINT_DARKENING * tone
    return joints_over(r, g, b, joint, tone, r * dark, g * dark, b * dark)


@kernel(inline="always")
def roof_tiles(u: float, v: float, fu: float, fv: float, r: float, g: float,
               b: float) -> tuple[float, float, float]:
    """Courses of roof tiles of colour (r, g, b) laid up the slope (u along the eaves, v up from them), footprint
    (fu, fv): each course's butt shades the one below, neighbours interlock, every tile its own tone."""
    course = np.floor(v / TILE_GAUGE_M)
    across = u + 0.5 * TILE_COVER_M * (course - 2.0 * np.floor(0.5 * course))
    butt = lines(v + 0.5 * TILE_BUTT_M, fv, TILE_BUTT_M, TILE_GAUGE_M)
    side = lines(across + 0.5 * TILE_SIDE_M, fu, TILE_SIDE_M, TILE_COVER_M)
    blur = min(fv / TILE_GAUGE_M, 1.0)  # a footprint over several courses sees their interlocks' mean
    side = side * (1.0 - blur) + TILE_SIDE_M / TILE_COVER_M * blur
    fade = max(1.0 - 2.0 * fv / TILE_GAUGE_M, 0.0) * max(1.0 - fu / TILE_COVER_M, 0.0)
    tone = 1.0 + TILE_TONE * fade * cell_hash(course + 31.0, np.floor(across / TILE_COVER_M))
    dark = TILE_SHADE * tone
    return joints_over(r, g, b, butt + (1.0 - butt) * side, tone, r * dark, g * dark, b * dark)


@kernel(inline="always")
def weathered(v: float, stain: float, streak: float) -> float:
    """Albedo factor of a wall's weathering at height ``v``: broad stains, streaks run down from the sills (both
    noise in [-1, 1]) and the splash-back at its foot."""
    in_storey = v - STOREY_M * np.floor(v / STOREY_M)
    under_sill = 1.0 if in_storey < SILL_ABOVE_FLOOR_M else 0.35
    return (1.0 + STAIN_DEPTH * stain - STREAK_DEPTH * under_sill * max(streak, 0.0)) \
        * (1.0 - SPLASH_DEPTH * np.exp(-max(v, 0.0) / SPLASH_M))


@kernel(inline="always")
def glazing(finish: int, u: float, v: float, fu: float, fv: float, r: float, g: float,
            b: float) -> tuple[float, float, float, float]:
    """(r, g, b, glass): a window pane's bars (mullion, transom) and the reveal's shadow over what lies behind the
    glass, or a shop window's glazing bars and stall riser; ``glass`` is the share of the pixel that is glass."""
    if finish == GLASS:
        bars = max(band_coverage(u, fu, -0.5 * BAR_M, 0.5 * BAR_M),
                   band_coverage(v, fv, TRANSOM_M - 0.5 * BAR_M, TRANSOM_M + 0.5 * BAR_M))
        shade = 1.0 - LINTEL_DARKENING * band_coverage(v, fv, PANE_HEIGHT_M - LINTEL_SHADE_M, PANE_HEIGHT_M + 1.0)
        r, g, b = joints_over(r, g, b, bars, shade, BAR_ALBEDO[0], BAR_ALBEDO[1], BAR_ALBEDO[2])
        return r, g, b, 1.0 - bars
    bars = max(lines(u + 0.5 * SHOP_BAR_M, fu, SHOP_BAR_M, SHOP_BAY_M),
               band_coverage(v, fv, SHOP_TRANSOM_M - 0.5 * SHOP_BAR_M, SHOP_TRANSOM_M + 0.5 * SHOP_BAR_M))
    riser = band_coverage(v, fv, -1.0, SHOP_RISER_M)
    solid = riser + (1.0 - riser) * bars
    dark = 1.0 - riser
    r, g, b = joints_over(r, g, b, bars * dark, 1.0, BAR_ALBEDO[0] * dark, BAR_ALBEDO[1] * dark,
                          BAR_ALBEDO[2] * dark)
    return r * (1.0 - riser) + RISER_ALBEDO[0] * riser, g * (1.0 - riser) + RISER_ALBEDO[1] * riser, \
        b * (1.0 - riser) + RISER_ALBEDO[2] * riser, 1.0 - solid


@kernel(inline="always")
def facade(finish: int, u: float, v: float, fu: float, fv: float, stain: float, streak: float, r: float, g: float,
           b: float) -> tuple[float, float, float, float]:
    """(r, g, b, glass) of a building face of ``finish`` (not plain) at facade coordinates (u, v), footprint
    (fu, fv): its structure, then the weathering of walls (``stain``, ``streak``: noise in [-1, 1])."""
    if finish == GLASS or finish == SHOP_GLASS:
        return glazing(finish, u, v, fu, fv, r, g, b)
    if finish == TILES:  # a roof: moss and lichen in patches, no sills to streak it
        r, g, b = roof_tiles(u, v, fu, fv, r, g, b)
        moss = 1.0 + ROOF_STAIN_DEPTH * stain
        return r * moss, g * moss, b * moss, 0.0
    if finish == BRICK:
        r, g, b = brick_wall(u, v, fu, fv, r, g, b)
    elif finish == PANELS:
        r, g, b = panel_wall(u, v, fu, fv, r, g, b)
    tone = weathered(v, stain, streak)
    return r * tone, g * tone, b * tone, 0.0


@kernel(inline="always")
def footway(kerb: bool, s: float, t: float, fs: float, ft: float, r: float, g: float,
            b: float) -> tuple[float, float, float]:
    """(r, g, b) of a footway of square paving flags, or of kerb stones, with their joints, in road coordinates."""
    if kerb:
        joint = lines(s + 0.5 * KERB_JOINT_M, fs, KERB_JOINT_M, KERB_STONE_M)
        fade = max(1.0 - fs / KERB_STONE_M, 0.0)
        tone = 1.0 + FLAG_TONE * fade * cell_hash(np.floor(s / KERB_STONE_M), 7.0)
    else:
        joint = max(lines(s + 0.5 * FLAG_JOINT_M, fs, FLAG_JOINT_M, FLAG_M),
                    lines(t + 0.5 * FLAG_JOINT_M, ft, FLAG_JOINT_M, FLAG_M))
        fade = max(1.0 - 2.0 * max(fs, ft) / FLAG_M, 0.0)
        tone = 1.0 + FLAG_TONE * fade * cell_hash(np.floor(s / FLAG_M), np.floor(t / FLAG_M))
    dark = JOINT_DARKENING * tone
    return joints_over(r, g, b, joint, tone, r * dark, g * dark, b * dark)
