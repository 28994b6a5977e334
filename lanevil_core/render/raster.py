"""Triangle rasterization with a depth buffer (numba).

The rasterizer knows nothing about what it draws: it takes vertices already in a view frame and writes, per
pixel, the nearest face id, its depth and perspective-correct barycentric weights (a pytorch3d-style
``Fragments``). Pixel (col, row) is sampled at its centre (col + 0.5, row + 0.5).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from ..typed import Float32Array, IntArray
from ._jit import kernel
from .bands import band_rows, in_band, overlaps_band, run_bands


@dataclass(frozen=True)
class Fragments:
    """Per-pixel result of rasterization.

    Attributes:
        face: (H, W) int32 face index, -1 where nothing was drawn.
        depth: (H, W) float32 view depth (camera z, or distance along the light for orthographic views); inf if empty.
        bary: (H, W, 2) float32 perspective-correct weights of the face's 2nd and 3rd vertex.
    """

    face: IntArray
    depth: Float32Array
    bary: Float32Array


@kernel(inline="always")
def _edge(ax: float, ay: float, bx: float, by: float, px: float, py: float) -> float:
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax)


@kernel
def _fill(
    tris: np.ndarray, slot: int, face_index: int, face_buf: np.ndarray, depth_buf: np.ndarray, bary_buf: np.ndarray,
    perspective: bool, attributes: bool, band: int, bands: int,
) -> None:
    """Scan-convert the rows of band ``band`` of the screen-space triangle ``tris[slot]`` (see SX .. DZ).

    With ``attributes`` False only the depth buffer is written (shadow maps).
    """
    height, width = depth_buf.shape
    tri = tris[slot]
    sx = (tri[SX, 0], tri[SX, 1], tri[SX, 2])
    sy = (tri[SY, 0], tri[SY, 1], tri[SY, 2])
    sw = (tri[SW, 0], tri[SW, 1], tri[SW, 2])
    b1 = (tri[B1, 0], tri[B1, 1], tri[B1, 2])
    b2 = (tri[B2, 0], tri[B2, 1], tri[B2, 2])
    depth_v = (tri[DZ, 0], tri[DZ, 1], tri[DZ, 2])
    area = _edge(sx[0], sy[0], sx[1], sy[1], sx[2], sy[2])
    if area == 0.0 or not np.isfinite(area):
        return
    inv_area = 1.0 / area
    y_min = max(int(np.floor(min(sy[0], sy[1], sy[2]) - 0.5)) + 1, 0)
    y_max = min(int(np.floor(max(sy[0], sy[1], sy[2]) - 0.5)), height - 1)
    x_lo_f = min(sx[0], sx[1], sx[2])
    x_hi_f = max(sx[0], sx[1], sx[2])
    for row in range(y_min, y_max + 1):
        if not in_band(row, band, bands):
            continue
        py = row + 0.5
        # Solve the three edge inequalities for the covered x interval of this row.
        lo, hi = x_lo_f - 0.5, x_hi_f + 0.5
        ok = True
        for e in range(3):
            i, j = e, (e + 1) % 3
            ax, ay, bx, by = sx[i], sy[i], sx[j], sy[j]
            # edge(px) * sign(area) >= 0  with  edge = A*px + B,  A = -(by - ay)
            a_coef = -(by - ay) * inv_area
            b_coef = ((bx - ax) * (py - ay) + (by - ay) * ax) * inv_area
            if a_coef > 0.0:
                lo = max(lo, -b_coef / a_coef)
            elif a_coef < 0.0:
                hi = min(hi, -b_coef / a_coef)
            elif b_coef < 0.0:
                ok = False
        if not ok or hi < lo:
            continue
        c0 = max(int(np.ceil(lo - 0.5)), 0)
        c1 = min(int(np.floor(hi - 0.5)), width - 1)
        for col in range(c0, c1 + 1):
            px = col + 0.5
            l0 = _edge(sx[1], sy[1], sx[2], sy[2], px, py) * inv_area
            l1 = _edge(sx[2], sy[2], sx[0], sy[0], px, py) * inv_area
            l2 = 1.0 - l0 - l1
            if perspective:
                w = l0 * sw[0] + l1 * sw[1] + l2 * sw[2]
                if w <= 0.0:
                    continue
                z = 1.0 / w
                p0, p1, p2 = l0 * sw[0] * z, l1 * sw[1] * z, l2 * sw[2] * z
            else:
                p0, p1, p2 = l0, l1, l2
                z = l0 * depth_v[0] + l1 * depth_v[1] + l2 * depth_v[2]
            if z < depth_buf[row, col]:
                depth_buf[row, col] = z
                if not attributes:
                    continue
                face_buf[row, col] = face_index
                bary_buf[row, col, 0] = p0 * b1[0] + p1 * b1[1] + p2 * b1[2]
                bary_buf[row, col, 1] = p0 * b2[0] + p1 * b2[1] + p2 * b2[2]


@kernel(inline="always")
def _clear_band(face_buf: np.ndarray, depth_buf: np.ndarray, bary_buf: np.ndarray, attributes: bool, band: int,
                bands: int) -> None:
    """Empty the band's rows (its own thread touches them first: they stay in its cache)."""
    for row in band_rows(depth_buf.shape[0], band, bands):
        depth_buf[row, :] = np.inf
        if attributes:
            face_buf[row, :] = -1
            bary_buf[row, :, :] = 0.0


