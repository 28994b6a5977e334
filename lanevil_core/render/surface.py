"""Procedural road-surface material, evaluated per pixel in road coordinates with analytic antialiasing.

Every pattern is box-filtered over the pixel's footprint in (s, t) so thin paint and cracks stay stable from
frame to frame instead of shimmering.
"""

from __future__ import annotations

import numpy as np

from ..world.paint import MAX_CORNERS, PAINT_WEAR, POLYGON, POLYGON_CORNERS
from ._jit import kernel
from .textures import NOISE_LEVELS, NOISE_SIZE, level_offset

MAX_ANISO = 6
# Worn paint: the share left where the chip noise is n is 1 - wear (1 + CHIP_CONTRAST n), so chips come and go along
# the line and a far pixel (noise filtered towards 0) sees the line faded to 1 - wear; what is left is dirtier.
CHIP_CONTRAST = 2.0
CHIP_TEXEL_M = 0.05
DIRT_DIMMING = 0.35
# Worn paint's edges: where the edge noise is n > 0 an edge is eaten in by wear * RAGGED_BITE * n of the half width.
RAGGED_BITE = 0.7
RAGGED_TEXEL_M = 0.03
RAGGED_STRETCH = 0.15  # the bites run about 7 times longer along the line than across it
# Botts' dots: a ceramic dome; its rim, tilted away from the sky, is darker than its crown.
DOME_RIM_DARKENING = 0.45
DOME_MEAN_SHADE = 1.0 - DOME_RIM_DARKENING / 2  # the mean of 1 - k (d / r)^2 over the disc
SQRT_PI = float(np.sqrt(np.pi))


@kernel(inline="always")
def box_overlap(x: float, width: float, lo: float, hi: float) -> float:
    """Fraction of the interval [x - width/2, x + width/2] that lies inside [lo, hi]."""
    a = max(x - 0.5 * width, lo)
    b = min(x + 0.5 * width, hi)
    return max(b - a, 0.0) / width


@kernel(inline="always")
def _periodic_integral(x: float, on: float, period: float) -> float:
    """Integral from 0 to x of a pattern that is 1 on [0, on) of every period."""
    k = np.floor(x / period)
    r = x - k * period
    return k * on + min(r, on)


@kernel(inline="always")
def dash_coverage(s: float, width: float, on: float, period: float) -> float:
    """Share of [s - width/2, s + width/2] covered by dashes of length ``on`` repeating every ``period``."""
    a, b = s - 0.5 * width, s + 0.5 * width
    return (_periodic_integral(b, on, period) - _periodic_integral(a, on, period)) / width


@kernel(inline="always")
def sample_noise(pyramid: np.ndarray, texel_m: float, s: float, t: float, footprint_m: float) -> float:
    """Bilinear sample of a tiled mip pyramid (``textures.noise_textures``) at road position (s, t), in the level
    whose texel covers the footprint. Weights and texel indices are those of level 0; each index is read in the
    level at index >> level, so a coarse level is sampled as blocks of 2^level texels with bilinear seams."""
    level = 0
    ratio = footprint_m / texel_m
    while ratio > 1.0 and level < NOISE_LEVELS - 1:
        ratio *= 0.5
        level += 1
    x = s / texel_m
    y = t / texel_m
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = x - x0
    fy = y - y0
    mask = NOISE_SIZE - 1  # a power of two, so wrapping is a bit mask even for negative coordinates
    i0 = int(x0) & mask
    j0 = int(y0) & mask
    i1 = ((i0 + 1) & mask) >> level
    j1 = ((j0 + 1) & mask) >> level
    i0 >>= level
    j0 >>= level
    side = NOISE_SIZE >> level
    base = level_offset(level)
    a = pyramid[base + i0 * side + j0] * (1 - fy) + pyramid[base + i0 * side + j1] * fy
    b = pyramid[base + i1 * side + j0] * (1 - fy) + pyramid[base + i1 * side + j1] * fy
    return a * (1 - fx) + b * fx


@kernel(inline="always")
def dot_coverage(ds: float, dt: float, fs: float, ft: float, radius: float) -> tuple[float, float]:
    """(coverage, shade) of a round raised marker of ``radius`` centred (ds, dt) from the pixel, over a footprint
    (fs, ft). Near the camera the disc's edge is filtered over the footprint and the dome is lit less towards its
    rim (its side faces away from the sky); a footprint over twice the diameter sees the disc's area spread over
    the footprint, and the dome's mean shade."""
    d = np.sqrt(ds * ds + dt * dt)
    foot = 0.5 * (fs + ft)
    disc = min(max((radius - d) / foot + 0.5, 0.0), 1.0)
    rim = min(d / radius, 1.0)
    near_shade = 1.0 - DOME_RIM_DARKENING * rim * rim
    side = radius * SQRT_PI  # the square of the disc's area
    spread = box_overlap(ds, fs, -0.5 * side, 0.5 * side) * box_overlap(dt, ft, -0.5 * side, 0.5 * side)
    far = min(max(max(fs, ft) / (2.0 * radius) - 1.0, 0.0), 1.0)
    return disc * (1.0 - far) + spread * far, near_shade * (1.0 - far) + DOME_MEAN_SHADE * far


