"""Our renderer beside Mesa's llvmpipe: the same compiled scene's triangles and cameras, timed in one run.

The scene is compiled and packed once (``compile_scene`` then ``pack_scene``). llvmpipe draws its triangles
through moderngl on a headless EGL context: a depth-only pass into a 2048x2048 sun shadow map (an orthographic
light covering the view's ground region), then the camera pass (flat Lambert shading with a 2x2 PCF shadow lookup,
sky ambient, the project's tone curve) over a sky-coloured clear, and a read-back of the frame into numpy, which
waits for the drawing to finish. Our side is ``render_frame(scene, frame, size)`` (rasterize, shadow cascades,
full shading, post). Both run on the same frames and sizes, interleaved and alternating which goes first, after an
untimed warm-up (numba compilation, shader compilation, uploading the triangles).

llvmpipe draws with ``LP_NUM_THREADS`` threads; ``--gl-threads 0`` (the default) sets it to 0, which makes
llvmpipe rasterize in the calling thread, so both renderers use one core. The variable is read when Mesa creates
the context, so it is set before moderngl loads. The threads the context started are printed by name
(llvmpipe-N are its rasterizer threads).

Geometry check: once per size, an untimed pass writes each pixel's object id (``scene.ID_SKY``, ``ID_ROAD`` ...)
and the share of pixels agreeing with ``Frame.object_id`` is printed; ``--save DIR`` writes both images as PNG.

Usage, from the repository root (after ``sh bench/setup_gl.sh``):
``python bench/compare_gl.py [--case PATH] [--frames 3] [--repeat 5] [--threads N] [--gl-threads 0|N|auto]
[--save DIR]``. Exits with status 2 and one line when moderngl or Mesa's EGL llvmpipe is missing.
"""

from __future__ import annotations

import argparse
import functools
import inspect
import os
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lanevil_core.camera import PinholeCamera
from lanevil_core.case import load_case
from lanevil_core.images import png_bytes
from lanevil_core.pipeline.bench import BENCH_SIZES, frames_to_time
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.lighting import SKY_SCALE, SUN_SCALE
from lanevil_core.render.packed import PackedScene, pack_scene
from lanevil_core.render.post import WHITE_POINT
from lanevil_core.render.shadow_map import CASCADE_FAR_M, GROUND_BAND_M, light_rotation
from lanevil_core.typed import Float32Array, FloatArray, UInt8Array
from lanevil_core.world.scene import ID_SKY, CompiledScene

ROOT = Path(__file__).resolve().parents[1]
# a low sun, long fence shadows
DEFAULT_CASE = ROOT / "scenes" / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon" / "03_level3.json"
SHADOW_MAP_SIZE = 2048
SHADOW_FAR_M = CASCADE_FAR_M[-1]  # the ground our renderer's farthest cascade covers
SHADOW_BIAS_M = 0.05  # depth bias against self-shadowing, in metres along the light
EXIT_NO_GL = 2

CAMERA_VERTEX = """
#version 330
uniform mat4 world_to_clip;
uniform mat4 world_to_shadow;  // to shadow-map texture coordinates and depth, all in [0, 1]
in vec3 in_position;
in vec3 in_normal;
in vec3 in_color;
out vec3 v_shadow;
out vec3 v_world;
flat out vec3 v_normal;
flat out vec3 v_color;
void main() {
    gl_Position = world_to_clip * vec4(in_position, 1.0);
    v_shadow = (world_to_shadow * vec4(in_position, 1.0)).xyz;
    v_world = in_position;
    v_normal = in_normal;
    v_color = in_color;
}
"""

