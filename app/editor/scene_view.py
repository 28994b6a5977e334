"""The editor's 3D view: viser scene nodes built from a ``CompiledScene`` (world frame, +Z up, metres).

Nodes (all under fixed names, so rebuilding one replaces it):
  /road          road surface, lane paint and every roadside prop, one flat-coloured mesh
  /illusions/NN  illusion NN's meshes and its road-surface decals (textured quads on the road)
  /trajectory    the ego camera's path over all frames
  /camera        the ego camera's frustum at the current frame (OpenCV axes, as viser's frustums)
  /sun           an arrow towards the sun and a small sun ball
  /gizmo         the move handle of the selected illusion (along / across the road)

Geometry comes from ``lanevil_core`` (``road_surface``, ``paint.paint_mesh``, the meshes and surface layers of the
compiled scene, ``ego_camera``); this module only converts it to viser nodes. Colours are the scene's linear albedos,
written as glTF vertex colours (linear by the glTF spec), so the view matches the renderer's materials.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np
import trimesh
import viser
import viser.transforms as vtf
from PIL import Image

from lanevil_core.camera import PinholeCamera, ego_camera
from lanevil_core.case import Case
from lanevil_core.images import linear_to_srgb as _linear_to_srgb
from lanevil_core.typed import Float32Array, FloatArray, IntArray
from lanevil_core.world.paint import road_albedo, road_paint
from lanevil_core.world.primitives import flat_trimesh
from lanevil_core.world.road_layout import RoadNetwork
from lanevil_core.world.road_mesh import RoadSurface, road_surface
from lanevil_core.world.scene import CompiledScene, Mesh, SurfaceLayer

DECAL_LIFT_M = 0.02  # decals float this far above the asphalt (paint sits at 0.01 m)
DECAL_STEP_S_M = 1.0
DECAL_STEP_T_M = 0.5
DECAL_MAX_TEXELS = 2048
SUN_ARROW_M = 30.0
GIZMO_LIFT_M = 0.3
TRAJECTORY_COLOR = (255, 140, 0)
FRUSTUM_COLOR = (255, 60, 40)
SUN_COLOR = (255, 210, 60)
SELECTED_TINT = np.array([1.0, 0.55, 0.1], np.float32)

MoveHandler = Callable[[FloatArray], None]


def merged(parts: Sequence[tuple[FloatArray, IntArray, Float32Array]]) -> tuple[FloatArray, IntArray, Float32Array]:
    """One (vertices, faces, colours) triple from several."""
    parts = [part for part in parts if len(part[1])]
    if not parts:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32)
    offsets = np.cumsum([0] + [len(v) for v, _f, _c in parts[:-1]])
    return (np.concatenate([v for v, _f, _c in parts]),
            np.concatenate([f + o for (_v, f, _c), o in zip(parts, offsets)]).astype(np.int32),
            np.concatenate([c for _v, _f, c in parts]).astype(np.float32))


def mesh_parts(meshes: Sequence[Mesh]) -> list[tuple[FloatArray, IntArray, Float32Array]]:
    return [(mesh.vertices, mesh.faces, mesh.colors) for mesh in meshes if mesh.visible and len(mesh.faces)]


def road_parts(surface: RoadSurface, network: RoadNetwork, case: Case) -> list[tuple[FloatArray, IntArray,
                                                                                     Float32Array]]:
    """Road surface (coloured by material) and lane paint, as in ``export.scene_glb``."""
    return [(surface.vertices, surface.faces, road_albedo(network)[surface.material]),
            road_paint(case.road).mesh(network)]


def decal_trimesh(network: RoadNetwork, layer: SurfaceLayer) -> trimesh.Trimesh:
    """A road-surface layer as a textured grid lying on its road piece (texture in sRGB with alpha)."""
    line = network.pieces[layer.piece].line
    rows, cols = layer.rgba.shape[:2]
    s1, t1 = layer.s0 + rows * layer.texel, layer.t0 + cols * layer.texel
    s_road = np.append(np.arange(layer.s0, s1, DECAL_STEP_S_M), s1)
    t_road = np.append(np.arange(layer.t0, t1, DECAL_STEP_T_M), t1)
    s_grid, t_grid = np.meshgrid(s_road, t_road, indexing="ij")
    p_world = line.to_world(s_grid, t_grid, DECAL_LIFT_M).reshape(-1, 3)
    # trimesh UVs have v = 0 at the bottom image row; image row 0 is s0.
    u = (t_grid - layer.t0) / (t1 - layer.t0)
    v = 1.0 - (s_grid - layer.s0) / (s1 - layer.s0)
    uv = np.stack([u.ravel(), v.ravel()], axis=-1)
    n_s, n_t = len(s_road), len(t_road)
    i, j = np.meshgrid(np.arange(n_s - 1), np.arange(n_t - 1), indexing="ij")
    a = (i * n_t + j).ravel()
    faces = np.concatenate([np.stack([a, a + 1, a + n_t], 1), np.stack([a + 1, a + n_t + 1, a + n_t], 1)])
    step = max(1, int(np.ceil(max(rows, cols) / DECAL_MAX_TEXELS)))
    rgba = layer.rgba[::step, ::step]
    pixels = np.empty(rgba.shape, np.uint8)
    pixels[..., :3] = np.round(_linear_to_srgb(rgba[..., :3]) * 255.0)
    pixels[..., 3] = np.round(np.clip(rgba[..., 3], 0.0, 1.0) * 255.0)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(pixels, "RGBA"),
                                                   alphaMode="BLEND", metallicFactor=0.0, roughnessFactor=1.0,
                                                   doubleSided=True)
    return trimesh.Trimesh(vertices=p_world, faces=faces, process=False,
                           visual=trimesh.visual.TextureVisuals(uv=uv, material=material))


def wxyz_of(R_world_local: FloatArray) -> np.ndarray:
    return vtf.SO3.from_matrix(np.asarray(R_world_local, np.float64)).wxyz


def road_pose(network: RoadNetwork, s_road: float, t_road: float, lift: float = 0.0) -> tuple[np.ndarray, FloatArray]:
    """(wxyz, position) of a frame at (s, t) on the main road: +X along the road, +Y to its left, +Z up."""
    line = network.main.line
    _origin, tangent, left = line.frame(s_road)
    forward = np.array([tangent[0], tangent[1], 0.0])
    forward /= np.linalg.norm(forward)
    R_world_local = np.stack([forward, left, np.cross(forward, left)], axis=1)
    return wxyz_of(R_world_local), line.to_world(s_road, t_road, lift)


WORLD = "/world"  # every node of the view hangs under this frame, so hiding it hides the view
ViewMode = Literal["full", "light", "off"]
VIEW_MODES: tuple[ViewMode, ...] = ("full", "light", "off")


class SceneView:
    """Keeps the viser scene in step with the edited case; rebuilds only the parts whose inputs changed.

    ``mode``: ``full`` (viser's lights with shadow maps and its environment map), ``light`` (no shadow maps, no
    environment map: far cheaper where the browser draws in software) or ``off`` (no scene drawn; the camera
    preview fills the view as its background image)."""

    def __init__(self, scene: viser.SceneApi) -> None:
        self.scene = scene
        self.mode: ViewMode = "full"
        self.root = scene.add_frame(WORLD, show_axes=False)
        self._road_key: str | None = None
        self._illusion_keys: list[str] = []
        self._selected: int | None = None
        self.surface: RoadSurface | None = None
        self.network: RoadNetwork | None = None
        self._gizmo: viser.TransformControlsHandle | None = None
        self._on_move: MoveHandler | None = None
        self._frustum: viser.CameraFrustumHandle | None = None

    def set_mode(self, mode: ViewMode) -> None:
        """Draw the view in ``mode`` (see the class)."""
        self.mode = mode
        self.root.visible = mode != "off"
        if mode != "off":
            self.scene.set_background_image(None)
        if mode == "full":
            self.scene.configure_environment_map()
        else:
            self.scene.configure_environment_map(hdri=None)
        self.scene.configure_default_lights(enabled=True, cast_shadow=mode == "full")

    def show_backdrop(self, rgb: np.ndarray) -> None:
        """With the view off: the camera preview ``rgb`` (H, W, 3) uint8 fills the 3D view's place."""
        self.scene.set_background_image(rgb, format="jpeg", jpeg_quality=85)

    def show(self, compiled: CompiledScene, road_key: str, illusion_keys: list[str], selected: int | None) -> None:
        """Show ``compiled``: the road and roadside when ``road_key`` changed, each illusion whose key changed."""
        if road_key != self._road_key:
            self.network = compiled.network
            self.surface = road_surface(compiled.network)
            roadside = [m for m in compiled.meshes if m.source < 0]
            parts = road_parts(self.surface, compiled.network, compiled.case) + mesh_parts(roadside)
            self.scene.add_mesh_trimesh(f"{WORLD}/road", flat_trimesh(*merged(parts)), cast_shadow=False)
            self._show_trajectory(compiled.case, compiled.network)
            self._road_key = road_key
            self._illusion_keys = []
        self.network = compiled.network
        for index, key in enumerate(illusion_keys):
            stale = index >= len(self._illusion_keys) or self._illusion_keys[index] != key
            if stale or (index == selected) != (index == self._selected):
                self._show_illusion(compiled, index, index == selected)
        for index in range(len(illusion_keys), len(self._illusion_keys)):
            self.scene.remove_by_name(f"{WORLD}/illusions/{index:02d}")
        self._illusion_keys = list(illusion_keys)
        self._selected = selected
        self._show_sun(compiled)

    def _show_illusion(self, compiled: CompiledScene, index: int, selected: bool) -> None:
        name = f"{WORLD}/illusions/{index:02d}"
        self.scene.remove_by_name(name)
        self.scene.add_frame(name, show_axes=False)
        parts = mesh_parts([m for m in compiled.meshes if m.source == index])
        if parts:
            vertices, faces, colors = merged(parts)
            if selected:
                colors = 0.5 * colors + 0.5 * SELECTED_TINT
            self.scene.add_mesh_trimesh(f"{name}/meshes", flat_trimesh(vertices, faces, colors))
        for number, layer in enumerate(layer for layer in compiled.layers if layer.source == index):
            self.scene.add_mesh_trimesh(f"{name}/decal_{number:02d}", decal_trimesh(compiled.network, layer),
                                        cast_shadow=False)

    def _show_trajectory(self, case: Case, network: RoadNetwork) -> None:
        frames = range(0, case.ego.frames, max(1, case.ego.frames // 50))
        points = np.array([ego_camera(case, network, frame).p_world_camera for frame in frames])
        self.scene.add_spline_catmull_rom(f"{WORLD}/trajectory", points, thickness=3.0, thickness_units="screen",
                                          color=TRAJECTORY_COLOR)

    def _show_sun(self, compiled: CompiledScene) -> None:
        case, line = compiled.case, compiled.network.main.line
        s_mid = min(case.ego_s(case.ego.frames // 2), line.length)
        base = line.to_world(s_mid, 0.0, 0.5)
        tip = base + compiled.env.sun_dir_world * SUN_ARROW_M
        color = SUN_COLOR if compiled.env.sun_intensity > 0 and not compiled.env.night else (120, 120, 160)
        self.scene.add_line_segments(f"{WORLD}/sun/ray", np.array([[base, tip]]), colors=color, thickness=3.0,
                                     thickness_units="screen")
        self.scene.add_icosphere(f"{WORLD}/sun/ball", radius=1.5, color=color, position=tip, cast_shadow=False)

    def show_camera(self, camera: PinholeCamera) -> None:
        """The ego camera's frustum at the current frame."""
        k = camera.intrinsics
        fov_vertical = 2.0 * float(np.arctan(0.5 * k.height / k.fy))
        wxyz, position = wxyz_of(camera.R_world_camera), camera.p_world_camera
        if self._frustum is None:
            self._frustum = self.scene.add_camera_frustum(f"{WORLD}/camera", fov=fov_vertical,
                                                          aspect=k.width / k.height, scale=1.6, color=FRUSTUM_COLOR,
                                                          thickness=2.5, thickness_units="screen",
                                                          wxyz=wxyz, position=position)
        else:
            self._frustum.fov, self._frustum.aspect = fov_vertical, k.width / k.height
            self._frustum.wxyz, self._frustum.position = wxyz, position

    def show_gizmo(self, anchor: tuple[float, float] | None, on_move: MoveHandler) -> None:
        """Put the move handle at road coordinates ``anchor`` (None hides it); ``on_move(p_world)`` on release."""
        if anchor is None or self.network is None:
            if self._gizmo is not None:
                self._gizmo.visible = False
            return
        wxyz, position = road_pose(self.network, anchor[0], anchor[1], GIZMO_LIFT_M)
        if self._gizmo is None:
            self._gizmo = self.scene.add_transform_controls(
                f"{WORLD}/gizmo", scale=4.0, disable_rotations=True, active_axes=(True, True, False),
                depth_test=False, wxyz=wxyz, position=position)

            @self._gizmo.on_update
            def _(event: viser.TransformControlsEvent) -> None:
                if event.phase == "end":
                    self._moved(np.asarray(event.target.position))

        self._on_move = on_move
        self._gizmo.wxyz, self._gizmo.position = wxyz, position
        self._gizmo.visible = True

    def _moved(self, p_world: FloatArray) -> None:
        if self._on_move is not None:
            self._on_move(p_world)
