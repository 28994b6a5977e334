"""A case's road as OpenDRIVE 1.6 (``road.xodr``), written with the ``scenariogeneration`` package.

- Reference line: the case's line / arc / clothoid pieces as ``line`` / ``arc`` / ``spiral`` geometries.
- Elevation: cubic records through the road's height and grade every ``ELEVATION_STEP_M`` (exact at the knots).
- Lanes: ``lanes_per_direction`` driving lanes each side of the centre lane (id 0, on the reference line), left ids
  1..n (oncoming), right ids -1..-n (the ego's direction), constant width; every boundary's road mark with its
  type, colour, width and dash / gap (double lines as two ``line`` entries).
- Junctions (``t_junction``, ``crossroad``): the main road is cut into an incoming and an outgoing road around the
  junction, the arms join them through an OpenDRIVE junction with connecting roads.
- Roadside objects: every connected part of the scene's roadside and illusion meshes that OpenDRIVE can name
  (guard rails and barriers, fences, poles and street lamps, trees, buildings, gantries) as an ``object``
  with its station, offset, size and heading; long ones along the road as a repeated object.

What does not carry over: illusion surface textures (cracks, repairs, tyre marks, puddles), exact prop shapes,
traffic participants (they are OpenSCENARIO entities), weather and sun (the OpenSCENARIO environment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..case import DOUBLE_LINE_SPACING_M, Case, Marking, write_atomic
from ..road_geometry import Piece, ReferenceLine
from ..road_layout import RoadNetwork, build_network, reference_pieces
from ..scene import CompiledScene, Mesh

if TYPE_CHECKING:
    from scenariogeneration import xodr

REVISION = ("1", "6")
ELEVATION_STEP_M = 10.0
MAIN_ROAD_ID = 1
JUNCTION_ID = 100
REPEAT_MIN_LENGTH_M = 12.0  # objects longer than this along the road are written as repeated objects
# mesh kind -> OpenDRIVE 1.6 object type; other kinds (vehicles, pedestrians, terrain) are not objects
OBJECT_TYPES: dict[str, str] = {
    "barrier": "barrier", "guard_rail": "barrier", "fence": "barrier", "pole": "pole", "lamp": "streetLamp",
    "streetlight": "streetLamp", "power_lines": "pole", "tree": "tree", "bush": "vegetation",
    "building": "building", "bridge": "gantry", "tunnel": "building",
}
# the paint's line type -> (OpenDRIVE road-mark type, colour, the kinds of its lines left to right)
MARK_TYPES: dict[str, tuple[str, str, tuple[str, ...]]] = {
    "white_solid": ("solid", "white", ("solid",)),
    "white_dashed": ("broken", "white", ("broken",)),
    "white_double_solid": ("solid_solid", "white", ("solid", "solid")),
    "yellow_solid": ("solid", "yellow", ("solid",)),
    "yellow_dashed": ("broken", "yellow", ("broken",)),
    "yellow_double_solid": ("solid_solid", "yellow", ("solid", "solid")),
    "white_solid_dashed": ("solid_broken", "white", ("solid", "broken")),
    "yellow_solid_dashed": ("solid_broken", "yellow", ("solid", "broken")),
    "botts_dots": ("botts_dots", "white", ()),
    "none": ("none", "standard", ()),
}


def _xodr():  # noqa: ANN202 - the module, imported only when writing
    from scenariogeneration import xodr

    return xodr


def road_mark(marking: Marking) -> xodr.RoadMark:
    """The OpenDRIVE road mark of one boundary's paint."""
    xodr = _xodr()
    mark_type, color, lines = MARK_TYPES.get(marking.type, ("none", "standard", ()))
    mark = xodr.RoadMark(mark_type, width=marking.width, color=color)
    offset = (marking.width + DOUBLE_LINE_SPACING_M) / 2 if len(lines) == 2 else 0.0
    for index, kind in enumerate(lines):
        t_offset = offset if index == 0 else -offset
        length, space = (marking.dash, marking.gap) if kind == "broken" else (0.0, 0.0)
        mark.add_specific_road_line(xodr.RoadLine(marking.width, length, space, t_offset, 0.0, color=color))
    return mark


def lanes(network: RoadNetwork, markings: list[Marking]) -> xodr.Lanes:
    """One lane section: the centre lane and ``n`` lanes each side, each with its outer boundary's mark."""
    xodr = _xodr()
    n = network.lanes_per_direction
    centre = xodr.Lane(a=0.0)
    centre.add_roadmark(road_mark(markings[n]))
    section = xodr.LaneSection(0.0, centre)
    for k in range(1, n + 1):
        left = xodr.Lane(a=network.lane_width)
        left.add_roadmark(road_mark(markings[n - k]))
        section.add_left_lane(left)
        right = xodr.Lane(a=network.lane_width)
        right.add_roadmark(road_mark(markings[n + k]))
        section.add_right_lane(right)
    result = xodr.Lanes()
    result.add_lanesection(section)
    return result


