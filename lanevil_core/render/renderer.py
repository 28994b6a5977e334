"""Render one frame of a compiled scene: camera -> raster -> shadow maps -> shade -> post."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache

import cv2
import numpy as np

from ..camera import PinholeCamera
from ..camera.bonnet import bonnet_mask, paint_bonnet
from ..camera.cover import cover_camera, cover_maps
from ..camera.sensor import development
from ..typed import Float32Array, FloatArray, IntArray, UInt8Array
from ..world.paint import MATERIAL_ALBEDO, PAINT_WEAR, road_albedo
from ..world.road_layout import RoadNetwork
from ..world.scene import ID_EGO, ID_SKY, CompiledScene, Environment
from .bands import run_bands
from .develop import NO_STREAKS, Streaks, develop, motion_blur
from .ground import ground_table
from .lighting import LIGHT_COLUMNS, face_sun_terms, light_row
from .materials import surface_table
from .packed import PackedScene, pack_scene
from .post import SRGB_LUT, blur_columns, finish, glare
from .raster import per_pixel, rasterize_perspective
from .shading import (
    Geometry,
    Reflection,
    RoadLook,
    SunShadow,
    View,
    frame_lighting,
    shade,
    shade_mirror,
)
from .shadow_map import CascadeCache, ShadowMaps, build_shadow_maps
from .textures import noise_textures

SURFACE_TABLE = surface_table(MATERIAL_ALBEDO)
MIRROR_BLUR_PX_AT_1280 = 10
MIRROR_LAMP_SPILL = 0.02  # irradiance of the street lamps on the objects a wet road mirrors at night
HEADLIGHT_COLOR = (1.0, 0.95, 0.85)  # halogen-white low beams
SOFTNESS_WIDTH = 1280  # image width at which a sensor's softness sigma is given
HEADLIGHT_HEIGHT_M = 0.7  # the low beams' height above the road (ECE R48: 0.5-1.2 m)
HEADLIGHT_AHEAD_M = 1.5  # how far ahead of the camera the lamps stand
HEADLIGHT_HALF_SPAN_M = 0.75  # half the distance between the two lamps
LAMP_RANGE_M = 75.0
LAMP_BEHIND_M = 12.0


@dataclass(frozen=True)
class Frame:
    """A rendered frame.

    Attributes:
        rgb: (H, W, 3) uint8 sRGB image.
        depth: (H, W) float32 camera z (m), inf for sky.
        object_id: (H, W) int32: scene.ID_SKY, ID_ROAD, ID_ROADSIDE or FIRST_OBJECT_ID + mesh index.
        camera: the camera it was rendered with.
        timings: milliseconds per stage.
    """

    rgb: UInt8Array
    depth: Float32Array
    object_id: IntArray
    camera: PinholeCamera
    timings: dict[str, float] = field(default_factory=dict)


def _env_vector(env: Environment) -> np.ndarray:
    return np.array([env.sun_intensity, env.ambient, env.wetness, env.puddles, env.fog_density, env.fog_distance,
                     env.cloudiness, env.penumbra, env.detail], np.float64)


def _no_shadows() -> ShadowMaps:
    return ShadowMaps(np.full((1, 8, 8), np.inf, np.float32), np.full((1, 1, 1, 2), np.inf, np.float32),
                      np.array([[0.0, 0.0, 1.0]]), np.eye(3))


def _mirror_pass(packed: PackedScene, scene: CompiledScene, camera: PinholeCamera,
                 threads: int) -> tuple[np.ndarray, np.ndarray]:
    """Objects mirrored about the ground under them, rasterized and flat-shaded, blurred along columns."""
    k = camera.intrinsics
    env = scene.env
    ground = scene.cache.get("mirror_ground")
    if ground is None:
        ground = _ground_heights(packed)
        scene.cache["mirror_ground"] = ground
    v_world = packed.vertices.copy()
    v_world[:, 2] = 2.0 * ground - v_world[:, 2]
    frags = rasterize_perspective(camera.world_to_camera(v_world), packed.faces, packed.mirror_faces,
                                  (k.width, k.height), k.fx, k.fy, k.cx, k.cy, camera.near, threads)
    img = np.zeros((k.height, k.width, 3), np.float64)
    spill = MIRROR_LAMP_SPILL if env.night and len(scene.lights) else 0.0
    env_f = _env_vector(env)
    sun_color, zenith, horizon = (env.sun_color.astype(np.float64), env.sky_zenith.astype(np.float64),
                                  env.sky_horizon.astype(np.float64))
    view = View(camera.R_world_camera, camera.p_world_camera, k.fx, k.fy, k.cx, k.cy)
    run_bands(lambda band, bands: shade_mirror(frags.face, frags.depth, packed.face_color, packed.face_emission,
                                               packed.face_normal, packed.face_finish, view, env.sun_dir_world,
                                               sun_color, env_f, zenith, horizon, spill, img, band, bands), threads)
    blur_columns(img, frags.depth, max(1, round(MIRROR_BLUR_PX_AT_1280 * k.width / 1280)), threads)
    return img, frags.depth


def _ground_heights(packed: PackedScene) -> np.ndarray:
    """Per vertex: the lowest z of its connected object (the ground it stands on)."""
    ground = np.zeros(len(packed.vertices))
    obj_faces = packed.mirror_faces
    if obj_faces.size == 0:
        return ground
    face_obj = packed.face_object[obj_faces]
    for obj in np.unique(face_obj):
        vids = np.unique(packed.faces[obj_faces[face_obj == obj]])
        ground[vids] = packed.vertices[vids, 2].min()
    return ground


def headlight_positions(camera: PinholeCamera, mount_height: float) -> tuple[FloatArray, FloatArray]:
    """The ego's level heading (3,) and its two low beams' world positions (2, 3), left then right: on the car,
    ``HEADLIGHT_HEIGHT_M`` above the road under a camera ``mount_height`` up, whatever the camera's pitch."""
    forward = camera.R_world_camera[:, 2]
    heading = np.array([forward[0], forward[1], 0.0]) / max(float(np.hypot(forward[0], forward[1])), 1e-9)
    right = np.array([heading[1], -heading[0], 0.0])
    drop = np.array([0.0, 0.0, HEADLIGHT_HEIGHT_M - mount_height])
    lamps_world = np.array([camera.p_world_camera + heading * HEADLIGHT_AHEAD_M + right * side * HEADLIGHT_HALF_SPAN_M
                            + drop for side in (-1.0, 1.0)])
    return heading, lamps_world


