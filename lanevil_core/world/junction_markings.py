"""Transverse markings and symbols at a junction: stop and give-way lines, crosswalks and lane-use arrows, as convex
shapes in road coordinates that ``world/paint.py`` turns into rows of its stripe table, so they are painted like the
lane lines (colour, wear, wetness, night, filtered over the pixel).

A town junction (its roads have sidewalks, and traffic signals stand at every approach: ``scenery.signal_poses``)
has on every approach a crosswalk across the whole road in line with the crossing road's sidewalk, a stop line
across the approach lanes a little before it, and an arrow in every approach lane some metres before the stop line
(``arrow_shapes.lane_heads``: which moves each lane may make). A junction in the open (no sidewalk) has a give-way
line across the arms' approach lanes only: the main road has the right of way. The sizes come from the road's marking
standard (``JUNCTION_STANDARDS``, sources in ``docs/realism.md#junction-markings``). None of this is a lane line:
the labels do not change.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from ..typed import FloatArray, MarkingStandardName
from .arrow_shapes import Heads, arrow_parts, counter_clockwise, lane_heads
from .marking_standards import FOOT_M, INCH_M
from .road_layout import RoadNetwork, RoadPiece
from .scenery import sidewalk_kerb

CENTRE_CLEARANCE_M = 0.15  # a stop or give-way line stops this short of the centre line


@dataclass(frozen=True)
class JunctionStandard:
    """Sizes of one manual's junction markings (m): the stop line's width along the road and its distance before
    the crosswalk, the crosswalk's width along the road and its bars' width and gap across it, the give-way line
    (``teeth``: a row of triangles pointing at the approaching traffic; else a broken line) and the lane-use
    arrows' length and the distance from their tip to the stop line."""

    stop_width: float
    stop_before_crosswalk: float
    crosswalk_width: float
    bar_width: float
    bar_gap: float
    give_way: str  # "teeth" or "broken"
    give_way_width: float  # a broken line's width along the road, or a tooth's height
    give_way_dash: float  # a dash (or a tooth's base) across the road
    give_way_gap: float
    arrow_length: float
    arrow_before_stop: float
    source: str


_US = JunctionStandard(
    24 * INCH_M, 4 * FOOT_M, 10 * FOOT_M, 24 * INCH_M, 24 * INCH_M, "teeth", 36 * INCH_M, 24 * INCH_M, 12 * INCH_M,
    24 * FOOT_M, 20 * FOOT_M,
    "MUTCD (FHWA) 2009, 3B.16: stop lines 12 to 24 in wide, at least 4 ft before the crosswalk; yield lines of "
    "triangles 12 to 24 in at the base, 1.5 times as high, 3 to 12 in apart; 3B.18: crosswalks at least 6 ft wide, "
    "longitudinal bars 12 to 24 in wide with gaps of 12 to 60 in (Chapter 3C in the 2023 edition); Figure 3B-24: "
    "elongated lane-use arrows")
_DE = JunctionStandard(
    0.50, 1.0, 4.0, 0.50, 0.50, "broken", 0.50, 0.50, 0.25, 5.0, 5.0,
    "RMS (FGSV), Teil 1, and R-FGÜ 2001: Haltlinie Breitstrich 0.50 m; Wartelinie 0.50 m, Strich 0.50 m, Lücke "
    "0.25 m; Fußgängerüberweg 4 m breit (at least 3 m), Balken 0.50 m, Lücken 0.50 m; Richtungspfeile innerorts "
    "5 m lang")
_CN = JunctionStandard(
    0.40, 1.5, 4.0, 0.40, 0.60, "broken", 0.20, 0.60, 0.20, 4.5, 5.0,
    "GB 5768.3-2009: 停止线 20, 30 or 40 cm; 人行横道线 at least 3 m wide, bars 40 cm with 60 cm gaps; 减速让行线 "
    "dashed; 导向箭头 4.5 m long at 40 to 60 km/h (3 m slower, 6 m and 9 m faster)")
_JP = JunctionStandard(
    0.45, 2.0, 4.0, 0.45, 0.45, "broken", 0.30, 0.50, 0.50, 5.0, 5.0,
    "標識令 (道路標識、区画線及び道路標示に関する命令), 別表第六: 停止線 30 to 45 cm; 横断歩道 bars 45 cm wide, 45 to "
    "90 cm apart, 4 m long (3 m on narrow roads); 進行方向別通行区分 arrows 5 m")

JUNCTION_STANDARDS: dict[MarkingStandardName, JunctionStandard] = {
    "custom": JunctionStandard(0.40, 1.5, 4.0, 0.50, 0.50, "broken", 0.40, 0.50, 0.25, 5.0, 5.0,
                               "a Vienna-convention junction (the German numbers, the older 0.40 m stop line)"),
    "us_mutcd": _US,
    "de_autobahn": replace(_DE, arrow_length=7.5,
                           source=_DE.source.replace("innerorts 5 m lang", "außerorts 7.5 m lang")),
    "de_urban": _DE,
    "cn_fast": replace(_CN, arrow_length=6.0),
    "cn_slow": replace(_CN, arrow_length=3.0),
    "jp_expressway": _JP,
    "jp_general": _JP,
}


@dataclass(frozen=True)
class Approach:
    """One way into the junction along one piece: traffic moves along ``direction`` (+1: +s, -1: -s) in the lanes
    on its right and reaches the crosswalk's near edge at ``s_edge``; it may turn ``moves``."""

    piece: int
    direction: float
    s_edge: float
    moves: Heads


