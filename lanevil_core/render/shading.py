"""Per-pixel shading (numba): road material, objects, sun + sky + lamps, wet reflections, fog.

Inputs are the rasterizer's fragments; output is linear HDR radiance. World positions are rebuilt from depth
and the pixel's camera ray, road coordinates from the face's vertex (s, t) and the barycentric weights.

The kernel walks each row once; what differs between road materials and objects (roughness, Fresnel, water
film) comes from a table (``materials.surface_table``), not from branches, and one lighting path serves both. (Separate
sweeps per row for sky, road and objects measured slower in this scalar code: 2 ms more for the sky's own sweep
at 1280x720, more again with the lighting duplicated for roads and objects.)
The sky is smooth away from the sun and the horizon, so a row's sky radiance is evaluated every ``SKY_STEP`` columns
and interpolated (exact near the sun and across the horizon): at most one level of 255 apart from a per-pixel sky
on 0.1 % of pixels, 2.5 ms less ``shade`` at 1280x720 on the clean cases.
The inputs travel in a few named bundles (``View``, ``Geometry``, ``RoadLook``, ``Lighting``, ``SunShadow``,
``Reflection``) and every step of a pixel is a small inlined helper: where the pixel lies (``pixel_geometry``),
what its surface is made of (``materials``, paint and layers in ``surface``, ``facades``, ``ground``, ``foliage``)
and the light it receives (``light_terms``, sky and shadows in ``lighting``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..typed import Float32Array, FloatArray, IntArray
from ..world.facade import GLASS as GLASS_FINISH
from ..world.facade import LEAVES as LEAVES_FINISH
from ._jit import kernel
from .bands import band_rows
from .facades import facade, footway
from .foliage import leaf_clumps, leaf_cosine, leaf_footprint, leaf_sky, leaf_transmission
from .ground import GRASS, NO_LAND, PATCH_TEXEL_M, ground
from .light_terms import blend, lamp_light, shade_lit, sun_lit
from .lighting import (
    FOOTPRINT_TAP_TEXELS,
    RETROREFLECTION,
    SKY_AMBIENT_GAIN,
    SUN_BIAS,
    SUN_OFFSET,
    SUN_SCALE,
    WET_RETRO_LOSS,
    fresnel_schlick,
    sky_openness,
    sky_radiance,
    sun_visibility,
    sun_visibility_over,
)
from .materials import (
    ALBEDO_R,
    ASPHALT,
    CLUMP_TEXEL_M,
    CONCRETE,
    F0,
    HOLDS_WATER,
    KERB,
    MID_TEXEL_M,
    MIRROR_F0,
    OBJECT_ROW,
    PUDDLE_RAGGED,
    PUDDLE_SHORE_TEXEL_M,
    ROUGHNESS,
    SLAB,
    albedo,
    clumps,
    puddle_depth,
    slab_joints,
    wet_surface,
)
from .pixel_geometry import (
    facade_footprint,
    facing_normal,
    gradients_camera,
    mirrored_ray,
    object_plane,
    pixel_ray,
    pixel_steps,
    road_coordinates,
    road_footprint,
)
from .surface import (
    CHIP_TEXEL_M,
    RAGGED_STRETCH,
    RAGGED_TEXEL_M,
    boundaries_near,
    paint,
    sample_layers,
    sample_noise,
)
from .textures import COARSE_TEXEL_M, FINE_TEXEL_M

# env_f layout
SUN_I, AMBIENT, WETNESS, PUDDLES, FOG_DENSITY, FOG_DISTANCE, CLOUD, PENUMBRA, DETAIL = range(9)
WET_FILM_MIRROR = 0.45  # a wet film mirrors less than standing water
FOG_LUT_SIZE = 8192
FOG_LUT_PER_M = 4.0
CHIP_STRETCH = 0.4  # worn paint's chips run about 2.5 times longer along the line than across it
CHIP_FLAKES = 0.55  # share of the chip noise that is flakes (the rest: longer worn and kept stretches)
STAIN_TEXEL_M = 0.8  # broad weathering stains on walls (m)
STREAK_TEXEL_M = 0.4  # streaks down walls: the noise stretched STREAK_STRETCH times across, ten times along
STREAK_STRETCH = 4.0
FINISHED_TEXTURE = 0.4  # a wall with a finish shows this share of the photographic clumps (its structure is drawn)
SKY_STEP = 8  # sky radiance is evaluated every SKY_STEP columns of a row and interpolated between
SKY_EXACT_NEAR_SUN = 0.95  # cosine to the sun above which the sky is evaluated per pixel (glow, halo and disk)


class View(NamedTuple):
    """The camera: rotation and position of the camera in the world, pinhole intrinsics (pixels)."""

    R_world_camera: FloatArray
    p_world_camera: FloatArray
    fx: float
    fy: float
    cx: float
    cy: float


class Geometry(NamedTuple):
    """Per-face and per-vertex arrays of the packed scene (see ``PackedScene``)."""

    faces: IntArray
    vertex_st: Float32Array
    vertex_piece: IntArray
    face_grad_st: Float32Array
    face_normal: Float32Array
    face_material: IntArray
    face_color: Float32Array
    face_emission: Float32Array
    face_gloss: Float32Array
    face_texture: Float32Array
    face_finish: np.ndarray


class RoadLook(NamedTuple):
    """What the road surface looks like: material table, paint, surface layers, noise and sky openness."""

    surface: FloatArray  # (materials + 1, 8) see materials.surface_table()
    stripes: FloatArray
    stripe_index: np.ndarray
    lanes: float
    lane_width: float
    layer_texels: Float32Array
    layer_table: FloatArray
    layer_first: IntArray
    noise_fine: Float32Array
    noise_coarse: Float32Array
    overhead: Float32Array
    overhead_params: FloatArray
    paint_wear: float  # the most worn stripe's wear (0: fresh paint everywhere, no chip noise is sampled)
    wear_shift: float  # where along the road worn paint's chip and edge noise starts (m; by the case's seed)
    ground: FloatArray  # (pieces, 2) ground.ground_table: where each piece's grass begins and what land it is


class Lighting(NamedTuple):
    """Sun, sky, lamps and fog of the frame; ``ambient``, ``fog_color`` and ``sun`` are derived (rgb)."""

    env_f: FloatArray
    sun_dir: FloatArray
    sun_color: FloatArray
    zenith: FloatArray
    horizon: FloatArray
    lights: FloatArray
    fog_lut: FloatArray
    ambient: FloatArray
    fog_color: FloatArray
    sun: FloatArray


class SunShadow(NamedTuple):
    """The shadow cascades (see ``ShadowMaps``)."""

    depth: Float32Array
    cells: Float32Array
    params: FloatArray
    R_light_world: FloatArray
    face_terms: FloatArray  # (m, 2) lighting.face_sun_terms


class Reflection(NamedTuple):
    """The blurred mirror image of the objects and its depth (inf where nothing is mirrored)."""

    rgb: np.ndarray
    depth: Float32Array


def fog_table(density: float, start_m: float) -> np.ndarray:
    """(FOG_LUT_SIZE,) float64 share of fog at distance (i + 0.5) / FOG_LUT_PER_M metres."""
    distance_m = (np.arange(FOG_LUT_SIZE) + 0.5) / FOG_LUT_PER_M
    return 1.0 - np.exp(-density * np.maximum(distance_m - start_m, 0.0))


def frame_lighting(env_f: FloatArray, sun_dir: FloatArray, sun_color: FloatArray, zenith: FloatArray,
                   horizon: FloatArray, lights: FloatArray) -> Lighting:
    """The frame's ``Lighting`` with its derived colours: sky ambient, fog colour and sun irradiance."""
    ambient = env_f[AMBIENT] * (0.5 * horizon + 0.5 * zenith) * SKY_AMBIENT_GAIN
    fog_color = horizon * (1.6 * (0.25 + 0.75 * min(env_f[AMBIENT] * 3.0, 1.0)))
    sun = SUN_SCALE * env_f[SUN_I] * sun_color
    return Lighting(env_f, sun_dir, sun_color, zenith, horizon, np.ascontiguousarray(lights, np.float64),
                    fog_table(env_f[FOG_DENSITY], env_f[FOG_DISTANCE]), ambient, fog_color, sun)