CAMERA_FRAGMENT = """
#version 330
uniform sampler2DShadow shadow_map;
uniform vec3 sun_dir;      // world, towards the sun
uniform vec3 sun_rgb;      // irradiance of the sun
uniform vec3 ambient_rgb;  // sky light on an upward face
uniform vec3 eye;          // camera centre, world
uniform float exposure;
uniform float inv_white2;
uniform float depth_bias;
in vec3 v_shadow;
in vec3 v_world;
flat in vec3 v_normal;
flat in vec3 v_color;
out vec4 f_color;

vec3 srgb(vec3 x) {  // extended Reinhard, then the sRGB curve (the project's post.finish)
    x = max(x, 0.0);
    vec3 y = clamp(x * (1.0 + x * inv_white2) / (1.0 + x), 0.0, 1.0);
    return mix(12.92 * y, 1.055 * pow(y, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, y));
}

void main() {
    vec3 n = dot(v_normal, eye - v_world) < 0.0 ? -v_normal : v_normal;  // two-sided faces
    float lambert = max(dot(n, sun_dir), 0.0);
    float lit = 1.0;
    bool inside = all(greaterThan(v_shadow, vec3(0.0))) && all(lessThan(v_shadow, vec3(1.0)));
    if (lambert > 0.0 && inside) {
        lit = texture(shadow_map, vec3(v_shadow.xy, v_shadow.z - depth_bias));
    }
    vec3 hdr = v_color * (sun_rgb * lambert * lit + ambient_rgb * (0.6 + 0.4 * n.z));
    f_color = vec4(srgb(hdr * exposure), 1.0);
}
"""

DEPTH_VERTEX = """
#version 330
uniform mat4 world_to_clip;
in vec3 in_position;
void main() {
    gl_Position = world_to_clip * vec4(in_position, 1.0);
}
"""

DEPTH_FRAGMENT = """
#version 330
void main() {
}
"""

ID_VERTEX = """
#version 330
uniform mat4 world_to_clip;
in vec3 in_position;
in float in_object;
flat out float v_object;
void main() {
    gl_Position = world_to_clip * vec4(in_position, 1.0);
    v_object = in_object;
}
"""

ID_FRAGMENT = """
#version 330
flat in float v_object;
out float f_object;
void main() {
    f_object = v_object;
}
"""


def set_gl_threads(gl_threads: str) -> None:
    """Set LP_NUM_THREADS before Mesa loads (``auto`` leaves it unset: llvmpipe then starts one per core)."""
    os.environ["GALLIUM_DRIVER"] = "llvmpipe"
    os.environ["LIBGL_ALWAYS_SOFTWARE"] = "1"
    if gl_threads == "auto":
        os.environ.pop("LP_NUM_THREADS", None)
    else:
        os.environ["LP_NUM_THREADS"] = str(int(gl_threads))


def thread_names() -> dict[str, str]:
    """Name of every thread of this process by its id (Linux; empty where /proc is missing)."""
    tasks = Path("/proc/self/task")
    try:
        return {task.name: (task / "comm").read_text().strip() for task in tasks.iterdir()}
    except OSError:
        return {}


def open_llvmpipe() -> tuple[Any, list[str]] | str:
    """A headless EGL context on llvmpipe and the names of the threads it started, or why there is none.

    llvmpipe's rasterizer threads are named ``llvmpipe-N``; ``disk$0`` is Mesa's shader-cache writer."""
    try:
        import moderngl
    except ImportError:
        return "moderngl is not installed: run `sh bench/setup_gl.sh`"
    before = thread_names()
    try:
        headless: dict[str, Any] = {"backend": "egl"}  # moderngl's inferred signature mistypes the keywords
        ctx = moderngl.create_standalone_context(require=330, **headless)
    except Exception as error:  # glcontext raises plain Exceptions for missing EGL libraries
        return f"no EGL context ({error}): run `sh bench/setup_gl.sh`"
    renderer = str(ctx.info["GL_RENDERER"])
    if "llvmpipe" not in renderer:
        return f"the EGL context runs on {renderer!r}, not Mesa's llvmpipe"
    started = [name for task, name in thread_names().items() if task not in before]
    return ctx, sorted(started)


def camera_to_clip(camera: PinholeCamera) -> FloatArray:
    """(4, 4) OpenCV camera frame -> clip space for the camera's intrinsics, far plane at infinity.

    Image row v maps to NDC y = 2 v / H - 1, so the first row GL stores (its bottom row) is the image's top row
    and the read-back needs no flip; the mirror reverses winding, which does not matter with culling off.
    """
    k = camera.intrinsics
    return np.array([
        [2.0 * k.fx / k.width, 0.0, 2.0 * k.cx / k.width - 1.0, 0.0],
        [0.0, 2.0 * k.fy / k.height, 2.0 * k.cy / k.height - 1.0, 0.0],
        [0.0, 0.0, 1.0, -2.0 * camera.near],
        [0.0, 0.0, 1.0, 0.0],
    ])