@kernel(inline="always")
def _clamped_integral(lo: float, hi: float, xa: float, ya: float, slope: float, y0: float, y1: float) -> float:
    """Integral over x in [lo, hi] of clamp(ya + slope (x - xa), y0, y1) - y0: linear between the points where the
    line crosses y0 and y1, so each of the three pieces is its length times its middle's value."""
    if hi <= lo:
        return 0.0
    p, q = lo, hi
    if slope != 0.0:
        c0 = min(max(xa + (y0 - ya) / slope, lo), hi)
        c1 = min(max(xa + (y1 - ya) / slope, lo), hi)
        p, q = min(c0, c1), max(c0, c1)
    total = 0.0
    for a, b in ((lo, p), (p, q), (q, hi)):
        if b > a:
            total += (b - a) * (min(max(ya + slope * (0.5 * (a + b) - xa), y0), y1) - y0)
    return total


@kernel(inline="always")
def polygon_coverage(row: np.ndarray, s: float, t: float, fs: float, ft: float) -> float:
    """Share of the footprint [s -+ fs/2] x [t -+ ft/2] inside the convex polygon of a stripe row (its corners,
    counter-clockwise in (s, t)): the exact box filter, by Green's theorem, area = -sum over the edges of the
    integral of (t - t_lo) ds, with s and t clamped to the footprint."""
    s0, s1 = s - 0.5 * fs, s + 0.5 * fs
    t0, t1 = t - 0.5 * ft, t + 0.5 * ft
    area = 0.0
    for k in range(MAX_CORNERS):
        j = (k + 1) % MAX_CORNERS
        sa, ta = row[POLYGON_CORNERS + 2 * k], row[POLYGON_CORNERS + 2 * k + 1]
        sb, tb = row[POLYGON_CORNERS + 2 * j], row[POLYGON_CORNERS + 2 * j + 1]
        if sa == sb:
            continue
        slope = (tb - ta) / (sb - sa)
        ua, ub = min(max(sa, s0), s1), min(max(sb, s0), s1)
        if ub > ua:
            area -= _clamped_integral(ua, ub, sa, ta, slope, t0, t1)
        else:
            area += _clamped_integral(ub, ua, sa, ta, slope, t0, t1)
    return min(max(area / (fs * ft), 0.0), 1.0)


@kernel(inline="always")
def paint(stripes: np.ndarray, lo: int, hi: int, s: float, t: float, fs: float, ft: float,
          r: float, g: float, b: float, chips: float, ragged: float) -> tuple[float, float, float]:
    """(r, g, b) with the paint of stripes[lo:hi] blended over it; ``chips`` (noise in [-1, 1], filtered over the
    pixel) is where worn paint has flaked off, ``ragged`` (likewise) where its edges are eaten away. The rows of
    one slot start in order along the road, so the first that starts beyond the footprint ends the walk."""
    for k in range(lo, hi):
        s0, s1 = stripes[k, 3], stripes[k, 4]
        if s0 >= s + 0.5 * fs:
            break
        t_c, half = stripes[k, 1], stripes[k, 2]
        if abs(t - t_c) > half + ft:
            continue
        span = box_overlap(s, fs, s0, s1)
        if span <= 0.0:
            continue
        wear = stripes[k, PAINT_WEAR]
        polygon = stripes[k, 5] > POLYGON - 0.5
        dots = stripes[k, 5] > 1.5 and not polygon
        shade = 1.0
        if polygon:
            cov = polygon_coverage(stripes[k], s, t, fs, ft)
        elif dots:
            period = stripes[k, 7]
            ds = s - s0 - half
            ds -= np.floor(ds / period + 0.5) * period  # from the nearest dot's centre
            cov, shade = dot_coverage(ds, t - t_c, fs, ft, half)
        elif wear > 0.0:  # worn edges: eaten in by up to RAGGED_BITE of the half width where ``ragged`` > 0
            bite = half * RAGGED_BITE * wear * max(ragged, 0.0)
            cov = box_overlap(t, ft, t_c - half + bite, t_c + half - bite)
        else:
            cov = box_overlap(t, ft, t_c - half, t_c + half)
        if not polygon:
            cov *= span
        if cov <= 0.0:
            continue
        if stripes[k, 5] > 0.5 and not dots and not polygon:
            cov *= dash_coverage(s - s0, fs, stripes[k, 6], stripes[k, 7])
        dirt = 1.0
        if wear > 0.0:
            cov *= min(max(1.0 - wear * (1.0 + CHIP_CONTRAST * chips), 0.0), 1.0)
            dirt = 1.0 - DIRT_DIMMING * wear
        dirt *= shade
        r = r * (1.0 - cov) + stripes[k, 8] * dirt * cov
        g = g * (1.0 - cov) + stripes[k, 9] * dirt * cov
        b = b * (1.0 - cov) + stripes[k, 10] * dirt * cov
    return r, g, b


