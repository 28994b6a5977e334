"""Per-pixel shading (numba): road material, objects, sun + sky + lamps, wet reflections, fog.

Inputs are the rasterizer's fragments; output is linear HDR radiance. World positions are rebuilt from depth
and the pixel's camera ray, road coordinates from the face's vertex (s, t) and the barycentric weights.

The kernel walks each row once; what differs between road materials and objects (roughness, Fresnel, water
film) comes from a table (``surface_table``), not from branches, and one lighting path serves both. (Separate
sweeps per row for sky, road and objects measured slower in this scalar code: 2 ms more for the sky's own sweep
at 1280x720, more again with the lighting duplicated for roads and objects.)
The sky is smooth away from the sun and the horizon, so a row's sky radiance is evaluated every ``SKY_STEP`` columns
and interpolated (exact near the sun and across the horizon): at most one level of 255 apart from a per-pixel sky
on 0.1 % of pixels, 2.5 ms less ``shade`` at 1280x720 on the clean cases.
The inputs travel in a few named bundles (``View``, ``Geometry``, ``RoadLook``, ``Lighting``, ``SunShadow``,
``Reflection``) and every step of a pixel is a small inlined helper.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..typed import MATERIALS, Float32Array, FloatArray, IntArray
from ..world.facade import GLASS as GLASS_FINISH
from ..world.facade import LEAVES as LEAVES_FINISH
from ..world.paint import MATERIAL_ALBEDO
from ._jit import kernel
from .bands import band_rows
from .facades import cell_hash, facade, footway
from .foliage import leaf_cosine, leaf_sky, leaf_transmission
from .ground import GRASS, NO_LAND, PATCH_TEXEL_M, ground
from .lighting import (
    BEAM_LOW,
    FOOTPRINT_TAP_TEXELS,
    LIGHT_BEAM,
    LIGHT_POWER,
    LIGHT_R,
    RETROREFLECTION,
    SKY_AMBIENT_GAIN,
    SUN_BIAS,
    SUN_OFFSET,
    SUN_SCALE,
    WET_RETRO_LOSS,
    beam_weight,
    fresnel_schlick,
    glossy_lobe,
    lobe_shape,
    sky_openness,
    sky_radiance,
    sun_visibility,
    sun_visibility_over,
)
from .surface import CHIP_TEXEL_M, RAGGED_STRETCH, RAGGED_TEXEL_M, dash_coverage, paint, sample_layers, sample_noise
from .textures import COARSE_TEXEL_M, FINE_TEXEL_M

# env_f layout
SUN_I, AMBIENT, WETNESS, PUDDLES, FOG_DENSITY, FOG_DISTANCE, CLOUD, PENUMBRA, DETAIL = range(9)
ASPHALT = MATERIALS.index("asphalt")
SLAB = MATERIALS.index("slab")
CONCRETE = MATERIALS.index("concrete")  # footways: paving flags
KERB = MATERIALS.index("kerb")
MIN_SLOPE_SINE = 0.2  # a facade coordinate's footprint up a face no flatter than this (12 deg roofs and steeper)
PAVED = ("asphalt", "concrete", "kerb", "slab")  # hold a water film; grass, gravel and dirt soak it up
# surface_table columns; its rows are the road MATERIALS, then one for every object
ALBEDO_R, ALBEDO_G, ALBEDO_B, ROUGHNESS, F0, HOLDS_WATER, MIRROR_F0, GRAIN = range(8)
FLAG_GRAIN = 0.4  # paving flags and kerb stones are smoother than asphalt: this share of its grain and stains
OBJECT_ROW = len(MATERIALS)
WET_FILM_MIRROR = 0.45  # a wet film mirrors less than standing water
FOOTPRINT_SCALE = 0.75  # box-filter width in pixels' worth of road coordinate
MAX_FOOTPRINT_M = 50.0
FOG_LUT_SIZE = 8192
FOG_LUT_PER_M = 4.0
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

    surface: FloatArray  # (materials, 6) see surface_table()
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
def pixel_ray(R_world_camera: np.ndarray, x_cam: float, y_cam: float) -> tuple[float, float, float, float]:
    """(dx, dy, dz, norm): the unit world direction through camera-plane point (x_cam, y_cam, 1) and that
    point's length (camera z to distance along the ray)."""
    R = R_world_camera
    norm = np.sqrt(x_cam * x_cam + y_cam * y_cam + 1.0)
    inv_norm = 1.0 / norm
    dx = (R[0, 0] * x_cam + R[0, 1] * y_cam + R[0, 2]) * inv_norm
    dy = (R[1, 0] * x_cam + R[1, 1] * y_cam + R[1, 2]) * inv_norm
    dz = (R[2, 0] * x_cam + R[2, 1] * y_cam + R[2, 2]) * inv_norm
    return dx, dy, dz, norm


