"""A case's road as OpenDRIVE 1.6 (``road.xodr``), written with the ``scenariogeneration`` package.

- Reference line: the case's line / arc / clothoid pieces as ``line`` / ``arc`` / ``spiral`` geometries.
- Elevation: cubic records through the road's height and grade every ``ELEVATION_STEP_M`` (exact at the knots).
- Lanes: ``lanes_per_direction`` driving lanes each side of the centre lane (id 0, on the reference line), left ids
  1..n (oncoming), right ids -1..-n (the ego's direction), constant width; every boundary's road mark with its
  type, colour, width and dash / gap (double lines as two ``line`` entries).
- Junctions (``t_junction``, ``crossroad``): the main road is cut into an incoming and an outgoing road
  ``junction_radius`` from the junction's centre, the arms start as far from it, and every pair of these roads is
  joined by one connecting road (a ``line`` straight across, an ``arc`` of that radius for a turn, so that its
  innermost lane keeps a positive radius) listed in exactly one ``connection``. The connecting road straight along
  the main road carries the main road's marks (edge lines broken where an arm leaves, as painted); turns and the
  road between two arms carry none.
- Roadside objects: every connected part of the scene's roadside and illusion meshes that OpenDRIVE can name
  (guard rails and barriers, fences, poles and street lamps, trees, buildings, gantries) as an ``object``
  with its station, offset, size and heading; long ones along the road as a repeated object. Upright objects
  (poles, street lamps, utility poles) are written with the footprint of what stands on the ground, so lamp arms
  and wires do not widen them; nothing stands on the carriageway: a part across it is written as its pieces beside
  the road and, where it is high enough to drive under, the piece above it. Objects lie within their road's s.

What does not carry over: illusion surface textures (cracks, repairs, tire marks, puddles), exact prop shapes,
traffic participants (they are OpenSCENARIO entities), weather and sun (the OpenSCENARIO environment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..case import Case, Marking
from ..files import write_atomic
from ..world.paint import DOUBLE_LINE_SPACING_M, road_paint
from ..world.road_geometry import Piece, ReferenceLine
from ..world.road_layout import RoadNetwork, build_network, reference_pieces
from ..world.scene import CompiledScene, Mesh

if TYPE_CHECKING:
    from scenariogeneration import xodr

REVISION = ("1", "6")
ELEVATION_STEP_M = 10.0
MAIN_ROAD_ID = 1
JUNCTION_ID = 100
THROUGH_ROAD_ID = JUNCTION_ID + 1  # the first connecting road: the main road through the junction
REPEAT_MIN_LENGTH_M = 12.0  # objects longer than this along the road are written as repeated objects
# The carriageway material as an OpenDRIVE lane <material>: surface name and dry friction coefficient.
SURFACES: dict[str, tuple[str, float]] = {"asphalt": ("asphalt", 0.9), "slab": ("concrete", 0.85)}
CORNER_RADIUS_M = 4.0  # radius of the innermost lane edge of a junction turn (a tight urban kerb)
BASE_HEIGHT_M = 1.0  # an upright object's footprint is that of its parts reaching this close to the road
CLEARANCE_M = 4.0  # a part over the carriageway this high above the road is written as an overhead object
UPRIGHT_TYPES = ("pole", "streetLamp")
# mesh kind -> OpenDRIVE 1.6 object type; other kinds (vehicles, pedestrians, terrain) are not objects
OBJECT_TYPES: dict[str, str] = {
    "barrier": "barrier", "guard_rail": "barrier", "fence": "barrier", "pole": "pole", "lamp": "streetLamp",
    "streetlight": "streetLamp", "power_lines": "pole", "tree": "tree", "bush": "vegetation",
    "building": "building", "bridge": "gantry", "tunnel": "building", "street_furniture": "obstacle",
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
    """One lane section: the centre lane and ``n`` lanes each side, each with its outer boundary's mark and the
    carriageway's surface material."""
    xodr = _xodr()
    n = network.lanes_per_direction
    surface, friction = SURFACES[network.main.carriageway]
    centre = xodr.Lane(a=0.0)
    centre.add_roadmark(road_mark(markings[n]))
    section = xodr.LaneSection(0.0, centre)
    for k in range(1, n + 1):
        left = xodr.Lane(a=network.lane_width)
        left.add_roadmark(road_mark(markings[n - k]))
        left.add_lane_material(friction, surface=surface)
        section.add_left_lane(left)
        right = xodr.Lane(a=network.lane_width)
        right.add_roadmark(road_mark(markings[n + k]))
        right.add_lane_material(friction, surface=surface)
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
    height and grade at knots ``ELEVATION_STEP_M`` apart, a straight stretch as one record (one for a road of
    constant grade)."""
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
        record = (float(knots[i] - s0), float(z[i]), float(g[i]), float(c), float(d))
        if not records or not _continues(records[-1], record):
            records.append(record)
    return records


def _continues(previous: tuple[float, ...], record: tuple[float, ...], tol: float = 1e-9) -> bool:
    """Whether ``record`` is the straight continuation of a straight ``previous`` (a redundant record)."""
    s, a, b, c, d = previous
    straight = max(abs(c), abs(d), abs(record[3]), abs(record[4])) < tol
    return straight and abs(record[2] - b) < tol and abs(a + b * (record[0] - s) - record[1]) < 1e-6


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
    half_width = scene.network.main.half_width
    objects = []
    for mesh in scene.meshes:
        kind = OBJECT_TYPES.get(mesh.kind)
        if kind is None or not mesh.visible and mesh.kind != "bridge":
            continue
        components = _components(mesh)
        for group in _merged_parts(mesh, components):
            height = float(np.ptp(mesh.vertices[group][:, 2]))
            if kind in UPRIGHT_TYPES:
                pieces = _upright_pieces(mesh, line, [c for c in components if np.isin(c[0], group)])
            else:
                pieces = _off_carriageway(mesh.vertices[group], line, half_width)
                height = height if len(pieces) == 1 else -1.0
            objects += [_measured(mesh.name, kind, line, p_world, p_road,
                                  height if height >= 0 else float(np.ptp(p_world[:, 2])))
                        for p_world, p_road in pieces]
    return objects


def _road_frame(line: ReferenceLine, p_world: np.ndarray) -> np.ndarray:
    """(n, 2) station and offset of the points (n, 3), each point's own (no subsampling)."""
    return np.array([line.station(p) for p in p_world]).reshape(-1, 2)


