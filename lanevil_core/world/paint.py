"""Road paint: the albedo of the road's materials and of its paint, the stripe table the renderer shades paint from,
and the paint as quads (the glTF scene, the editor's view).

Every painted line is one row of the stripe table, in road coordinates of its piece; the renderer, the exporter and
the editor all start from that table, so paint looks the same everywhere and lines up with the labels (the same
reference line).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..typed import MATERIALS, Float32Array, FloatArray, IntArray
from .road_layout import RoadNetwork

if TYPE_CHECKING:  # the case model builds on the world (through the illusions), not the other way round
    from ..case import Marking, Road

DOUBLE_LINE_SPACING_M = 0.12  # clear space between the two lines of a double marking
BOTTS_DOT_DIAMETER_M = 0.12
BOTTS_DOT_SPACING_M = 1.2

# Linear albedo of the cross-section materials (index = typed.MATERIALS).
MATERIAL_ALBEDO = np.array([
    [0.055, 0.055, 0.058],  # asphalt
    [0.30, 0.29, 0.27],  # concrete
    [0.075, 0.11, 0.045],  # grass (mown lawn and verge, a little yellow and grey in it)
    [0.16, 0.145, 0.13],  # gravel
    [0.38, 0.37, 0.35],  # kerb
    [0.13, 0.10, 0.07],  # dirt
    [0.21, 0.205, 0.19],  # slab: weathered concrete pavement (new 0.35-0.40, aged 0.20-0.30)
], np.float32)



def road_albedo(network: RoadNetwork) -> Float32Array:
    """(len(MATERIALS), 3) float32 linear albedo of the road materials on ``network``: ``MATERIAL_ALBEDO`` with the
    carriageway's material in the case's ``road.surface_color`` when it has one (the renderer, the glTF scene and
    the editor colour the road from this)."""
    if network.surface_color is None:
        return MATERIAL_ALBEDO
    albedo = MATERIAL_ALBEDO.copy()
    albedo[MATERIALS.index(network.main.carriageway)] = network.surface_color
    return albedo


WHITE_PAINT = (0.70, 0.70, 0.67)
YELLOW_PAINT = (0.72, 0.46, 0.04)
STOP_LINE_M = 0.4

# Stripe table columns: piece, t_center, half_width, s0, s1, pattern (0 solid, 1 dashed, 2 dots), on, period, r, g, b,
# boundary index (-1: not tied to a lane boundary), wear (0 = fresh paint)
STRIPE_COLUMNS = 13
PAINT_WEAR = 12  # the wear column
PAINT_LIFT_M = 0.01  # paint quads float this far above the asphalt in meshes (glTF scene, editor)
PAINT_STEP_M = 1.0  # length of one paint quad along the road


@dataclass(frozen=True)
class RoadPaint:
    """The main road's markings, resolved at compile time: one per lane boundary, left to right, and whether paint
    is drawn at all (``painted`` False: the paint-free control; the labels still follow the markings)."""

    markings: tuple[Marking, ...]
    painted: bool = True

    @property
    def line_types(self) -> tuple[str, ...]:
        """The marking type of each boundary, left to right (``none``: unmarked, no label)."""
        return tuple(marking.type for marking in self.markings)

    def stripes(self, network: RoadNetwork) -> FloatArray:
        """The stripe table of this paint on ``network`` (see ``paint_stripes``)."""
        return paint_stripes(network, self.markings, self.painted)

    def mesh(self, network: RoadNetwork) -> tuple[FloatArray, IntArray, Float32Array]:
        """The paint as quads (see ``paint_mesh``)."""
        return paint_mesh(network, self.markings, self.painted)


def road_paint(road: Road) -> RoadPaint:
    """A road's markings and paint switch."""
    return RoadPaint(markings=tuple(road.markings), painted=road.paint)


def _color(marking: Marking) -> tuple[float, float, float]:
    return YELLOW_PAINT if marking.type.startswith("yellow") else WHITE_PAINT


def _stripes_of_boundary(piece: int, t: float, marking: Marking, s0: float, s1: float) -> list[list[float]]:
    """Stripes of one marking; for double lines the pair is centred on the boundary, the first on the left
    (none for an unmarked boundary)."""
    if marking.type == "none":
        return []
    offset = (marking.width + DOUBLE_LINE_SPACING_M) / 2
    rgb = list(_color(marking))
    period = marking.dash + marking.gap

    def stripe(t_c: float, pattern: int, width: float = marking.width, on: float = marking.dash,
               per: float = period) -> list[float]:
        return [piece, t_c, width / 2, s0, s1, pattern, on, per, *rgb]

    kind = marking.type.split("_", 1)[1] if marking.type != "botts_dots" else "dots"
    if kind == "solid":
        return [stripe(t, 0)]
    if kind == "dashed":
        return [stripe(t, 1)]
    if kind == "double_solid":
        return [stripe(t + offset, 0), stripe(t - offset, 0)]
    if kind == "solid_dashed":
        return [stripe(t + offset, 0), stripe(t - offset, 1)]
    return [stripe(t, 2, BOTTS_DOT_DIAMETER_M, BOTTS_DOT_DIAMETER_M, BOTTS_DOT_SPACING_M)]