def world_to_camera(camera: PinholeCamera, origin_world: FloatArray) -> FloatArray:
    """(4, 4) shifted world frame (world minus ``origin_world``) -> OpenCV camera frame."""
    R_world_camera = camera.R_world_camera
    T_camera_world = np.eye(4)
    T_camera_world[:3, :3] = R_world_camera.T
    T_camera_world[:3, 3] = -R_world_camera.T @ (camera.p_world_camera - origin_world)
    return T_camera_world


def ground_region_world(camera: PinholeCamera, ground_z: float) -> FloatArray:
    """(8, 3) world points bounding the ground the view sees out to SHADOW_FAR_M: the image corners' rays at the
    near plane and at SHADOW_FAR_M, their heights clamped to the band around the ground that receives shadows."""
    k = camera.intrinsics
    u = np.array([0.0, k.width, 0.0, k.width])
    v = np.array([0.0, 0.0, k.height, k.height])
    rays_camera = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(4)], axis=-1)
    p_world = np.concatenate([camera.p_world_camera + (rays_camera * depth) @ camera.R_world_camera.T
                              for depth in (camera.near, SHADOW_FAR_M)])
    p_world[:, 2] = np.clip(p_world[:, 2], ground_z + GROUND_BAND_M[0], ground_z + GROUND_BAND_M[1])
    return p_world


def light_to_unit(lo: FloatArray, hi: FloatArray) -> FloatArray:
    """(4, 4) orthographic map of the light-frame box [lo, hi] onto [-1, 1]^3."""
    scale = 2.0 / (hi - lo)
    ortho = np.diag([*scale, 1.0])
    ortho[:3, 3] = -1.0 - lo * scale
    return ortho


@dataclass(frozen=True)
class LightView:
    """The sun's orthographic view of one frame: ``world_to_clip`` for the depth pass, ``world_to_shadow`` (clip
    then [-1, 1] -> [0, 1]) for the lookup; both from the shifted world frame. ``depth_bias`` in map depth units."""

    world_to_clip: FloatArray
    world_to_shadow: FloatArray
    depth_bias: float


def sun_view(camera: PinholeCamera, ground_z: float, caster_depth: tuple[float, float], R_light_world: FloatArray,
             origin_world: FloatArray) -> LightView:
    """The light's box spans the view's ground region across, and every caster and that ground along the sun."""
    p_light = (ground_region_world(camera, ground_z) - origin_world) @ R_light_world.T
    lo, hi = p_light.min(axis=0), p_light.max(axis=0)
    lo[2], hi[2] = min(lo[2], caster_depth[0]) - 1.0, max(hi[2], caster_depth[1]) + 1.0
    T_light_world = np.eye(4)
    T_light_world[:3, :3] = R_light_world
    world_to_clip = light_to_unit(lo, hi) @ T_light_world
    to_texture = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1.0]])
    return LightView(world_to_clip, to_texture @ world_to_clip, SHADOW_BIAS_M / float(hi[2] - lo[2]))


def tone_map(hdr: np.ndarray, exposure: float) -> UInt8Array:
    """sRGB bytes of linear colours by the camera pass's curve (extended Reinhard, then sRGB)."""
    x = np.maximum(np.asarray(hdr, np.float64) * exposure, 0.0)
    y = np.clip(x * (1.0 + x / WHITE_POINT**2) / (1.0 + x), 0.0, 1.0)
    srgb = np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def face_corners(values: np.ndarray, faces: np.ndarray) -> Float32Array:
    """(3 m, k) float32: a per-face attribute (m, k) repeated on the three corners of each face."""
    return np.ascontiguousarray(np.repeat(values[faces], 3, axis=0), np.float32)


