"""Light transport pieces (numba): sky radiance, sun shadows, Fresnel and glossy highlights."""

from __future__ import annotations

import numpy as np

# The irradiance unit, set in world/environment.py beside the daylight models: SUN_SCALE is a clear noon sun's
# irradiance relative to the sky's ambient unit, SKY_AMBIENT_GAIN the sky's ambient light per unit of its colour.
from ..world.environment import SKY_AMBIENT_GAIN as SKY_AMBIENT_GAIN
from ..world.environment import SUN_SCALE as SUN_SCALE
from ._jit import kernel

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


@kernel(inline="always")
def sky_radiance(dx: float, dy: float, dz: float, sun_dir: np.ndarray, sun_color: np.ndarray, sun_intensity: float,
                 zenith: np.ndarray, horizon: np.ndarray, cloudiness: float) -> tuple[float, float, float]:
    """Radiance (r, g, b) of the sky seen along unit world direction (dx, dy, dz): gradient, sun disk, glow."""
    sun_r, sun_g, sun_b = sun_color[0], sun_color[1], sun_color[2]  # read before any branch (see ``_jit``)
    k = np.sqrt(max(dz, 0.0))
    below = 0.85 if dz < 0.0 else 1.0  # below the horizon (seen past the terrain's edge): darker haze
    r = SKY_SCALE * below * (horizon[0] * (1.0 - k) + zenith[0] * k)
    g = SKY_SCALE * below * (horizon[1] * (1.0 - k) + zenith[1] * k)
    b = SKY_SCALE * below * (horizon[2] * (1.0 - k) + zenith[2] * k)
    cos_sun = dx * sun_dir[0] + dy * sun_dir[1] + dz * sun_dir[2]
    if cos_sun > 0.0 and sun_intensity > 0.0:
        clear = 1.0 - cloudiness
        disk = 60.0 * clear if cos_sun > 0.99996 else 0.0
        c2 = cos_sun * cos_sun
        c4 = c2 * c2
        c8 = c4 * c4
        c16 = c8 * c8
        halo = np.exp(400.0 * np.log(cos_sun)) if cos_sun > 0.97 else 0.0
        glow = sun_intensity * (disk + halo * 3.0 * clear + c16 * 0.35 * (0.3 + 0.7 * clear))
        r += sun_r * glow
        g += sun_g * glow
        b += sun_b * glow
    return r, g, b


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
    """Share of the sky's light reaching ground point (px, py): 1 in the open, less under roofs and decks."""
    height, width = openness.shape
    x = int((px - params[0]) * params[2])
    y = int((py - params[1]) * params[2])
    if x < 0 or y < 0 or x >= width or y >= height:
        return 1.0
    return openness[y, x]


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