def paint_stripes(network: RoadNetwork, markings: Sequence[Marking], paint: bool = True) -> FloatArray:
    """Every painted stripe of the network as rows of the stripe table (none when ``paint`` is False)."""
    rows: list[list[float]] = []
    if not paint:
        return np.zeros((0, STRIPE_COLUMNS), np.float64)
    for index, piece in enumerate(network.pieces):
        last = len(piece.boundaries_t) - 1
        for k, (t, marking) in enumerate(zip(piece.boundaries_t, markings)):
            side = 1 if k == 0 else (-1 if k == last else 0)
            spans = [(piece.s_start, piece.line.length)]
            for g0, g1, g_side in piece.gaps:  # edge lines break where a junction arm leaves
                if side and g_side == side:
                    spans = [(a, b) for a0, b0 in spans for a, b in ((a0, min(b0, g0)), (max(a0, g1), b0)) if b > a]
            for s0, s1 in spans:
                rows += [[*row, k, marking.wear] for row in _stripes_of_boundary(index, float(t), marking, s0, s1)]
        if index:  # a stop line across the arm's lanes that lead into the junction
            s0 = piece.s_start + 1.5
            rows.append([index, -piece.half_width / 2, piece.half_width / 2, s0, s0 + STOP_LINE_M, 0,
                         1.0, 1.0, *WHITE_PAINT, -1, 0.0])
    return np.array(rows, np.float64).reshape(-1, STRIPE_COLUMNS)


def stripe_index(stripes: FloatArray, pieces: int, boundaries: int) -> np.ndarray:
    """(pieces, boundaries + 1, 2) int64 [start, stop) rows of the stripe table per piece and boundary; the last
    slot holds stripes not tied to one boundary (stop lines). The shader looks only at the boundaries near a
    pixel instead of every stripe."""
    index = np.zeros((pieces, boundaries + 1, 2), np.int64)
    piece_of, boundary_of = stripes[:, 0].astype(int), stripes[:, 11].astype(int)
    for p in range(pieces):
        for k in range(-1, boundaries):
            rows = np.flatnonzero((piece_of == p) & (boundary_of == k))
            if rows.size:
                index[p, k if k >= 0 else boundaries] = (rows[0], rows[-1] + 1)
    return index


def dash_spans(s0: float, s1: float, pattern: int, on: float, period: float) -> list[tuple[float, float]]:
    """Painted [a, b) spans of one stripe; dashes and dots start at ``s0`` with period ``period``."""
    if pattern == 0:
        return [(s0, s1)]
    starts = np.arange(s0, s1, period)
    return [(float(a), float(min(a + on, s1))) for a in starts]


def paint_mesh(network: RoadNetwork, markings: Sequence[Marking],
               paint: bool = True) -> tuple[FloatArray, IntArray, Float32Array]:
    """Quads of every paint stripe just above the road: vertices (n, 3), faces (m, 3), colours (m, 3)."""
    stripes = paint_stripes(network, markings, paint).reshape(-1, STRIPE_COLUMNS)
    vertices, faces, colors = [], [], []
    count = 0
    for piece, t_c, half, s0, s1, pattern, on, period, r, g, b, _boundary, _wear in stripes:
        line = network.pieces[int(piece)].line
        for a, b_end in dash_spans(s0, s1, int(pattern), on, period):
            s_road = np.append(np.arange(a, b_end, PAINT_STEP_M), b_end)
            left = line.to_world(s_road, t_c + half, PAINT_LIFT_M)
            right = line.to_world(s_road, t_c - half, PAINT_LIFT_M)
            n = len(s_road)
            vertices.append(np.concatenate([left, right]))
            i = np.arange(n - 1)
            quads = np.stack([i, i + n, i + 1, i + 1, i + n, i + n + 1], axis=1).reshape(-1, 3) + count
            faces.append(quads)
            colors.append(np.tile([r, g, b], (len(quads), 1)))
            count += 2 * n
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32)
    return (np.concatenate(vertices), np.concatenate(faces).astype(np.int32),
            np.concatenate(colors).astype(np.float32))