class LlvmpipeScene:
    """The packed scene's triangles on the GL context, drawn per frame by ``draw`` and, untimed, by ``object_ids``.

    Vertices are uploaded relative to ``origin_world`` (the scene's centre) so float32 keeps millimetres.
    """

    def __init__(self, ctx: Any, scene: CompiledScene, packed: PackedScene) -> None:
        self.ctx, self.scene = ctx, scene
        self.origin_world = 0.5 * (packed.vertices.min(axis=0) + packed.vertices.max(axis=0))
        self.R_light_world = light_rotation(scene.env.sun_dir_world)
        v_shifted = packed.vertices - self.origin_world
        caster_depth = (v_shifted[np.unique(packed.faces[packed.shadow_faces])] @ self.R_light_world[2]
                        if packed.shadow_faces.size else np.zeros(1))
        self.caster_depth = (float(caster_depth.min()), float(caster_depth.max()))
        self.mount_height = float(scene.ego.mount.z)  # the camera above the road under the ego
        self._programs()
        self._buffers(packed, v_shifted)
        self.shadow_map = ctx.depth_texture((SHADOW_MAP_SIZE, SHADOW_MAP_SIZE))
        self.shadow_map.compare_func = "<="  # a shadow sampler: linear filtering gives 2x2 PCF
        self.shadow_map.repeat_x = self.shadow_map.repeat_y = False
        self.shadow_fbo = ctx.framebuffer(depth_attachment=self.shadow_map)
        self.targets: dict[tuple[int, int], tuple[Any, Any]] = {}

    def _programs(self) -> None:
        env, ctx = self.scene.env, self.ctx
        self.camera_program = ctx.program(vertex_shader=CAMERA_VERTEX, fragment_shader=CAMERA_FRAGMENT)
        self.depth_program = ctx.program(vertex_shader=DEPTH_VERTEX, fragment_shader=DEPTH_FRAGMENT)
        self.id_program = ctx.program(vertex_shader=ID_VERTEX, fragment_shader=ID_FRAGMENT)
        ambient = env.ambient * (0.5 * env.sky_horizon + 0.5 * env.sky_zenith) * 2.2
        vectors = {"sun_dir": env.sun_dir_world, "sun_rgb": SUN_SCALE * env.sun_intensity * env.sun_color,
                   "ambient_rgb": ambient}
        for name, vector in vectors.items():
            self.camera_program[name].value = tuple(float(x) for x in vector)
        self.camera_program["exposure"].value = float(env.exposure)
        self.camera_program["inv_white2"].value = 1.0 / WHITE_POINT**2
        self.camera_program["shadow_map"].value = 0  # texture unit
        self.sky_rgb = tone_map(SKY_SCALE * env.sky_horizon, env.exposure) / 255.0

    def _buffers(self, packed: PackedScene, v_shifted: FloatArray) -> None:
        ctx, shown = self.ctx, packed.faces[packed.camera_faces]
        positions = ctx.buffer(np.ascontiguousarray(v_shifted[shown].reshape(-1, 3), np.float32))
        normals = ctx.buffer(face_corners(packed.face_normal, packed.camera_faces))
        colors = ctx.buffer(face_corners(packed.face_color, packed.camera_faces))
        objects = ctx.buffer(face_corners(packed.face_object[:, None], packed.camera_faces))
        casters = ctx.buffer(np.ascontiguousarray(v_shifted[packed.faces[packed.shadow_faces]].reshape(-1, 3),
                                                  np.float32))
        self.camera_vao = ctx.vertex_array(self.camera_program, [(positions, "3f", "in_position"),
                                                                 (normals, "3f", "in_normal"),
                                                                 (colors, "3f", "in_color")])
        self.depth_vao = ctx.vertex_array(self.depth_program, [(casters, "3f", "in_position")])
        self.id_vao = ctx.vertex_array(self.id_program, [(positions, "3f", "in_position"),
                                                         (objects, "1f", "in_object")])

    def _target(self, size: tuple[int, int]) -> tuple[Any, Any]:
        """The colour and object-id framebuffers of one image size (they share a depth buffer)."""
        if size not in self.targets:
            depth = self.ctx.depth_renderbuffer(size)
            color = self.ctx.framebuffer([self.ctx.renderbuffer(size, 4)], depth)
            ids = self.ctx.framebuffer([self.ctx.renderbuffer(size, 1, dtype="f4")], depth)
            self.targets[size] = (color, ids)
        return self.targets[size]

    def _world_to_clip(self, camera: PinholeCamera) -> bytes:
        return matrix_bytes(camera_to_clip(camera) @ world_to_camera(camera, self.origin_world))

    def draw(self, camera: PinholeCamera) -> UInt8Array:
        """(H, W, 3) uint8 frame: shadow pass, camera pass, read-back."""
        ctx, k = self.ctx, camera.intrinsics
        ground_z = float(camera.p_world_camera[2]) - self.mount_height
        light = sun_view(camera, ground_z, self.caster_depth, self.R_light_world, self.origin_world)
        ctx.enable(ctx.DEPTH_TEST)
        self.shadow_fbo.use()
        self.shadow_fbo.clear(depth=1.0)
        ctx.polygon_offset = 1.5, 2.0
        self.depth_program["world_to_clip"].write(matrix_bytes(light.world_to_clip))
        self.depth_vao.render()
        ctx.polygon_offset = 0.0, 0.0
        color, _ = self._target((k.width, k.height))
        color.use()
        color.clear(*self.sky_rgb, 1.0, depth=1.0)
        self.shadow_map.use(location=0)
        program = self.camera_program
        program["world_to_clip"].write(self._world_to_clip(camera))
        program["world_to_shadow"].write(matrix_bytes(light.world_to_shadow))
        program["eye"].value = tuple(float(x) for x in camera.p_world_camera - self.origin_world)
        program["depth_bias"].value = light.depth_bias
        self.camera_vao.render()
        pixels = color.read(components=3, alignment=1)
        return np.frombuffer(pixels, np.uint8).reshape(k.height, k.width, 3)

    def object_ids(self, camera: PinholeCamera) -> np.ndarray:
        """(H, W) int32 object id of every pixel (ID_SKY where nothing is drawn)."""
        k = camera.intrinsics
        self.ctx.enable(self.ctx.DEPTH_TEST)
        _, ids = self._target((k.width, k.height))
        ids.use()
        ids.clear(float(ID_SKY), 0.0, 0.0, 0.0, depth=1.0)
        self.id_program["world_to_clip"].write(self._world_to_clip(camera))
        self.id_vao.render()
        values = np.frombuffer(ids.read(components=1, dtype="f4"), np.float32)
        return values.reshape(k.height, k.width).astype(np.int32)