def _frame_lights(packed: PackedScene, camera: PinholeCamera, env: Environment, mount_height: float) -> np.ndarray:
    """The lamps near enough to matter this frame plus, when on, the ego's headlights (they move with it; the
    camera stands ``mount_height`` above the road).

    Lamps farther than LAMP_RANGE_M light the road below them to a few per cent of a near one and sit deep in
    the fog; leaving them out keeps the per-pixel light loop short.
    """
    lamps_world = packed.lights
    if len(lamps_world):
        offset = lamps_world[:, :3] - camera.p_world_camera
        ahead = offset @ camera.R_world_camera[:, 2]
        near = (np.linalg.norm(offset, axis=1) < LAMP_RANGE_M) & (ahead > -LAMP_BEHIND_M)
        lamps_world = lamps_world[near]
    if env.headlights <= 0.0:
        return np.ascontiguousarray(lamps_world)
    heading, beams_world = headlight_positions(camera, mount_height)
    rows = np.array([light_row(p, HEADLIGHT_COLOR, env.headlights, heading, "low") for p in beams_world])
    return np.concatenate([lamps_world.reshape(-1, LIGHT_COLUMNS), rows])


def _needs_mirror(scene: CompiledScene, packed: PackedScene) -> bool:
    wet_layers = any(layer.wet is not None and float(layer.wet.max()) > 0 for layer in scene.layers)
    return packed.mirror_faces.size > 0 and (scene.env.wetness > 0.05 or scene.env.puddles > 0.0 or wet_layers)


@lru_cache(maxsize=4)
def _nothing_mirrored(height: int, width: int) -> Float32Array:
    """(H, W) float32 all inf: the mirror depth of a dry frame (shared; the renderer never writes to it)."""
    return np.full((height, width), np.inf, np.float32)


def _geometry(packed: PackedScene) -> Geometry:
    return Geometry(packed.faces, packed.vertex_st, packed.vertex_piece, packed.face_grad_st, packed.face_normal,
                    packed.face_material, packed.face_color, packed.face_emission, packed.face_gloss,
                    packed.face_texture, packed.face_finish)


def _surface_table(network: RoadNetwork) -> FloatArray:
    """The road materials' table, the carriageway's row in the case's own colour when it has one."""
    return SURFACE_TABLE if network.surface_color is None else surface_table(road_albedo(network))


def _road_look(scene: CompiledScene, packed: PackedScene) -> RoadLook:
    fine, coarse = noise_textures()
    return RoadLook(_surface_table(scene.network), packed.stripes, packed.stripe_index,
                    float(scene.network.lanes_per_direction), float(scene.network.lane_width), packed.layers.texels,
                    packed.layers.table, packed.layers.first_level, fine, coarse, packed.overhead,
                    packed.overhead_params, float(packed.stripes[:, PAINT_WEAR].max(initial=0.0)),
                    scene.paint.wear_shift_m, ground_table(scene.network.pieces))


