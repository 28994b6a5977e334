"""Light transport pieces (numba): sky radiance, sun shadows, Fresnel and glossy highlights."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..typed import FloatArray

# The irradiance unit, set in world/environment.py beside the daylight models: SUN_SCALE is a clear noon sun's
# irradiance relative to the sky's ambient unit, SKY_AMBIENT_GAIN the sky's ambient light per unit of its colour.
from ..world.environment import SKY_AMBIENT_GAIN as SKY_AMBIENT_GAIN
from ..world.environment import SUN_SCALE as SUN_SCALE
from ..world.scene import BEAMS
from ._jit import kernel
from .surface import sample_noise

SKY_SCALE = 1.6
NORMAL_OFFSET_M = 0.03
LOBE_FLOOR = 1e-3
PCF_MAX_TEXELS = 6.0  # widest soft edge, in texels of the cascade (the coarse test must cover it)
COARSE_SHIFT = 3  # shadow-map texels per coarse cell = 2 ** COARSE_SHIFT
FOOTPRINT_TAPS = 4  # most shadow lookups along each side of a pixel's footprint (photographed frames)
# Texels between two footprint taps at most: each tap is itself a soft lookup over a window at least 2.4 texels wide
# (``_visibility_at``'s radius is at least 0.7 texel, its bilinear taps reach half a texel further), so a
# footprint under 3 texels needs one tap; against taps every half texel (docs/performance.md) frames differ by
# 0.005-0.04 levels on average.
FOOTPRINT_TAP_TEXELS = 3.0
# Per coarse cell: nearest and farthest caster depth over it and its 8 neighbours.
NEAR_AROUND, FAR_AROUND = range(2)
# The sun's disk: its true angular radius (0.267 deg) and its radiance per unit of the sun's intensity (a clipped
# highlight at any exposure: the camera's glare, render.post.glare, spreads it, not a painted halo), then the
# circumsolar aureole (a narrow Gaussian of SUN_AUREOLE_COS's width, about 1.3 deg) and the wide Mie glow.
SUN_COS_RADIUS = 0.99998914
SUN_DISK_RADIANCE = 1500.0
SUN_AUREOLE_POWER = 2000.0
SUN_AUREOLE = 1.2
# The cloud deck (``cloud_cover``): a plane CLOUD_HEIGHT_M up textured by the coarse noise (CLOUD_TEXEL_M texels,
# plus a CLOUD_DETAIL share of an octave four times finer), covering about the case's cloudiness of the sky
# (threshold and sharpness of the noise), thinning into the haze below about 1 / CLOUD_HAZE of elevation; lit
# by the sun (CLOUD_SUNLIT of its intensity where thin) and by the sky (CLOUD_BASE of the horizon's
# luminance); CLOUD_PIXEL_RAD is the angle a pixel spans (the footprint the noise is filtered over).
CLOUD_HEIGHT_M = 1500.0
CLOUD_TEXEL_M = 30.0
CLOUD_DETAIL = 0.45
CLOUD_MEDIAN = -0.16  # median of the two octaves' sum (the noise is normalised by its largest value)
CLOUD_THRESHOLD = 0.45
CLOUD_SHARPNESS = 4.0
CLOUD_HAZE = 6.0
CLOUD_LOWEST = 0.01
CLOUD_SUNLIT = 0.6  # a cloud scatters the sun's light from any altitude (bright undersides at sunset)
CLOUD_BASE = 1.05
CLOUD_PIXEL_RAD = 0.0016
# The light table (PackedScene.lights; the frame adds the headlights): one row per lamp.
LIGHT_X, LIGHT_R, LIGHT_POWER, LIGHT_AXIS, LIGHT_BEAM = 0, 3, 6, 7, 10
LIGHT_COLUMNS = 11
BEAM_OMNI, BEAM_STREET, BEAM_LOW = (BEAMS.index(name) for name in ("omni", "street", "low"))
DOWN = (0.0, 0.0, -1.0)
# A full cut-off street lamp: all of its light within STREET_FULL of the nadir (cosine), none beyond STREET_CUT.
STREET_FULL, STREET_CUT = 0.45, 0.17
# A low beam (UN ECE R112's pattern, simplified): a sharp cut-off LOW_CUTOFF below the horizontal (the 1 %
# downward aim) with a stray LOW_ABOVE above it, falling off downwards over LOW_DROP and sideways over LOW_SPREAD
# (tangents of the angles off the beam's axis).
LOW_CUTOFF, LOW_EDGE, LOW_ABOVE, LOW_DROP, LOW_SPREAD = -0.01, 0.012, 0.02, 0.15, 0.45
# Road markings and asphalt send a headlight's light back towards the driver (glass beads; EN 1436's coefficient of
# retroreflected luminance R_L, about 150 mcd/m2/lx for white paint against 15 for asphalt, i.e. about half their
# albedo in the renderer's units): seen from behind its own headlights the road returns RETROREFLECTION times its
# albedo times the beam's irradiance square to it, far more than a diffuse surface lit at a grazing angle. A water
# film drowns the beads (WET_RETRO_LOSS of it is lost on a wet road).
RETROREFLECTION = 0.5
WET_RETRO_LOSS = 0.8


def light_row(p_world: npt.ArrayLike, color: npt.ArrayLike, intensity: float, axis: npt.ArrayLike,
              beam: str) -> FloatArray:
    """(LIGHT_COLUMNS,) float64 row of the light table: position, linear rgb, intensity (radiance scale at 1 m),
    beam axis, beam."""
    return np.concatenate([np.ravel(p_world), np.ravel(color), [intensity], np.ravel(axis),
                           [BEAMS.index(beam)]]).astype(np.float64)


@kernel(inline="always")
def beam_weight(lights: np.ndarray, i: int, qx: float, qy: float, qz: float) -> float:
    """Share of lamp ``i``'s intensity sent along unit direction q (from the lamp towards the lit point)."""
    beam = lights[i, LIGHT_BEAM]
    ax, ay = lights[i, LIGHT_AXIS], lights[i, LIGHT_AXIS + 1]
    weight = 1.0
    if beam == BEAM_STREET:
        weight = min(max((-qz - STREET_CUT) / (STREET_FULL - STREET_CUT), 0.0), 1.0)
    elif beam == BEAM_LOW:
        ahead = qx * ax + qy * ay
        if ahead <= 0.05:
            weight = 0.0
        else:
            side = (ay * qx - ax * qy) / ahead
            up = qz / ahead
            if up > LOW_CUTOFF:
                vertical = max(1.0 - (up - LOW_CUTOFF) / LOW_EDGE, LOW_ABOVE)
            else:
                drop = (up - LOW_CUTOFF) / LOW_DROP
                vertical = np.exp(-drop * drop)
            weight = vertical * np.exp(-(side / LOW_SPREAD) * (side / LOW_SPREAD))
    return weight


