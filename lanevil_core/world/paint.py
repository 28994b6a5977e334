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

from ..typed import MATERIALS, Float32Array, FloatArray, IntArray, MarkingStandardName
from .junction_markings import Mark, junction_marks
from .marking_standards import standard_markings
from .road_layout import RoadNetwork

if TYPE_CHECKING:  # the case model builds on the world (through the illusions), not the other way round
    from ..case import Marking, Road

DOUBLE_LINE_SPACING_M = 0.12  # clear space between the two lines of a double marking
# Botts' dots: round raised ceramic markers, 4 in across, every 4 ft along the line (Caltrans' non-reflective
# Type A marker and lane-line spacing).
BOTTS_DOT_DIAMETER_M = 0.10
BOTTS_DOT_SPACING_M = 1.2
WEAR_SHIFT_SPAN_M = 4096.0  # worn paint's chip pattern starts this far along the road or less, by the case's seed

# Linear albedo of the cross-section materials (index = typed.MATERIALS).
MATERIAL_ALBEDO = np.array([
    [0.055, 0.055, 0.058],  # asphalt
    [0.25, 0.245, 0.23],  # concrete: paving flags of footways (weathered, 0.2-0.3)
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

# Stripe table columns: piece, t_center, half_width, s0, s1, pattern (0 solid, 1 dashed, 2 dots, 3 a convex polygon),
# on, period, r, g, b, boundary index (-1: not tied to a lane boundary), wear (0 = fresh paint), then a polygon's
# corners s, t (up to MAX_CORNERS, counter-clockwise; a triangle repeats its last; t_center, half_width, s0 and s1
# are then its bounding box).
STRIPE_COLUMNS = 21
PAINT_WEAR = 12  # the wear column
POLYGON = 3
POLYGON_CORNERS = 13
MAX_CORNERS = 4
PAINT_LIFT_M = 0.01  # paint quads float this far above the asphalt in meshes (glTF scene, editor)
PAINT_STEP_M = 1.0  # length of one paint quad along the road


@dataclass(frozen=True)
class RoadPaint:
    """The main road's markings, resolved at compile time (a marking standard's dashes and widths applied): one per
    lane boundary, left to right, whether paint is drawn at all (``painted`` False: the paint-free control; the
    labels still follow the markings) and where along the road worn paint's chip pattern starts (by the seed)."""

    markings: tuple[Marking, ...]
    painted: bool = True
    wear_shift_m: float = 0.0
    dot_groups: bool = False  # Botts' dots in groups that stand in for the dashes (under a marking standard)
    standard: MarkingStandardName = "custom"  # the manual the junction's markings are painted to

    @property
    def line_types(self) -> tuple[str, ...]:
        """The marking type of each boundary, left to right (``none``: unmarked, no label)."""
        return tuple(marking.type for marking in self.markings)

    def stripes(self, network: RoadNetwork) -> FloatArray:
        """The stripe table of this paint on ``network`` (see ``paint_stripes``)."""
        return paint_stripes(network, self.markings, self.painted, self.dot_groups, self.standard)

    def mesh(self, network: RoadNetwork) -> tuple[FloatArray, IntArray, Float32Array]:
        """The paint as quads (see ``paint_mesh``)."""
        return paint_mesh(network, self.markings, self.painted, self.dot_groups, self.standard)


def road_paint(road: Road, seed: int = 0) -> RoadPaint:
    """A road's markings under its marking standard (which also groups Botts' dots into its dashes), its paint
    switch, and the chip pattern of the case ``seed`` (worn paint flakes differently under another seed)."""
    shift = float(np.random.default_rng([seed, 0x3EA4]).uniform(0.0, WEAR_SHIFT_SPAN_M))
    return RoadPaint(markings=standard_markings(road.markings, road.marking_standard), painted=road.paint,
                     wear_shift_m=shift, dot_groups=road.marking_standard != "custom",
                     standard=road.marking_standard)


def _color(marking: Marking) -> tuple[float, float, float]:
    return YELLOW_PAINT if marking.type.startswith("yellow") else WHITE_PAINT


def _dot_groups(s0: float, s1: float, marking: Marking) -> list[tuple[float, float]]:
    """[start, end) of each group of Botts' dots standing in for a dash of ``marking`` (MUTCD 3B.14: a group of
    markers in place of each segment of a broken line): as many dots, BOTTS_DOT_SPACING_M apart, as fit in the
    dash, every dash + gap."""
    count = int(np.floor(marking.dash / BOTTS_DOT_SPACING_M + 1e-9)) + 1
    length = (count - 1) * BOTTS_DOT_SPACING_M + BOTTS_DOT_DIAMETER_M
    return [(float(a), float(min(a + length, s1))) for a in np.arange(s0, s1, marking.dash + marking.gap)]


def _stripes_of_boundary(piece: int, t: float, marking: Marking, s0: float, s1: float,
                         dot_groups: bool = False) -> list[list[float]]:
    """Stripes of one marking; for double lines the pair is centred on the boundary, the first on the left; Botts'
    dots in a row, or with ``dot_groups`` one stripe per group (none for an unmarked boundary)."""
    if marking.type == "none":
        return []
    offset = (marking.width + DOUBLE_LINE_SPACING_M) / 2
    rgb = list(_color(marking))
    period = marking.dash + marking.gap

    def stripe(t_c: float, pattern: int) -> list[float]:
        return [piece, t_c, marking.width / 2, s0, s1, pattern, marking.dash, period, *rgb]

    kind = marking.type.split("_", 1)[1] if marking.type != "botts_dots" else "dots"
    if kind == "solid":
        return [stripe(t, 0)]
    if kind == "dashed":
        return [stripe(t, 1)]
    if kind == "double_solid":
        return [stripe(t + offset, 0), stripe(t - offset, 0)]
    if kind == "solid_dashed":
        return [stripe(t + offset, 0), stripe(t - offset, 1)]
    spans = _dot_groups(s0, s1, marking) if dot_groups else [(s0, s1)]
    return [[piece, t, BOTTS_DOT_DIAMETER_M / 2, a, b, 2, BOTTS_DOT_DIAMETER_M, BOTTS_DOT_SPACING_M, *rgb]
            for a, b in spans]


def mark_row(mark: Mark, wear: float) -> list[float]:
    """The stripe table's row of a junction mark in white paint worn ``wear``: a solid stripe for an upright
    rectangle, else a polygon with its corners."""
    s_road, t_road = mark.corners_st[:, 0], mark.corners_st[:, 1]
    s0, s1, t0, t1 = float(s_road.min()), float(s_road.max()), float(t_road.min()), float(t_road.max())
    row = [mark.piece, 0.5 * (t0 + t1), 0.5 * (t1 - t0), s0, s1, 0 if mark.upright else POLYGON, 1.0, 1.0,
           *WHITE_PAINT, -1, wear] + [0.0] * (STRIPE_COLUMNS - POLYGON_CORNERS)
    if not mark.upright:
        corners = np.concatenate([mark.corners_st, np.repeat(mark.corners_st[-1:],
                                                             MAX_CORNERS - len(mark.corners_st), axis=0)])
        row[POLYGON_CORNERS:] = corners.ravel().tolist()
    return row


def paint_stripes(network: RoadNetwork, markings: Sequence[Marking], paint: bool = True,
                  dot_groups: bool = False, standard: MarkingStandardName = "custom") -> FloatArray:
    """Every painted stripe of the network as rows of the stripe table (none when ``paint`` is False); Botts' dots
    in groups with ``dot_groups``; the junction's markings (``junction_markings``) to ``standard``, as worn as the
    most worn line, after each piece's lines."""
    rows: list[list[float]] = []
    if not paint:
        return np.zeros((0, STRIPE_COLUMNS), np.float64)
    marks = junction_marks(network, standard)
    wear = max((marking.wear for marking in markings), default=0.0)
    for index, piece in enumerate(network.pieces):
        last = len(piece.boundaries_t) - 1
        for k, (t, marking) in enumerate(zip(piece.boundaries_t, markings)):
            side = 1 if k == 0 else (-1 if k == last else 0)
            spans = [(piece.s_start, piece.line.length)]
            for g0, g1, g_side in piece.gaps:  # edge lines break where a junction arm leaves
                if side and g_side == side:
                    spans = [(a, b) for a0, b0 in spans for a, b in ((a0, min(b0, g0)), (max(a0, g1), b0)) if b > a]
            for s0, s1 in spans:
                rows += [[*row, k, marking.wear] + [0.0] * (STRIPE_COLUMNS - POLYGON_CORNERS)
                         for row in _stripes_of_boundary(index, float(t), marking, s0, s1, dot_groups)]
        rows += [mark_row(mark, wear) for mark in marks if mark.piece == index]
    return np.array(rows, np.float64).reshape(-1, STRIPE_COLUMNS)


def stripe_index(stripes: FloatArray, pieces: int, boundaries: int) -> np.ndarray:
    """(pieces, boundaries + 1, 2) int64 [start, stop) rows of the stripe table per piece and boundary; the last
    slot holds stripes not tied to one boundary (the junction's markings). The shader looks only at the boundaries
    near a pixel instead of every stripe."""
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


def paint_mesh(network: RoadNetwork, markings: Sequence[Marking], paint: bool = True,
               dot_groups: bool = False,
               standard: MarkingStandardName = "custom") -> tuple[FloatArray, IntArray, Float32Array]:
    """Quads of every paint stripe and fans of every painted polygon just above the road: vertices (n, 3), faces
    (m, 3), colours (m, 3)."""
    stripes = paint_stripes(network, markings, paint, dot_groups, standard).reshape(-1, STRIPE_COLUMNS)
    vertices, faces, colors = [], [], []
    count = 0
    for piece, t_c, half, s0, s1, pattern, on, period, r, g, b, *_rest in stripes:
        line = network.pieces[int(piece)].line
        if int(pattern) == POLYGON:
            corners = np.asarray(_rest[POLYGON_CORNERS - 11:]).reshape(MAX_CORNERS, 2)
            n = MAX_CORNERS if not np.allclose(corners[-1], corners[-2]) else MAX_CORNERS - 1
            vertices.append(line.to_world(corners[:n, 0], corners[:n, 1], PAINT_LIFT_M))
            fan = np.array([[0, k, k + 1] for k in range(1, n - 1)]) + count
            faces.append(fan)
            colors.append(np.tile([r, g, b], (len(fan), 1)))
            count += n
            continue
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