@kernel(inline="always")
def facing_normal(normal: np.ndarray, f: int, dx: float, dy: float,
                  dz: float) -> tuple[float, float, float, float]:
    """(nx, ny, nz, n.v): the face's world normal turned towards the viewer (faces are two-sided)."""
    nx, ny, nz = normal[f, 0], normal[f, 1], normal[f, 2]
    n_dot_v = -(nx * dx + ny * dy + nz * dz)
    if n_dot_v < 0.0:
        return -nx, -ny, -nz, -n_dot_v
    return nx, ny, nz, n_dot_v


@kernel(inline="always")
def gradients_camera(R_world_camera: np.ndarray, grad_st: np.ndarray,
                     f: int) -> tuple[float, float, float, float, float, float]:
    """The world gradients of s and of t on road face ``f`` in camera axes: (s_x, s_y, s_z, t_x, t_y, t_z)."""
    R = R_world_camera
    sx, sy, sz, tx, ty, tz = grad_st[f, 0], grad_st[f, 1], grad_st[f, 2], grad_st[f, 3], grad_st[f, 4], grad_st[f, 5]
    return (sx * R[0, 0] + sy * R[1, 0] + sz * R[2, 0], sx * R[0, 1] + sy * R[1, 1] + sz * R[2, 1],
            sx * R[0, 2] + sy * R[1, 2] + sz * R[2, 2], tx * R[0, 0] + ty * R[1, 0] + tz * R[2, 0],
            tx * R[0, 1] + ty * R[1, 1] + tz * R[2, 1], tx * R[0, 2] + ty * R[1, 2] + tz * R[2, 2])


@kernel(inline="always")
def coordinate_step(g_x_cam: float, g_y_cam: float, g_z_cam: float, x_cam: float, y_cam: float, k_u: float,
                    k_v: float, su: float, sv: float) -> float:
    """How much a road coordinate with gradient g (camera axes) changes across one pixel: its steps along the
    pixel's ray differentials u = su (x - r k_u) and v = sv (y - r k_v) on the face's plane, r = (x_cam, y_cam, 1)."""
    g_dot_r = g_x_cam * x_cam + g_y_cam * y_cam + g_z_cam
    step = abs(su * (g_x_cam - g_dot_r * k_u)) + abs(sv * (g_y_cam - g_dot_r * k_v))
    return min(FOOTPRINT_SCALE * step + 1e-3, MAX_FOOTPRINT_M)


@kernel(inline="always")
def road_footprint(R_world_camera: np.ndarray, fx: float, fy: float,
                   grad_cam: tuple[float, float, float, float, float, float], depth: float, norm: float,
                   x_cam: float, y_cam: float, nx: float, ny: float, nz: float, n_dot_v: float) -> tuple[float, float]:
    """(fs, ft): how much s and t change across the pixel, by ray differentials on the face's plane (exact for
    the affine (s, t) of a road triangle); ``grad_cam`` is the face's ``gradients_camera``."""
    R = R_world_camera
    n_dot_r = -max(n_dot_v, 1e-4) * norm  # n faces the viewer, so n.ray < 0
    k_u = (nx * R[0, 0] + ny * R[1, 0] + nz * R[2, 0]) / n_dot_r
    k_v = (nx * R[0, 1] + ny * R[1, 1] + nz * R[2, 1]) / n_dot_r
    su, sv = depth / fx, depth / fy
    fs = coordinate_step(grad_cam[0], grad_cam[1], grad_cam[2], x_cam, y_cam, k_u, k_v, su, sv)
    ft = coordinate_step(grad_cam[3], grad_cam[4], grad_cam[5], x_cam, y_cam, k_u, k_v, su, sv)
    return fs, ft