@kernel  # called, not inlined: the sky is inlined at four places of the shading kernel
def cloud_cover(dx: float, dy: float, dz: float, coarse: np.ndarray, cloudiness: float) -> float:
    """Opacity in [0, 1] of the cloud deck seen along unit world direction (dx, dy, dz): two octaves of the coarse
    noise on a plane CLOUD_HEIGHT_M up, thresholded so that about ``cloudiness`` of the sky is covered, filtered
    over the pixel's footprint (the far deck near the horizon blurs) and thinning into the haze low down."""
    if cloudiness <= 0.0 or dz <= CLOUD_LOWEST:
        return 0.0
    reach = CLOUD_HEIGHT_M / dz
    x, y, foot = dx * reach, dy * reach, reach * CLOUD_PIXEL_RAD
    shape = sample_noise(coarse, CLOUD_TEXEL_M, x, y, foot) \
        + CLOUD_DETAIL * sample_noise(coarse, CLOUD_TEXEL_M * 0.25, y + 911.0, x, foot)
    edge = CLOUD_MEDIAN + CLOUD_THRESHOLD * (1.0 - 2.0 * cloudiness)  # about the (1 - cloudiness) quantile
    cover = min(max((shape - edge) * CLOUD_SHARPNESS + 0.5, 0.0), 1.0)
    return cover * (1.0 - np.exp(-dz * CLOUD_HAZE))