def _sun_terms(scene: CompiledScene, packed: PackedScene) -> np.ndarray:
    """The packed faces' ``face_sun_terms`` for the scene's sun (kept while the sun stays)."""
    key = np.asarray(scene.env.sun_dir_world, np.float64).tobytes()
    cached = scene.cache.get("sun_terms")
    if cached is None or cached[0] != key:
        cached = key, face_sun_terms(packed.face_normal, scene.env.sun_dir_world)
        scene.cache["sun_terms"] = cached
    return cached[1]


def _cascade_cache(scene: CompiledScene) -> CascadeCache:
    """The scene's cache of drawn shadow cascades (its casters never change once packed)."""
    cache = scene.cache.get("shadow_cascades")
    if cache is None:
        cache = scene.cache.setdefault("shadow_cascades", CascadeCache())
    return cache


def render_frame(scene: CompiledScene, frame: int, size: tuple[int, int] | None = None, threads: int = 1) -> Frame:
    """Render frame ``frame`` of ``scene`` from the ego camera, optionally at another size (same lens).

    ``threads`` row bands of every stage run in parallel; the bytes are those of one thread.
    """
    return render_view(scene, scene.ego.camera(frame, size), threads, frame)


def render_view(scene: CompiledScene, camera: PinholeCamera, threads: int = 1, frame: int = 0) -> Frame:
    """Render ``scene`` from any camera (e.g. ``camera.pose_camera`` of a vehicle driven in closed loop).

    Without a sensor, lens or bonnet in the case's camera the frame is the ideal render (Reinhard curve, no
    noise); otherwise ``_photograph`` takes it through the camera. ``frame`` seeds the sensor noise.
    """
    timings: dict[str, float] = {}
    clock = time.perf_counter()

    def lap(name: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        timings[name] = (now - clock) * 1e3
        clock = now

    mount = scene.ego.mount
    if mount.sensor is not None or mount.bonnet is not None or not camera.pinhole:
        return _photograph(scene, camera, threads, frame, lap, timings)
    hdr, depth, object_id = _radiance(scene, camera, threads, lap)
    k = camera.intrinsics
    rgb = np.empty((k.height, k.width, 3), np.uint8)
    glare(hdr, scene.env.exposure)
    finish(hdr, object_id, scene.env.exposure, SRGB_LUT, rgb, threads)
    lap("post")
    return Frame(rgb, depth, object_id, camera, timings)


def _radiance(scene: CompiledScene, camera: PinholeCamera, threads: int,
              lap: Callable[[str], None]) -> tuple[Float32Array, Float32Array, IntArray]:
    """Linear radiance (H, W, 3) float32, depth (H, W) float32 and object ids (H, W) int32 of a pinhole camera."""
    packed = pack_scene(scene)
    k = camera.intrinsics
    env = scene.env
    lap("setup")
    frags = rasterize_perspective(camera.world_to_camera(packed.vertices), packed.faces, packed.camera_faces,
                                  (k.width, k.height), k.fx, k.fy, k.cx, k.cy, camera.near, threads)
    lap("raster")
    shadows = (build_shadow_maps(packed, camera, env.sun_dir_world, threads=threads, cache=_cascade_cache(scene))
               if env.sun_intensity > 0 and packed.shadow_faces.size else _no_shadows())
    lap("shadow_map")
    if _needs_mirror(scene, packed):
        refl_rgb, refl_depth = _mirror_pass(packed, scene, camera, threads)
    else:
        refl_rgb, refl_depth = np.zeros((1, 1, 3)), _nothing_mirrored(k.height, k.width)
    lap("mirror")
    hdr = np.empty((k.height, k.width, 3), np.float32)
    view = View(camera.R_world_camera, camera.p_world_camera, k.fx, k.fy, k.cx, k.cy)
    lighting = frame_lighting(_env_vector(env), env.sun_dir_world, env.sun_color.astype(np.float64),
                              env.sky_zenith.astype(np.float64), env.sky_horizon.astype(np.float64),
                              _frame_lights(packed, camera, env, scene.ego.mount.z))
    geometry, road = _geometry(packed), _road_look(scene, packed)
    sun_shadow = SunShadow(shadows.depth, shadows.cells, shadows.params, shadows.R_light_world,
                           _sun_terms(scene, packed))
    reflection = Reflection(refl_rgb, refl_depth)
    run_bands(lambda band, bands: shade(frags.face, frags.depth, frags.bary, view, geometry, road, lighting,
                                        sun_shadow, reflection, hdr, band, bands), threads)
    lap("shade")
    object_id = per_pixel(frags.face, packed.face_object, ID_SKY, threads)
    return hdr, frags.depth, object_id


def _photograph(scene: CompiledScene, camera: PinholeCamera, threads: int, frame: int,
                lap: Callable[[str], None], timings: dict[str, float]) -> Frame:
    """The frame a real camera takes: pinhole radiance (through the lens's cover camera when it distorts), motion
    blur over the shutter, the lens's resampling, the bonnet, then the sensor (or the ideal curve without one)."""
    mount = scene.ego.mount
    sensor = mount.sensor
    k = camera.intrinsics
    render_camera = camera if camera.pinhole else cover_camera(camera)
    hdr, depth, object_id = _radiance(scene, render_camera, threads, lap)
    travel = scene.ego.speed * sensor.shutter if sensor is not None else 0.0
    rk = render_camera.intrinsics
    streaks = NO_STREAKS
    if travel > 0.0:
        # Through a plain pinhole without a bonnet the sensor blurs as it develops, in one pass; otherwise the
        # streaks are those of the pinhole image, before the lens resamples it and the bonnet (which moves with
        # the camera) covers it.
        if camera.pinhole and mount.bonnet is None:
            streaks = Streaks(depth, rk.cx, rk.cy, travel)
        else:
            hdr = motion_blur(hdr, depth, (rk.cx, rk.cy), travel, threads)
    if not camera.pinhole:
        map_u, map_v = cover_maps(camera)
        hdr = np.asarray(cv2.remap(hdr, map_u, map_v, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE), np.float32)
        cols = np.clip(np.rint(map_u), 0, depth.shape[1] - 1).astype(np.intp)
        rows = np.clip(np.rint(map_v), 0, depth.shape[0] - 1).astype(np.intp)
        depth, object_id = depth[rows, cols], object_id[rows, cols]
    lap("lens")  # the buffers are this frame's own: the bonnet below may write into them
    if mount.bonnet is not None:
        env = scene.env
        mask = bonnet_mask(camera, mount, mount.bonnet)
        sky = env.ambient * 0.5 * (env.sky_zenith.astype(np.float64) + env.sky_horizon.astype(np.float64))
        sun = env.sun_intensity * max(float(env.sun_dir_world[2]), 0.0)
        paint_bonnet(hdr, mask, mount.bonnet, sky, sun)
        object_id[mask] = ID_EGO
        depth[mask] = mount.bonnet.reach
    rgb = np.empty((k.height, k.width, 3), np.uint8)
    if sensor is None:
        glare(hdr, scene.env.exposure)
        finish(hdr, object_id, scene.env.exposure, SRGB_LUT, rgb, threads)
    else:
        dev = development(hdr, sensor)
        glare(hdr, dev.gain)
        develop(hdr, dev.gain, dev.channel_gain, sensor.vignetting, (k.cx, k.cy), dev.shot, dev.read,
                sensor.saturation, _noise_seed(scene.ego.seed, frame), dev.lut, rgb, threads, object_id, streaks)
        if sensor.softness > 0.0:  # the sigma is the camera's at 1280 wide: the same blur of the scene at any size
            rgb = np.asarray(cv2.GaussianBlur(rgb, (0, 0), sensor.softness * k.width / SOFTNESS_WIDTH), np.uint8)
        if sensor.sharpen > 0.0:
            soft = cv2.GaussianBlur(rgb, (0, 0), 1.0)
            rgb = np.asarray(cv2.addWeighted(rgb, 1.0 + sensor.sharpen, soft, -sensor.sharpen, 0.0), np.uint8)
        if sensor.compression is not None:
            rgb = recompressed(rgb, sensor.compression)
    lap("post")
    return Frame(rgb, depth, object_id, camera, timings)


def recompressed(rgb: UInt8Array, quality: int) -> UInt8Array:
    """(H, W, 3) uint8 through a JPEG encoder at ``quality`` and back: the blocks and ringing of compressed video."""
    ok, data = cv2.imencode(".jpg", np.ascontiguousarray(rgb[..., ::-1]), [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    decoded = cv2.imdecode(data, cv2.IMREAD_COLOR) if ok else None
    if decoded is None:  # pragma: no cover - OpenCV always encodes and decodes a uint8 image
        raise RuntimeError("JPEG round trip failed")
    return np.ascontiguousarray(np.asarray(decoded, np.uint8)[..., ::-1])


def _noise_seed(case_seed: int, frame: int) -> int:
    """The sensor noise stream of one frame of one case."""
    return int(np.random.SeedSequence([case_seed, frame, 0x5E45]).generate_state(1, np.uint64)[0])
