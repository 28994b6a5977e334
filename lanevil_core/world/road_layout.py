"""Road types as reference-line pieces, lane boundaries, cross-sections and junction arms.

The main road is piece 0 of a ``RoadNetwork``; junction roads (``t_junction`` / ``crossroad``) are arms that
leave it at right angles. Lane boundaries are ordered left to right as seen by the ego (who drives on the
right, in the +s direction): boundary k sits at ``t = (n - k) * lane_width``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..typed import FloatArray, Material, Pavement, SceneKind
from .road_geometry import GradeChange, Piece, ReferenceLine

if TYPE_CHECKING:  # the case model builds on the world (through the illusions), not the other way round
    from ..case import Road

LEAD_IN_M = 40.0  # straight road before any bend or slope starts
TRANSITION_M = 30.0  # clothoid length between line and arc
ARM_LENGTH_M = 90.0


@dataclass(frozen=True)
class Strip:
    """One band of the cross-section beyond the carriageway edge, walking outwards."""

    width: float
    material: Material
    height: float  # surface height above the carriageway (m); a change of height makes a vertical face


# What lies beside the carriageway, by scene kind (walking outwards from the edge line).
CROSS_SECTIONS: dict[SceneKind, tuple[Strip, ...]] = {
    "urban": (Strip(0.4, "asphalt", 0.0), Strip(0.2, "kerb", 0.15), Strip(3.5, "concrete", 0.15),
              Strip(60.0, "concrete", 0.15)),
    "suburban": (Strip(0.5, "asphalt", 0.0), Strip(0.2, "kerb", 0.12), Strip(2.0, "concrete", 0.12),
                 Strip(60.0, "grass", 0.12)),
    "highway": (Strip(2.5, "asphalt", 0.0), Strip(1.5, "gravel", 0.0), Strip(60.0, "grass", -0.05)),
    "rural": (Strip(0.6, "asphalt", 0.0), Strip(1.2, "gravel", -0.02), Strip(60.0, "grass", -0.08)),
    "tunnel_approach": (Strip(1.0, "asphalt", 0.0), Strip(0.3, "kerb", 0.2), Strip(1.0, "concrete", 0.2),
                        Strip(60.0, "dirt", 0.0)),
}


@dataclass
class RoadPiece:
    """A reference line with its lanes and its cross-section."""

    line: ReferenceLine
    half_width: float  # carriageway half width (m)
    strips: tuple[Strip, ...]
    boundaries_t: FloatArray  # (k,) t of every lane boundary, left to right
    s_start: float = 0.0  # arms start at the main road's edge
    carriageway: Material = "asphalt"  # the carriageway's material (``slab``: concrete slabs)

    @property
    def paved_reach(self) -> float:
        """|t| up to which the road is flat pavement: the carriageway plus any level strips at its edge paved
        like it."""
        reach = self.half_width
        for strip in self.strips:
            if strip.material != self.carriageway or strip.height != 0.0:
                break
            reach += strip.width
        return reach
    # (s0, s1, side): where the roadside of one side (+1 left, -1 right) gives way to a junction arm
    gaps: list[tuple[float, float, int]] = field(default_factory=list)


@dataclass
class RoadNetwork:
    """The main road (``pieces[0]``) and any junction arms."""

    pieces: list[RoadPiece]
    lane_width: float
    lanes_per_direction: int
    surface_color: tuple[float, float, float] | None = None  # the carriageway's albedo; None = its material's

    @property
    def main(self) -> RoadPiece:
        return self.pieces[0]

    def lane_center_t(self, lane: int) -> float:
        """t of the centre of ego-direction lane ``lane`` (0 = next to the centre line)."""
        return -(lane + 0.5) * self.lane_width


def reference_pieces(road: Road) -> tuple[list[Piece], tuple[GradeChange, ...]]:
    """The main road's planar pieces and grade changes for its road type."""
    sign = 1.0 if road.turn == "left" else -1.0
    k = sign / road.radius
    rest = road.length - LEAD_IN_M
    if road.type == "bend":
        arc = min(np.pi / 2 * road.radius, rest - 2 * TRANSITION_M - 10.0)
        tail = rest - 2 * TRANSITION_M - arc
        return [Piece(LEAD_IN_M), Piece(TRANSITION_M, 0, k), Piece(arc, k, k),
                Piece(TRANSITION_M, k, 0), Piece(tail)], ()
    if road.type == "s_curve":
        arc = min(np.pi / 4 * road.radius, (rest - 4 * TRANSITION_M - 10.0) / 2)
        tail = rest - 4 * TRANSITION_M - 2 * arc
        return [Piece(LEAD_IN_M), Piece(TRANSITION_M, 0, k), Piece(arc, k, k), Piece(2 * TRANSITION_M, k, -k),
                Piece(arc, -k, -k), Piece(TRANSITION_M, -k, 0), Piece(tail)], ()
    if road.type in ("uphill", "downhill"):
        grade = road.grade if road.type == "uphill" else -road.grade
        changes = (GradeChange(LEAD_IN_M, 50.0, grade),
                   GradeChange(road.length - 120.0, 60.0, 0.0))
        return [Piece(road.length)], changes
    return [Piece(road.length)], ()


def paved(strips: tuple[Strip, ...], pavement: Pavement) -> tuple[tuple[Strip, ...], Material]:
    """The cross-section and the carriageway's material for ``pavement``: a concrete road is slabs out to its
    paved shoulder (the first strip, when it is flush asphalt)."""
    if pavement == "asphalt":
        return strips, "asphalt"
    first = strips[0]
    if first.material == "asphalt" and first.height == 0.0:
        strips = (Strip(first.width, "slab", 0.0), *strips[1:])
    return strips, "slab"


def build_network(road: Road, scene_kind: SceneKind) -> RoadNetwork:
    """Compile the road description into reference lines and cross-sections."""
    pieces, grades = reference_pieces(road)
    n, w = road.lanes_per_direction, road.lane_width
    boundaries = np.array([(n - k) * w for k in range(2 * n + 1)], dtype=np.float64)
    strips, carriageway = paved(CROSS_SECTIONS[scene_kind], road.pavement)
    main = RoadPiece(ReferenceLine(pieces, grade_changes=grades), n * w, strips, boundaries,
                     carriageway=carriageway)
    network = RoadNetwork([main], w, n, road.surface_color)
    if road.type in ("t_junction", "crossroad"):
        sides = (-1,) if road.type == "t_junction" else (-1, 1)
        for side in sides:
            network.pieces.append(_arm(main, road.junction_s, side, strips, boundaries))
    return network


def _arm(main: RoadPiece, s_junction: float, side: int, strips: tuple[Strip, ...], boundaries: FloatArray) -> RoadPiece:
    """A straight side road leaving the main road at right angles on ``side`` (+1 left, -1 right)."""
    p_world, _, left = main.line.frame(s_junction)
    heading = float(main.line.heading_at(s_junction)) + side * np.pi / 2
    origin = p_world[:2]
    arm_line = ReferenceLine([Piece(ARM_LENGTH_M + main.half_width)], origin_xy=(origin[0], origin[1]),
                             origin_heading=heading, origin_z=float(p_world[2]))
    arm = RoadPiece(arm_line, main.half_width, strips, boundaries, s_start=main.half_width,
                    carriageway=main.carriageway)
    # The main road's roadside gives way over the arm's carriageway and its first roadside band.
    mouth = main.half_width + strips[0].width + (strips[1].width if len(strips) > 1 else 0.0)
    main.gaps.append((s_junction - mouth, s_junction + mouth, side))
    return arm