@kernel(inline="always")
def sky_radiance(dx: float, dy: float, dz: float, sun_dir: np.ndarray, sun_color: np.ndarray, sun_intensity: float,
                 zenith: np.ndarray, horizon: np.ndarray, cloudiness: float,
                 coarse: np.ndarray) -> tuple[float, float, float]:
    """Radiance (r, g, b) of the sky seen along unit world direction (dx, dy, dz): gradient, clouds
    (``cloud_cover``: grey-white, lit by the sun from behind the viewer, darker in their thick cores), the sun's
    disk at its true size (hidden by a cloud in front of it), its aureole and glow."""
    sun_r, sun_g, sun_b = sun_color[0], sun_color[1], sun_color[2]  # read before any branch (see ``_jit``)
    k = np.sqrt(max(dz, 0.0))
    below = 0.85 if dz < 0.0 else 1.0  # below the horizon (seen past the terrain's edge): darker haze
    r = SKY_SCALE * below * (horizon[0] * (1.0 - k) + zenith[0] * k)
    g = SKY_SCALE * below * (horizon[1] * (1.0 - k) + zenith[1] * k)
    b = SKY_SCALE * below * (horizon[2] * (1.0 - k) + zenith[2] * k)
    cos_sun = dx * sun_dir[0] + dy * sun_dir[1] + dz * sun_dir[2]
    cover = cloud_cover(dx, dy, dz, coarse, cloudiness)
    if cover > 0.0:
        grey = SKY_SCALE * (0.2126 * horizon[0] + 0.7152 * horizon[1] + 0.0722 * horizon[2])
        lit = sun_intensity * CLOUD_SUNLIT * (1.0 - cover) + CLOUD_BASE * grey * (1.0 - 0.4 * cover)
        r = r * (1.0 - cover) + (lit * sun_r + 0.1 * grey) * cover
        g = g * (1.0 - cover) + (lit * sun_g + 0.1 * grey) * cover
        b = b * (1.0 - cover) + (lit * sun_b + 0.12 * grey) * cover
    if cos_sun > 0.0 and sun_intensity > 0.0:
        clear = 1.0 - cloudiness
        disk = SUN_DISK_RADIANCE * clear * (1.0 - cover) if cos_sun > SUN_COS_RADIUS else 0.0
        c2 = cos_sun * cos_sun
        c4 = c2 * c2
        c8 = c4 * c4
        c16 = c8 * c8
        halo = np.exp(SUN_AUREOLE_POWER * np.log(cos_sun)) if cos_sun > 0.99 else 0.0
        glow = sun_intensity * (disk + halo * SUN_AUREOLE * clear + c16 * 0.35 * (0.3 + 0.7 * clear))
        r += sun_r * glow
        g += sun_g * glow
        b += sun_b * glow
    return (r, g, b) if coarse.size > 0 else (r, g, b)


@kernel(inline="always")
def _shadow_tap(depth: np.ndarray, c: int, u: float, v: float, d: float, bias: float) -> float:
    """Bilinear percentage-closer test at map coordinates (u, v) (texels)."""
    size = depth.shape[1]
    x = u - 0.5
    y = v - 0.5
    x0 = int(np.floor(x))
    y0 = int(np.floor(y))
    fx = x - x0
    fy = y - y0
    lit = 0.0
    for dy in range(2):
        for dx in range(2):
            xi = min(max(x0 + dx, 0), size - 1)
            yi = min(max(y0 + dy, 0), size - 1)
            w = (fx if dx else 1.0 - fx) * (fy if dy else 1.0 - fy)
            if depth[c, yi, xi] >= d - bias:
                lit += w
    return lit


@kernel(inline="always")
def _window_weights(x: float, radius: float) -> tuple[int, int, float, float, float, float]:
    """The bilinear taps at x - radius, x and x + radius (texels) along one axis as weights of the four
    consecutive texels from ``first``: (first, span, w0, w1, w2, w3). The four hold every tap when ``span`` (the
    last tap's first texel minus the first tap's) is at most 2."""
    a, b, c = x - radius - 0.5, x - 0.5, x + radius - 0.5
    ia, ib, ic = int(np.floor(a)), int(np.floor(b)), int(np.floor(c))
    fa, fb, fc = a - ia, b - ib, c - ic
    ob, oc = ib - ia, ic - ia
    w0 = 1.0 - fa + (1.0 - fb if ob == 0 else 0.0)
    w1 = fa + (fb if ob == 0 else 0.0) + (1.0 - fb if ob == 1 else 0.0) + (1.0 - fc if oc == 1 else 0.0)
    w2 = (fb if ob == 1 else 0.0) + (1.0 - fb if ob == 2 else 0.0) + (fc if oc == 1 else 0.0) \
        + (1.0 - fc if oc == 2 else 0.0)
    w3 = (fb if ob == 2 else 0.0) + (fc if oc == 2 else 0.0)
    return ia, oc, w0, w1, w2, w3


