"""The road surface as a triangle mesh: every road piece swept along its reference line.

Each vertex carries its road-frame coordinates (s, t) and piece index so the renderer can shade the surface
procedurally (asphalt, paint, surface layers) per pixel; each face carries its material.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..typed import MATERIALS, FloatArray, IntArray
from .road_layout import RoadNetwork, RoadPiece, Strip

ROW_STEP_M = 1.0
FAR_TERRAIN_M = 250.0  # terrain reaches this far beside the road (less on the inside of tight bends)
ARM_LIFT_M = 0.02  # junction arms sit a hair above the main road's terrain they overlap


@dataclass
class RoadSurface:
    """The swept road surface of a whole network.

    Attributes:
        vertices: (n, 3) float64 world positions.
        faces: (m, 3) int32.
        st: (n, 2) float64 road-frame (s, t) of every vertex in its piece.
        piece: (n,) int32 road piece index of every vertex.
        material: (m,) int32 index into typed.MATERIALS.
        carriageway: (m,) bool, True for faces between the outer lane boundaries.
    """

    vertices: FloatArray
    faces: IntArray
    st: FloatArray
    piece: IntArray
    material: IntArray
    carriageway: np.ndarray


def _profile(piece: RoadPiece, far_m: float) -> tuple[list[tuple[float, float]], list[int], list[int]]:
    """Cross-section polyline (t, h) from the left outer edge to the right one, with each segment's material
    and side (+1 left roadside, 0 carriageway, -1 right roadside)."""
    hw = piece.half_width
    strips = list(piece.strips)
    last = strips[-1]
    outer = sum(strip.width for strip in strips[:-1])
    strips[-1] = Strip(max(last.width, far_m - hw - outer), last.material, last.height)

    def walk(sign: int) -> tuple[list[tuple[float, float]], list[int]]:
        points, mats = [(sign * hw, 0.0)], []
        t, h = sign * hw, 0.0
        for strip in strips:
            if strip.height != h:
                points.append((t, strip.height))
                mats.append(MATERIALS.index("kerb") if strip.height > h else MATERIALS.index(strip.material))
                h = strip.height
            t += sign * strip.width
            points.append((t, h))
            mats.append(MATERIALS.index(strip.material))
        return points, mats

    left_pts, left_mats = walk(+1)
    right_pts, right_mats = walk(-1)
    points = left_pts[::-1] + right_pts
    mats = left_mats[::-1] + [MATERIALS.index(piece.carriageway)] + right_mats
    sides = [1] * len(left_mats) + [0] + [-1] * len(right_mats)
    return points, mats, sides


def _far_reach(piece: RoadPiece) -> float:
    k_max = float(np.max(np.abs(piece.line.curvature))) if piece.line.curvature.size else 0.0
    if k_max < 1e-6:
        return FAR_TERRAIN_M
    return min(FAR_TERRAIN_M, 0.8 / k_max)


def _sweep(piece: RoadPiece, index: int, lift: float) -> tuple[FloatArray, IntArray, FloatArray, IntArray, np.ndarray]:
    points, mats, sides = _profile(piece, _far_reach(piece))
    s_rows = np.arange(piece.s_start, piece.line.length, ROW_STEP_M)
    s_rows = np.append(s_rows, piece.line.length)
    t_prof = np.array([p[0] for p in points])
    h_prof = np.array([p[1] for p in points]) + lift
    n_rows, n_cols = s_rows.size, t_prof.size
    s_grid = np.repeat(s_rows, n_cols)
    t_grid = np.tile(t_prof, n_rows)
    vertices = piece.line.to_world(s_grid, t_grid, np.tile(h_prof, n_rows))
    st = np.stack([s_grid, t_grid], axis=-1)

    faces, face_mats, face_cw = [], [], []
    for row in range(n_rows - 1):
        s_a, s_b = s_rows[row], s_rows[row + 1]
        for col in range(n_cols - 1):
            side = sides[col]
            if side and any(g0 < s_b and s_a < g1 and g_side == side for g0, g1, g_side in piece.gaps):
                continue
            a, b = row * n_cols + col, row * n_cols + col + 1
            c, d = a + n_cols, b + n_cols
            # Columns run left to right (t decreasing) and rows forward, so (a, b, c) is counter-clockwise from above
            # (normals up, as glTF viewers that cull back faces expect).
            faces += [(a, b, c), (b, d, c)]
            face_mats += [mats[col]] * 2
            face_cw += [side == 0] * 2
    return (vertices, np.array(faces, np.int32).reshape(-1, 3), st,
            np.array(face_mats, np.int32), np.array(face_cw, bool))


def road_surface(network: RoadNetwork) -> RoadSurface:
    """Sweep every road piece of ``network`` into one mesh."""
    parts_v, parts_f, parts_st, parts_piece, parts_m, parts_cw = [], [], [], [], [], []
    offset = 0
    for index, piece in enumerate(network.pieces):
        vertices, faces, st, mats, cw = _sweep(piece, index, ARM_LIFT_M if index else 0.0)
        parts_v.append(vertices)
        parts_f.append(faces + offset)
        parts_st.append(st)
        parts_piece.append(np.full(len(vertices), index, np.int32))
        parts_m.append(mats)
        parts_cw.append(cw)
        offset += len(vertices)
    return RoadSurface(
        np.concatenate(parts_v), np.concatenate(parts_f).astype(np.int32), np.concatenate(parts_st),
        np.concatenate(parts_piece), np.concatenate(parts_m), np.concatenate(parts_cw),
    )
