"""Per-pixel shading (numba): road material, objects, sun + sky + lamps, wet reflections, fog.

Inputs are the rasterizer's fragments; output is linear HDR radiance. World positions are rebuilt from depth
and the pixel's camera ray, road coordinates from the face's vertex (s, t) and the barycentric weights.
"""

from __future__ import annotations

import numpy as np

from ._jit import kernel
from .bands import band_rows
from .lighting import (
    SUN_SCALE,
    fresnel_schlick,
    glossy_lobe,
    lobe_shape,
    sky_openness,
    sky_radiance,
    sun_visibility,
)
from .surface import paint, sample_layers, sample_noise
from .textures import COARSE_TEXEL_M, FINE_TEXEL_M

# env_f layout
SUN_I, AMBIENT, WETNESS, PUDDLES, FOG_DENSITY, FOG_DISTANCE, CLOUD, PENUMBRA = range(8)
ASPHALT, CONCRETE, KERB = 0, 1, 4
WET_FILM_MIRROR = 0.45
FOOTPRINT_SCALE = 0.75  # box-filter width in pixels' worth of road coordinate
MAX_FOOTPRINT_M = 50.0  # a wet film mirrors less than standing water
FOG_LUT_SIZE = 8192
FOG_LUT_PER_M = 4.0


def fog_table(density: float, start_m: float) -> np.ndarray:
    """(FOG_LUT_SIZE,) float64 share of fog at distance (i + 0.5) / FOG_LUT_PER_M metres."""
    distance_m = (np.arange(FOG_LUT_SIZE) + 0.5) / FOG_LUT_PER_M
    return 1.0 - np.exp(-density * np.maximum(distance_m - start_m, 0.0))


@kernel(inline="always")
def coordinate_step(gx: float, gy: float, gz: float, ux: float, uy: float, uz: float, vx: float, vy: float,
                    vz: float) -> float:
    """How much a road coordinate with world gradient g changes across one pixel (steps u and v)."""
    return FOOTPRINT_SCALE * (abs(gx * ux + gy * uy + gz * uz) + abs(gx * vx + gy * vy + gz * vz)) + 1e-3