@kernel(inline="always")
def _window_row(depth: np.ndarray, c: int, y: int, x: int, limit: float, w0: float, w1: float, w2: float,
                w3: float) -> float:
    """The sum of the weights of texels x .. x + 3 of map row ``y`` lit at ``limit``. The window lies inside the
    map: the point is 2 texels inside it (``sun_visibility``) and a window's taps reach less than 1.5 texels
    around it (its span is at most 2), so the four reads are contiguous and unclamped."""
    lit = w0 if depth[c, y, x] >= limit else 0.0
    lit += w1 if depth[c, y, x + 1] >= limit else 0.0
    lit += w2 if depth[c, y, x + 2] >= limit else 0.0
    lit += w3 if depth[c, y, x + 3] >= limit else 0.0
    return lit


SUN_OFFSET, SUN_BIAS = range(2)  # face_sun_terms columns


def face_sun_terms(face_normal: np.ndarray, sun_dir_world: np.ndarray) -> np.ndarray:
    """(m, 2) float64 per face, for the sun lighting its front or back: the normal offset of shadow lookups (m)
    and the depth bias in texels. Both grow with the slope of the face to the light, so grazing-lit faces do not
    self-shadow (the offset moves the lookup off the surface, the bias tolerates the depth change across a
    texel)."""
    n_dot_l = np.abs(np.asarray(face_normal, np.float64) @ np.asarray(sun_dir_world, np.float64))
    slope = np.minimum(np.sqrt(np.maximum(1.0 - n_dot_l * n_dot_l, 0.0)) / np.maximum(n_dot_l, 0.05), 8.0)
    return np.stack([NORMAL_OFFSET_M * (1.0 + np.minimum(slope, 4.0)), 1.5 + 1.5 * slope], axis=-1)


@kernel(inline="always")
def _visibility_at(maps: np.ndarray, cells: np.ndarray, c: int, x: float, y: float, d: float, bias: float,
                   scale: float, penumbra: float) -> float:
    """Fraction of the sun seen at map coordinates (x, y) (texels, at least 2 inside the map) of cascade ``c`` by
    a point at light depth ``d``, with contact-hardening soft edges.

    The soft edge's taps reach less than 2**COARSE_SHIFT texels, so the point's dilated coarse cell answers
    "all lit" (its nearest caster is behind the point) and "all shaded" (its farthest one is in front); only
    between the two are the taps read.
    """
    size = maps.shape[1]
    cell_y, cell_x = int(y) >> COARSE_SHIFT, int(x) >> COARSE_SHIFT
    nearest = cells[c, cell_y, cell_x, NEAR_AROUND]
    lit = 1.0
    if nearest >= d - bias:
        lit = 1.0
    elif cells[c, cell_y, cell_x, FAR_AROUND] < d - bias:
        lit = 0.0
    else:
        # The caster right above the point (else the nearest one around) sets the penumbra width.
        z_center = maps[c, min(int(y), size - 1), min(int(x), size - 1)]
        blocker = z_center if z_center < d - bias else nearest
        radius = max(0.7, min(penumbra * (d - blocker) * scale, PCF_MAX_TEXELS))
        x0, x_span, wx0, wx1, wx2, wx3 = _window_weights(x, radius)
        y0, y_span, wy0, wy1, wy2, wy3 = _window_weights(y, radius)
        if x_span <= 2 and y_span <= 2:  # a narrow soft edge: the nine taps read a 4x4 window of texels
            limit = d - bias
            taps = wy0 * _window_row(maps, c, y0, x0, limit, wx0, wx1, wx2, wx3)
            taps += wy1 * _window_row(maps, c, y0 + 1, x0, limit, wx0, wx1, wx2, wx3)
            taps += wy2 * _window_row(maps, c, y0 + 2, x0, limit, wx0, wx1, wx2, wx3)
            taps += wy3 * _window_row(maps, c, y0 + 3, x0, limit, wx0, wx1, wx2, wx3)
        else:
            taps = 0.0
            for j in range(-1, 2):
                for i in range(-1, 2):
                    taps += _shadow_tap(maps, c, x + i * radius, y + j * radius, d, bias)
        lit = taps / 9.0
    # Every path ends on a use of both arrays, so numba releases them in one place (see ``_jit``).
    return lit if maps.shape[0] == cells.shape[0] else lit