def plan_view(pieces: list[Piece], x: float, y: float, heading: float) -> xodr.PlanView:
    """The reference line's pieces as OpenDRIVE geometries, starting at (x, y) with ``heading`` (radians)."""
    xodr = _xodr()
    view = xodr.PlanView(x, y, heading)
    for piece in pieces:
        if piece.k0 == 0.0 and piece.k1 == 0.0:
            view.add_geometry(xodr.Line(piece.length))
        elif piece.k0 == piece.k1:
            view.add_geometry(xodr.Arc(piece.k0, length=piece.length))
        else:
            view.add_geometry(xodr.Spiral(piece.k0, piece.k1, length=piece.length))
    return view


def elevation_records(line: ReferenceLine, s0: float = 0.0, s1: float | None = None) -> list[tuple[float, ...]]:
    """(s, a, b, c, d) cubic records of the height over [s0, s1] (s relative to s0): Hermite cubics through the
    height and grade at knots ``ELEVATION_STEP_M`` apart; one record for a road of constant grade."""
    s1 = line.length if s1 is None else s1
    grade = line.grade_at(np.array([s0, s1]))
    if np.ptp(line.grade) == 0.0:
        return [(0.0, float(line.z_at(s0)), float(grade[0]), 0.0, 0.0)]
    knots = np.unique(np.append(np.arange(s0, s1, ELEVATION_STEP_M), s1))
    z, g = line.z_at(knots), line.grade_at(knots)
    records: list[tuple[float, ...]] = []
    for i in range(len(knots) - 1):
        h = knots[i + 1] - knots[i]
        dz = z[i + 1] - z[i]
        c = (3 * dz - (2 * g[i] + g[i + 1]) * h) / h**2
        d = ((g[i] + g[i + 1]) * h - 2 * dz) / h**3
        records.append((float(knots[i] - s0), float(z[i]), float(g[i]), float(c), float(d)))
    return records


# ---------------------------------------------------------------------------------------------- objects

@dataclass(frozen=True)
class RoadsideObject:
    """A roadside object in the main road's frame: its centre station and offset (m), its extent along the road,
    across it and up (m), its heading relative to the road (radians) and its height above the road (m)."""

    name: str
    type: str
    s_road: float
    t_road: float
    length: float
    width: float
    height: float
    heading: float
    z_offset: float