def approaches(network: RoadNetwork) -> list[Approach]:
    """Every way into the network's junction (none without arms): both of the main road's (before the arms' mouth
    along +s, beyond it along -s) and each arm's, towards the main road."""
    if len(network.pieces) < 2:
        return []
    main = network.main
    g0, g1, _side = main.gaps[0]
    junction_s = 0.5 * (g0 + g1)
    mouth = 0.5 * (g1 - g0)
    sides = {side for _a, _b, side in main.gaps}
    out = []
    for direction in (1.0, -1.0):  # along +s the arm on the right (-1) is a right turn; along -s a left one
        moves = {"straight"} | {("right" if side == -direction else "left") for side in sides}
        out.append(Approach(0, direction, junction_s - direction * mouth, frozenset(moves)))
    for index, arm in enumerate(network.pieces[1:], start=1):
        moves = {"left", "right"} | ({"straight"} if len(network.pieces) > 2 else set())
        out.append(Approach(index, -1.0, arm.s_start + _kerb_reach(main), frozenset(moves)))
    return out


def _kerb_reach(piece: RoadPiece) -> float:
    """|t| of a piece's kerb (its first raised strip), or of its carriageway's edge strip where it has none."""
    kerb = sidewalk_kerb(piece)
    return kerb[0] - piece.half_width if kerb is not None else (piece.strips[0].width if piece.strips else 0.0)


@dataclass(frozen=True)
class Mark:
    """One painted shape of a junction on piece ``piece``: its corners (k <= 4, counter-clockwise in (s, t));
    ``upright``: a rectangle whose sides run along s and t (a stripe of the table, with worn ragged edges)."""

    piece: int
    corners_st: FloatArray
    upright: bool = False

    @property
    def s_start(self) -> float:
        return float(self.corners_st[:, 0].min())


def _rect(piece: int, t0: float, t1: float, s0: float, s1: float) -> Mark:
    """An upright rectangle over [t0, t1] x [s0, s1] (either order)."""
    (a, b), (c, e) = sorted((s0, s1)), sorted((t0, t1))
    return Mark(piece, np.array([[a, c], [b, c], [b, e], [a, e]]), upright=True)


def _approach_marks(network: RoadNetwork, approach: Approach, table: JunctionStandard,
                   town: bool) -> Iterator[Mark]:
    """The marks of one approach: crosswalk, stop line and arrows in a town, a give-way line on an arm elsewhere."""
    piece, d = approach.piece, approach.direction
    half = network.pieces[piece].half_width
    lanes_t = (CENTRE_CLEARANCE_M * d, half * d)  # the approach lanes, on the traffic's right: t < 0 along +s
    if not town:
        if piece:
            yield from _give_way(piece, approach.s_edge - d * 0.3, lanes_t, d, table)
        return
    far = approach.s_edge - d * table.crosswalk_width
    pitch = table.bar_width + table.bar_gap
    count = int((2 * half - table.bar_width) // pitch) + 1
    first = -0.5 * (count - 1) * pitch  # the bars centred on the road
    for k in range(count):
        t_c = first + k * pitch
        yield _rect(piece, t_c - 0.5 * table.bar_width, t_c + 0.5 * table.bar_width, far, approach.s_edge)
    stop = far - d * table.stop_before_crosswalk
    yield _rect(piece, -lanes_t[0], -lanes_t[1], stop, stop - d * table.stop_width)
    tip = stop - d * (table.stop_width + table.arrow_before_stop)
    lanes = network.lanes_per_direction
    for lane in range(lanes):
        t_lane = d * network.lane_center_t(lane)
        for part in arrow_parts(lane_heads(approach.moves, lane, lanes), table.arrow_length):
            # the arrow's frame (x ahead, y left) on the road: s = tip + d x, t = t_lane + d y (a half turn for -s)
            yield Mark(piece, np.stack([tip + d * part[:, 0], t_lane + d * part[:, 1]], axis=1))


def _give_way(piece: int, s_near: float, lanes_t: tuple[float, float], d: float,
              table: JunctionStandard) -> Iterator[Mark]:
    """A give-way line across the approach lanes (t between ``lanes_t``, on the -d side), its near edge at
    ``s_near``: teeth pointing at the traffic, or a broken line."""
    t_lo, t_hi = sorted((-lanes_t[0], -lanes_t[1]))
    pitch = table.give_way_dash + table.give_way_gap
    far = s_near - d * table.give_way_width
    for t0 in np.arange(t_lo, t_hi - 0.5 * table.give_way_dash, pitch):
        t1 = min(t0 + table.give_way_dash, t_hi)
        if table.give_way == "teeth":
            yield Mark(piece, counter_clockwise(np.array([[s_near, t0], [s_near, t1], [far, 0.5 * (t0 + t1)]])))
        else:
            yield _rect(piece, t0, t1, s_near, far)


def junction_marks(network: RoadNetwork, standard: MarkingStandardName) -> list[Mark]:
    """Every junction marking of ``network`` painted to ``standard``, grouped by piece and each piece's sorted by
    where they start along it (the shader stops at the first that starts beyond the pixel)."""
    table = JUNCTION_STANDARDS[standard]
    town = sidewalk_kerb(network.main) is not None
    marks = [mark for approach in approaches(network) for mark in _approach_marks(network, approach, table, town)]
    return sorted(marks, key=lambda mark: (mark.piece, mark.s_start))
