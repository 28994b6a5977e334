"""Per-pixel shading (numba): road material, objects, sun + sky + lamps, wet reflections, fog.

Inputs are the rasterizer's fragments; output is linear HDR radiance. World positions are rebuilt from depth
and the pixel's camera ray, road coordinates from the face's vertex (s, t) and the barycentric weights.
"""

from __future__ import annotations

import numpy as np

from ._jit import kernel

from .lighting import SUN_SCALE, fresnel_schlick, glossy_lobe, sky_openness, sky_radiance, sun_visibility
from .surface import paint, sample_layers, sample_noise
from .textures import COARSE_TEXEL_M, FINE_TEXEL_M

# env_f layout
SUN_I, AMBIENT, WETNESS, PUDDLES, FOG_DENSITY, FOG_DISTANCE, CLOUD, PENUMBRA = range(8)
ASPHALT, CONCRETE, KERB = 0, 1, 4
WET_FILM_MIRROR = 0.45  # a wet film mirrors less than standing water
FOG_LUT_SIZE = 8192
FOG_LUT_PER_M = 4.0


@kernel
def road_coordinates(face_buf: np.ndarray, bary_buf: np.ndarray, faces: np.ndarray, vertex_st: np.ndarray,
                     vertex_piece: np.ndarray, face_material: np.ndarray, st_buf: np.ndarray,
                     piece_buf: np.ndarray) -> None:
    """Interpolate road-frame (s, t) and the piece index for every road-surface pixel (piece -1 elsewhere)."""
    height, width = face_buf.shape
    for row in range(height):
        for col in range(width):
            f = face_buf[row, col]
            if f < 0 or face_material[f] < 0:
                piece_buf[row, col] = -1
                continue
            b1 = bary_buf[row, col, 0]
            b2 = bary_buf[row, col, 1]
            b0 = 1.0 - b1 - b2
            i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
            st_buf[row, col, 0] = b0 * vertex_st[i0, 0] + b1 * vertex_st[i1, 0] + b2 * vertex_st[i2, 0]
            st_buf[row, col, 1] = b0 * vertex_st[i0, 1] + b1 * vertex_st[i1, 1] + b2 * vertex_st[i2, 1]
            piece_buf[row, col] = vertex_piece[i0]


@kernel(inline="always")
def _difference(st_buf: np.ndarray, piece_buf: np.ndarray, row: int, col: int, drow: int, dcol: int,
                axis: int) -> float:
    height, width = piece_buf.shape
    p = piece_buf[row, col]
    r2, c2 = row + drow, col + dcol
    if 0 <= r2 < height and 0 <= c2 < width and piece_buf[r2, c2] == p:
        return abs(st_buf[r2, c2, axis] - st_buf[row, col, axis])
    r2, c2 = row - drow, col - dcol
    if 0 <= r2 < height and 0 <= c2 < width and piece_buf[r2, c2] == p:
        return abs(st_buf[r2, c2, axis] - st_buf[row, col, axis])
    return 0.0