@kernel(inline="always")
def pixel_steps(R_world_camera: np.ndarray, fx: float, fy: float, depth: float, norm: float, dx: float, dy: float,
                dz: float, nx: float, ny: float, nz: float,
                n_dot_v: float) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(du, dv): the world steps on the face's plane (normal n, facing the viewer) between the pixel and its
    neighbours across and down, by ray differentials (see ``road_footprint``)."""
    R = R_world_camera
    n_dot_r = -max(n_dot_v, 1e-4) * norm
    k_u = (nx * R[0, 0] + ny * R[1, 0] + nz * R[2, 0]) / n_dot_r
    k_v = (nx * R[0, 1] + ny * R[1, 1] + nz * R[2, 1]) / n_dot_r
    su, sv = depth / fx, depth / fy
    rx, ry, rz = dx * norm, dy * norm, dz * norm  # the pixel's ray (camera z = 1) in world axes
    return ((su * (R[0, 0] - k_u * rx), su * (R[1, 0] - k_u * ry), su * (R[2, 0] - k_u * rz)),
            (sv * (R[0, 1] - k_v * rx), sv * (R[1, 1] - k_v * ry), sv * (R[2, 1] - k_v * rz)))


@kernel(inline="always")
def facade_footprint(du: tuple[float, float, float], dv: tuple[float, float, float], nx: float, ny: float,
                     nz: float) -> tuple[float, float]:
    """(fu, fv): how far the pixel's footprint (world steps du, dv on the face's plane) reaches along a wall or
    roof (the horizontal in the face's plane) and up it (up a roof's slope: its rise over the slope's sine)."""
    hx, hy = -ny, nx
    h = np.sqrt(hx * hx + hy * hy)
    if h > 1e-6:
        hx, hy = hx / h, hy / h
    else:  # a horizontal face: "along" is any horizontal, x
        hx, hy = 1.0, 0.0
    fu = abs(du[0] * hx + du[1] * hy) + abs(dv[0] * hx + dv[1] * hy)
    fv = (abs(du[2]) + abs(dv[2])) / max(np.sqrt(max(1.0 - nz * nz, 0.0)), MIN_SLOPE_SINE)
    return min(FOOTPRINT_SCALE * fu + 1e-3, MAX_FOOTPRINT_M), min(FOOTPRINT_SCALE * fv + 1e-3, MAX_FOOTPRINT_M)


@kernel(inline="always")
def road_coordinates(faces: np.ndarray, vertex_st: np.ndarray, bary: np.ndarray, row: int, col: int,
                     f: int) -> tuple[float, float]:
    """(s, t) of the pixel on road face ``f`` from its perspective-correct barycentric weights."""
    b1 = bary[row, col, 0]
    b2 = bary[row, col, 1]
    b0 = 1.0 - b1 - b2
    i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
    s = b0 * vertex_st[i0, 0] + b1 * vertex_st[i1, 0] + b2 * vertex_st[i2, 0]
    t = b0 * vertex_st[i0, 1] + b1 * vertex_st[i1, 1] + b2 * vertex_st[i2, 1]
    return s, t


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
def object_plane(px: float, py: float, pz: float, nx: float, ny: float, nz: float) -> tuple[float, float]:
    """Two world coordinates (m) across an object's face: the pair the face's normal is least aligned with."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    if az >= ax and az >= ay:
        return px, py
    if ax >= ay:
        return py, pz
    return px, pz


@kernel(inline="always")
def boundaries_near(lanes: float, lane_width: float, last: int, t: float, ft: float) -> tuple[int, int]:
    """(k0, k1): the lane boundaries whose paint can reach a pixel at ``t`` (boundary k: t = (n - k) w)."""
    k0 = max(int(np.floor(lanes - (t + ft + 0.5) / lane_width + 0.5)), 0)
    k1 = min(int(np.floor(lanes - (t - ft - 0.5) / lane_width + 0.5)), last - 1)
    return k0, k1


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


@kernel(inline="always")
def sun_lit(sun_dir: np.ndarray, sun: np.ndarray, visibility: float, n_dot_l: float, nx: float, ny: float,
            nz: float, dx: float, dy: float, dz: float, roughness: float, fresnel: float,
            shiny: float) -> tuple[float, float, float, float, float, float]:
    """(diffuse irradiance rgb, specular radiance rgb) of the sun seen with ``visibility``."""
    sun_x, sun_y, sun_z = sun_dir[0], sun_dir[1], sun_dir[2]  # read before any branch (see ``_jit``)
    sun_r, sun_g, sun_b = sun[0], sun[1], sun[2]
    k = n_dot_l * visibility
    spec = 0.0
    if visibility > 0.0 and shiny > 0.0:
        hx, hy, hz = sun_x - dx, sun_y - dy, sun_z - dz
        n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
        exponent, normalisation, cutoff = lobe_shape(roughness)
        spec = visibility * glossy_lobe(n_dot_h, exponent, normalisation, cutoff) * fresnel * 0.25 * shiny
    return sun_r * k, sun_g * k, sun_b * k, sun_r * spec, sun_g * spec, sun_b * spec


@kernel(inline="always")
def lamp_light(lights: np.ndarray, px: float, py: float, pz: float, nx: float, ny: float, nz: float, dx: float,
               dy: float, dz: float, roughness: float, fresnel: float, shiny: float,
               retro: float) -> tuple[float, float, float, float, float, float]:
    """(diffuse irradiance rgb, specular radiance rgb) of every lamp at world point p, each through its beam
    (``beam_weight``); the ego's low beams also come back from the road by ``retro`` (its retroreflection, as a
    share of the beam's irradiance square to it; 0 off the road)."""
    light_r = light_g = light_b = 0.0
    spec_r = spec_g = spec_b = 0.0
    if lights.shape[0] == 0:
        return light_r, light_g, light_b, spec_r, spec_g, spec_b
    lobe = lobe_shape(roughness)
    for i in range(lights.shape[0]):
        lx = lights[i, 0] - px
        ly = lights[i, 1] - py
        lz = lights[i, 2] - pz
        d2 = lx * lx + ly * ly + lz * lz
        inv_dl = 1.0 / np.sqrt(d2)
        ndl = (nx * lx + ny * ly + nz * lz) * inv_dl
        if ndl <= 0.0:
            continue
        power = lights[i, LIGHT_POWER] / (d2 + 1.0) * beam_weight(lights, i, -lx * inv_dl, -ly * inv_dl,
                                                                  -lz * inv_dl)
        if power <= 0.0:
            continue
        hx, hy, hz = lx * inv_dl - dx, ly * inv_dl - dy, lz * inv_dl - dz
        n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
        k_spec = power * glossy_lobe(n_dot_h, lobe[0], lobe[1], lobe[2]) * fresnel * (0.1 + shiny)
        k_diff = power * (ndl + (retro if lights[i, LIGHT_BEAM] == BEAM_LOW else 0.0))
        light_r += lights[i, LIGHT_R] * k_diff
        light_g += lights[i, LIGHT_R + 1] * k_diff
        light_b += lights[i, LIGHT_R + 2] * k_diff
        spec_r += lights[i, LIGHT_R] * k_spec
        spec_g += lights[i, LIGHT_R + 1] * k_spec
        spec_b += lights[i, LIGHT_R + 2] * k_spec
    return light_r, light_g, light_b, spec_r, spec_g, spec_b


@kernel(inline="always")
def shade_lit(color: tuple[float, float, float], ambient: np.ndarray, up: float, emission: np.ndarray, f: int,
              glow: float, sun: tuple[float, float, float, float, float, float],
              lamps: tuple[float, float, float, float, float, float]) -> tuple[float, float, float]:
    """Albedo ``color`` under the sun, the lamps and the sky's ambient (times ``up``), plus specular and the face's
    emission times ``glow`` (the share of a lit window that is glass, not bars; else 1)."""
    return (color[0] * (sun[0] + lamps[0] + ambient[0] * up) + sun[3] + lamps[3] + emission[f, 0] * glow,
            color[1] * (sun[1] + lamps[1] + ambient[1] * up) + sun[4] + lamps[4] + emission[f, 1] * glow,
            color[2] * (sun[2] + lamps[2] + ambient[2] * up) + sun[5] + lamps[5] + emission[f, 2] * glow)


@kernel(inline="always")
def blend(r: float, g: float, b: float, ref: tuple[float, float, float], strength: float) -> tuple[float, float, float]:
    """(r, g, b) mixed towards the reflected colour ``ref`` by ``strength``."""
    return (r * (1.0 - strength) + ref[0] * strength, g * (1.0 - strength) + ref[1] * strength,
            b * (1.0 - strength) + ref[2] * strength)


@kernel(inline="always")
def mirrored_ray(dx: float, dy: float, dz: float, nx: float, ny: float, nz: float) -> tuple[float, float, float]:
    """The view ray reflected about the normal."""
    dot = dx * nx + dy * ny + dz * nz
    return dx - 2.0 * dot * nx, dy - 2.0 * dot * ny, dz - 2.0 * dot * nz


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
            if leafy:
                up = leaf_sky(nz)
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
        n_dot_l = nx * sun_dir[0] + ny * sun_dir[1] + nz * sun_dir[2]
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
    sun_x, sun_y, sun_z = sun_dir[0], sun_dir[1], sun_dir[2]
    for row in band_rows(height, band, bands):
        y_cam = (row + 0.5 - view.cy) / view.fy
        for col in range(width):
            f = face_buf[row, col]
            if f < 0:
                continue
            dx, dy, dz, _ = pixel_ray(R, (col + 0.5 - view.cx) / view.fx, y_cam)
            nx, ny, nz, _ = facing_normal(face_normal, f, dx, dy, -dz)
            n_dot_l = nx * sun_x + ny * sun_y + nz * sun_z
            up = 0.6 + 0.4 * nz
            if face_finish[f] == LEAVES_FINISH:  # a crown: lit as a volume of leaves, as ``shade_row`` lights it
                up = leaf_sky(nz)
                n_dot_l = leaf_cosine(n_dot_l) + leaf_transmission(n_dot_l)
            n_dot_l = max(n_dot_l, 0.0)
            for c in range(3):
                amb = env_f[AMBIENT] * (0.5 * horizon[c] + 0.5 * zenith[c]) * SKY_AMBIENT_GAIN * up + lamp_spill
                out[row, col, c] = face_color[f, c] * (SUN_SCALE * env_f[SUN_I] * sun_color[c] * n_dot_l + amb) \
                    + face_emission[f, c]
