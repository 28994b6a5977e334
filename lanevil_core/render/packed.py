"""Flat arrays of a compiled scene, built once per scene and shared by every frame's render."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import cv2
import numpy as np

from ..typed import MATERIALS, Float32Array, FloatArray, IntArray
from ..world.paint import MATERIAL_ALBEDO, stripe_index
from ..world.road_layout import RoadNetwork
from ..world.road_mesh import RoadSurface, road_surface
from ..world.scene import FIRST_OBJECT_ID, ID_ROAD, ID_ROADSIDE, CompiledScene, Mesh
from ._jit import kernel
from .lighting import DOWN, LIGHT_COLUMNS, light_row
from .raster import depth_orthographic


@dataclass
class LayerAtlas:
    """Every surface layer's mip pyramid in one flat buffer.

    Attributes:
        texels: (n, 5) float32 premultiplied rgb, alpha, wet of all levels of all layers.
        table: (k, 9) float64 per (layer, level): piece, s0, t0, texel, rows, cols, offset, over_paint, level.
        first_level: (layers + 1,) int32 index of each layer's level 0 in ``table``.
    """

    texels: Float32Array
    table: FloatArray
    first_level: IntArray


@dataclass
class PackedScene:
    """Triangles of the road surface and all objects, with per-face and per-vertex attributes."""

    vertices: FloatArray  # (n, 3) world
    faces: IntArray  # (m, 3)
    vertex_st: Float32Array  # (n, 2) road-frame s, t of road vertices, facade coordinates of objects (or 0)
    vertex_piece: IntArray  # (n,) road piece or -1
    face_material: IntArray  # (m,) MATERIALS index for road faces, -1 for objects
    face_object: IntArray  # (m,) id-buffer value
    face_color: Float32Array  # (m, 3)
    face_emission: Float32Array  # (m, 3)
    face_gloss: Float32Array  # (m,)
    face_texture: Float32Array  # (m,) strength of the photographic surface texture (``TEXTURE_BY_KIND``)
    face_finish: np.ndarray  # (m,) int8 ``facade.FINISHES`` index of object faces (0 = plain, and on the road)
    face_normal: Float32Array  # (m, 3) world, unit
    face_grad_st: Float32Array  # (m, 6) world gradients of s and of t on each road face (0 for objects)
    camera_faces: IntArray  # faces drawn in the camera
    shadow_faces: IntArray  # faces drawn into the sun's shadow map
    mirror_faces: IntArray  # object faces that wet roads mirror
    stripes: FloatArray  # (k, paint.STRIPE_COLUMNS)
    stripe_index: np.ndarray  # (pieces, boundaries + 1, 2) see stripe_index()
    layers: LayerAtlas
    lights: FloatArray  # (l, LIGHT_COLUMNS): x, y, z, r, g, b, intensity, beam axis x, y, z, beam (BEAMS index)
    overhead: Float32Array  # (H, W) share of the sky each ground cell sees (1 = open)
    overhead_params: FloatArray  # (3,) x0, y0, cells per metre


MAX_MIP_LEVELS = 10


def _mip_shapes(rows: int, cols: int) -> list[tuple[int, int]]:
    """(rows, cols) of every mip level of a layer: halving (rounding down) while both sides exceed 2."""
    shapes = [(rows, cols)]
    while min(shapes[-1]) > 2 and len(shapes) < MAX_MIP_LEVELS:
        shapes.append((shapes[-1][0] // 2, shapes[-1][1] // 2))
    return shapes


def _fill_mips(rgba: np.ndarray, wet: np.ndarray | None, levels: list[np.ndarray]) -> None:
    """Write a layer's pyramid into ``levels`` ((rows, cols, 5) float32 views of the atlas): premultiplied rgb,
    alpha and wetness at level 0, then each level the 2x2 box mean of the one above."""
    base = levels[0]
    alpha = np.asarray(rgba[..., 3], np.float32)
    np.multiply(np.asarray(rgba[..., :3], np.float32), alpha[..., None], out=base[..., :3])
    base[..., 3] = alpha
    base[..., 4] = 0.0 if wet is None else wet
    for above, level in zip(levels, levels[1:]):
        h, w = level.shape[0] * 2, level.shape[1] * 2
        # The 2x2 box mean as four strided adds: several times faster than reshape().mean() on large layers.
        np.add(above[0:h:2, 0:w:2], above[1:h:2, 0:w:2], out=level)
        level += above[0:h:2, 1:w:2]
        level += above[1:h:2, 1:w:2]
        level *= 0.25


def layer_atlas(scene: CompiledScene) -> LayerAtlas:
    table, first, spans = [], [0], []
    offset = 0
    for layer in scene.layers:
        shapes = _mip_shapes(*layer.rgba.shape[:2])
        for lvl, (rows, cols) in enumerate(shapes):
            table.append([layer.piece, layer.s0, layer.t0, layer.texel * 2**lvl, rows, cols, offset,
                          float(layer.over_paint), lvl])
            offset += rows * cols
        first.append(len(table))
        spans.append(shapes)
    texels = np.empty((max(offset, 1), 5), np.float32)
    if offset == 0:
        texels[:] = 0.0
    for layer, shapes, row0 in zip(scene.layers, spans, first):
        views = [texels[int(table[row0 + lvl][6]):int(table[row0 + lvl][6]) + rows * cols].reshape(rows, cols, 5)
                 for lvl, (rows, cols) in enumerate(shapes)]
        _fill_mips(layer.rgba, layer.wet, views)
    return LayerAtlas(texels, np.array(table, np.float64).reshape(-1, 9), np.array(first, np.int32))


def _face_normals(vertices: FloatArray, faces: IntArray) -> Float32Array:
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return (normal / np.where(length > 0, length, 1.0)).astype(np.float32)


OVERHEAD_CELL_M = 0.25
OVERHEAD_MAX_CELLS = 2048
OVERHEAD_MARGIN_M = 25.0
COVER_HEIGHT_M = 1.5
COVERED_AMBIENT = 0.3  # share of the sky's light that reaches ground under a roof
# Ambient occlusion of the ground by what stands on it or hangs over it (walls, parked cars, hedges, crowns): the
# sky a ground cell sees past the casters around it, in AO_DIRECTIONS directions out to the last of AO_REACH_M.
# Casters narrower than two cells (poles, wires, lamp arms, trunks, boards) are left out: one ray would stand
# for their sliver of sky as for a wall's half.
AO_DIRECTIONS = 12
AO_REACH_M = (0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0)


def _overhead_grid(road: RoadSurface) -> tuple[FloatArray, float, tuple[int, int]]:
    """(corner (2,), cell (m), (W, H) cells) of the top-down maps over the ground near the carriageways."""
    near_road = road.vertices[np.abs(road.st[:, 1]) < np.abs(road.st[:, 1]).min() + OVERHEAD_MARGIN_M + 20.0]
    lo, hi = near_road[:, :2].min(axis=0) - OVERHEAD_MARGIN_M, near_road[:, :2].max(axis=0) + OVERHEAD_MARGIN_M
    cell = max(OVERHEAD_CELL_M, float(max(hi - lo)) / OVERHEAD_MAX_CELLS)
    return lo, cell, (int(np.ceil((hi[0] - lo[0]) / cell)) + 1, int(np.ceil((hi[1] - lo[1]) / cell)) + 1)


def _heights(packed: PackedScene, road: RoadSurface, faces: IntArray, lowest: bool = False) -> Float32Array:
    """(H, W) on the ``_overhead_grid``: the highest point of ``faces`` over each cell (-inf where none), or with
    ``lowest`` their lowest (inf where none)."""
    lo, cell, size = _overhead_grid(road)
    if lowest:
        return depth_orthographic(packed.vertices, packed.faces, faces, size, 1.0 / cell, lo[0], lo[1])
    v_down = np.stack([packed.vertices[:, 0], packed.vertices[:, 1], -packed.vertices[:, 2]], axis=-1)
    return -depth_orthographic(v_down, packed.faces, faces, size, 1.0 / cell, lo[0], lo[1])


def _ground(packed: PackedScene, road: RoadSurface) -> Float32Array:
    """(H, W) on the ``_overhead_grid``: the road surface's height over each cell (-inf where none), drawn once per
    road surface (its faces come first in the packed faces) for the cover and the occlusion maps alike."""
    return _reuse(("ground", id(road)), road,
                  lambda: _heights(packed, road, np.arange(len(road.faces), dtype=np.int32)))


def overhead_map(packed: PackedScene, road: RoadSurface) -> tuple[Float32Array, FloatArray]:
    """Top-down map of how much sky the ground near the carriageways sees under roofs (1 = open sky), and its
    (x0, y0, cells per metre).

    A cell is covered where the highest shadow caster above it stands more than COVER_HEIGHT_M over the road
    surface there (a bridge deck, a tunnel roof, a tree crown); covered ground gets COVERED_AMBIENT of the
    sky's light, and a 3x3 box blur softens the edges. ``ground_occlusion`` is the sky the roadside hides.
    """
    lo, cell, _ = _overhead_grid(road)
    top, ground = _heights(packed, road, packed.shadow_faces), _ground(packed, road)
    covered = (top > np.where(np.isfinite(ground), ground, -np.inf) + COVER_HEIGHT_M).astype(np.float32)
    openness = 1.0 - (1.0 - COVERED_AMBIENT) * _box3(covered)
    return np.ascontiguousarray(openness, np.float32), np.array([lo[0], lo[1], 1.0 / cell])


def ground_occlusion(packed: PackedScene, road: RoadSurface, roadside_faces: int) -> Float32Array:
    """(H, W) on the ``_overhead_grid``: the share of the sky's light the ground receives past what stands on it
    or hangs over it in the roadside (``sky_past``: the darkening at the foot of walls, under and around parked
    cars, along hedges and bins), from the shadow casters among the first ``roadside_faces`` packed faces. The
    roadside is what an edit leaves as it was, so the map is built once per roadside; an illusion's objects
    (fences, vehicles, pedestrians) add none (their shadows, and the cover term's roofs, are drawn as before)."""
    _, cell, _ = _overhead_grid(road)
    casters = packed.shadow_faces[packed.shadow_faces < roadside_faces]
    top, bottom = _heights(packed, road, casters), _heights(packed, road, casters, lowest=True)
    ground = _ground(packed, road)
    return np.ascontiguousarray(_box3(sky_past(*_wide_columns(top, bottom, ground), cell)), np.float32)


def _box3(values: Float32Array) -> Float32Array:
    """A 3x3 box blur (edges repeated)."""
    return np.asarray(cv2.blur(values, (3, 3), borderType=cv2.BORDER_REPLICATE), np.float32)


def _wide_columns(top: np.ndarray, bottom: np.ndarray, ground: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """(tops, bottoms) (H, W) of the casters over the ground (m above it; 0 where none), only where a caster is at
    least two cells wide each way (a 2x2 opening of where casters stand)."""
    there = np.isfinite(top) & np.isfinite(bottom) & np.isfinite(ground)
    core = there[:-1, :-1] & there[1:, :-1] & there[:-1, 1:] & there[1:, 1:]  # 2x2 blocks of casters
    wide = np.zeros_like(there)
    for i in (0, 1):
        for j in (0, 1):
            wide[i:i + core.shape[0], j:j + core.shape[1]] |= core
    tops, bottoms = np.zeros(top.shape), np.zeros(top.shape)
    tops[wide] = np.maximum(top[wide] - ground[wide], 0.0)
    bottoms[wide] = np.clip(bottom[wide] - ground[wide], 0.0, tops[wide])
    return tops, bottoms


@kernel
def sky_past(tops: FloatArray, bottoms: FloatArray, cell: float) -> Float32Array:
    """(H, W) share of the sky's cosine-weighted light each ground cell receives past the casters around it (each
    a column from ``bottoms`` to ``tops`` over the ground, m; both 0 where none). In each of AO_DIRECTIONS
    azimuths the sky is blocked between the elevations a column spans, the most of any column out to
    AO_REACH_M's last reach: the cosine-weighted light of the sky above elevation h is cos^2 h of the open sky's,
    so a column blocks sin^2 of its top's elevation less sin^2 of its bottom's."""
    rows, cols = tops.shape
    out = np.ones((rows, cols), np.float32)
    reach = np.array(AO_REACH_M)
    cos_k = np.cos(2.0 * np.pi * np.arange(AO_DIRECTIONS) / AO_DIRECTIONS)
    sin_k = np.sin(2.0 * np.pi * np.arange(AO_DIRECTIONS) / AO_DIRECTIONS)
    for i in range(rows):
        for j in range(cols):
            blocked = 0.0
            for d in range(AO_DIRECTIONS):
                most = 0.0
                for k in range(len(reach)):
                    y = int(round(i + sin_k[d] * reach[k] / cell))
                    x = int(round(j + cos_k[d] * reach[k] / cell))
                    if 0 <= y < rows and 0 <= x < cols and tops[y, x] > 0.0:
                        high, low = tops[y, x] / reach[k], bottoms[y, x] / reach[k]
                        most = max(most, high * high / (1.0 + high * high) - low * low / (1.0 + low * low))
                blocked += most
            out[i, j] = 1.0 - blocked / AO_DIRECTIONS
    return out


def _st_gradients(vertices: FloatArray, faces: IntArray, st: FloatArray, road_faces: int) -> Float32Array:
    """(m, 6) float32: the world-space gradients of s and t over each of the first ``road_faces`` faces (the road
    surface, where s and t are affine on every triangle); zeros for the rest."""
    grads = np.zeros((len(faces), 6), np.float32)
    tri = vertices[faces[:road_faces]]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    normal = np.cross(e1, e2)
    area2 = np.einsum("ij,ij->i", normal, normal)
    ok = area2 > 1e-12
    values = st[faces[:road_faces]]  # (k, 3, 2)
    for column in range(2):
        d1 = values[:, 1, column] - values[:, 0, column]
        d2 = values[:, 2, column] - values[:, 0, column]
        # Gradient g in the triangle's plane with g.e1 = d1 and g.e2 = d2.
        g = d1[:, None] * np.cross(e2, normal) + d2[:, None] * np.cross(normal, e1)
        g /= np.where(ok, area2, 1.0)[:, None]
        grads[:road_faces, 3 * column:3 * column + 3] = np.where(ok[:, None], g, 0.0)
    return grads


REUSED_ENTRIES = 16  # road surfaces, their heights, sky-openness and ground-occlusion maps of the same road
_reused: OrderedDict[tuple[str, Any], tuple[Any, Any]] = OrderedDict()
_reused_lock = threading.Lock()
T = TypeVar("T")


def _reuse(key: tuple[str, Any], owner: Any, build: Callable[[], T]) -> T:
    """``build()``, or what it returned for the same key and the same ``owner`` object (kept alive meanwhile).

    An edited case is compiled again around the same road network (``compile_scene(case, reuse=...)``); what
    depends only on the network, or on geometry whose digest is the key, need not be built again.
    """
    with _reused_lock:
        found = _reused.get(key)
        if found is not None and found[0] is owner:
            _reused.move_to_end(key)
            return found[1]
    value = build()
    with _reused_lock:
        _reused[key] = (owner, value)
        while len(_reused) > REUSED_ENTRIES:
            _reused.popitem(last=False)
    return value


def _road_surface(network: RoadNetwork) -> RoadSurface:
    return _reuse(("road", id(network)), network, lambda: road_surface(network))


# How strongly the photographic surface texture (weathering, grime, leaf clumps, tufts) marks each kind of mesh
# and each road material when the case's camera has a sensor (``Environment.detail``); 0 = flat colour.
TEXTURE_BY_KIND: dict[str, float] = {"tree": 1.0, "bush": 1.0, "terrain": 0.9, "building": 0.12, "tunnel": 0.6,
                                     "bridge": 0.5, "barrier": 0.3, "guard_rail": 0.2, "fence": 0.2, "pole": 0.3,
                                     "streetlight": 0.15, "vehicle": 0.08, "pedestrian": 0.15, "bicycle": 0.1}
DEFAULT_TEXTURE = 0.3
# Per road material (index = typed.MATERIALS): asphalt, concrete, grass, gravel, kerb, dirt, slab.
MATERIAL_TEXTURE = np.array([0.3, 0.15, 1.0, 0.8, 0.2, 0.8, 0.15], np.float32)


def _road_arrays(road: RoadSurface) -> dict[str, list[np.ndarray]]:
    """The road surface's per-vertex and per-face arrays, each the first entry of a list that meshes extend."""
    m = len(road.faces)
    return {"verts": [road.vertices], "faces": [road.faces], "st": [road.st], "piece": [road.piece],
            "mat": [road.material], "obj": [np.where(road.carriageway, ID_ROAD, ID_ROADSIDE).astype(np.int32)],
            "color": [MATERIAL_ALBEDO[road.material]], "emission": [np.zeros((m, 3), np.float32)],
            "gloss": [np.zeros(m, np.float32)], "texture": [MATERIAL_TEXTURE[road.material]],
            "finish": [np.zeros(m, np.int8)],
            "shadow": [np.zeros(m, bool)], "visible": [np.ones(m, bool)], "mirror": [np.zeros(m, bool)]}


def _append_meshes(arrays: dict[str, list[np.ndarray]], meshes: list[Mesh], first_index: int, offset: int) -> None:
    """Append ``meshes`` (object ids from ``first_index``, vertex numbers from ``offset``)."""
    for index, mesh in enumerate(meshes, start=first_index):
        m = len(mesh.faces)
        arrays["verts"].append(mesh.vertices)
        arrays["faces"].append(mesh.faces + offset)
        # an object's vertices carry its facade coordinates where it has them (read only on faces with a finish)
        arrays["st"].append(np.zeros((len(mesh.vertices), 2)) if mesh.uv is None else mesh.uv)
        arrays["finish"].append(np.zeros(m, np.int8) if mesh.finish is None else mesh.finish)
        arrays["piece"].append(np.full(len(mesh.vertices), -1, np.int32))
        arrays["mat"].append(np.full(m, -1, np.int32))
        arrays["obj"].append(np.full(m, FIRST_OBJECT_ID + index, np.int32))
        arrays["color"].append(mesh.colors)
        arrays["emission"].append(mesh.emission if mesh.emission is not None else np.zeros((m, 3), np.float32))
        arrays["gloss"].append(np.full(m, mesh.gloss, np.float32))
        arrays["texture"].append(np.full(m, TEXTURE_BY_KIND.get(mesh.kind, DEFAULT_TEXTURE), np.float32))
        arrays["shadow"].append(np.full(m, mesh.casts_shadow, bool))
        arrays["visible"].append(np.full(m, mesh.visible, bool))
        arrays["mirror"].append(np.full(m, mesh.visible and mesh.kind not in ("building", "terrain"), bool))
        offset += len(mesh.vertices)


@dataclass
class _Roadside:
    """The road surface and the roadside meshes that lead ``scene.meshes``, packed (what an edit of the case's
    illusions, sun or camera leaves as it was), with the per-face work on them done."""

    meshes: tuple[Mesh, ...]
    arrays: dict[str, np.ndarray]  # each key of _road_arrays, concatenated
    normals: Float32Array
    road_grad_st: Float32Array  # (road faces, 6)
    casters: Any  # blake2b over the shadow casters' corners so far (copied, then fed the rest)


def _pack_roadside(road: RoadSurface, meshes: tuple[Mesh, ...]) -> _Roadside:
    arrays = _road_arrays(road)
    _append_meshes(arrays, list(meshes), 0, len(road.vertices))
    joined = {key: np.concatenate(parts) for key, parts in arrays.items()}
    vertices, faces = joined["verts"], joined["faces"].astype(np.int32)
    casters = hashlib.blake2b(digest_size=16)
    casters.update(np.ascontiguousarray(vertices[faces[np.flatnonzero(joined["shadow"])]]).tobytes())
    road_faces = len(road.faces)
    road_grad_st = _st_gradients(vertices, faces[:road_faces], joined["st"], road_faces)
    return _Roadside(meshes, joined, _face_normals(vertices, faces), road_grad_st, casters)


def _roadside(scene: CompiledScene, road: RoadSurface) -> _Roadside:
    """The packed roadside of ``scene``, reused from a scene compiled around the same network and meshes (the
    cached value holds its meshes, so equal ids in the key are the same objects)."""
    leading = 0
    while leading < len(scene.meshes) and scene.meshes[leading].source < 0:
        leading += 1
    meshes = tuple(scene.meshes[:leading])
    return _reuse(("roadside", (id(scene.network), tuple(map(id, meshes)))), scene.network,
                  lambda: _pack_roadside(road, meshes))


def pack_scene(scene: CompiledScene) -> PackedScene:
    """Concatenate the road surface and every mesh into flat arrays (cached on the scene).

    The road and the roadside meshes come first and are packed once per road (``_roadside``); the illusions'
    meshes follow. The arrays are those of packing everything in one go."""
    cached = scene.cache.get("packed")
    if cached is not None:
        return cached
    road = _road_surface(scene.network)
    roadside = _roadside(scene, road)
    arrays = {key: [value] for key, value in roadside.arrays.items()}
    leading = len(roadside.meshes)
    _append_meshes(arrays, scene.meshes[leading:], leading, len(roadside.arrays["verts"]))
    joined = {key: np.concatenate(parts) for key, parts in arrays.items()}  # fresh arrays for every scene
    all_v, all_f = joined["verts"], joined["faces"].astype(np.int32)
    rest = all_f[len(roadside.normals):]
    grad_st = np.zeros((len(all_f), 6), np.float32)
    grad_st[:len(road.faces)] = roadside.road_grad_st
    shadow_faces = np.flatnonzero(joined["shadow"]).astype(np.int32)
    casters = roadside.casters.copy()
    casters.update(np.ascontiguousarray(all_v[all_f[shadow_faces[shadow_faces >= len(roadside.normals)]]]).tobytes())
    stripes = scene.paint.stripes(scene.network)
    lights = np.array([light_row(light.p_world, light.color, light.intensity, DOWN, light.beam)
                       for light in scene.lights], np.float64).reshape(-1, LIGHT_COLUMNS)
    packed = PackedScene(
        vertices=all_v, faces=all_f, vertex_st=joined["st"].astype(np.float32),
        vertex_piece=joined["piece"], face_material=joined["mat"],
        face_object=joined["obj"], face_color=joined["color"].astype(np.float32),
        face_emission=joined["emission"].astype(np.float32), face_gloss=joined["gloss"],
        face_texture=joined["texture"], face_finish=joined["finish"].astype(np.int8),
        face_normal=np.concatenate([roadside.normals, _face_normals(all_v, rest)]),
        face_grad_st=grad_st,
        camera_faces=np.flatnonzero(joined["visible"]).astype(np.int32),
        shadow_faces=shadow_faces,
        mirror_faces=np.flatnonzero(joined["mirror"]).astype(np.int32),
        stripes=stripes, stripe_index=stripe_index(stripes, len(scene.network.pieces), len(scene.paint.markings)),
        layers=layer_atlas(scene), lights=lights,
        overhead=np.zeros((1, 1), np.float32), overhead_params=np.zeros(3),
    )
    cover, packed.overhead_params = _reuse(("overhead", (id(scene.network), casters.hexdigest())), scene.network,
                                           lambda: overhead_map(packed, road))
    occlusion = _reuse(("occlusion", (id(scene.network), roadside.casters.hexdigest())), scene.network,
                       lambda: ground_occlusion(packed, road, len(roadside.normals)))
    packed.overhead = cover * occlusion
    scene.cache["packed"] = packed
    return packed


__all__ = ["MATERIALS", "PackedScene", "pack_scene"]