@kernel
def shade(
    face_buf, depth_buf, st_buf, piece_buf, R_wc, c_world, fx, fy, cx, cy,
    face_material, face_color, face_emission, face_gloss, face_normal, material_albedo,
    stripes, stripe_range, layer_texels, layer_table, layer_first, lights,
    noise_fine, noise_coarse, env_f, sun_dir, sun_color, zenith, horizon,
    shadow_depth, shadow_coarse, shadow_params, R_light, overhead, overhead_params, refl_rgb, refl_depth, out,
):
    height, width = face_buf.shape
    rgb = np.empty(3)
    sky = np.empty(3)
    d_world = np.empty(3)
    p = np.empty(3)
    n = np.empty(3)
    refl = np.empty(3)
    ambient_rgb = np.empty(3)
    light = np.empty(3)
    spec = np.empty(3)
    r = np.empty(3)
    scratch = np.empty(5)
    for c in range(3):
        ambient_rgb[c] = env_f[AMBIENT] * (0.5 * horizon[c] + 0.5 * zenith[c]) * 2.2
    fog_rgb = np.empty(3)
    for c in range(3):
        fog_rgb[c] = horizon[c] * 1.6 * (0.25 + 0.75 * min(env_f[AMBIENT] * 3.0, 1.0))
    sun_i = env_f[SUN_I]
    fog_lut = np.empty(FOG_LUT_SIZE)
    for i in range(FOG_LUT_SIZE):
        fog_lut[i] = 1.0 - np.exp(-env_f[FOG_DENSITY] * max((i + 0.5) / FOG_LUT_PER_M - env_f[FOG_DISTANCE], 0.0))
    for row in range(height):
        y_cam = (row + 0.5 - cy) / fy
        for col in range(width):
            x_cam = (col + 0.5 - cx) / fx
            norm = np.sqrt(x_cam * x_cam + y_cam * y_cam + 1.0)
            for i in range(3):
                d_world[i] = (R_wc[i, 0] * x_cam + R_wc[i, 1] * y_cam + R_wc[i, 2]) / norm
            f = face_buf[row, col]
            if f < 0:
                sky_radiance(d_world, sun_dir, sun_color, sun_i, zenith, horizon, env_f[CLOUD], sky)
                for c in range(3):
                    out[row, col, c] = sky[c]
                continue
            depth = depth_buf[row, col]
            dist = depth * norm
            for i in range(3):
                p[i] = c_world[i] + d_world[i] * dist
                n[i] = face_normal[f, i]
            n_dot_v = -(n[0] * d_world[0] + n[1] * d_world[1] + n[2] * d_world[2])
            if n_dot_v < 0.0:  # back side of a two-sided face
                for i in range(3):
                    n[i] = -n[i]
                n_dot_v = -n_dot_v
            material = face_material[f]
            wet = 0.0
            gloss = face_gloss[f]
            roughness = 0.35
            f0 = 0.04
            if material >= 0:
                piece = piece_buf[row, col]
                s = st_buf[row, col, 0]
                t = st_buf[row, col, 1]
                fs = 0.75 * (_difference(st_buf, piece_buf, row, col, 0, 1, 0)
                             + _difference(st_buf, piece_buf, row, col, 1, 0, 0)) + 1e-3
                ft = 0.75 * (_difference(st_buf, piece_buf, row, col, 0, 1, 1)
                             + _difference(st_buf, piece_buf, row, col, 1, 0, 1)) + 1e-3
                footprint = max(fs, ft)
                grain = sample_noise(noise_fine, FINE_TEXEL_M, s, t, footprint)
                blotch = sample_noise(noise_coarse, COARSE_TEXEL_M, s * 0.5, t, footprint)
                for c in range(3):
                    rgb[c] = material_albedo[material, c] * (1.0 + 0.35 * grain) * (1.0 + 0.18 * blotch)
                if material == ASPHALT:
                    wet = sample_layers(layer_texels, layer_table, layer_first, piece, s, t, fs, ft, False, rgb,
                                        scratch)
                    paint(stripes, stripe_range[piece, 0], stripe_range[piece, 1], s, t, fs, ft, rgb)
                    wet = max(wet, sample_layers(layer_texels, layer_table, layer_first, piece, s, t, fs, ft,
                                                 True, rgb, scratch))
                    puddles = env_f[PUDDLES]
                    if puddles > 0.0:
                        shape = sample_noise(noise_coarse, COARSE_TEXEL_M, s * 0.7 + 37.0, t * 0.7, footprint)
                        level = 0.55 - 1.2 * puddles
                        wet = max(wet, min(max((shape - level) * 6.0, 0.0), 1.0))
                    roughness = 0.55
                    f0 = 0.02
                gloss = 0.0
            else:
                for c in range(3):
                    rgb[c] = face_color[f, c]
                roughness = 0.25
            # Paved surfaces hold a water film; grass, gravel and dirt soak it up.
            paved = material == ASPHALT or material == CONCRETE or material == KERB
            surface_wet = max(env_f[WETNESS] if paved else 0.0, wet)
            if surface_wet > 0.0:
                darken = 1.0 - 0.5 * surface_wet
                for c in range(3):
                    rgb[c] *= darken
                roughness = roughness * (1.0 - surface_wet) + 0.09 * surface_wet
                if wet > 0.5:
                    roughness = 0.03
            shiny = surface_wet + gloss
            # Direct sun.
            n_dot_l = n[0] * sun_dir[0] + n[1] * sun_dir[1] + n[2] * sun_dir[2]
            light[:] = 0.0
            spec[:] = 0.0
            if sun_i > 0.0 and n_dot_l > 0.0:
                vis = sun_visibility(p, n, n_dot_l, shadow_depth, shadow_coarse, shadow_params, R_light, env_f[PENUMBRA])
                for c in range(3):
                    light[c] += SUN_SCALE * sun_i * sun_color[c] * n_dot_l * vis
                if vis > 0.0 and shiny > 0.0:
                    hx = sun_dir[0] - d_world[0]
                    hy = sun_dir[1] - d_world[1]
                    hz = sun_dir[2] - d_world[2]
                    hn = np.sqrt(hx * hx + hy * hy + hz * hz)
                    n_dot_h = (n[0] * hx + n[1] * hy + n[2] * hz) / hn
                    lobe = glossy_lobe(n_dot_h, roughness) * fresnel_schlick(n_dot_v, max(f0, gloss * 0.08))
                    for c in range(3):
                        spec[c] += SUN_SCALE * sun_i * sun_color[c] * vis * lobe * 0.25 * shiny
            # Lamps.
            for k in range(lights.shape[0]):
                lx = lights[k, 0] - p[0]
                ly = lights[k, 1] - p[1]
                lz = lights[k, 2] - p[2]
                d2 = lx * lx + ly * ly + lz * lz
                dl = np.sqrt(d2)
                ndl = (n[0] * lx + n[1] * ly + n[2] * lz) / dl
                if ndl <= 0.0:
                    continue
                power = lights[k, 6] / (d2 + 1.0)
                hx = lx / dl - d_world[0]
                hy = ly / dl - d_world[1]
                hz = lz / dl - d_world[2]
                hn = np.sqrt(hx * hx + hy * hy + hz * hz)
                n_dot_h = (n[0] * hx + n[1] * hy + n[2] * hz) / hn
                lobe = glossy_lobe(n_dot_h, roughness) * fresnel_schlick(n_dot_v, max(f0, gloss * 0.08))
                for c in range(3):
                    light[c] += power * lights[k, 3 + c] * ndl
                    spec[c] += power * lights[k, 3 + c] * lobe * (0.1 + shiny)
            up = 0.6 + 0.4 * n[2]
            if material >= 0:  # ground under a roof, deck or crown sees less sky
                up *= sky_openness(overhead, overhead_params, p)
            for c in range(3):
                rgb[c] = rgb[c] * (light[c] + ambient_rgb[c] * up) + spec[c] + face_emission[f, c]
            # Mirror reflection of sky and objects on wet surfaces and glossy paint.
            mirror = surface_wet if material >= 0 else gloss
            if mirror > 0.0:
                fres = fresnel_schlick(n_dot_v, 0.02 if material >= 0 else 0.05)
                strength = fres * (wet + (surface_wet - wet) * WET_FILM_MIRROR if material >= 0 else gloss)
                dot = d_world[0] * n[0] + d_world[1] * n[1] + d_world[2] * n[2]
                for i in range(3):
                    r[i] = d_world[i] - 2.0 * dot * n[i]
                sky_radiance(r, sun_dir, sun_color, sun_i * (1.0 - roughness), zenith, horizon, env_f[CLOUD],
                             refl)
                if material >= 0 and refl_depth[row, col] < np.inf and refl_depth[row, col] > depth:
                    for c in range(3):
                        refl[c] = refl_rgb[row, col, c]
                for c in range(3):
                    rgb[c] = rgb[c] * (1.0 - strength) + refl[c] * strength
            # Distance fog.
            fog = fog_lut[min(int(dist * FOG_LUT_PER_M), fog_lut.size - 1)]
            for c in range(3):
                out[row, col, c] = rgb[c] * (1.0 - fog) + fog_rgb[c] * fog


@kernel
def shade_mirror(face_buf, depth_buf, face_color, face_emission, face_normal, sun_dir, sun_color, env_f,
                 zenith, horizon, lights_rgb_scale, out):
    """Flat-shade the mirrored objects (no shadows): what a wet road reflects."""
    height, width = face_buf.shape
    for row in range(height):
        for col in range(width):
            f = face_buf[row, col]
            if f < 0:
                continue
            n_dot_l = abs(face_normal[f, 0] * sun_dir[0] + face_normal[f, 1] * sun_dir[1]
                          + face_normal[f, 2] * sun_dir[2])
            for c in range(3):
                amb = env_f[AMBIENT] * (0.5 * horizon[c] + 0.5 * zenith[c]) * 2.2 + lights_rgb_scale
                out[row, col, c] = face_color[f, c] * (SUN_SCALE * env_f[SUN_I] * sun_color[c] * n_dot_l + amb) \
                    + face_emission[f, c]