@kernel(inline="always")
def _cells_decide(cells: np.ndarray, c: int, x_lo: float, x_hi: float, y_lo: float, y_hi: float, d_lo: float,
                  d_hi: float) -> float:
    """1 when every point of the map box [x_lo, x_hi] x [y_lo, y_hi] (texels) at light depths up to ``d_hi`` is
    lit by the coarse test of its own cell, 0 when every one at depths from ``d_lo`` is shaded, else -1 (read the
    taps)."""
    lit, shaded = True, True
    for cell_y in range(int(y_lo) >> COARSE_SHIFT, (int(y_hi) >> COARSE_SHIFT) + 1):
        for cell_x in range(int(x_lo) >> COARSE_SHIFT, (int(x_hi) >> COARSE_SHIFT) + 1):
            lit = lit and cells[c, cell_y, cell_x, NEAR_AROUND] >= d_hi
            shaded = shaded and cells[c, cell_y, cell_x, FAR_AROUND] < d_lo
    decided = 1.0 if lit else (0.0 if shaded else -1.0)
    return decided if cells.shape[0] > 0 else decided


@kernel(inline="always")
def _light_space(q0: float, q1: float, q2: float, R_light: np.ndarray) -> tuple[float, float, float]:
    """World point (or step) q in the sun's frame: (u, v) across the shadow maps (m), d its depth along the light."""
    u = R_light[0, 0] * q0 + R_light[0, 1] * q1 + R_light[0, 2] * q2
    v = R_light[1, 0] * q0 + R_light[1, 1] * q1 + R_light[1, 2] * q2
    d = R_light[2, 0] * q0 + R_light[2, 1] * q1 + R_light[2, 2] * q2
    return u, v, d


@kernel(inline="always")
def _cascade_of(u: float, v: float, params: np.ndarray, size: int) -> tuple[int, float, float, float]:
    """(cascade, x, y, texels per metre): the first cascade whose map holds light-space point (u, v) at least 2
    texels inside, and the point's map coordinates there; the cascade count when none does."""
    c = 0
    x = y = scale = 0.0
    while c < params.shape[0]:
        scale = params[c, 2]
        x = (u - params[c, 0]) * scale
        y = (v - params[c, 1]) * scale
        if x >= 2 and y >= 2 and x <= size - 2 and y <= size - 2:
            break
        c += 1
    return (c, x, y, scale) if params.shape[1] > 0 else (c, x, y, scale)


@kernel(inline="always")
def sun_visibility(px: float, py: float, pz: float, nx: float, ny: float, nz: float, offset: float,
                   bias_texels: float, maps: np.ndarray, cells: np.ndarray, params: np.ndarray, R_light: np.ndarray,
                   penumbra: float) -> float:
    """Fraction of the sun seen from world point ``p`` (1 = lit), with contact-hardening soft edges (see
    ``_visibility_at``). ``offset`` (m, along the normal) and ``bias_texels`` are the face's ``face_sun_terms``."""
    u, v, d = _light_space(px + nx * offset, py + ny * offset, pz + nz * offset, R_light)
    c, x, y, scale = _cascade_of(u, v, params, maps.shape[1])
    lit = 1.0
    if c < maps.shape[0]:
        lit = _visibility_at(maps, cells, c, x, y, d, bias_texels / scale, scale, penumbra)
    # Every path ends on a use of the four arrays, so numba releases them in one place (see ``_jit``).
    return lit if maps.shape[0] == cells.shape[0] == params.shape[0] and R_light.shape[0] == 3 else lit