@kernel
def shade(
    face_buf, depth_buf, bary_buf, faces, vertex_st, vertex_piece, face_grad_st, R_wc, c_world, fx, fy, cx, cy,
    face_material, face_color, face_emission, face_gloss, face_normal, material_albedo,
    stripes, stripe_index, lanes, lane_width, layer_texels, layer_table, layer_first, lights,
    noise_fine, noise_coarse, env_f, sun_dir, sun_color, zenith, horizon,
    shadow_depth, shadow_coarse, shadow_params, R_light, overhead, overhead_params, refl_rgb, refl_depth, fog_lut,
    out, band, bands,
):
    """Linear radiance of the pixels of one row band into ``out`` (H, W, 3). Per-pixel state lives in scalars."""
    height, width = face_buf.shape
    amb_r = env_f[AMBIENT] * (0.5 * horizon[0] + 0.5 * zenith[0]) * 2.2
    amb_g = env_f[AMBIENT] * (0.5 * horizon[1] + 0.5 * zenith[1]) * 2.2
    amb_b = env_f[AMBIENT] * (0.5 * horizon[2] + 0.5 * zenith[2]) * 2.2
    fog_level = 1.6 * (0.25 + 0.75 * min(env_f[AMBIENT] * 3.0, 1.0))
    fog_r, fog_g, fog_b = horizon[0] * fog_level, horizon[1] * fog_level, horizon[2] * fog_level
    sun_i = env_f[SUN_I]
    lx_sun, ly_sun, lz_sun = sun_dir[0], sun_dir[1], sun_dir[2]
    sun_r, sun_g, sun_b = (SUN_SCALE * sun_i * sun_color[0], SUN_SCALE * sun_i * sun_color[1],
                           SUN_SCALE * sun_i * sun_color[2])
    wetness, puddles, cloud, penumbra = env_f[WETNESS], env_f[PUDDLES], env_f[CLOUD], env_f[PENUMBRA]
    last_fog = FOG_LUT_SIZE - 1
    for row in band_rows(height, band, bands):
        y_cam = (row + 0.5 - cy) / fy
        for col in range(width):
            x_cam = (col + 0.5 - cx) / fx
            norm = np.sqrt(x_cam * x_cam + y_cam * y_cam + 1.0)
            inv_norm = 1.0 / norm
            dx = (R_wc[0, 0] * x_cam + R_wc[0, 1] * y_cam + R_wc[0, 2]) * inv_norm
            dy = (R_wc[1, 0] * x_cam + R_wc[1, 1] * y_cam + R_wc[1, 2]) * inv_norm
            dz = (R_wc[2, 0] * x_cam + R_wc[2, 1] * y_cam + R_wc[2, 2]) * inv_norm
            f = face_buf[row, col]
            if f < 0:
                r, g, b = sky_radiance(dx, dy, dz, sun_dir, sun_color, sun_i, zenith, horizon, cloud)
                out[row, col, 0] = r
                out[row, col, 1] = g
                out[row, col, 2] = b
                continue
            depth = depth_buf[row, col]
            dist = depth * norm
            px = c_world[0] + dx * dist
            py = c_world[1] + dy * dist
            pz = c_world[2] + dz * dist
            nx, ny, nz = face_normal[f, 0], face_normal[f, 1], face_normal[f, 2]
            n_dot_v = -(nx * dx + ny * dy + nz * dz)
            if n_dot_v < 0.0:  # back side of a two-sided face
                nx, ny, nz, n_dot_v = -nx, -ny, -nz, -n_dot_v
            material = face_material[f]
            wet = 0.0
            gloss = face_gloss[f]
            roughness = 0.25
            f0 = 0.04
            if material >= 0:
                # Road coordinates from the face's vertices, and their change across the pixel by ray
                # differentials on the face's plane (exact for the affine (s, t) of a road triangle).
                b1 = bary_buf[row, col, 0]
                b2 = bary_buf[row, col, 1]
                b0 = 1.0 - b1 - b2
                i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
                piece = vertex_piece[i0]
                s = b0 * vertex_st[i0, 0] + b1 * vertex_st[i1, 0] + b2 * vertex_st[i2, 0]
                t = b0 * vertex_st[i0, 1] + b1 * vertex_st[i1, 1] + b2 * vertex_st[i2, 1]
                n_dot_r = -max(n_dot_v, 1e-4) * norm  # n faces the viewer, so n.ray < 0
                k_u = (nx * R_wc[0, 0] + ny * R_wc[1, 0] + nz * R_wc[2, 0]) / n_dot_r
                k_v = (nx * R_wc[0, 1] + ny * R_wc[1, 1] + nz * R_wc[2, 1]) / n_dot_r
                su, sv = depth / fx, depth / fy
                ux = su * (R_wc[0, 0] - dx * norm * k_u)
                uy = su * (R_wc[1, 0] - dy * norm * k_u)
                uz = su * (R_wc[2, 0] - dz * norm * k_u)
                vx = sv * (R_wc[0, 1] - dx * norm * k_v)
                vy = sv * (R_wc[1, 1] - dy * norm * k_v)
                vz = sv * (R_wc[2, 1] - dz * norm * k_v)
                fs = min(coordinate_step(face_grad_st[f, 0], face_grad_st[f, 1], face_grad_st[f, 2],
                                         ux, uy, uz, vx, vy, vz), MAX_FOOTPRINT_M)
                ft = min(coordinate_step(face_grad_st[f, 3], face_grad_st[f, 4], face_grad_st[f, 5],
                                         ux, uy, uz, vx, vy, vz), MAX_FOOTPRINT_M)
                footprint = max(fs, ft)
                grain = sample_noise(noise_fine, FINE_TEXEL_M, s, t, footprint)
                blotch = sample_noise(noise_coarse, COARSE_TEXEL_M, s * 0.5, t, footprint)
                tone = (1.0 + 0.35 * grain) * (1.0 + 0.18 * blotch)
                r = material_albedo[material, 0] * tone
                g = material_albedo[material, 1] * tone
                b = material_albedo[material, 2] * tone
                if material == ASPHALT:
                    r, g, b, wet = sample_layers(layer_texels, layer_table, layer_first, piece, s, t, fs, ft, False,
                                                 r, g, b)
                    # Only the lane boundaries within the footprint can paint this pixel (boundary k: t = (n - k) w).
                    last = stripe_index.shape[1] - 1
                    k0 = max(int(np.floor(lanes - (t + ft + 0.5) / lane_width + 0.5)), 0)
                    k1 = min(int(np.floor(lanes - (t - ft - 0.5) / lane_width + 0.5)), last - 1)
                    for k in range(k0, k1 + 1):
                        r, g, b = paint(stripes, stripe_index[piece, k, 0], stripe_index[piece, k, 1], s, t, fs, ft,
                                        r, g, b)
                    r, g, b = paint(stripes, stripe_index[piece, last, 0], stripe_index[piece, last, 1], s, t, fs, ft,
                                    r, g, b)
                    r, g, b, wet_over = sample_layers(layer_texels, layer_table, layer_first, piece, s, t, fs, ft,
                                                      True, r, g, b)
                    wet = max(wet, wet_over)
                    if puddles > 0.0:
                        shape = sample_noise(noise_coarse, COARSE_TEXEL_M, s * 0.7 + 37.0, t * 0.7, footprint)
                        wet = max(wet, min(max((shape - (0.55 - 1.2 * puddles)) * 6.0, 0.0), 1.0))
                    roughness = 0.55
                    f0 = 0.02
                else:
                    roughness = 0.35
                gloss = 0.0
            else:
                r, g, b = face_color[f, 0], face_color[f, 1], face_color[f, 2]
            # Paved surfaces hold a water film; grass, gravel and dirt soak it up.
            paved = material == ASPHALT or material == CONCRETE or material == KERB
            surface_wet = max(wetness if paved else 0.0, wet)
            if surface_wet > 0.0:
                darken = 1.0 - 0.5 * surface_wet
                r *= darken
                g *= darken
                b *= darken
                roughness = roughness * (1.0 - surface_wet) + 0.09 * surface_wet
                if wet > 0.5:
                    roughness = 0.03
            shiny = surface_wet + gloss
            spec_f0 = max(f0, gloss * 0.08)
            exponent, normalisation, cutoff = lobe_shape(roughness)
            light_r = light_g = light_b = 0.0
            spec_r = spec_g = spec_b = 0.0
            # Direct sun.
            n_dot_l = nx * lx_sun + ny * ly_sun + nz * lz_sun
            if sun_i > 0.0 and n_dot_l > 0.0:
                vis = sun_visibility(px, py, pz, nx, ny, nz, n_dot_l, shadow_depth, shadow_coarse, shadow_params,
                                     R_light, penumbra)
                k = n_dot_l * vis
                light_r += sun_r * k
                light_g += sun_g * k
                light_b += sun_b * k
                if vis > 0.0 and shiny > 0.0:
                    hx, hy, hz = lx_sun - dx, ly_sun - dy, lz_sun - dz
                    n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
                    k = (vis * glossy_lobe(n_dot_h, exponent, normalisation, cutoff)
                         * fresnel_schlick(n_dot_v, spec_f0) * 0.25 * shiny)
                    spec_r += sun_r * k
                    spec_g += sun_g * k
                    spec_b += sun_b * k
            # Lamps.
            for i in range(lights.shape[0]):
                lx = lights[i, 0] - px
                ly = lights[i, 1] - py
                lz = lights[i, 2] - pz
                d2 = lx * lx + ly * ly + lz * lz
                inv_dl = 1.0 / np.sqrt(d2)
                ndl = (nx * lx + ny * ly + nz * lz) * inv_dl
                if ndl <= 0.0:
                    continue
                power = lights[i, 6] / (d2 + 1.0)
                hx, hy, hz = lx * inv_dl - dx, ly * inv_dl - dy, lz * inv_dl - dz
                n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
                k_spec = (power * glossy_lobe(n_dot_h, exponent, normalisation, cutoff)
                          * fresnel_schlick(n_dot_v, spec_f0) * (0.1 + shiny))
                k_diff = power * ndl
                light_r += lights[i, 3] * k_diff
                light_g += lights[i, 4] * k_diff
                light_b += lights[i, 5] * k_diff
                spec_r += lights[i, 3] * k_spec
                spec_g += lights[i, 4] * k_spec
                spec_b += lights[i, 5] * k_spec
            up = 0.6 + 0.4 * nz
            if material >= 0:  # ground under a roof, deck or crown sees less sky
                up *= sky_openness(overhead, overhead_params, px, py)
            r = r * (light_r + amb_r * up) + spec_r + face_emission[f, 0]
            g = g * (light_g + amb_g * up) + spec_g + face_emission[f, 1]
            b = b * (light_b + amb_b * up) + spec_b + face_emission[f, 2]
            # Mirror reflection of sky and objects on wet surfaces and glossy paint.
            mirror = surface_wet if material >= 0 else gloss
            if mirror > 0.0:
                fres = fresnel_schlick(n_dot_v, 0.02 if material >= 0 else 0.05)
                strength = fres * (wet + (surface_wet - wet) * WET_FILM_MIRROR if material >= 0 else gloss)
                dot = dx * nx + dy * ny + dz * nz
                ref_r, ref_g, ref_b = sky_radiance(dx - 2.0 * dot * nx, dy - 2.0 * dot * ny, dz - 2.0 * dot * nz,
                                                   sun_dir, sun_color, sun_i * (1.0 - roughness), zenith, horizon,
                                                   cloud)
                if material >= 0 and refl_depth[row, col] < np.inf and refl_depth[row, col] > depth:
                    ref_r, ref_g, ref_b = refl_rgb[row, col, 0], refl_rgb[row, col, 1], refl_rgb[row, col, 2]
                r = r * (1.0 - strength) + ref_r * strength
                g = g * (1.0 - strength) + ref_g * strength
                b = b * (1.0 - strength) + ref_b * strength
            # Distance fog.
            fog = fog_lut[min(int(dist * FOG_LUT_PER_M), last_fog)]
            out[row, col, 0] = r * (1.0 - fog) + fog_r * fog
            out[row, col, 1] = g * (1.0 - fog) + fog_g * fog
            out[row, col, 2] = b * (1.0 - fog) + fog_b * fog


@kernel
def shade_mirror(face_buf, depth_buf, face_color, face_emission, face_normal, sun_dir, sun_color, env_f,
                 zenith, horizon, lights_rgb_scale, out, band, bands):
    """Flat-shade the mirrored objects (no shadows) of one row band: what a wet road reflects."""
    height, width = face_buf.shape
    for row in band_rows(height, band, bands):
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