# A screen triangle: rows SX, SY, SW (1 / camera z, perspective) of its vertices, then their weights of the
# source face's 2nd and 3rd vertex (B1, B2) and their view depth (DZ).
SX, SY, SW, B1, B2, DZ = range(6)


@kernel(inline="always")
def _store(tris: np.ndarray, rows: np.ndarray, slot: int, height: int) -> None:
    """Record the rows a stored triangle can cover (the same range ``_fill`` scans)."""
    sy = tris[slot, SY]
    rows[slot, 0] = max(int(np.floor(min(sy[0], sy[1], sy[2]) - 0.5)) + 1, 0)
    rows[slot, 1] = min(int(np.floor(max(sy[0], sy[1], sy[2]) - 0.5)), height - 1)


@kernel
def _setup_perspective(
    v_view: np.ndarray, faces: np.ndarray, face_ids: np.ndarray, fx: float, fy: float, cx: float, cy: float,
    near: float, width: int, height: int, tris: np.ndarray, rows: np.ndarray, band: int, bands: int,
) -> None:
    """Cull, clip at the near plane and project the band's share of the faces (a contiguous run of them): face k
    becomes screen triangles in slots 2k and 2k + 1 (an empty slot gets no rows)."""
    # Clipped polygon: up to 4 vertices, each with position and its weights of the original vertices 1 and 2.
    px = np.empty(4)
    py = np.empty(4)
    pz = np.empty(4)
    pb1 = np.empty(4)
    pb2 = np.empty(4)
    ref_b1 = (0.0, 1.0, 0.0)
    ref_b2 = (0.0, 0.0, 1.0)
    for k in range(band * face_ids.size // bands, (band + 1) * face_ids.size // bands):
        rows[2 * k, 0] = rows[2 * k + 1, 0] = 1
        rows[2 * k, 1] = rows[2 * k + 1, 1] = 0
        f = face_ids[k]
        i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
        z0, z1, z2 = v_view[i0, 2], v_view[i1, 2], v_view[i2, 2]
        if z0 <= near and z1 <= near and z2 <= near:
            continue
        # Cheap frustum rejection on x and y.
        if (v_view[i0, 0] > z0 * (width - cx) / fx + 1e-9 and v_view[i1, 0] > z1 * (width - cx) / fx
                and v_view[i2, 0] > z2 * (width - cx) / fx and z0 > near and z1 > near and z2 > near):
            continue
        if (v_view[i0, 0] < -z0 * cx / fx and v_view[i1, 0] < -z1 * cx / fx and v_view[i2, 0] < -z2 * cx / fx
                and z0 > near and z1 > near and z2 > near):
            continue
        if (v_view[i0, 1] > z0 * (height - cy) / fy and v_view[i1, 1] > z1 * (height - cy) / fy
                and v_view[i2, 1] > z2 * (height - cy) / fy and z0 > near and z1 > near and z2 > near):
            continue
        if (v_view[i0, 1] < -z0 * cy / fy and v_view[i1, 1] < -z1 * cy / fy and v_view[i2, 1] < -z2 * cy / fy
                and z0 > near and z1 > near and z2 > near):
            continue
        # Sutherland-Hodgman against z = near.
        n = 0
        idx = (i0, i1, i2)
        for e in range(3):
            a, b = idx[e], idx[(e + 1) % 3]
            za, zb = v_view[a, 2], v_view[b, 2]
            if za > near:
                px[n], py[n], pz[n] = v_view[a, 0], v_view[a, 1], za
                pb1[n], pb2[n] = ref_b1[e], ref_b2[e]
                n += 1
            if (za > near) != (zb > near):
                u = (near - za) / (zb - za)
                e1 = (e + 1) % 3
                px[n] = v_view[a, 0] + u * (v_view[b, 0] - v_view[a, 0])
                py[n] = v_view[a, 1] + u * (v_view[b, 1] - v_view[a, 1])
                pz[n] = near
                pb1[n] = ref_b1[e] + u * (ref_b1[e1] - ref_b1[e])
                pb2[n] = ref_b2[e] + u * (ref_b2[e1] - ref_b2[e])
                n += 1
        for t in range(1, n - 1):
            slot = 2 * k + t - 1
            for m, q in enumerate((0, t, t + 1)):
                inv = 1.0 / pz[q]
                tris[slot, SX, m] = fx * px[q] * inv + cx
                tris[slot, SY, m] = fy * py[q] * inv + cy
                tris[slot, SW, m] = inv
                tris[slot, B1, m], tris[slot, B2, m] = pb1[q], pb2[q]
                tris[slot, DZ, m] = pz[q]
            _store(tris, rows, slot, height)


@kernel
def _setup_orthographic(
    v_view: np.ndarray, faces: np.ndarray, face_ids: np.ndarray, scale: float, u0: float, v0: float, width: int,
    height: int, tris: np.ndarray, rows: np.ndarray, band: int, bands: int,
) -> None:
    """Scale the band's share of the faces (a contiguous run) to map texels: face k in slot k (a face off the map
    is culled before anything is stored for it: its slot keeps no rows)."""
    for k in range(band * face_ids.size // bands, (band + 1) * face_ids.size // bands):
        rows[k, 0], rows[k, 1] = 1, 0
        f = face_ids[k]
        i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
        x0, x1, x2 = (v_view[i0, 0] - u0) * scale, (v_view[i1, 0] - u0) * scale, (v_view[i2, 0] - u0) * scale
        if max(x0, x1, x2) < 0 or min(x0, x1, x2) > width:
            continue
        y0, y1, y2 = (v_view[i0, 1] - v0) * scale, (v_view[i1, 1] - v0) * scale, (v_view[i2, 1] - v0) * scale
        if max(y0, y1, y2) < 0 or min(y0, y1, y2) > height:
            continue
        tris[k, SX, 0], tris[k, SX, 1], tris[k, SX, 2] = x0, x1, x2
        tris[k, SY, 0], tris[k, SY, 1], tris[k, SY, 2] = y0, y1, y2
        tris[k, SW, 0] = tris[k, SW, 1] = tris[k, SW, 2] = 1.0
        tris[k, DZ, 0], tris[k, DZ, 1], tris[k, DZ, 2] = v_view[i0, 2], v_view[i1, 2], v_view[i2, 2]
        _store(tris, rows, k, height)


@kernel
def _fill_band(
    tris: np.ndarray, rows: np.ndarray, per_slot: int, face_ids: np.ndarray, face_buf: np.ndarray,
    depth_buf: np.ndarray, bary_buf: np.ndarray, perspective: bool, attributes: bool, band: int, bands: int,
) -> None:
    """Clear the band's rows, then draw every stored triangle, in face order, into them."""
    _clear_band(face_buf, depth_buf, bary_buf, attributes, band, bands)
    for slot in range(rows.shape[0]):
        if not overlaps_band(rows[slot, 0], rows[slot, 1], band, bands):
            continue
        _fill(tris, slot, face_ids[slot // per_slot], face_buf, depth_buf, bary_buf, perspective, attributes, band,
              bands)


Scratch = dict[int, tuple[np.ndarray, np.ndarray]]  # view -> (slots, 6, 3) triangles, (slots, 2) row ranges
_spare: list[Scratch] = []
_spare_lock = threading.Lock()


@contextmanager
def _scratch_set() -> Iterator[Scratch]:
    """Draw buffers for one draw, handed on to the next draw when it ends: fresh large arrays cost page faults
    every frame (2.6 of a 160x90 frame's 7 ms were the shadow cascades' setup writing into new pages), and buffers
    kept per thread made a server hold one set (41 MB after a 1280x720 frame of the largest stock scene measured)
    for every request thread that ever rendered. Sets are as many as draws ever ran at once."""
    with _spare_lock:
        buffers = _spare.pop() if _spare else {}
    try:
        yield buffers
    finally:
        with _spare_lock:
            _spare.append(buffers)


def _scratch(buffers: Scratch, slots: int, view: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(slots, 6, 3) float64 triangles and (slots, 2) int64 row ranges of a draw's ``view`` from ``buffers``, grown
    when they are too small."""
    tris, rows = buffers.get(view, (None, None))
    if tris is None or rows is None or tris.shape[0] < slots:
        tris, rows = np.empty((slots, 6, 3)), np.empty((slots, 2), np.int64)
        buffers[view] = tris, rows
    return tris[:slots], rows[:slots]


def _draw(setup: Callable[[np.ndarray, np.ndarray, int, int], None], slots: int, per_slot: int, face_ids: IntArray,
          buffers: tuple[IntArray, Float32Array, Float32Array], perspective: bool, attributes: bool,
          threads: int) -> None:
    """Set up every face's screen triangles (bands take runs of faces), then fill (bands take rows)."""
    face_buf, depth_buf, bary_buf = buffers
    with _scratch_set() as scratch:
        tris, rows = _scratch(scratch, slots)
        run_bands(lambda band, bands: setup(tris, rows, band, bands), threads)
        run_bands(lambda band, bands: _fill_band(tris, rows, per_slot, face_ids, face_buf, depth_buf, bary_buf,
                                                 perspective, attributes, band, bands), threads)


def rasterize_perspective(
    v_view: np.ndarray, faces: IntArray, face_ids: IntArray, size: tuple[int, int],
    fx: float, fy: float, cx: float, cy: float, near: float, threads: int = 1,
) -> Fragments:
    """Rasterize faces ``face_ids`` of a mesh whose vertices (n, 3) are in an OpenCV camera frame.

    Faces crossing the near plane are clipped; depth is camera z. Each of ``threads`` row bands walks every face
    in order, so the depth test resolves ties as one thread would.
    """
    width, height = size
    face_buf, depth_buf = np.empty((height, width), np.int32), np.empty((height, width), np.float32)
    bary_buf = np.empty((height, width, 2), np.float32)
    v_camera = np.ascontiguousarray(v_view, np.float64)
    ids = face_ids.astype(np.int32)
    _draw(lambda tris, rows, band, bands: _setup_perspective(v_camera, faces, ids, fx, fy, cx, cy, near, width,
                                                             height, tris, rows, band, bands),
          2 * ids.size, 2, ids, (face_buf, depth_buf, bary_buf), True, True, threads)
    return Fragments(face_buf, depth_buf, bary_buf)


def depth_orthographic_views(
    v_view: np.ndarray, faces: IntArray, face_ids: IntArray, size: tuple[int, int],
    views: Sequence[tuple[float, float, float]], outs: Sequence[Float32Array], threads: int = 1,
) -> None:
    """Nearest depth along +z of a view frame into each of ``outs`` ((H, W) float32, C-contiguous) for the
    orthographic ``views`` (scale, u0, v0): pixel = (x - u0, y - v0) * scale (no clipping). All views are set up
    in one parallel step and filled in another, so threads are handed work twice, not twice per view."""
    width, height = size
    v_view = np.ascontiguousarray(v_view, np.float64)
    ids = face_ids.astype(np.int32)
    no_faces, no_bary = np.empty((1, 1), np.int32), np.empty((1, 1, 2), np.float32)
    with _scratch_set() as scratch:
        stored = [_scratch(scratch, ids.size, 1 + view) for view in range(len(views))]  # view 0: the camera's draw

        def set_up(band: int, bands: int) -> None:
            for (scale, u0, v0), (tris, rows) in zip(views, stored):
                _setup_orthographic(v_view, faces, ids, scale, u0, v0, width, height, tris, rows, band, bands)

        def fill(band: int, bands: int) -> None:
            for depth_buf, (tris, rows) in zip(outs, stored):
                _fill_band(tris, rows, 1, ids, no_faces, depth_buf, no_bary, False, False, band, bands)

        run_bands(set_up, threads)
        run_bands(fill, threads)


def depth_orthographic(
    v_view: np.ndarray, faces: IntArray, face_ids: IntArray, size: tuple[int, int], scale: float, u0: float, v0: float,
    threads: int = 1,
) -> Float32Array:
    """(H, W) float32 nearest depth along +z of a view frame: pixel = (x - u0, y - v0) * scale (no clipping)."""
    width, height = size
    depth_buf = np.empty((height, width), np.float32)
    depth_orthographic_views(v_view, faces, face_ids, size, [(scale, u0, v0)], [depth_buf], threads)
    return depth_buf


@kernel
def _lookup_rows(face_buf: np.ndarray, per_face: np.ndarray, empty: int, out: np.ndarray, band: int,
                 bands: int) -> None:
    height, width = face_buf.shape
    for row in band_rows(height, band, bands):
        for col in range(width):
            f = face_buf[row, col]
            out[row, col] = per_face[max(f, 0)] if f >= 0 else empty


def per_pixel(face_buf: IntArray, per_face: IntArray, empty: int, threads: int = 1) -> IntArray:
    """(H, W) int32 ``per_face[face]`` of every pixel's face, ``empty`` where nothing was drawn."""
    out = np.empty(face_buf.shape, np.int32)
    table = np.ascontiguousarray(per_face, np.int32)
    run_bands(lambda band, bands: _lookup_rows(face_buf, table, empty, out, band, bands), threads)
    return out