@kernel(inline="always")
def write_fogged(fog_lut: np.ndarray, fog_color: np.ndarray, out: np.ndarray, row: int, col: int, dist: float,
                 r: float, g: float, b: float) -> None:
    """Store (r, g, b) seen through ``dist`` metres of fog."""
    fog = fog_lut[min(int(dist * FOG_LUT_PER_M), fog_lut.size - 1)]
    out[row, col, 0] = r * (1.0 - fog) + fog_color[0] * fog
    out[row, col, 1] = g * (1.0 - fog) + fog_color[1] * fog
    out[row, col, 2] = b * (1.0 - fog) + fog_color[2] * fog


@kernel(inline="always")
def shade_row(face: np.ndarray, depth_buf: np.ndarray, bary: np.ndarray, view: View, geometry: Geometry,
              road: RoadLook, lighting: Lighting, shadow: SunShadow, reflection: Reflection, row: int, y_cam: float,
              out: np.ndarray) -> None:
    """Shade ``row``: the sky where nothing was drawn, else the road material (by ``surface_table``) or an
    object's flat colour, then the same lighting for both.

    The bundles are opened once per row. Helpers that loop (noise, paint, layers, shadow taps) are called from
    here, not from other helpers, and results are written here: measured, either nested costs 5-10 % of the
    kernel's time."""
    R, c_world, fx, fy, cx, _ = view
    faces, vertex_st, vertex_piece, grad_st, normal, face_material, color, emission, face_gloss, \
        face_texture, face_finish = geometry
    surface, stripes, stripe_index, lanes, lane_width, texels, table, first, fine, coarse, overhead, \
        overhead_params, paint_wear, wear_shift, ground_rows = road
    env_f, sun_dir, sun_color, zenith, horizon, lights, fog_lut, ambient, fog_color, sun = lighting
    maps, cells, shadow_params, R_light, sun_terms = shadow
    refl_rgb, refl_depth = reflection
    wetness, puddles, sun_i, cloud, penumbra = env_f[WETNESS], env_f[PUDDLES], env_f[SUN_I], env_f[CLOUD], \
        env_f[PENUMBRA]
    detail = env_f[DETAIL]
    finest = 0.0  # texels per metre of the finest shadow cascade
    for c in range(shadow_params.shape[0]):
        finest = max(finest, shadow_params[c, 2])
    last = stripe_index.shape[1] - 1
    width = face.shape[1]
    span = -1  # the sky samples below are those of columns span * SKY_STEP and (span + 1) * SKY_STEP
    exact = True
    r0 = g0 = b0 = r1 = g1 = b1 = 0.0
    grad_face = -1  # the road face whose gradients_camera grad_cam holds (faces repeat along a row)
    grad_cam = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for col in range(width):
        f = face[row, col]
        if f < 0:
            # The sky is smooth away from the sun and the horizon: sampled every SKY_STEP columns and
            # interpolated, exact where a sample is near the sun or the two lie on both sides of the horizon.
            k = col // SKY_STEP
            if k != span:
                c0, c1 = k * SKY_STEP, min((k + 1) * SKY_STEP, width - 1)
                ex, ey, ez, _ = pixel_ray(R, (c0 + 0.5 - cx) / fx, y_cam)
                r0, g0, b0 = sky_radiance(ex, ey, ez, sun_dir, sun_color, sun_i, zenith, horizon, cloud, coarse)
                qx, qy, qz, _ = pixel_ray(R, (c1 + 0.5 - cx) / fx, y_cam)
                r1, g1, b1 = sky_radiance(qx, qy, qz, sun_dir, sun_color, sun_i, zenith, horizon, cloud, coarse)
                near_sun = max(ex * sun_dir[0] + ey * sun_dir[1] + ez * sun_dir[2],
                               qx * sun_dir[0] + qy * sun_dir[1] + qz * sun_dir[2]) > SKY_EXACT_NEAR_SUN
                exact = near_sun or (ez < 0.0) != (qz < 0.0) or c1 == c0
                span = k
            if exact:
                dx, dy, dz, _ = pixel_ray(R, (col + 0.5 - cx) / fx, y_cam)
                r, g, b = sky_radiance(dx, dy, dz, sun_dir, sun_color, sun_i, zenith, horizon, cloud, coarse)
            else:
                w = (col - k * SKY_STEP) / (min((k + 1) * SKY_STEP, width - 1) - k * SKY_STEP)
                r, g, b = r0 + (r1 - r0) * w, g0 + (g1 - g0) * w, b0 + (b1 - b0) * w
            out[row, col, 0] = r
            out[row, col, 1] = g
            out[row, col, 2] = b
            continue
        x_cam = (col + 0.5 - cx) / fx
        dx, dy, dz, norm = pixel_ray(R, x_cam, y_cam)
        depth = depth_buf[row, col]
        dist = depth * norm
        px, py, pz = c_world[0] + dx * dist, c_world[1] + dy * dist, c_world[2] + dz * dist
        nx, ny, nz, n_dot_v = facing_normal(normal, f, dx, dy, dz)
        material = face_material[f]
        kind = material if material >= 0 else OBJECT_ROW
        wet = 0.0
        glass = 0.0  # the share of the pixel that is window glass (a mirror)
        glow = 1.0  # the share of the face's emission the pixel shows: a lit window's bars hide its light
        up = 0.6 + 0.4 * nz
        leafy = False  # a crown's face, lit as a volume of leaves (``foliage``)
        lx, ly, lz = nx, ny, nz  # the normal the sun's cosine is taken on (a crown's clumps tilt it)
        if material >= 0:
            if f != grad_face:
                grad_cam = gradients_camera(R, grad_st, f)
                grad_face = f
            fs, ft = road_footprint(R, fx, fy, grad_cam, depth, norm, x_cam, y_cam, nx, ny, nz, n_dot_v)
            footprint = max(fs, ft)
            s, t = road_coordinates(faces, vertex_st, bary, row, col, f)
            stain = sample_noise(coarse, COARSE_TEXEL_M, s * 0.5, t, footprint)
            r, g, b = albedo(surface, material, sample_noise(fine, FINE_TEXEL_M, s, t, footprint), stain, detail)
            texture = face_texture[f]
            if material == GRASS and ground_rows[vertex_piece[faces[f, 0]], 1] != NO_LAND:  # verges, fields, lawns
                tone = r / surface[GRASS, ALBEDO_R]
                r, g, b, rougher = ground(ground_rows, vertex_piece[faces[f, 0]], s, t, fs, ft,
                                          sample_noise(coarse, PATCH_TEXEL_M, s, t, footprint), stain, wetness)
                r, g, b, texture = r * tone, g * tone, b * tone, texture * rougher
            if detail > 0.0:  # tufts, aggregate patches and stains at the scale a camera resolves
                tone = clumps(detail * texture, sample_noise(fine, CLUMP_TEXEL_M, s + 11.0, t, footprint),
                              sample_noise(fine, MID_TEXEL_M, s, t + 5.0, footprint))
                r, g, b = r * tone, g * tone, b * tone
            if material == CONCRETE or material == KERB:
                r, g, b = footway(material == KERB, s, t, fs, ft, r, g, b)
            if material == SLAB:
                r, g, b = slab_joints(s, t, fs, ft, lane_width,
                                      sample_noise(coarse, COARSE_TEXEL_M, s * 2.0 + 53.0, t, footprint), r, g, b)
            if material == ASPHALT or material == SLAB:  # only the carriageway carries paint and surface layers
                piece = vertex_piece[faces[f, 0]]
                r, g, b, wet = sample_layers(texels, table, first, piece, s, t, fs, ft, False, r, g, b)
                k0, k1 = boundaries_near(lanes, lane_width, last, t, ft)
                chips = 0.0
                ragged = 0.0
                if paint_wear > 0.0:  # flakes (fine) in worn stretches (coarse), along the line, filtered
                    chip_foot = max(fs * CHIP_STRETCH, ft)
                    s_chip = (s + wear_shift) * CHIP_STRETCH
                    chips = CHIP_FLAKES * sample_noise(fine, CHIP_TEXEL_M, s_chip, t + 3.0, chip_foot) \
                        + (1.0 - CHIP_FLAKES) * sample_noise(coarse, CHIP_TEXEL_M, s_chip, t, chip_foot)
                    ragged = sample_noise(fine, RAGGED_TEXEL_M, (s + wear_shift) * RAGGED_STRETCH, t + 9.0,
                                          max(fs * RAGGED_STRETCH, ft))
                for k in range(k0, k1 + 1):
                    r, g, b = paint(stripes, stripe_index[piece, k, 0], stripe_index[piece, k, 1], s, t, fs, ft, r,
                                    g, b, chips, ragged)
                r, g, b = paint(stripes, stripe_index[piece, last, 0], stripe_index[piece, last, 1], s, t, fs, ft, r,
                                g, b, chips, ragged)
                r, g, b, wet_over = sample_layers(texels, table, first, piece, s, t, fs, ft, True, r, g, b)
                wet = max(wet, wet_over)
                if puddles > 0.0:  # coarse blobs with ragged, soft shores (a finer octave)
                    shape = sample_noise(coarse, COARSE_TEXEL_M, s * 0.7 + 37.0, t * 0.7, footprint) \
                        + PUDDLE_RAGGED * sample_noise(fine, PUDDLE_SHORE_TEXEL_M, s + 17.0, t, footprint)
                    wet = max(wet, puddle_depth(shape, puddles))
            up *= sky_openness(overhead, overhead_params, px, py)  # ground under a roof sees less sky
        else:
            r, g, b = color[f, 0], color[f, 1], color[f, 2]
            texture = face_texture[f]
            finish = face_finish[f]
            leafy = finish == LEAVES_FINISH
            if leafy:  # clumps of leaves in world space, filtered over the footprint along the face
                tr, tg, tb, lx, ly, lz = leaf_clumps(px, py, pz, nx, ny, nz, leaf_footprint(dist, fx, n_dot_v))
                r, g, b = r * tr, g * tg, b * tb
                up = leaf_sky(lz)
            elif finish > 0:  # brick, render, panels, window glass: drawn in facade coordinates over the footprint
                u, v = road_coordinates(faces, vertex_st, bary, row, col, f)
                du, dv = pixel_steps(R, fx, fy, depth, norm, dx, dy, dz, nx, ny, nz, n_dot_v)
                fu, fv = facade_footprint(du, dv, nx, ny, nz)
                r, g, b, glass = facade(finish, u, v, fu, fv,
                                        sample_noise(coarse, STAIN_TEXEL_M, u * 0.5 + 19.0, v, max(fu, fv)),
                                        sample_noise(coarse, STREAK_TEXEL_M, u * STREAK_STRETCH, v * 0.1 + 7.0,
                                                     fu * STREAK_STRETCH), r, g, b)
                texture *= FINISHED_TEXTURE
                if finish >= GLASS_FINISH:
                    glow = glass
            if detail > 0.0:  # weathering, grime and leaf clumps on objects, in world space on the face's plane
                u, v = object_plane(px, py, pz, nx, ny, nz)
                foot = dist / fx
                tone = clumps(detail * texture, sample_noise(fine, CLUMP_TEXEL_M, u, v, foot),
                              sample_noise(fine, MID_TEXEL_M, v + 3.0, u, foot))
                r, g, b = r * tone, g * tone, b * tone
        gloss = face_gloss[f] + glass  # 0 on the road
        surface_wet = max(wetness * surface[kind, HOLDS_WATER], wet)  # 0 on objects
        r, g, b, roughness = wet_surface(r, g, b, surface[kind, ROUGHNESS], surface_wet, wet)
        shiny = surface_wet + gloss
        fresnel = fresnel_schlick(n_dot_v, max(surface[kind, F0], gloss * 0.08))
        n_dot_l = lx * sun_dir[0] + ly * sun_dir[1] + lz * sun_dir[2]
        through = 0.0  # the share of the sun seen through a crown's leaves
        if leafy:
            through = leaf_transmission(n_dot_l)
            n_dot_l = leaf_cosine(n_dot_l)
        direct = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        if sun_i > 0.0 and n_dot_l > 0.0:
            # The ideal render reads the point; a photograph filters over the pixel's footprint, unless no side of
            # it can reach a second tap in the finest cascade (|du| <= depth / fx * (1 + 1 / n.v), |dv| likewise,
            # under FOOTPRINT_TAP_TEXELS texels): one lookup is then its filter.
            if detail > 0.0 and depth * max(1.0 / fx, 1.0 / fy) * (1.0 + 1.0 / max(n_dot_v, 1e-4)) * finest >= \
                    FOOTPRINT_TAP_TEXELS:
                du, dv = pixel_steps(R, fx, fy, depth, norm, dx, dy, dz, nx, ny, nz, n_dot_v)
                vis = sun_visibility_over(px, py, pz, nx, ny, nz, sun_terms[f, SUN_OFFSET], sun_terms[f, SUN_BIAS],
                                          maps, cells, shadow_params, R_light, penumbra, du, dv)
            else:
                vis = sun_visibility(px, py, pz, nx, ny, nz, sun_terms[f, SUN_OFFSET], sun_terms[f, SUN_BIAS], maps,
                                     cells, shadow_params, R_light, penumbra)
            direct = sun_lit(sun_dir, sun, vis, n_dot_l, nx, ny, nz, dx, dy, dz, roughness, fresnel, shiny)
        if through > 0.0 and sun_i > 0.0:
            direct = (direct[0] + sun[0] * through, direct[1] + sun[1] * through, direct[2] + sun[2] * through,
                      direct[3], direct[4], direct[5])
        retro = RETROREFLECTION * (1.0 - WET_RETRO_LOSS * surface_wet) if material >= 0 else 0.0
        lamps = lamp_light(lights, px, py, pz, nx, ny, nz, dx, dy, dz, roughness, fresnel, shiny, retro)
        r, g, b = shade_lit((r, g, b), ambient, up, emission, f, glow, direct, lamps)
        if shiny > 0.0:  # wet road or glossy paint: a mirror of the sky, or on the road of the objects
            strength = fresnel_schlick(n_dot_v, surface[kind, MIRROR_F0]) * (
                wet + (surface_wet - wet) * WET_FILM_MIRROR + gloss)
            mirrored = refl_depth[row, col]
            if material >= 0 and mirrored < np.inf and mirrored > depth:
                ref = (refl_rgb[row, col, 0], refl_rgb[row, col, 1], refl_rgb[row, col, 2])
            else:
                mx, my, mz = mirrored_ray(dx, dy, dz, nx, ny, nz)
                ref = sky_radiance(mx, my, mz, sun_dir, sun_color, sun_i * (1.0 - roughness), zenith, horizon,
                                   cloud, coarse)
            r, g, b = blend(r, g, b, ref, strength)
        write_fogged(fog_lut, fog_color, out, row, col, dist, r, g, b)