@kernel(inline="always")
def sun_visibility_over(px: float, py: float, pz: float, nx: float, ny: float, nz: float, offset: float,
                        bias_texels: float, maps: np.ndarray, cells: np.ndarray, params: np.ndarray,
                        R_light: np.ndarray, penumbra: float, du: tuple[float, float, float],
                        dv: tuple[float, float, float]) -> float:
    """Fraction of the sun seen from world point ``p`` (1 = lit), averaged over the pixel's footprint, the
    parallelogram p + a du + b dv (|a|, |b| <= 1/2; du, dv are the world steps of one pixel across and down on
    the surface; zero steps read the point alone, as ``sun_visibility`` does).

    ``offset`` (m, along the normal) and ``bias_texels`` are the face's ``face_sun_terms``. Each side is read
    once per FOOTPRINT_TAP_TEXELS of its length on the surface, at most FOOTPRINT_TAPS, all in the cascade that holds
    p: shadows finer than a pixel (a slatted fence's far off) average to their share of shade instead of beating
    with the pixel grid (moire). When the coarse cells under the whole footprint agree, no tap is read.
    """
    u, v, d = _light_space(px + nx * offset, py + ny * offset, pz + nz * offset, R_light)
    size = maps.shape[1]
    c, x, y, scale = _cascade_of(u, v, params, size)
    lit = 1.0
    if c < maps.shape[0]:
        bias = bias_texels / scale
        per_tap = scale / FOOTPRINT_TAP_TEXELS
        n_u = min(int(np.sqrt(du[0] * du[0] + du[1] * du[1] + du[2] * du[2]) * per_tap) + 1, FOOTPRINT_TAPS)
        n_v = min(int(np.sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]) * per_tap) + 1, FOOTPRINT_TAPS)
        lo, hi = 2.0, size - 2.0
        ux = uy = ud = vx = vy = vd = 0.0  # the footprint's sides in the map (texels) and in light depth (m)
        lit = -1.0
        if n_u * n_v > 1:
            ux, uy, ud = _light_space(du[0], du[1], du[2], R_light)
            vx, vy, vd = _light_space(dv[0], dv[1], dv[2], R_light)
            ux, uy, vx, vy = ux * scale, uy * scale, vx * scale, vy * scale
            hx, hy, hd = 0.5 * (abs(ux) + abs(vx)), 0.5 * (abs(uy) + abs(vy)), 0.5 * (abs(ud) + abs(vd))
            lit = _cells_decide(cells, c, max(x - hx, lo), min(x + hx, hi), max(y - hy, lo), min(y + hy, hi),
                                d - hd - bias, d + hd - bias)
        if lit < 0.0:  # one loop for one tap or many: the soft-edge code is inlined once (see ``_jit``)
            total = 0.0
            for j in range(n_v):
                b = (j + 0.5) / n_v - 0.5
                for i in range(n_u):
                    a = (i + 0.5) / n_u - 0.5
                    total += _visibility_at(maps, cells, c, min(max(x + a * ux + b * vx, lo), hi),
                                            min(max(y + a * uy + b * vy, lo), hi), d + a * ud + b * vd, bias, scale,
                                            penumbra)
            lit = total / (n_u * n_v)
    # Every path ends on a use of the four arrays, so numba releases them in one place (see ``_jit``).
    return lit if maps.shape[0] == cells.shape[0] == params.shape[0] and R_light.shape[0] == 3 else lit


@kernel(inline="always")
def sky_openness(openness: np.ndarray, params: np.ndarray, px: float, py: float) -> float:
    """Share of the sky's light reaching ground point (px, py): 1 in the open, less under roofs and decks and
    beside what stands on the ground (bilinear between the map's cell centres)."""
    height, width = openness.shape
    x = (px - params[0]) * params[2] - 0.5
    y = (py - params[1]) * params[2] - 0.5
    if x < 0.0 or y < 0.0 or x >= width - 1 or y >= height - 1:
        return 1.0
    i, j = int(y), int(x)
    fy, fx = y - i, x - j
    top = openness[i, j] + (openness[i, j + 1] - openness[i, j]) * fx
    below = openness[i + 1, j] + (openness[i + 1, j + 1] - openness[i + 1, j]) * fx
    return top + (below - top) * fy


@kernel(inline="always")
def fresnel_schlick(cos_theta: float, f0: float) -> float:
    m = 1.0 - max(min(cos_theta, 1.0), 0.0)
    return f0 + (1.0 - f0) * m * m * m * m * m


@kernel(inline="always")
def lobe_shape(roughness: float) -> tuple[float, float, float]:
    """(exponent, normalisation, cutoff) of a normalised Blinn-Phong lobe standing in for GGX: narrow and tall for
    smooth water, wide for asphalt. Below ``cutoff`` (of n.h) the lobe is under LOBE_FLOOR of its peak."""
    alpha = max(roughness * roughness, 1e-4)
    exponent = 2.0 / alpha - 2.0
    return exponent, (exponent + 2.0) / (2.0 * np.pi), np.exp(np.log(LOBE_FLOOR) / max(exponent, 1.0))


@kernel(inline="always")
def glossy_lobe(n_dot_h: float, exponent: float, normalisation: float, cutoff: float) -> float:
    """The lobe at n.h (0 below the cutoff, where it is negligible; skips the power for most pixel-lamp pairs)."""
    if n_dot_h <= cutoff:
        return 0.0
    return normalisation * np.exp(exponent * np.log(n_dot_h))