@kernel(inline="always")
def boundaries_near(lanes: float, lane_width: float, last: int, t: float, ft: float) -> tuple[int, int]:
    """(k0, k1): the lane boundaries whose paint can reach a pixel at ``t`` (boundary k: t = (n - k) w)."""
    k0 = max(int(np.floor(lanes - (t + ft + 0.5) / lane_width + 0.5)), 0)
    k1 = min(int(np.floor(lanes - (t - ft - 0.5) / lane_width + 0.5)), last - 1)
    return k0, k1


@kernel(inline="always")
def _bilinear5(texels: np.ndarray, table: np.ndarray, level: int, s: float, t: float, s0: float,
               t0: float) -> tuple[float, float, float, float, float]:
    """Bilinear sample (premultiplied r, g, b, alpha, wet) of one mip level at road point (s, t)."""
    texel = table[level, 3]
    rows, cols, offset = int(table[level, 4]), int(table[level, 5]), int(table[level, 6])
    y = (s - s0) / texel - 0.5
    x = (t - t0) / texel - 0.5
    y0 = min(max(int(np.floor(y)), 0), rows - 1)
    x0 = min(max(int(np.floor(x)), 0), cols - 1)
    y1 = min(y0 + 1, rows - 1)
    x1 = min(x0 + 1, cols - 1)
    fy = min(max(y - y0, 0.0), 1.0)
    fx = min(max(x - x0, 0.0), 1.0)
    w00 = (1 - fx) * (1 - fy)
    w01 = fx * (1 - fy)
    w10 = (1 - fx) * fy
    w11 = fx * fy
    a = offset + y0 * cols
    b = offset + y1 * cols
    out0 = w00 * texels[a + x0, 0] + w01 * texels[a + x1, 0] + w10 * texels[b + x0, 0] + w11 * texels[b + x1, 0]
    out1 = w00 * texels[a + x0, 1] + w01 * texels[a + x1, 1] + w10 * texels[b + x0, 1] + w11 * texels[b + x1, 1]
    out2 = w00 * texels[a + x0, 2] + w01 * texels[a + x1, 2] + w10 * texels[b + x0, 2] + w11 * texels[b + x1, 2]
    out3 = w00 * texels[a + x0, 3] + w01 * texels[a + x1, 3] + w10 * texels[b + x0, 3] + w11 * texels[b + x1, 3]
    out4 = w00 * texels[a + x0, 4] + w01 * texels[a + x1, 4] + w10 * texels[b + x0, 4] + w11 * texels[b + x1, 4]
    return out0, out1, out2, out3, out4


@kernel(inline="always")
def _anisotropy(fs: float, ft: float) -> tuple[float, float, int]:
    """(short, long, taps): the footprint's short axis (the mip level's width, at least long / MAX_ANISO), its
    long axis and the samples spread along it."""
    short = min(fs, ft)
    long = max(fs, ft)
    taps = min(int(np.ceil(long / max(short, 1e-6))), MAX_ANISO)
    return max(short, long / MAX_ANISO), long, taps


@kernel(inline="always")
def sample_layers(texels: np.ndarray, table: np.ndarray, first: np.ndarray, piece: int, s: float, t: float,
                  fs: float, ft: float, over_paint: bool, r: float, g: float,
                  b: float) -> tuple[float, float, float, float]:
    """(r, g, b, wet): every surface layer of ``piece`` (under or over paint) blended over (r, g, b), and the
    puddle wetness there.

    Anisotropic filtering: the mip level follows the pixel's short footprint axis and up to MAX_ANISO samples
    spread along the long one, so marks running along the road stay sharp far ahead.
    """
    wet = 0.0
    for layer in range(first.size - 1):
        row0 = first[layer]
        if int(table[row0, 0]) != piece or (table[row0, 7] > 0.5) != over_paint:
            continue
        s0, t0, texel0 = table[row0, 1], table[row0, 2], table[row0, 3]
        rows0, cols0 = table[row0, 4], table[row0, 5]
        if s < s0 or t < t0 or s >= s0 + rows0 * texel0 or t >= t0 + cols0 * texel0:
            continue
        short, long, taps = _anisotropy(fs, ft)
        level = row0
        ratio = short / texel0
        while ratio > 1.0 and level < first[layer + 1] - 1:
            ratio *= 0.5
            level += 1
        pr = pg = pb = alpha = w = 0.0
        for k in range(taps):
            offset = ((k + 0.5) / taps - 0.5) * long
            if fs >= ft:
                q0, q1, q2, q3, q4 = _bilinear5(texels, table, level, s + offset, t, s0, t0)
            else:
                q0, q1, q2, q3, q4 = _bilinear5(texels, table, level, s, t + offset, s0, t0)
            pr += q0
            pg += q1
            pb += q2
            alpha += q3
            w += q4
        inv = 1.0 / taps
        alpha *= inv
        r = r * (1.0 - alpha) + pr * inv  # premultiplied
        g = g * (1.0 - alpha) + pg * inv
        b = b * (1.0 - alpha) + pb * inv
        wet = max(wet, w * inv)
    return r, g, b, wet