@kernel
def shade(face: np.ndarray, depth: np.ndarray, bary: np.ndarray, view: View, geometry: Geometry, road: RoadLook,
          lighting: Lighting, shadow: SunShadow, reflection: Reflection, out: np.ndarray, band: int,
          bands: int) -> None:
    """Linear radiance of the pixels of one row band into ``out`` (H, W, 3)."""
    for row in band_rows(face.shape[0], band, bands):
        y_cam = (row + 0.5 - view.cy) / view.fy
        shade_row(face, depth, bary, view, geometry, road, lighting, shadow, reflection, row, y_cam, out)


@kernel
def shade_mirror(face_buf: np.ndarray, depth_buf: np.ndarray, face_color: np.ndarray, face_emission: np.ndarray,
                 face_normal: np.ndarray, face_finish: np.ndarray, view: View, sun_dir: np.ndarray,
                 sun_color: np.ndarray, env_f: np.ndarray, zenith: np.ndarray, horizon: np.ndarray, lamp_spill: float,
                 out: np.ndarray, band: int, bands: int) -> None:
    """Shade the mirrored objects of one row band (no shadows): what a wet road reflects.

    A pixel sees the real object from the camera mirrored below the ground, along its ray with z flipped: each
    face is lit on the side that camera sees (the underside of a crown, the back of a backlit tree stay dark), so
    a reflection is never brighter than what it reflects. ``lamp_spill`` is the lamps' light on objects at night."""
    height, width = face_buf.shape
    R = view.R_world_camera
    c_world = view.p_world_camera
    sun_x, sun_y, sun_z = sun_dir[0], sun_dir[1], sun_dir[2]
    for row in band_rows(height, band, bands):
        y_cam = (row + 0.5 - view.cy) / view.fy
        for col in range(width):
            f = face_buf[row, col]
            if f < 0:
                continue
            dx, dy, dz, norm = pixel_ray(R, (col + 0.5 - view.cx) / view.fx, y_cam)
            nx, ny, nz, n_dot_v = facing_normal(face_normal, f, dx, dy, -dz)
            up = 0.6 + 0.4 * nz
            tone = (1.0, 1.0, 1.0)
            leafy = face_finish[f] == LEAVES_FINISH
            if leafy:  # a crown: lit as a volume of leaves, as ``shade_row`` lights it
                # its clumps at the real crown's point (the mirrored one flipped back up; the ground's height is
                # a shift of the pattern, which the mirror's blur hides)
                dist = depth_buf[row, col] * norm
                p_world = (c_world[0] + dx * dist, c_world[1] + dy * dist, -(c_world[2] + dz * dist))
                tr, tg, tb, nx, ny, nz = leaf_clumps(p_world[0], p_world[1], p_world[2], nx, ny, nz,
                                                     leaf_footprint(dist, view.fx, n_dot_v))
                tone = (tr, tg, tb)
                up = leaf_sky(nz)
            n_dot_l = nx * sun_x + ny * sun_y + nz * sun_z
            if leafy:
                n_dot_l = leaf_cosine(n_dot_l) + leaf_transmission(n_dot_l)
            n_dot_l = max(n_dot_l, 0.0)
            for c in range(3):
                amb = env_f[AMBIENT] * (0.5 * horizon[c] + 0.5 * zenith[c]) * SKY_AMBIENT_GAIN * up + lamp_spill
                out[row, col, c] = face_color[f, c] * tone[c] * (SUN_SCALE * env_f[SUN_I] * sun_color[c] * n_dot_l
                                                                 + amb) + face_emission[f, c]
