"""Cascaded orthographic shadow maps along the sun direction.

Light frame: +Z points from the sun into the scene (``-sun_dir_world``); X and Y span the map. A cascade covers
the ground part of one slice of the camera frustum, snapped to whole texels so shadows do not crawl as the ego moves.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..camera import PinholeCamera
from ..typed import Float32Array, FloatArray
from ._jit import kernel
from .bands import band_rows, run_bands
from .lighting import COARSE_SHIFT, FAR_AROUND, NEAR_AROUND
from .packed import PackedScene
from .raster import depth_orthographic_views

CASCADE_FAR_M = (18.0, 55.0, 220.0)
CASCADE_SIZE = 1024  # at 1280 pixels wide
GROUND_BAND_M = (-4.0, 14.0)  # heights around the camera's ground that receive shadows worth mapping
CACHED_CASCADES = 6  # two frames' worth: a cascade whose snapped origin stays put is not drawn again


@dataclass(frozen=True)
class ShadowMaps:
    """Attributes:
    depth: (C, S, S) float32 light-frame depth of the nearest caster, inf where none.
    params: (C, 3) float64 per cascade: u0, v0, texels per metre.
    R_light_world: (3, 3) float64 rows = light-frame axes in world coordinates.
    """

    depth: Float32Array
    cells: Float32Array  # (C, S/8, S/8, 2) per 8x8 texels, see lighting.NEAR_AROUND, FAR_AROUND
    params: FloatArray
    R_light_world: FloatArray


def light_rotation(sun_dir_world: FloatArray) -> FloatArray:
    """(3, 3) rotation whose rows are the light frame's X, Y, Z axes in the world."""
    z_axis = -np.asarray(sun_dir_world, np.float64)
    z_axis /= np.linalg.norm(z_axis)
    helper = np.array([0.0, 0.0, 1.0]) if abs(z_axis[2]) < 0.95 else np.array([1.0, 0.0, 0.0])
    x_axis = np.cross(helper, z_axis)
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(z_axis, x_axis)
    return np.stack([x_axis, y_axis, z_axis])


def _slice_points_world(camera: PinholeCamera, near: float, far: float) -> FloatArray:
    """World points bounding the ground band of the frustum between depths ``near`` and ``far``."""
    k = camera.intrinsics
    corners = np.array([[0, 0], [k.width, 0], [0, k.height], [k.width, k.height]], np.float64)
    rays_camera = np.stack([(corners[:, 0] - k.cx) / k.fx, (corners[:, 1] - k.cy) / k.fy, np.ones(4)], axis=-1)
    points = [camera.p_world_camera + (rays_camera * d) @ camera.R_world_camera.T for d in (near, far)]
    p_world = np.concatenate(points)
    ground = camera.p_world_camera[2] - 3.0
    p_world[:, 2] = np.clip(p_world[:, 2], ground + GROUND_BAND_M[0], ground + GROUND_BAND_M[1])
    return p_world


def cascade_size(image_width: int) -> int:
    """Texels per cascade side for an image width: shadow detail follows pixel size (1024 at 1280 wide)."""
    return int(min(max(2 ** round(np.log2(image_width * CASCADE_SIZE / 1280)), 256), 2048))


@kernel
def _pool_cells(depth: np.ndarray, nearest: np.ndarray, farthest: np.ndarray, band: int, bands: int) -> None:
    """The nearest and the farthest caster depth of every coarse cell (2**COARSE_SHIFT texels square) of one map,
    for one band's cell rows. The map is read row by row, each row's cells side by side, in the order it lies
    in memory (with the cell's width known when compiling, 4-5x faster than a cell at a time)."""
    cells = depth.shape[0] >> COARSE_SHIFT
    for cell_y in band_rows(cells, band, bands):
        low = nearest[cell_y]
        high = farthest[cell_y]
        low[:] = np.inf
        high[:] = -np.inf
        for y in range(cell_y << COARSE_SHIFT, (cell_y + 1) << COARSE_SHIFT):
            row = depth[y]
            for cell_x in range(cells):
                a = low[cell_x]
                b = high[cell_x]
                for k in range(1 << COARSE_SHIFT):
                    a = min(a, row[(cell_x << COARSE_SHIFT) + k])
                    b = max(b, row[(cell_x << COARSE_SHIFT) + k])
                low[cell_x] = a
                high[cell_x] = b


@kernel(inline="always")
def _around(cells: np.ndarray, rows: tuple[int, int, int], x: int, last: int, nearest: bool) -> float:
    """The least (``nearest``) or greatest value of ``cells`` over the given rows and columns x - 1 .. x + 1
    (clamped to the grid: a repeated cell changes neither)."""
    left, right = max(x - 1, 0), min(x + 1, last)
    out = cells[rows[1], x]
    for y in rows:
        for i in (left, x, right):
            out = min(out, cells[y, i]) if nearest else max(out, cells[y, i])
    return out


@kernel
def _dilate_cells(nearest: np.ndarray, farthest: np.ndarray, out: np.ndarray, band: int, bands: int) -> None:
    """Every cell's extremes over itself and its eight neighbours, for the cell rows of one band."""
    cells = nearest.shape[0]
    for y in band_rows(cells, band, bands):
        rows = (max(y - 1, 0), y, min(y + 1, cells - 1))
        for x in range(cells):
            out[y, x, NEAR_AROUND] = _around(nearest, rows, x, cells - 1, True)
            out[y, x, FAR_AROUND] = _around(farthest, rows, x, cells - 1, False)