def matrix_bytes(matrix: FloatArray) -> bytes:
    """A (4, 4) row-major matrix as the column-major float32 bytes a GLSL mat4 uniform takes."""
    return np.ascontiguousarray(matrix.T, np.float32).tobytes()


def our_renderer(threads: int | None) -> Callable[[CompiledScene, int, tuple[int, int]], UInt8Array]:
    """``render_frame`` as a function of (scene, frame, size) -> rgb, given ``threads`` where it accepts them."""
    takes_threads = "threads" in inspect.signature(render_frame).parameters
    if threads is not None and not takes_threads:
        print(f"note: render_frame takes no threads argument here; --threads {threads} is ignored")
    options: dict[str, Any] = {"threads": threads} if threads is not None and takes_threads else {}

    def draw(scene: CompiledScene, frame: int, size: tuple[int, int]) -> UInt8Array:
        return render_frame(scene, frame, size, **options).rgb

    return draw


def elapsed_ms(draw: Callable[[], object]) -> float:
    start = time.perf_counter()
    draw()
    return (time.perf_counter() - start) * 1000.0


def check_geometry(scene: CompiledScene, gl: LlvmpipeScene, frame: int, size: tuple[int, int]) -> float:
    """Share of pixels whose object id is the same in both renderers."""
    ours = render_frame(scene, frame, size).object_id
    return float(np.mean(gl.object_ids(scene.ego.camera(frame, size)) == ours))