def _components(mesh: Mesh) -> list[np.ndarray]:
    """Vertex index arrays of the mesh's connected parts."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    faces = mesh.faces
    rows = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2]])
    cols = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(mesh.vertices),) * 2)
    count, label = connected_components(graph, directed=False)
    used = np.zeros(len(mesh.vertices), bool)
    used[faces.ravel()] = True
    return [np.flatnonzero((label == i) & used) for i in range(count) if np.any((label == i) & used)]


def _merged_parts(mesh: Mesh, parts: list[np.ndarray], gap_m: float = 1.0) -> list[np.ndarray]:
    """Parts whose footprints overlap (a pole and its lamp, a tree's trunk and crown) taken as one object."""
    boxes = [np.concatenate([mesh.vertices[p, :2].min(0) - gap_m, mesh.vertices[p, :2].max(0) + gap_m])
             for p in parts]
    groups: list[tuple[np.ndarray, np.ndarray]] = []
    for part, box in zip(parts, boxes):
        for index, (members, group_box) in enumerate(groups):
            if np.all(box[:2] <= group_box[2:]) and np.all(group_box[:2] <= box[2:]):
                union = np.concatenate([np.minimum(box[:2], group_box[:2]), np.maximum(box[2:], group_box[2:])])
                groups[index] = (np.concatenate([members, part]), union)
                break
        else:
            groups.append((part, box))
    return [members for members, _ in groups]


def roadside_objects(scene: CompiledScene) -> list[RoadsideObject]:
    """Every nameable part of the scene's meshes, measured in the main road's frame."""
    line = scene.network.main.line
    objects = []
    for mesh in scene.meshes:
        kind = OBJECT_TYPES.get(mesh.kind)
        if kind is None or not mesh.visible and mesh.kind != "bridge":
            continue
        for part in _merged_parts(mesh, _components(mesh)):
            p_world = mesh.vertices[part]
            p_road = np.array([line.station(p) for p in p_world[:: max(1, len(p_world) // 200)]])
            length = float(np.ptp(p_road[:, 0]))
            width = float(np.ptp(p_road[:, 1]))
            s_mid = 0.5 * (p_road[:, 0].min() + p_road[:, 0].max())
            t_mid = 0.5 * (p_road[:, 1].min() + p_road[:, 1].max())
            z_road = float(line.z_at(s_mid))
            objects.append(RoadsideObject(mesh.name, kind, float(s_mid), float(t_mid), max(length, 0.05),
                                          max(width, 0.05), float(np.ptp(p_world[:, 2])), 0.0,
                                          float(p_world[:, 2].min() - z_road)))
    return objects


def _object(item: RoadsideObject, s_offset: float, index: int) -> xodr.Object:
    xodr = _xodr()
    s_road = item.s_road - s_offset
    if item.length >= REPEAT_MIN_LENGTH_M:
        road_object = xodr.Object(s_road - item.length / 2, item.t_road, Type=item.type,
                                  name=item.name, zOffset=item.z_offset, width=item.width, length=1.0,
                                  height=item.height)
        road_object.repeat(item.length, 0.0, tStart=item.t_road, tEnd=item.t_road, heightStart=item.height,
                           heightEnd=item.height, zOffsetStart=item.z_offset, zOffsetEnd=item.z_offset,
                           widthStart=item.width, widthEnd=item.width)
        return road_object
    return xodr.Object(s_road, item.t_road, Type=item.type, name=item.name, zOffset=item.z_offset,
                       hdg=item.heading, width=item.width, length=item.length, height=item.height)


# ---------------------------------------------------------------------------------------------- roads

def _road(road_id: int, view: xodr.PlanView, network: RoadNetwork, markings: list[Marking],
          name: str, junction: int = -1) -> xodr.Road:
    xodr = _xodr()
    return xodr.Road(road_id, view, lanes(network, markings), road_type=junction, name=name)


def opendrive(case: Case, scene: CompiledScene | None = None) -> xodr.OpenDrive:
    """The case's road network, marks and roadside objects as an OpenDRIVE document."""
    xodr = _xodr()
    network = scene.network if scene is not None else build_network(case.road, case.scene.kind)
    markings = case.road.markings
    pieces, _ = reference_pieces(case.road)
    line = network.main.line
    objects = roadside_objects(scene) if scene is not None else []
    document = xodr.OpenDrive(case.title or "lanevil case", revMajor=REVISION[0], revMinor=REVISION[1])
    if len(network.pieces) == 1:
        road = _road(MAIN_ROAD_ID, plan_view(pieces, 0.0, 0.0, 0.0), network, markings, "main")
        for record in elevation_records(line):
            road.add_elevation(*record)
        for index, item in enumerate(objects):
            road.add_object(_object(item, 0.0, index))
        document.add_road(road)
        document.adjust_roads_and_lanes()
        return document
    return _junction_document(document, case, network, markings, objects)


def _junction_document(document: xodr.OpenDrive, case: Case, network: RoadNetwork, markings: list[Marking],
                       objects: list[RoadsideObject]) -> xodr.OpenDrive:
    """A straight main road cut around its junction, the arms, and the junction's connecting roads."""
    xodr = _xodr()
    reach = network.main.half_width  # the arms start at the main road's edge, as in the case
    junction_s = case.road.junction_s
    line = network.main.line
    incoming = _road(MAIN_ROAD_ID, plan_view([Piece(junction_s - reach)], 0.0, 0.0, 0.0), network, markings,
                     "main (before the junction)")
    outgoing = _road(MAIN_ROAD_ID + 1, plan_view([Piece(line.length - junction_s - reach)], junction_s + reach,
                                                   0.0, 0.0), network, markings, "main (after the junction)")
    arms = []
    for index, piece in enumerate(network.pieces[1:]):
        p_world = piece.line.to_world(piece.s_start, 0.0)
        heading = float(piece.line.heading_at(piece.s_start))
        arms.append(_road(MAIN_ROAD_ID + 2 + index, plan_view([Piece(piece.line.length - piece.s_start)],
                                                             float(p_world[0]), float(p_world[1]), heading),
                          network, markings, f"arm {index + 1}"))
    for road in (incoming, outgoing, *arms):
        road.add_elevation(0.0, 0.0, 0.0, 0.0, 0.0)
    for index, item in enumerate(objects):
        if item.s_road < junction_s - reach:
            incoming.add_object(_object(item, 0.0, index))
        elif item.s_road > junction_s + reach:
            outgoing.add_object(_object(item, junction_s + reach, index))
    creator = xodr.CommonJunctionCreator(JUNCTION_ID, "junction", startnum=JUNCTION_ID + 1)
    creator.add_incoming_road_cartesian_geometry(incoming, -reach, 0.0, 0.0, "successor")
    creator.add_incoming_road_cartesian_geometry(outgoing, reach, 0.0, math.pi, "predecessor")
    for road, piece in zip(arms, network.pieces[1:]):
        side = 1.0 if math.sin(float(piece.line.heading_at(0.0))) > 0 else -1.0  # +1 = the arm leaves to the left
        creator.add_incoming_road_cartesian_geometry(road, 0.0, side * reach, -side * math.pi / 2, "predecessor")
    roads = [incoming, outgoing, *arms]
    for i, first in enumerate(roads):
        for second in roads[i + 1:]:
            creator.add_connection(first.id, second.id)
    for road in roads:
        document.add_road(road)
    document.add_junction_creator(creator)
    document.adjust_roads_and_lanes()
    return document


def write_opendrive(case: Case, out_dir: str | Path, scene: CompiledScene | None = None) -> Path:
    """Write ``out_dir/road.xodr``; returns its path."""
    from ..compile import compile_scene

    document = opendrive(case, scene if scene is not None else compile_scene(case))
    path = Path(out_dir) / "road.xodr"
    write_atomic(path, xodr_text(document).encode("utf-8"))
    return path


def xodr_text(document: xodr.OpenDrive) -> str:
    """The document as indented XML text."""
    import xml.etree.ElementTree as ET

    element = document.get_element()
    ET.indent(element)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(element, encoding="unicode") + "\n"