def pool_extremes(depths: Sequence[Float32Array], threads: int = 1) -> list[Float32Array]:
    """Per map of ``depths``, (S >> COARSE_SHIFT, S >> COARSE_SHIFT, 2): the nearest and the farthest caster depth
    in each coarse cell and its eight neighbours (see lighting.NEAR_AROUND, FAR_AROUND). One lookup answers "is
    any caster near enough to shade this point?" and "does every texel around it shade it?" for any filter
    reaching less than a cell. All maps are pooled in one parallel step and dilated in another."""
    cells = [depth.shape[0] >> COARSE_SHIFT for depth in depths]
    pooled = [(np.empty((n, n), np.float32), np.empty((n, n), np.float32)) for n in cells]
    outs = [np.empty((n, n, 2), np.float32) for n in cells]

    def pool(band: int, bands: int) -> None:
        for depth, (nearest, farthest) in zip(depths, pooled):
            _pool_cells(depth, nearest, farthest, band, bands)

    def dilate(band: int, bands: int) -> None:
        for (nearest, farthest), out in zip(pooled, outs):
            _dilate_cells(nearest, farthest, out, band, bands)

    run_bands(pool, threads)
    run_bands(dilate, threads)
    return outs


CascadeKey = tuple[bytes, int, float, float, float]
CascadeMaps = tuple[Float32Array, Float32Array]  # depth, extremes per coarse cell


@dataclass
class CascadeCache:
    """Rasterized cascades of one caster set (a packed scene's), most recent last.

    A cascade is fully determined by the sun direction, its size and its snapped origin and texel, so a key of
    those finds a map that is byte-identical to drawing it again. The casters of a packed scene never change;
    a scene whose objects change is compiled and packed anew and gets a new cache.
    """

    entries: OrderedDict[CascadeKey, CascadeMaps] = field(default_factory=OrderedDict)
    lock: threading.Lock = field(default_factory=threading.Lock)
    hits: int = 0

    def get(self, key: CascadeKey) -> CascadeMaps | None:
        with self.lock:
            found = self.entries.get(key)
            if found is not None:
                self.entries.move_to_end(key)
                self.hits += 1
            return found

    def put(self, key: CascadeKey, maps: CascadeMaps) -> None:
        with self.lock:
            self.entries[key] = maps
            while len(self.entries) > CACHED_CASCADES:
                self.entries.popitem(last=False)


def _cascade_frame(camera: PinholeCamera, R_light_world: FloatArray, near: float, far: float,
                   size: int) -> tuple[float, float, float]:
    """(u0, v0, texel) of the cascade covering the frustum slice [near, far]: light-frame origin of its corner
    texel and the texel's size in metres, snapped to whole power-of-two texels."""
    p_light = _slice_points_world(camera, near, far) @ R_light_world.T
    lo, hi = p_light[:, :2].min(axis=0), p_light[:, :2].max(axis=0)
    extent = float(max(hi - lo)) * 1.05 + 1.0
    texel = float(2.0 ** np.ceil(np.log2(extent / size)))  # power-of-two texels keep snapping stable
    u0 = float(np.floor((0.5 * (lo[0] + hi[0]) - 0.5 * size * texel) / texel) * texel)
    v0 = float(np.floor((0.5 * (lo[1] + hi[1]) - 0.5 * size * texel) / texel) * texel)
    return u0, v0, texel


def build_shadow_maps(packed: PackedScene, camera: PinholeCamera, sun_dir_world: FloatArray,
                      size: int | None = None, threads: int = 1, cache: CascadeCache | None = None) -> ShadowMaps:
    """Rasterize every shadow-casting face into each cascade (``size`` texels a side; default from the image).

    With a ``cache`` (of this packed scene's casters), a cascade already drawn for the same sun and snapped
    origin is reused.
    """
    size = size if size is not None else cascade_size(camera.intrinsics.width)
    R_light_world = light_rotation(sun_dir_world)
    sun_key = np.asarray(sun_dir_world, np.float64).tobytes()
    depth = np.empty((len(CASCADE_FAR_M), size, size), np.float32)
    cells = np.empty((len(CASCADE_FAR_M), size >> COARSE_SHIFT, size >> COARSE_SHIFT, 2), np.float32)
    params = np.zeros((len(CASCADE_FAR_M), 3))
    missing: list[tuple[int, CascadeKey]] = []
    near = 0.1
    for c, far in enumerate(CASCADE_FAR_M):
        u0, v0, texel = _cascade_frame(camera, R_light_world, near, far, size)
        key: CascadeKey = (sun_key, size, u0, v0, texel)
        params[c] = (u0, v0, 1.0 / texel)
        maps = cache.get(key) if cache is not None else None
        if maps is None:
            missing.append((c, key))
        else:
            depth[c], cells[c] = maps
        near = far * 0.9
    if missing:
        v_light = packed.vertices @ R_light_world.T
        views = [(params[c, 2], params[c, 0], params[c, 1]) for c, _ in missing]
        depth_orthographic_views(v_light, packed.faces, packed.shadow_faces, (size, size), views,
                                 [depth[c] for c, _ in missing], threads)
        for (c, key), extremes in zip(missing, pool_extremes([depth[c] for c, _ in missing], threads)):
            cells[c] = extremes
            if cache is not None:
                cache.put(key, (depth[c], cells[c]))  # views of this frame's maps, never written again
    return ShadowMaps(depth, cells, params, R_light_world)
