"""Roadside and overhead structures that cast shadows: streetlights, guard rails, fences, rails, power lines.

Every builder returns a ``scene.Mesh``, low-poly and flat-shaded. ``streetlight`` is built in its own local frame
(place it with ``primitives.transformed(mesh, primitives.pose_on_road(line, s, t, yaw, h))``); the others follow
the road: they are built in the world frame from ``ReferenceLine.to_world`` so they bend and climb with it.

Streetlight local frame: +X forward (along the road), +Y left, +Z up, origin at the foot of the pole on the
ground. The arm reaches towards +Y, so a pole on the right-hand roadside with yaw 0 hangs its lamp over the road
(use yaw = pi for a pole on the left-hand side).

Road-following builders take road-frame placements: ``s`` along the line, ``t`` to its left, ``ground`` the
height of the ground there above the carriageway surface (see ``ground_height``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np
import trimesh

from ..typed import FloatArray, IntArray
from .primitives import merge, to_mesh
from .road_geometry import ReferenceLine
from .road_layout import RoadPiece
from .scene import Mesh

Color = tuple[float, float, float]
SlotDirection = Literal["s", "t"]  # slots of a deck run along the road (s) or across it (t)

# Linear albedos of the materials used here.
GALVANISED: Color = (0.32, 0.33, 0.34)
RAIL_STEEL: Color = (0.45, 0.46, 0.47)
CONCRETE: Color = (0.35, 0.34, 0.32)
WOOD: Color = (0.13, 0.085, 0.05)
POLE_WOOD: Color = (0.11, 0.075, 0.045)
CABLE: Color = (0.03, 0.03, 0.03)
WARM_LAMP: Color = (1.0, 0.78, 0.45)

FOOTING_M = 0.3  # posts and piers reach this far below the ground, so kerbs and ditches never show a gap
BOARD_FOOT_M = 0.1  # a board fence's lowest board starts this high above the ground
LAMP_EMISSION = 30.0  # radiance of a glowing lamp glass relative to its colour: far above the road it lights

# W-beam guard rail front face, walking bottom to top: (u towards the traffic, v above the ground) in metres.
# A real W-beam is 310 mm tall and 83 mm deep; its top sits about 0.75 m above the ground.
W_BEAM_FRONT = np.array([
    [0.00, 0.440], [0.075, 0.475], [0.083, 0.520], [0.030, 0.575], [0.030, 0.615],
    [0.083, 0.670], [0.075, 0.715], [0.00, 0.750],
])
W_BEAM_THICKNESS_M = 0.02


# ---------------------------------------------------------------------------------------------------------------
# Placement helpers


def ground_height(piece: RoadPiece, t_road: float) -> float:
    """Height (m) of the roadside surface at lateral position ``t_road`` above the carriageway surface."""
    beyond = abs(t_road) - piece.half_width
    if beyond <= 0.0:
        return 0.0
    for strip in piece.strips:
        if beyond <= strip.width:
            return strip.height
        beyond -= strip.width
    return piece.strips[-1].height if piece.strips else 0.0


def road_poses(line: ReferenceLine, s_road: FloatArray, t_road: FloatArray | float,
               h_road: FloatArray | float = 0.0, yaw: float = 0.0) -> FloatArray:
    """(n, 4, 4) ``T_world_local`` of local frames standing at road points (+X along the horizontal heading
    turned by ``yaw`` radians, +Z straight up), vectorised ``primitives.pose_on_road``."""
    s_road = np.atleast_1d(np.asarray(s_road, np.float64))
    heading = line.heading_at(s_road) + yaw
    poses = np.zeros((s_road.size, 4, 4))
    poses[:, 0, 0], poses[:, 0, 1] = np.cos(heading), -np.sin(heading)
    poses[:, 1, 0], poses[:, 1, 1] = np.sin(heading), np.cos(heading)
    poses[:, 2, 2] = poses[:, 3, 3] = 1.0
    poses[:, :3, 3] = line.to_world(s_road, t_road, h_road)
    return poses


def _instances(template: trimesh.Trimesh, T_world_local: FloatArray) -> tuple[FloatArray, IntArray]:
    """Vertices (n*k, 3) and faces (n*m, 3) of ``template`` placed at every pose of T_world_local (n, 4, 4)."""
    v_local = np.asarray(template.vertices, np.float64)
    p_world = np.einsum("nij,kj->nki", T_world_local[:, :3, :3], v_local) + T_world_local[:, None, :3, 3]
    offsets = np.arange(len(T_world_local))[:, None, None] * len(v_local)
    faces = np.asarray(template.faces, np.int64)[None] + offsets
    return p_world.reshape(-1, 3), faces.reshape(-1, 3).astype(np.int32)


def _boxes(line: ReferenceLine, s_road: FloatArray, t_road: FloatArray | float, h_center: FloatArray | float,
           extents: Sequence[float], color: Color, name: str, kind: str) -> Mesh:
    """Identical boxes (extents along local X, Y, Z) centred at road points, aligned with the road heading."""
    poses = road_poses(line, s_road, t_road, h_center)
    vertices, faces = _instances(trimesh.creation.box(extents=np.asarray(extents, np.float64)), poses)
    return Mesh(vertices, faces, np.asarray(color, np.float32), name=name, kind=kind)


def _closed(vertices: FloatArray, faces: IntArray) -> tuple[FloatArray, IntArray]:
    """Faces flipped if needed so they wind counter-clockwise seen from outside (positive volume)."""
    volume = trimesh.Trimesh(vertices, faces, process=False).volume
    return vertices, (faces[:, ::-1] if volume < 0 else faces).astype(np.int32)


def sweep(line: ReferenceLine, s_road: FloatArray, t_road: float, ground: float, profile_uv: FloatArray,
          toward: float = 1.0, sheet: bool = False) -> tuple[FloatArray, IntArray]:
    """A closed tube following the road: a cross-section swept along ``s_road``.

    Args:
        s_road: (n,) increasing stations of the rings.
        profile_uv: (k, 2) closed polygon in the cross-section plane: u along ``toward * t`` from ``t_road``,
            v above ``ground``.
        sheet: the profile is a ``thin_sheet`` (caps joined front to back); otherwise it must be convex.

    Returns:
        vertices (n*k, 3) float64 world, faces (m, 3) int32 counter-clockwise from outside.
    """
    s_road = np.asarray(s_road, np.float64)
    n, k = s_road.size, len(profile_uv)
    t = t_road + toward * profile_uv[None, :, 0]
    h = ground + profile_uv[None, :, 1]
    p_world = line.to_world(np.repeat(s_road[:, None], k, axis=1), t, h).reshape(-1, 3)
    ring = np.arange(k)
    nxt = (ring + 1) % k
    sides: list[np.ndarray] = []
    for i in range(n - 1):
        a, b, c, d = i * k + ring, i * k + nxt, (i + 1) * k + nxt, (i + 1) * k + ring
        sides.append(np.stack([a, b, c], 1))
        sides.append(np.stack([a, c, d], 1))
    caps = _cap(k, 0, sheet, reverse=True) + _cap(k, (n - 1) * k, sheet, reverse=False)
    return _closed(p_world, np.concatenate(sides + caps))


def _cap(k: int, start: int, sheet: bool, reverse: bool) -> list[IntArray]:
    """Triangles closing one end ring of a ``thin_sheet`` or convex profile of k vertices."""
    if sheet:  # front polyline j and back polyline k-1-j, joined by quads
        half = k // 2
        j = np.arange(half - 1)
        a, b, c, d = j, j + 1, k - 2 - j, k - 1 - j
        tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    else:
        j = np.arange(1, k - 1)
        tris = np.stack([np.zeros_like(j), j, j + 1], 1)
    tris = tris + start
    return [tris[:, ::-1] if reverse else tris]


def thin_sheet(front_uv: FloatArray, thickness: float) -> FloatArray:
    """(2k, 2) closed profile of a folded sheet: the front polyline (k, 2) and its copy ``thickness`` behind."""
    back = front_uv - np.array([thickness, 0.0])
    return np.concatenate([front_uv, back[::-1]])


def _rect_uv(u0: float, u1: float, v0: float, v1: float) -> FloatArray:
    return np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]], np.float64)


def _stations(s0: float, s1: float, step: float) -> FloatArray:
    """(n,) evenly spaced stations from s0 to s1 inclusive, no further apart than ``step``."""
    return np.linspace(s0, s1, max(int(np.ceil((s1 - s0) / step)), 1) + 1)


def _toward_road(t_road: float) -> float:
    """+1 when the road centre lies towards +t from ``t_road``, else -1."""
    return 1.0 if t_road <= 0.0 else -1.0


def _check_span(s0: float, s1: float) -> None:
    if not s1 > s0:
        raise ValueError(f"need s1 > s0, got s0={s0}, s1={s1}")


Gaps = Sequence[tuple[float, float, int]]  # (s0, s1, side): stretches where nothing stands; side +1 left, -1 right


def outside_gaps(s_road: FloatArray, t_road: float, gaps: Gaps) -> np.ndarray:
    """(n,) bool: stations ``s_road`` on the side of ``t_road`` lie outside every gap (``RoadPiece.gaps``)."""
    s_road = np.asarray(s_road, np.float64)
    keep = np.ones(s_road.shape, bool)
    side = 1 if t_road > 0 else -1
    for g0, g1, gap_side in gaps:
        if gap_side == side:
            keep &= (s_road < g0) | (s_road > g1)
    return keep


def clear_runs(s0: float, s1: float, t_road: float, gaps: Gaps, shortest: float = 1.0) -> list[tuple[float, float]]:
    """Sub-intervals of [s0, s1] on the side of ``t_road`` outside every gap, each at least ``shortest`` long."""
    runs = [(s0, s1)]
    side = 1 if t_road > 0 else -1
    for g0, g1, gap_side in gaps:
        if gap_side == side:
            runs = [part for a, b in runs for part in ((a, min(b, g0)), (max(a, g1), b))
                    if part[1] - part[0] >= shortest]
    return runs


# ---------------------------------------------------------------------------------------------------------------
# Streetlight


def streetlight_lamp_offset(height: float = 8.0, arm: float = 1.5) -> FloatArray:
    """(3,) float64 position of the lamp's light-emitting face in the streetlight's local frame (m).

    Attach a ``PointLight`` here (after applying the pole's pose) to light the road at night.
    """
    return np.array([0.0, arm + 0.05, height - 0.22])


def streetlight(height: float = 8.0, arm: float = 1.5, lamp_color: Color = WARM_LAMP,
                emissive: bool = False, pole_radius: float = 0.11, name: str = "streetlight") -> Mesh:
    """A street lamp in its local frame: concrete plinth, tapered pole, arm towards +Y, lamp head.

    Args:
        height: pole height above the ground (m); the lamp hangs just below it.
        arm: horizontal reach of the arm from the pole axis to the lamp head (m).
        lamp_color: linear RGB of the lamp's glass (and of its glow when ``emissive``).
        emissive: the lamp glass emits light (night scenes).
        pole_radius: radius of the pole's lower half (m); the upper half is 0.7 times as thick.

    Returns:
        Mesh with local-frame vertices (+X forward, +Y left, +Z up, pole foot at the origin), ~150 faces.
    """
    top = height - 0.1
    cylinder = trimesh.creation.cylinder
    glow = np.asarray(lamp_color, np.float32) * LAMP_EMISSION if emissive else None
    parts = [
        to_mesh(trimesh.creation.box(extents=(0.25 + 2 * pole_radius,) * 2 + (0.4 + FOOTING_M,),
                                     transform=_translate((0.0, 0.0, 0.2 - FOOTING_M / 2))), CONCRETE),
        to_mesh(cylinder(radius=pole_radius, segment=[[0, 0, 0.4], [0, 0, height * 0.45]], sections=10),
                GALVANISED),
        to_mesh(cylinder(radius=0.7 * pole_radius, segment=[[0, 0, height * 0.45], [0, 0, top]], sections=10),
                GALVANISED),
        to_mesh(cylinder(radius=0.05, segment=[[0, 0, top - 0.05], [0, arm - 0.3, top + 0.12]], sections=8),
                GALVANISED),
        to_mesh(trimesh.creation.box(extents=(0.32, 0.75, 0.16), transform=_translate((0.0, arm, top + 0.05))),
                GALVANISED),
        to_mesh(trimesh.creation.box(extents=(0.26, 0.55, 0.08), transform=_translate((0.0, arm + 0.05, top - 0.07))),
                lamp_color, emission=glow),
    ]
    if emissive:  # merge keeps per-face emission only when every part says what it emits
        for part in parts[:-1]:
            part.emission = np.zeros((len(part.faces), 3), np.float32)
    return merge(parts, name=name, kind="streetlight", gloss=0.35)


def _translate(offset: Sequence[float]) -> FloatArray:
    T = np.eye(4)
    T[:3, 3] = offset
    return T


# ---------------------------------------------------------------------------------------------------------------
# Guard rail


def guard_rail(line: ReferenceLine, s0: float, s1: float, t: float, ground: float = 0.0,
               post_spacing: float = 2.0, color: Color = RAIL_STEEL, gloss: float = 0.4,
               name: str = "guard rail") -> Mesh:
    """A W-beam guard rail on steel posts from ``s0`` to ``s1`` at lateral position ``t``.

    The beam (0.31 m tall, top 0.75 m above the ground) faces the road centre and is swept along the curve every
    metre; posts (0.1 x 0.15 m) stand behind it every ``post_spacing`` metres.

    Returns:
        Mesh, world frame; about 30 faces per metre.
    """
    _check_span(s0, s1)
    toward = _toward_road(t)
    beam_v, beam_f = sweep(line, _stations(s0, s1, 1.0), t, ground, thin_sheet(W_BEAM_FRONT, W_BEAM_THICKNESS_M),
                           toward, sheet=True)
    beam = Mesh(beam_v, beam_f, np.asarray(color, np.float32))
    s_posts = _stations(s0 + 0.1, s1 - 0.1, post_spacing)
    post_top = 0.70
    posts = _boxes(line, s_posts, t - toward * 0.245, ground + (post_top - FOOTING_M) / 2,
                   (0.10, 0.15, post_top + FOOTING_M), GALVANISED, name, "guard_rail")
    blocks = _boxes(line, s_posts, t - toward * 0.095, ground + 0.56, (0.08, 0.15, 0.22), GALVANISED, name,
                    "guard_rail")
    return merge([beam, posts, blocks], name=name, kind="guard_rail", gloss=gloss)


# ---------------------------------------------------------------------------------------------------------------
# Fence


def fence(line: ReferenceLine, s0: float, s1: float, t: float, height: float = 1.8, slat_width: float = 0.1,
          slat_gap: float = 0.1, ground: float = 0.0, post_spacing: float = 2.5, color: Color = WOOD,
          boards: bool = False, name: str = "fence") -> Mesh:
    """A slatted fence: posts every ``post_spacing`` m, two rails, vertical slats on the road side.

    The slats (``slat_width`` along the road, ``slat_gap`` apart, 2.5 cm thick) make its shadow striped. With
    ``boards`` the slats lie horizontally instead and replace the rails (``slat_width`` high, ``slat_gap`` apart,
    laid from the bottom, see ``_boards``): under a low sun from the fence's side each gap lets
    through a line of light parallel to the road.

    Returns:
        Mesh, world frame; 12 faces per vertical slat, a swept box per board.
    """
    _check_span(s0, s1)
    if slat_width <= 0 or slat_gap < 0 or height <= 0:
        raise ValueError("fence needs slat_width > 0, slat_gap >= 0 and height > 0")
    toward = _toward_road(t)
    s_posts = _stations(s0, s1, post_spacing)
    posts = _boxes(line, s_posts, t, ground + (height + 0.1 - FOOTING_M) / 2, (0.1, 0.1, height + 0.1 + FOOTING_M),
                   color, name, "fence")
    if boards:
        boards_ = _boards(line, s0, s1, t + toward * 0.1125, ground, height, slat_width, slat_gap, toward, color)
        return merge([posts, *boards_], name=name, kind="fence")
    rails = []
    for v in (0.3, height - 0.3):
        rail_v, rail_f = sweep(line, _stations(s0, s1, 2.0), t, ground, _rect_uv(0.05, 0.10, v - 0.045, v + 0.045),
                               toward)
        rails.append(Mesh(rail_v, rail_f, np.asarray(color, np.float32)))
    pitch = slat_width + slat_gap
    s_slats = np.arange(s0 + slat_width / 2, s1 - slat_width / 2 + 1e-9, pitch)
    slats = _boxes(line, s_slats, t + toward * 0.1125, ground + (height + 0.05) / 2, (slat_width, 0.025, height - 0.05),
                   color, name, "fence")
    return merge([posts, *rails, slats], name=name, kind="fence")


def _boards(line: ReferenceLine, s0: float, s1: float, t: float, ground: float, height: float, board: float,
            gap: float, toward: float, color: Color) -> list[Mesh]:
    """Horizontal boards ``board`` m high, ``gap`` m apart, 2.5 cm thick, laid from 0.1 m up and the top one cut at
    ``height``: a taller fence is a lower one with more board on top, so its shadow holds the lower one's."""
    stations = _stations(s0, s1, 2.0)
    bottoms = np.arange(BOARD_FOOT_M, height - 0.02, board + gap)  # a board under 2 cm high is left out
    return [Mesh(*sweep(line, stations, t, ground, _rect_uv(-0.0125, 0.0125, bottom, min(bottom + board, height)),
                        toward), np.asarray(color, np.float32))
            for bottom in bottoms]


# ---------------------------------------------------------------------------------------------------------------
# Overhead rail structure


def overhead_rail(line: ReferenceLine, s_center: float, span: float, deck_width_along_s: float = 12.0,
                  slot_width: float = 0.3, slot_pitch: float = 1.0, clearance_height: float = 5.5,
                  slots_along: SlotDirection = "s", t_center: float = 0.0, deck_depth: float = 0.35,
                  pier_spacing: float = 8.0, color: Color = CONCRETE, gaps: Gaps = (),
                  name: str = "overhead rail") -> Mesh:
    """An elevated structure crossing the road: a slotted deck on two rows of piers beside the carriageway.

    The deck covers t in [t_center - span/2, t_center + span/2] and s in [s_center - L/2, s_center + L/2]
    (L = ``deck_width_along_s``), its underside ``clearance_height`` above the road. It is made of beams with
    ``slot_width`` gaps every ``slot_pitch`` metres; ``slots_along`` = "s" runs the slots along the road (the
    light through them draws bright lines parallel to the lanes), "t" runs them across. Edge girders (0.6 m wide,
    1 m deep) rest on square piers standing just outside the span every ``pier_spacing`` metres, none in ``gaps``.

    Returns:
        Mesh, world frame; nothing of it stands on [t_center - span/2, t_center + span/2] below the deck.
    """
    if slots_along not in ("s", "t"):
        raise ValueError(f"slots_along must be 's' or 't', got {slots_along!r}")
    if not 0.0 < slot_width < slot_pitch:
        raise ValueError("need 0 < slot_width < slot_pitch")
    half_s, half_t = deck_width_along_s / 2, span / 2
    s0, s1 = s_center - half_s, s_center + half_s
    deck_mid = clearance_height + deck_depth / 2
    parts: list[Mesh] = []
    # Edge girders along s just outside the span, with piers under them.
    for side in (-1.0, 1.0):
        t_girder = t_center + side * (half_t + 0.3)
        girder_v, girder_f = sweep(line, _stations(s0, s1, 2.0), t_girder, 0.0,
                                   _rect_uv(-0.3, 0.3, clearance_height - 0.6, clearance_height + 0.4 + deck_depth))
        parts.append(Mesh(girder_v, girder_f, np.asarray(color, np.float32)))
        s_piers = _stations(s0 + 0.5, s1 - 0.5, pier_spacing)
        s_piers = s_piers[outside_gaps(s_piers, t_girder, gaps)]
        pier_height = clearance_height - 0.6 + FOOTING_M
        if s_piers.size:
            parts.append(_boxes(line, s_piers, t_girder, clearance_height - 0.6 - pier_height / 2,
                                (0.6, 0.6, pier_height), color, name, "bridge"))
        parts.append(_parapet(line, s0, s1, t_girder, clearance_height + deck_depth + 0.4, color))
    # End cross girders along t at both ends of the deck.
    for s_end in (s0 + 0.3, s1 - 0.3):
        parts.append(_boxes(line, np.array([s_end]), t_center, deck_mid, (0.6, span, deck_depth + 0.2), color, name,
                            "bridge"))
    beam_width = slot_pitch - slot_width
    if slots_along == "s":
        t_beams = np.arange(-half_t + beam_width / 2, half_t - beam_width / 2 + 1e-9, slot_pitch) + t_center
        for t_beam in t_beams:
            beam_v, beam_f = sweep(line, _stations(s0 + 0.6, s1 - 0.6, 2.0), float(t_beam), 0.0,
                                   _rect_uv(-beam_width / 2, beam_width / 2, clearance_height,
                                            clearance_height + deck_depth))
            parts.append(Mesh(beam_v, beam_f, np.asarray(color, np.float32)))
    else:
        s_beams = np.arange(s0 + 0.6 + slot_width + beam_width / 2, s1 - 0.6 - beam_width / 2, slot_pitch)
        if s_beams.size:
            parts.append(_boxes(line, s_beams, t_center, deck_mid, (beam_width, span, deck_depth), color, name,
                                "bridge"))
    return merge(parts, name=name, kind="bridge")


def _parapet(line: ReferenceLine, s0: float, s1: float, t_road: float, top: float, color: Color) -> Mesh:
    rail_v, rail_f = sweep(line, _stations(s0, s1, 2.0), t_road, 0.0, _rect_uv(-0.08, 0.08, top - 0.9, top))
    return Mesh(rail_v, rail_f, np.asarray(color, np.float32))


# ---------------------------------------------------------------------------------------------------------------
# Power lines


def wire(points_world: FloatArray, radius: float, sides: int = 4) -> tuple[FloatArray, IntArray]:
    """A thin closed prism along a polyline (n, 3): vertices (n*sides, 3), faces; cross-section width 2*radius."""
    tangent = np.gradient(points_world, axis=0)
    length = np.linalg.norm(tangent, axis=1, keepdims=True)
    # a polyline that does not move (a zero span) has no direction: any will do for a prism of no length
    tangent = np.where(length > 0, tangent / np.where(length > 0, length, 1.0), [[1.0, 0.0, 0.0]])
    up = np.where(np.abs(tangent[:, 2:3]) > 0.9, [[1.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    side = np.cross(tangent, up)
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    normal = np.cross(side, tangent)
    angles = 2 * np.pi * (np.arange(sides) + 0.5) / sides
    # Scale so the flat-to-flat width of the polygon is 2 * radius.
    r = radius / np.cos(np.pi / sides)
    ring = (np.cos(angles)[None, :, None] * side[:, None] + np.sin(angles)[None, :, None] * normal[:, None]) * r
    vertices = (points_world[:, None, :] + ring).reshape(-1, 3)
    n, k = len(points_world), sides
    j = np.arange(k)
    tris: list[np.ndarray] = []
    for i in range(n - 1):
        a, b, c, d = i * k + j, i * k + (j + 1) % k, (i + 1) * k + (j + 1) % k, (i + 1) * k + j
        tris += [np.stack([a, b, c], 1), np.stack([a, c, d], 1)]
    tris += _cap(k, 0, False, True) + _cap(k, (n - 1) * k, False, False)
    return _closed(vertices, np.concatenate(tris))


def catenary(p0_world: FloatArray, p1_world: FloatArray, sag: float, segments: int = 12) -> FloatArray:
    """(segments+1, 3) points of a wire hanging between two attachment points, ``sag`` metres low mid-span."""
    u = np.linspace(0.0, 1.0, segments + 1)[:, None]
    p_world = (1 - u) * np.asarray(p0_world) + u * np.asarray(p1_world)
    p_world[:, 2] -= 4.0 * sag * u[:, 0] * (1.0 - u[:, 0])
    return p_world


WIRE_SEGMENT_M = 3.0  # a hanging wire is a polyline of pieces about this long (4 to 16 a span)
INSULATOR: Color = (0.55, 0.56, 0.55)  # glazed porcelain
INSULATOR_SIZE_M = (0.1, 0.1, 0.2)


def pole_stations(s0: float, s1: float, pole_spacing: float) -> FloatArray:
    """(n,) stations of a row of poles from s0 to s1, evenly spaced, no further apart than ``pole_spacing``."""
    return _stations(s0, s1, pole_spacing)


def power_lines(line: ReferenceLine, s0: float, s1: float, t_poles: Sequence[float], n_wires: int = 3,
                wire_radius: float = 0.03, heights: Sequence[float] | float = 8.0, pole_spacing: float = 35.0,
                wire_spacing: float = 0.8, sag: float = 0.5, cross_every: int = 0, cross_skew: float = 0.0,
                ground: float = 0.0, gaps: Gaps = (), insulators: bool = False, segment_m: float = WIRE_SEGMENT_M,
                name: str = "power lines") -> Mesh:
    """Utility poles in rows beside the road with wires along each row and, optionally, wires across the road.

    Args:
        t_poles: lateral position of each pole row (keep them off the carriageway).
        n_wires: wires per span, side by side on a cross-arm ``wire_spacing`` apart (a pair frames a bright band
            between its two shadows).
        wire_radius: half the wire's cross-section width (m); the wire is a square prism.
        heights: attachment height of each wire above the ground (one value for all, or ``n_wires`` values).
        cross_every: with two or more rows, every ``cross_every``-th pole of the first row also sends its outer
            two wires across the road to a pole of the second row (0 = none); ``cross_skew`` moves that pole
            along s (a diagonal crossing).
        gaps: (s0, s1, side) stretches where no pole stands (junction mouths); wires span over them.
        insulators: a porcelain insulator under every wire on the row poles' cross-arms.
        segment_m: about how long each straight piece of a hanging wire is.

    Returns:
        Mesh, world frame: poles (wood), cross-arms and wires (black).
    """
    _check_span(s0, s1)
    if wire_radius < 0.02:
        raise ValueError("wire_radius must be at least 0.02 m")
    h_wires = np.broadcast_to(np.asarray(heights, np.float64), (n_wires,)) + ground
    offsets: FloatArray = ((np.arange(n_wires) - (n_wires - 1) / 2) * wire_spacing).astype(np.float64)
    s_poles = pole_stations(s0, s1, pole_spacing)
    parts: list[Mesh] = []
    for t_row in t_poles:
        s_row = s_poles[outside_gaps(s_poles, t_row, gaps)]
        if not s_row.size:
            continue
        parts.append(_poles(line, s_row, t_row, ground, h_wires, across=offsets, name=name))
        if insulators:
            parts += [_boxes(line, s_row, t_row + o, h + 0.04, INSULATOR_SIZE_M, INSULATOR, name, "pole")
                      for o, h in zip(offsets, h_wires)]
        for a, b in zip(s_row[:-1], s_row[1:]):
            parts += [_span(line, (a, t_row + o), (b, t_row + o), h, sag, wire_radius, segment_m)
                      for o, h in zip(offsets, h_wires)]
    if cross_every > 0 and len(t_poles) >= 2:
        parts += _crossings(line, s_poles[::cross_every], t_poles[0], t_poles[1], cross_skew, ground, h_wires,
                            offsets, sag * 0.6, wire_radius, gaps, name)
    return merge(parts, name=name, kind="power_lines")


def _crossings(line: ReferenceLine, s_near: FloatArray, t_near: float, t_far: float, skew: float,
               ground: float, h_wires: FloatArray, offsets: FloatArray, sag: float, radius: float, gaps: Gaps,
               name: str) -> list[Mesh]:
    """The outer pair of wires crossing the road from the row poles at (s_near, t_near) to poles at
    (s_near + skew, t_far); each end gets a cross-arm along the road, the far end its own pole when skewed."""
    s_far = s_near + skew
    keep = (outside_gaps(s_near, t_near, gaps) & outside_gaps(s_far, t_far, gaps)
            & (s_far >= 0.0) & (s_far <= line.length))
    s_near, s_far = s_near[keep], s_far[keep]
    if not s_near.size:
        return []
    outer = [0, len(offsets) - 1] if len(offsets) > 1 else [0]
    parts = [_poles(line, s_near, t_near, ground, h_wires, along=offsets, column=False, name=name),
             _poles(line, s_far, t_far, ground, h_wires, along=offsets, column=abs(skew) > 0.5, name=name)]
    for a, b in zip(s_near, s_far):
        parts += [_span(line, (a + offsets[i], t_near), (b + offsets[i], t_far), h_wires[i], sag, radius)
                  for i in outer]
    return parts


def _poles(line: ReferenceLine, s_poles: FloatArray, t_row: float, ground: float, h_wires: FloatArray,
           across: FloatArray | None = None, along: FloatArray | None = None, column: bool = True,
           name: str = "pole") -> Mesh:
    """Wooden poles reaching above the highest wire (``column``), with a cross-arm holding the wires at offsets
    ``across`` the road (in t) or ``along`` it (in s); ``h_wires`` are heights above the road surface."""
    offsets = across if across is not None else along
    if offsets is None:
        raise ValueError("_poles needs the wire offsets across or along the road")
    reach = float(np.ptp(offsets)) + 0.6
    extents = (0.1, reach, 0.12) if across is not None else (reach, 0.1, 0.12)
    t_arm = t_row + float(offsets.mean()) if across is not None else t_row
    s_arm = s_poles + (float(offsets.mean()) if along is not None else 0.0)
    arms = _boxes(line, s_arm, t_arm, float(h_wires.min()) - 0.1, extents, POLE_WOOD, name, "pole")
    if not column:
        return arms
    poses = road_poses(line, s_poles, t_row, ground - FOOTING_M)
    top = float(h_wires.max()) + 0.6 - ground
    segment = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, top + FOOTING_M]])
    cylinder = trimesh.creation.cylinder(radius=0.13, segment=segment, sections=8)
    v_pole, f_pole = _instances(cylinder, poses)
    return merge([Mesh(v_pole, f_pole, np.asarray(POLE_WOOD, np.float32)), arms], name=name, kind="pole")


def _span(line: ReferenceLine, a_road: tuple[float, float], b_road: tuple[float, float], h: float, sag: float,
          radius: float, segment_m: float = WIRE_SEGMENT_M) -> Mesh:
    """One wire between two road-frame points ``h`` m above the road, sagging ``sag`` m mid-span, in straight
    pieces about ``segment_m`` long."""
    p0 = line.to_world(a_road[0], a_road[1], h)
    p1 = line.to_world(b_road[0], b_road[1], h)
    segments = int(np.clip(np.linalg.norm(p1 - p0) / segment_m, 4, 16))
    vertices, faces = wire(catenary(p0, p1, sag, segments), radius)
    return Mesh(vertices, faces, np.asarray(CABLE, np.float32), kind="wire")