def save_pair(out: Path, scene: CompiledScene, gl: LlvmpipeScene, frame: int, size: tuple[int, int],
              ours: Callable[[CompiledScene, int, tuple[int, int]], UInt8Array]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    stem = f"frame{frame:03d}_{size[0]}x{size[1]}"
    (out / f"{stem}_ours.png").write_bytes(png_bytes(ours(scene, frame, size)))
    (out / f"{stem}_llvmpipe.png").write_bytes(png_bytes(gl.draw(scene.ego.camera(frame, size))))


def time_interleaved(scene: CompiledScene, gl: LlvmpipeScene, frames: list[int], repeat: int,
                     ours: Callable[[CompiledScene, int, tuple[int, int]], UInt8Array],
                     ) -> dict[tuple[int, int], dict[str, list[float]]]:
    """ms per frame of both renderers per size; every (frame, size) runs both, alternating which goes first."""
    times: dict[tuple[int, int], dict[str, list[float]]] = {size: {"ours": [], "llvmpipe": []}
                                                            for size in BENCH_SIZES}
    turn = 0
    for _ in range(repeat):
        for frame in frames:
            for size in BENCH_SIZES:
                camera = scene.ego.camera(frame, size)  # outside the timings: both renderers need it
                runs: list[tuple[str, Callable[[], object]]] = [
                    ("ours", functools.partial(ours, scene, frame, size)),
                    ("llvmpipe", functools.partial(gl.draw, camera))]
                for name, draw in runs if turn % 2 == 0 else runs[::-1]:
                    times[size][name].append(elapsed_ms(draw))
                turn += 1
    return times


def report(times: dict[tuple[int, int], dict[str, list[float]]]) -> str:
    lines = [f"{'size':<10} {'ours ms':>9} {'llvmpipe ms':>12} {'ours/llvmpipe':>14}  runs"]
    for (width, height), runs in times.items():
        ours, gl = statistics.median(runs["ours"]), statistics.median(runs["llvmpipe"])
        lines.append(f"{f'{width}x{height}':<10} {ours:>9.1f} {gl:>12.1f} {ours / gl:>13.1f}x  {len(runs['ours'])}")
    return "\n".join(lines)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", type=Path, default=DEFAULT_CASE, help="case file (default: a stock shadow case)")
    parser.add_argument("--frames", type=int, default=3, help="frames spread over the drive (default 3)")
    parser.add_argument("--repeat", type=int, default=5, help="timed passes over the frames (default 5)")
    parser.add_argument("--threads", type=int, default=None,
                        help="threads for render_frame, where it takes a threads argument")
    parser.add_argument("--gl-threads", default="0",
                        help="LP_NUM_THREADS for llvmpipe: 0 (default) draws in the calling thread; auto leaves "
                             "it unset (one thread per core)")
    parser.add_argument("--save", type=Path, default=None, help="write both images of the first frame here")
    args = parser.parse_args(argv)
    if args.frames < 1 or args.repeat < 1 or not (args.gl_threads == "auto" or args.gl_threads.isdigit()):
        parser.error("--frames and --repeat must be at least 1; --gl-threads a count or auto")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    set_gl_threads(args.gl_threads)
    opened = open_llvmpipe()
    if isinstance(opened, str):
        print(opened, file=sys.stderr)
        return EXIT_NO_GL
    ctx, started = opened
    case = load_case(args.case)
    scene = compile_scene(case)
    packed = pack_scene(scene)
    gl = LlvmpipeScene(ctx, scene, packed)
    ours = our_renderer(args.threads)
    frames = frames_to_time(case, args.frames)
    print(f"case {args.case.name}: {len(packed.camera_faces)} triangles drawn, {len(packed.shadow_faces)} casting "
          f"shadows; frames {frames}")
    print(f"GL_RENDERER {ctx.info['GL_RENDERER']}; LP_NUM_THREADS={os.environ.get('LP_NUM_THREADS', 'unset')}: "
          f"the context started {len(started)} thread(s): {' '.join(started) or '-'}")
    for size in BENCH_SIZES:  # warm-up: numba and shader compilation, first uploads
        ours(scene, frames[0], size)
        gl.draw(scene.ego.camera(frames[0], size))
        agreement = check_geometry(scene, gl, frames[0], size)
        print(f"{size[0]}x{size[1]}: object ids agree on {agreement:.2%} of pixels")
        if args.save is not None:
            save_pair(args.save, scene, gl, frames[0], size, ours)
    print(report(time_interleaved(scene, gl, frames, args.repeat, ours)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