def _sample(p_world: np.ndarray) -> np.ndarray:
    return p_world[:: max(1, len(p_world) // 200)]


def _measured(name: str, kind: str, line: ReferenceLine, p_world: np.ndarray, p_road: np.ndarray,
              height: float) -> RoadsideObject:
    """The object whose points are ``p_world`` (n, 3) at ``p_road`` (n, 2) (s, t), ``height`` tall."""
    s_mid = 0.5 * (p_road[:, 0].min() + p_road[:, 0].max())
    t_mid = 0.5 * (p_road[:, 1].min() + p_road[:, 1].max())
    z_road = float(line.z_at(s_mid))
    return RoadsideObject(name, kind, float(s_mid), float(t_mid), max(float(np.ptp(p_road[:, 0])), 0.05),
                          max(float(np.ptp(p_road[:, 1])), 0.05), max(height, 0.05), 0.0,
                          float(p_world[:, 2].min() - z_road))


def _upright_pieces(mesh: Mesh, line: ReferenceLine,
                    components: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
    """(points, road frame) of each footing of an upright group: its parts that reach the road's height (plinths,
    poles), merged where they touch; arms, lamp heads and wires in the air widen nothing."""
    footing = []
    for part in components:
        p_world = _sample(mesh.vertices[part])
        p_road = _road_frame(line, p_world)
        if p_world[:, 2].min() - float(line.z_at(float(p_road[:, 0].mean()))) < BASE_HEIGHT_M:
            footing.append(part)
    pieces = []
    for group in _merged_parts(mesh, footing, gap_m=0.1):
        p_world = _sample(mesh.vertices[group])
        pieces.append((p_world, _road_frame(line, p_world)))
    return pieces


def _off_carriageway(p_world: np.ndarray, line: ReferenceLine,
                     half_width: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """(points, road frame) of the part, or of its pieces beside the carriageway and (when high enough to drive
    under) above it when the part spans the carriageway."""
    p_world = _sample(p_world)
    p_road = _road_frame(line, p_world)
    if p_road[:, 1].max() <= -half_width or p_road[:, 1].min() >= half_width:
        return [(p_world, p_road)]
    z_rel = p_world[:, 2] - line.z_at(p_road[:, 0])
    pieces = []
    for keep in (p_road[:, 1] >= half_width, p_road[:, 1] <= -half_width, z_rel >= CLEARANCE_M):
        if np.count_nonzero(keep) >= 2:
            pieces.append((p_world[keep], p_road[keep]))
    return pieces


def _object(item: RoadsideObject, s_offset: float, road_length: float) -> xodr.Object | None:
    """The object on a road starting at main-road station ``s_offset``; its part within [0, road_length] (None
    when nothing is)."""
    xodr = _xodr()
    s0 = max(0.0, item.s_road - s_offset - item.length / 2)
    s1 = min(road_length, item.s_road - s_offset + item.length / 2)
    if s1 < s0:
        return None
    s_road = 0.5 * (s0 + s1)
    if item.length >= REPEAT_MIN_LENGTH_M:
        road_object = xodr.Object(s0, item.t_road, Type=item.type,
                                  name=item.name, zOffset=item.z_offset, width=item.width, length=1.0,
                                  height=item.height)
        road_object.repeat(s1 - s0, 0.0, tStart=item.t_road, tEnd=item.t_road, heightStart=item.height,
                           heightEnd=item.height, zOffsetStart=item.z_offset, zOffsetEnd=item.z_offset,
                           widthStart=item.width, widthEnd=item.width)
        return road_object
    return xodr.Object(s_road, item.t_road, Type=item.type, name=item.name, zOffset=item.z_offset,
                       hdg=item.heading, width=item.width, length=max(s1 - s0, 0.05), height=item.height)


def _add_objects(road: xodr.Road, objects: list[RoadsideObject], s_offset: float, length: float) -> None:
    """The objects whose centre lies on the road from main-road station ``s_offset`` over ``length``."""
    for item in objects:
        if s_offset <= item.s_road <= s_offset + length:
            road_object = _object(item, s_offset, length)
            if road_object is not None:
                road.add_object(road_object)


# ---------------------------------------------------------------------------------------------- roads

def _road(road_id: int, view: xodr.PlanView, network: RoadNetwork, markings: list[Marking],
          name: str, junction: int = -1) -> xodr.Road:
    xodr = _xodr()
    return xodr.Road(road_id, view, lanes(network, markings), road_type=junction, name=name)


def junction_radius(network: RoadNetwork) -> float:
    """Radius of a junction's turning roads (m): the carriageway's half width plus ``CORNER_RADIUS_M``, so that the
    innermost lane of a turn keeps a positive radius. The roads meeting at the junction end this far from its
    centre."""
    return network.main.half_width + CORNER_RADIUS_M


def opendrive(case: Case, scene: CompiledScene | None = None) -> xodr.OpenDrive:
    """The case's road network, marks and roadside objects as an OpenDRIVE document."""
    xodr = _xodr()
    network = scene.network if scene is not None else build_network(case.road, case.scene.kind)
    markings = list(scene.paint.markings if scene is not None else road_paint(case.road).markings)
    pieces, _ = reference_pieces(case.road)
    line = network.main.line
    objects = roadside_objects(scene) if scene is not None else []
    document = xodr.OpenDrive(case.title or "lanevil case", revMajor=REVISION[0], revMinor=REVISION[1])
    if len(network.pieces) == 1:
        road = _road(MAIN_ROAD_ID, plan_view(pieces, 0.0, 0.0, 0.0), network, markings, "main")
        for record in elevation_records(line):
            road.add_elevation(*record)
        _add_objects(road, objects, 0.0, line.length)
        document.add_road(road)
        document.adjust_roads_and_lanes()
        return document
    return _junction_document(document, case, network, markings, objects)


@dataclass(frozen=True)
class _Leg:
    """A road meeting the junction: its id, the pose where it touches the junction (x, y, heading into the
    junction, radians) and whether it touches with its end (the incoming main road) or its start."""

    road: xodr.Road
    x: float
    y: float
    heading: float
    at_end: bool
    side: int = 0  # for arms: +1 leaves to the left of the main road, -1 to the right


def _junction_document(document: xodr.OpenDrive, case: Case, network: RoadNetwork, markings: list[Marking],
                       objects: list[RoadsideObject]) -> xodr.OpenDrive:
    """A straight main road cut around its junction, the arms, and one connecting road per pair of them."""
    xodr = _xodr()
    radius = junction_radius(network)
    junction_s = case.road.junction_s
    line = network.main.line
    incoming = _road(MAIN_ROAD_ID, plan_view([Piece(junction_s - radius)], 0.0, 0.0, 0.0), network, markings,
                     "main (before the junction)")
    outgoing = _road(MAIN_ROAD_ID + 1, plan_view([Piece(line.length - junction_s - radius)], junction_s + radius,
                                                   0.0, 0.0), network, markings, "main (after the junction)")
    incoming.add_successor(xodr.ElementType.junction, JUNCTION_ID)
    outgoing.add_predecessor(xodr.ElementType.junction, JUNCTION_ID)
    legs = [_Leg(incoming, junction_s - radius, 0.0, 0.0, True),
            _Leg(outgoing, junction_s + radius, 0.0, math.pi, False)]
    for index, piece in enumerate(network.pieces[1:]):
        p_world = piece.line.to_world(radius, 0.0)
        heading = float(piece.line.heading_at(radius))
        arm = _road(MAIN_ROAD_ID + 2 + index, plan_view([Piece(piece.line.length - radius)], float(p_world[0]),
                                                        float(p_world[1]), heading), network, markings,
                    f"arm {index + 1}")
        arm.add_predecessor(xodr.ElementType.junction, JUNCTION_ID)
        side = 1 if math.sin(heading) > 0 else -1
        legs.append(_Leg(arm, float(p_world[0]), float(p_world[1]), heading + math.pi, False, side))
    for leg in legs:
        leg.road.add_elevation(0.0, 0.0, 0.0, 0.0, 0.0)
    _add_objects(incoming, objects, 0.0, junction_s - radius)
    _add_objects(outgoing, objects, junction_s + radius, line.length - junction_s - radius)
    junction = xodr.Junction("junction", JUNCTION_ID)
    road_id = JUNCTION_ID + 1
    arm_sides = {leg.side for leg in legs}
    for i, first in enumerate(legs):
        for second in legs[i + 1:]:
            road, connection = _connecting_road(road_id, first, second, network,
                                                _connection_marks(markings, first, second, arm_sides))
            document.add_road(road)
            junction.add_connection(connection)
            road_id += 1
    for leg in legs:
        document.add_road(leg.road)
    document.add_junction(junction)
    document.adjust_startpoints()
    return document


def _connection_marks(markings: list[Marking], first: _Leg, second: _Leg, arm_sides: set[int]) -> list[Marking]:
    """The marks of the connecting road from ``first`` to ``second``: along the main road its paint, whose edge lines
    break where an arm leaves (as the case paints it); none on turns and between arms."""
    none = [marking.model_copy(update={"type": "none"}) for marking in markings]
    if first.side or second.side:
        return none
    marks = list(markings)
    if 1 in arm_sides:
        marks[0] = none[0]
    if -1 in arm_sides:
        marks[-1] = none[-1]
    return marks


def _connecting_road(road_id: int, first: _Leg, second: _Leg, network: RoadNetwork,
                     markings: list[Marking]) -> tuple[xodr.Road, xodr.Connection]:
    """The connecting road from ``first`` to ``second`` (a line straight across, an arc for a turn) with its lanes
    linked to both, and its one connection (incoming road ``first``)."""
    xodr = _xodr()
    turn = math.remainder(second.heading + math.pi - first.heading, 2 * math.pi)
    view = xodr.PlanView(first.x, first.y, first.heading)
    if abs(turn) < 1e-9:
        view.add_geometry(xodr.Line(math.hypot(second.x - first.x, second.y - first.y)))
    else:
        chord = math.hypot(second.x - first.x, second.y - first.y)
        radius = chord / (2 * math.sin(abs(turn) / 2))
        view.add_geometry(xodr.Arc(math.copysign(1.0 / radius, turn), length=radius * abs(turn)))
    road = _road(road_id, view, network, markings, f"{first.road.id} to {second.road.id}", junction=JUNCTION_ID)
    road.add_elevation(0.0, 0.0, 0.0, 0.0, 0.0)
    contact = (xodr.ContactPoint.start, xodr.ContactPoint.end)
    road.add_predecessor(xodr.ElementType.road, first.road.id, contact[first.at_end])
    road.add_successor(xodr.ElementType.road, second.road.id, contact[second.at_end])
    connection = xodr.Connection(first.road.id, road_id, xodr.ContactPoint.start)
    section = road.lanes.lanesections[0]
    for lane in section.leftlanes + section.rightlanes:
        # a road touching with its start runs away from the junction: its lanes swap sides
        before = lane.lane_id if first.at_end else -lane.lane_id
        after = -lane.lane_id if second.at_end else lane.lane_id
        lane.add_link("predecessor", before)
        lane.add_link("successor", after)
        connection.add_lanelink(before, lane.lane_id)
    return road, connection


def write_opendrive(case: Case, out_dir: str | Path, scene: CompiledScene | None = None) -> Path:
    """Write ``out_dir/road.xodr``; returns its path."""
    from ..pipeline.compile import compile_scene

    document = opendrive(case, scene if scene is not None else compile_scene(case))
    path = Path(out_dir) / "road.xodr"
    write_atomic(path, xodr_text(document).encode("utf-8"))
    return path


def xodr_text(document: xodr.OpenDrive) -> str:
    """The document as indented XML text, the same bytes for the same case."""
    import xml.etree.ElementTree as ET

    element = document.get_element()
    # The writer stamps the export time into the header, writes unset optional attributes as "None" and numbers
    # objects with a counter that runs on over exports; the first two are left out and objects numbered per
    # document, so that an export is byte-identical for the same case (the header's date is optional).
    for index, road_object in enumerate(element.iter("object")):
        road_object.set("id", str(index))
    for node in element.iter():
        for key in [key for key, value in node.attrib.items() if value == "None"]:
            del node.attrib[key]
    header = element.find("header")
    if header is not None:
        header.attrib.pop("date", None)
    ET.indent(element)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(element, encoding="unicode") + "\n"
