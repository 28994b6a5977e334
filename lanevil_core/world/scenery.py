"""What stands beside the road, by scene kind: buildings, houses, trees, bushes, barriers, a tunnel portal.

Props stand beyond every road piece's carriageway and its non-terrain cross-section strips (shoulders, kerbs,
sidewalks, gravel); the only exceptions are structures meant to be there (highway barriers on the gravel verge,
streetlights on the sidewalk, the tunnel mouth over the road). Placement is deterministic given the rng.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from ..typed import FloatArray, SceneKind
from . import buildings, people, props, vegetation, vehicles
from .primitives import merge, pose_on_road, swept, transformed
from .road_layout import RoadNetwork, RoadPiece
from .scene import Mesh, PointLight
from .structures import WARM_LAMP, ground_height, pole_stations, power_lines, streetlight, streetlight_lamp_offset

CLEAR_MARGIN_M = 0.3  # free space kept between a prop's footprint and any road corridor
GROUP_LENGTH_M = 100.0  # small props (trees, bushes, barriers) are merged into one mesh per side and stretch
TUNNEL_HEIGHT_M = 6.0
ROW_RETRY_STEP_M = 3.0
NEAR_PLANT_M = 18.0  # trees and bushes farther than this from the main road's centre line, or from the stretch
NEAR_AHEAD_M = 60.0  # the ego drives (this far beyond its end), are only ever seen from afar: built with less
# detail (``vegetation.FAR_DETAIL``)


@dataclass(frozen=True)
class RoadsideInputs:
    """What the roadside reads beside the road network (``pipeline/compile.py`` ``roadside_inputs`` fills it from a
    case): the scene kind and density, whether it is night (lit windows, street lamps on), the ego's drive along the
    main road (where parked cars are seen) and where a junction's arms cross the main road."""

    kind: SceneKind
    density: float
    night: bool
    start_s: float  # the ego's first and last positions along the main road (m)
    end_s: float
    junction_s: float


def corridor_half_width(piece: RoadPiece) -> float:
    """|t| up to which the piece's carriageway and non-terrain strips reach (m)."""
    return piece.half_width + sum(strip.width for strip in piece.strips[:-1])


def ground_h(piece: RoadPiece) -> float:
    """Height of the terrain strip above the carriageway (m)."""
    return piece.strips[-1].height if piece.strips else 0.0


class Clearance:
    """Which world points fall inside a road corridor, and which spots props already took."""

    def __init__(self, network: RoadNetwork, stride: int = 10) -> None:
        self.pieces = network.pieces
        self._samples = [(p.line.s[::stride], p.line.xy[::stride], p.line.heading[::stride]) for p in network.pieces]
        self.taken = np.zeros((0, 4, 2))  # footprints of the props placed so far, (n, 4, 2) corners
        self.closed_s: list[tuple[float, float]] = []  # main-road stretches where nothing may stand beside it

    def road_frame(self, index: int, p_xy: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(n,) s and t of world points (n, 2) in piece ``index``'s road frame (nearest sample, refined)."""
        s, xy, heading = self._samples[index]
        d2 = ((p_xy[:, None, :] - xy[None, :, :]) ** 2).sum(-1)
        near = np.argmin(d2, axis=1)
        delta = p_xy - xy[near]
        tangent = np.stack([np.cos(heading[near]), np.sin(heading[near])], -1)
        normal = np.stack([-tangent[:, 1], tangent[:, 0]], -1)
        return s[near] + (delta * tangent).sum(-1), (delta * normal).sum(-1)

    def on_road(self, p_xy: FloatArray, margin: float = CLEAR_MARGIN_M, skip: int | None = None) -> bool:
        """Whether any point (n, 2) lies within ``margin`` of some piece's corridor (piece ``skip`` ignored)."""
        for index, piece in enumerate(self.pieces):
            if index == skip:
                continue
            s, t = self.road_frame(index, p_xy)
            inside = (s > -margin) & (s < piece.line.length + margin)
            if np.any(inside & (np.abs(t) < corridor_half_width(piece) + margin)):
                return True
        return False

    def free(self, corners_xy: FloatArray, gap: float = 0.5) -> bool:
        """Whether the footprint (4, 2) keeps ``gap`` from every footprint taken so far and stands beside no
        closed stretch of the main road."""
        if self.closed_s:
            s, _ = self.road_frame(0, corners_xy.mean(0, keepdims=True))
            if any(s0 <= s[0] <= s1 for s0, s1 in self.closed_s):
                return False
        return not np.any(overlapping(corners_xy, self.taken, gap))

    def take(self, corners_xy: FloatArray) -> None:
        self.taken = np.concatenate([self.taken, np.asarray(corners_xy, np.float64)[None]])


def _edge_normals(quads: FloatArray) -> FloatArray:
    """(..., 2, 2) unit normals of the first two edges of convex quads (..., 4, 2)."""
    edges = quads[..., 1:3, :] - quads[..., 0:2, :]
    normals = np.stack([-edges[..., 1], edges[..., 0]], -1)
    return normals / np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-12)


def overlapping(quad: FloatArray, quads: FloatArray, gap: float) -> np.ndarray:
    """(n,) whether the rectangle ``quad`` (4, 2) comes within ``gap`` of each rectangle of ``quads``
    (n, 4, 2) (separating-axis test)."""
    if len(quads) == 0:
        return np.zeros(0, bool)
    axes = np.concatenate([np.broadcast_to(_edge_normals(quad), (len(quads), 2, 2)), _edge_normals(quads)], 1)
    pa = np.einsum("kj,naj->nak", quad, axes)
    pb = np.einsum("nkj,naj->nak", quads, axes)
    separated = (pa.max(-1) + gap < pb.min(-1)) | (pb.max(-1) + gap < pa.min(-1))
    return ~separated.any(1)


@dataclass
class Spot:
    """A candidate place beside piece ``index``: road frame (s, t), yaw, the footprint's half extents."""

    index: int
    s: float
    t: float
    yaw: float
    half_x: float
    half_y: float
    T_world_local: FloatArray = field(default_factory=lambda: np.eye(4))


def try_place(clear: Clearance, piece: RoadPiece, spot: Spot) -> bool:
    """Pose ``spot`` on its piece; accept it if its footprint is off every corridor, beyond no sharp inside
    bend, and free of other props (then mark it taken)."""
    if not 0.0 <= spot.s <= piece.line.length:
        return False
    curvature = float(np.interp(spot.s, piece.line.s, piece.line.curvature))
    if curvature * spot.t > 0 and abs(spot.t) + spot.half_y > 0.6 / abs(curvature):
        return False  # beyond the terrain on the inside of a bend
    # On a slope the footprint's downhill end must not float: sink the prop by the rise over its half length.
    sink = abs(float(piece.line.grade_at(spot.s))) * max(spot.half_x, spot.half_y)
    spot.T_world_local = pose_on_road(piece.line, spot.s, spot.t, spot.yaw, ground_h(piece) - sink)
    xs, ys = (-spot.half_x, 0.0, spot.half_x), (-spot.half_y, 0.0, spot.half_y)
    corners = np.array([(x, y, 0.0) for x in xs for y in ys])
    p_xy = (corners @ spot.T_world_local[:3, :3].T + spot.T_world_local[:3, 3])[:, :2]
    s_back, t_back = clear.road_frame(spot.index, p_xy[4:5])
    if abs(s_back[0] - spot.s) > 1.0 or abs(t_back[0] - spot.t) > 1.0:
        return False  # the spot folds onto another part of the road
    footprint = p_xy[[0, 2, 8, 6]]
    if clear.on_road(p_xy) or not clear.free(footprint):
        return False
    clear.take(footprint)
    return True


def sides(network: RoadNetwork) -> Iterator[tuple[int, RoadPiece, int]]:
    """(piece index, piece, side) for both sides of every piece; side +1 left, -1 right."""
    for index, piece in enumerate(network.pieces):
        for side in (-1, 1):
            yield index, piece, side


def stations(s0: float, s1: float, spacing: float, rng: np.random.Generator, jitter: float = 0.4) -> FloatArray:
    """Positions from s0 to s1 about ``spacing`` apart, each moved by up to +-jitter * spacing (none for a spacing
    that is not positive and finite: a density of next to nothing)."""
    if not 0 < spacing < np.inf or s1 <= s0:
        return np.zeros(0)
    base = np.arange(s0 + 0.5 * spacing, s1, spacing)
    return base + rng.uniform(-jitter, jitter, base.size) * spacing


def facing_yaw(side: int) -> float:
    """Yaw that turns a prop's +Y (its front) towards the road from ``side``."""
    return 0.0 if side < 0 else np.pi


def _grouped(placed: list[tuple[float, Mesh]], name: str, kind: str) -> list[Mesh]:
    """Merge (s, world mesh) pairs into one mesh per GROUP_LENGTH_M of road."""
    groups: dict[int, list[Mesh]] = {}
    for s, mesh in placed:
        groups.setdefault(int(s // GROUP_LENGTH_M), []).append(mesh)
    return [merge(meshes, name=f"{name} {k * GROUP_LENGTH_M:.0f}-{(k + 1) * GROUP_LENGTH_M:.0f} m", kind=kind)
            for k, meshes in sorted(groups.items())]


def own_rng(rng: np.random.Generator) -> np.random.Generator:
    """A generator of a prop's own, seeded by one draw of the placement's: what a prop's builder draws (its shape,
    its colours) never moves the props placed after it."""
    return np.random.default_rng(int(rng.integers(2**63)))


def plant(rng: np.random.Generator, bush_share: float,
          conifer_share: float) -> tuple[float, Callable[[bool], Mesh]]:
    """Pick a tree or bush: its footprint half size (m) and a builder for its local-frame mesh (given whether it
    stands near the ego's drive, ``near_the_drive``)."""
    own = own_rng(rng)
    if rng.random() < bush_share:
        radius = float(rng.uniform(0.6, 1.3))
        return 1.2 * radius, lambda near: vegetation.bush(own, radius=radius, near=near)
    conifer = bool(rng.random() < conifer_share)
    height = float(rng.uniform(5.0, 11.0))
    return (0.23 if conifer else 0.43) * height, lambda near: vegetation.tree(own, conifer=conifer, height=height,
                                                                              near=near)


def near_the_drive(inputs: RoadsideInputs, clear: Clearance, spot: Spot) -> bool:
    """Whether ``spot`` (posed) stands within ``NEAR_PLANT_M`` of the main road along the stretch the ego drives
    (from ``NEAR_PLANT_M`` behind its start to ``NEAR_AHEAD_M`` beyond its end)."""
    s, t = clear.road_frame(0, spot.T_world_local[None, :2, 3])
    return bool(inputs.start_s - NEAR_PLANT_M < s[0] < inputs.end_s + NEAR_AHEAD_M and abs(t[0]) < NEAR_PLANT_M)


def greenery(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator, spacing: float,
             setback: tuple[float, float], bush_share: float = 0.3, conifer_share: float = 0.35) -> list[Mesh]:
    """Trees and bushes along both sides of every piece, ``setback`` (min, max) m beyond the corridor."""
    out: list[Mesh] = []
    for index, piece, side in sides(network):
        placed: list[tuple[float, Mesh]] = []
        for s in stations(piece.s_start, piece.line.length, spacing, rng):
            half, build = plant(rng, bush_share, conifer_share)
            t = side * (corridor_half_width(piece) + float(rng.uniform(*setback)) + half)
            spot = Spot(index, float(s), t, float(rng.uniform(0, 2 * np.pi)), half, half)
            if try_place(clear, piece, spot):
                placed.append((float(s), transformed(build(near_the_drive(inputs, clear, spot)), spot.T_world_local)))
        label = "left" if side > 0 else "right"
        out += _grouped(placed, f"trees {label} piece {index}", "tree")
    return out


def rows_of(network: RoadNetwork, clear: Clearance, rng: np.random.Generator,
            make: Callable[[np.random.Generator], tuple[float, float, Callable[[], Mesh]]],
            setback: tuple[float, float], gap: tuple[float, float], kind: str) -> list[Mesh]:
    """Buildings in a row along both sides of every piece: ``make`` returns (width, depth, local mesh builder)."""
    out: list[Mesh] = []
    if not np.isfinite(gap[1]):  # a density of next to nothing: no row
        return out
    for index, piece, side in sides(network):
        s = piece.s_start + float(rng.uniform(0.0, gap[1]))
        while s < piece.line.length:
            width, depth, build = make(own_rng(rng))
            t = side * (corridor_half_width(piece) + float(rng.uniform(*setback)) + depth / 2)
            spot = Spot(index, s + width / 2, t, facing_yaw(side), width / 2, depth / 2)
            if try_place(clear, piece, spot):
                mesh = transformed(build(), spot.T_world_local)
                mesh.name = f"{kind} {len(out) + 1}"
                out.append(mesh)
                s += width + float(rng.uniform(*gap))
            else:  # something stands there: try the next building a little further on
                s += ROW_RETRY_STEP_M
    return out


def barriers(network: RoadNetwork, clear: Clearance, segment: float = 4.0) -> list[Mesh]:
    """Concrete barriers along the outer edge of the first roadside strip (the hard shoulder), both sides."""
    out: list[Mesh] = []
    template = props.jersey_barrier(segment - 0.03)
    for index, piece, side in sides(network):
        t = side * (piece.half_width + piece.strips[0].width + 0.45)
        h = piece.strips[1].height if len(piece.strips) > 2 else 0.0
        placed = []
        for s in np.arange(piece.s_start + segment / 2, piece.line.length - segment / 2, segment):
            T = pose_on_road(piece.line, float(s), t, 0.0, h)
            ends = np.array([[-segment / 2, -0.35, 0, 1], [segment / 2, -0.35, 0, 1], [-segment / 2, 0.35, 0, 1],
                             [segment / 2, 0.35, 0, 1]]) @ T.T
            if not clear.on_road(ends[:, :2], margin=0.1, skip=index):
                placed.append((float(s), transformed(template, T)))
        label = "left" if side > 0 else "right"
        out += _grouped(placed, f"barrier {label} piece {index}", "barrier")
    return out


STREETLIGHT_SPACING_M = 30.0  # street lamps along urban and suburban streets, on both sides
STREETLIGHT_KINDS = ("urban", "suburban")  # the scene kinds with street lamps on their sidewalks
STREET_LAMP_INTENSITY = 30.0  # radiance scale at 1 m of a roadside lamp: about 15 lux on the road below it


def raised_strips(piece: RoadPiece) -> list[int]:
    """The indices of a piece's raised strips (kerb, sidewalk) before the ground beyond its last strip."""
    return [i for i, strip in enumerate(piece.strips[:-1]) if strip.height > 0.05]


def sidewalk_kerb(piece: RoadPiece) -> tuple[float, float] | None:
    """(lateral distance from the reference line, height) of the kerb side of a piece's sidewalk (its first raised
    strip), or None where the piece has none."""
    raised = raised_strips(piece)
    if not raised:
        return None
    return piece.half_width + sum(strip.width for strip in piece.strips[:raised[0]]), piece.strips[raised[0]].height


def streetlight_poses(network: RoadNetwork, clear: Clearance,
                      spacing: float) -> list[tuple[str, int, float, FloatArray]]:
    """(side label, piece index, s, T_world_local) of every street lamp on the sidewalk (the first raised strip),
    every ``spacing`` m on both sides, arms over the road; none where a junction arm or its sidewalk passes."""
    poses = []
    for index, piece, side in sides(network):
        kerb = sidewalk_kerb(piece)
        if kerb is None:
            continue
        t, h = side * (kerb[0] + 0.6), kerb[1]
        offset = spacing / 2 if side > 0 else 0.0
        for s in np.arange(piece.s_start + 5.0 + offset, piece.line.length - 2.0, spacing):
            T_world_local = pose_on_road(piece.line, float(s), t, facing_yaw(side), h)
            if not clear.on_road(T_world_local[None, :2, 3], margin=1.0, skip=index):
                poses.append(("left" if side > 0 else "right", index, float(s), T_world_local))
    return poses


def streetlights(network: RoadNetwork, clear: Clearance, spacing: float, emissive: bool) -> list[Mesh]:
    """Street lamps at ``streetlight_poses``, grouped per side, piece and stretch of road."""
    template = streetlight(emissive=emissive)
    groups: dict[tuple[str, int], list[tuple[float, Mesh]]] = {}
    for label, index, s, T_world_local in streetlight_poses(network, clear, spacing):
        groups.setdefault((label, index), []).append((s, transformed(template, T_world_local)))
    out: list[Mesh] = []
    for (label, index), placed in groups.items():
        out += _grouped(placed, f"streetlights {label} piece {index}", "pole")
    return out


def street_lamps(inputs: RoadsideInputs, network: RoadNetwork) -> list[PointLight]:
    """The lights of the roadside's street lamps when they are lit (at night, in a scene kind with lamps):
    warm LED heads with a full cut-off beam at each lamp of ``streetlights``."""
    if inputs.kind not in STREETLIGHT_KINDS or not inputs.night:
        return []
    offset = streetlight_lamp_offset()
    return [PointLight(T_world_local[:3, :3] @ offset + T_world_local[:3, 3], np.asarray(WARM_LAMP, np.float32),
                       STREET_LAMP_INTENSITY, name=f"street lamp {label} {index} {s:.0f}", beam="street")
            for label, index, s, T_world_local in streetlight_poses(network, Clearance(network),
                                                                  STREETLIGHT_SPACING_M)]


FURNITURE_SPACING_M = 22.0  # mean distance between pieces of street furniture along each sidewalk


def street_furniture(network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    """Litter bins, bollards and sign posts (facing the traffic on their side) on the sidewalks (the first raised
    strip), about every FURNITURE_SPACING_M, at the sidewalk's kerb side like the lamps; none where a junction arm
    passes or within 2 m of a lamp."""
    templates = (props.litter_bin(), props.bollard())
    out: list[Mesh] = []
    for index, piece, side in sides(network):
        kerb = sidewalk_kerb(piece)
        if kerb is None:
            continue
        t, h = side * (kerb[0] + 0.5), kerb[1]
        lamp_first = piece.s_start + 5.0 + (STREETLIGHT_SPACING_M / 2 if side > 0 else 0.0)
        placed = []
        for s in stations(piece.s_start + 12.0, piece.line.length - 5.0, FURNITURE_SPACING_M, rng):
            choice = int(rng.integers(3))
            mesh = props.sign_post(own_rng(rng)) if choice == 2 else templates[choice]
            from_lamp = (s - lamp_first) % STREETLIGHT_SPACING_M
            if min(from_lamp, STREETLIGHT_SPACING_M - from_lamp) < 2.0:
                continue  # a lamp stands there
            T_world_local = pose_on_road(piece.line, float(s), t, facing_yaw(side), h)
            if not clear.on_road(T_world_local[None, :2, 3], margin=1.0, skip=index):
                placed.append((float(s), transformed(mesh, T_world_local)))
        label = "left" if side > 0 else "right"
        out += _grouped(placed, f"street furniture {label} piece {index}", "street_furniture")
    return out


PASSER_SPACING_M = {"urban": 16.0, "suburban": 60.0}  # one person about every this many metres of each sidewalk
PASSERS_BEHIND_M, PASSERS_AHEAD_M = 10.0, 80.0  # people stand along the main road from this far behind the ego's
# start to this far beyond its end (further on they are a few pixels and only cost triangles)
WALKING_SHARE = 0.7  # of the people on a sidewalk, those walking along it (the rest stand, facing any way)


def sidewalk_width(piece: RoadPiece) -> float:
    """How wide a piece's sidewalk is from its kerb side: its raised strips before the ground beyond (0: none)."""
    return float(sum(piece.strips[i].width for i in raised_strips(piece)))


def passers_by(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    """People on both sidewalks of the main road, about every ``PASSER_SPACING_M`` of the scene kind (over the
    density) along the stretch the ego sees: most walking along the sidewalk one way or the other, the rest
    standing; at least 0.9 m from the kerb (clear of the lamps and furniture at its edge) and 0.5 m from the
    sidewalk's back; none where another road crosses."""
    piece, kerb = network.main, sidewalk_kerb(network.main)
    width = sidewalk_width(piece)
    if kerb is None or width < 1.6 or inputs.density <= 0:
        return []
    spacing = PASSER_SPACING_M[inputs.kind] / inputs.density
    s0, s1 = max(inputs.start_s - PASSERS_BEHIND_M, 0.0), min(inputs.end_s + PASSERS_AHEAD_M, piece.line.length)
    out: list[Mesh] = []
    for side in (-1, 1):
        placed = []
        for s in stations(s0, s1, spacing, rng):
            t = side * (kerb[0] + float(rng.uniform(0.9, width - 0.5)))
            walking = bool(rng.random() < WALKING_SHARE)
            yaw = float(rng.choice([0.0, np.pi])) if walking else float(rng.uniform(-np.pi, np.pi))
            person = people.pedestrian(own_rng(rng), height=float(rng.uniform(1.55, 1.9)), walking=walking)
            T_world_local = pose_on_road(piece.line, float(s), t, yaw, kerb[1])
            if not clear.on_road(T_world_local[None, :2, 3], margin=0.8, skip=0):
                placed.append((float(s), transformed(person, T_world_local)))
        out += _grouped(placed, f"passers-by {'left' if side > 0 else 'right'}", "pedestrian")
    return out


PARKED_SETBACK_M = 0.45  # a parked vehicle's side from the edge of the sidewalk (its footprint keeps 0.1 m more)
PARKING_ROW_M = 2.6  # the depth of the row of parked vehicles beyond the sidewalk: a van's width and a door's room
PARKED_GAP_M = (0.7, 2.5)  # bumper to bumper between parked vehicles
DRIVEWAY_SHARE = 0.2  # the gaps that are an entrance or a driveway instead
DRIVEWAY_GAP_M = (3.5, 9.0)
JUNCTION_GAP_M = 8.0  # nobody parks this close to a crossing road's corridor
PARKING_AHEAD_M = (15.0, 100.0)  # parked along the main road from this far behind the ego's start to this far
# beyond its end, and along a junction's arms this far from the main road: further on they are a few pixels and
# only cost triangles
PARKING_ARM_M = 45.0


def parking_occupancy(density: float) -> float:
    """The share of the parking row's slots taken at a scene density: 0 for none, 0.33 at 1, 0.7 at 3."""
    return float(1.0 - np.exp(-0.4 * density))


def parked_cars(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    """Rows of parked cars and vans beyond the sidewalk (kerb-parallel, facing the traffic of their side's lanes),
    in car-paint colours; slots taken at ``parking_occupancy`` of the scene density, with gaps for driveways, none
    within JUNCTION_GAP_M of a crossing road and only along the stretch the ego can see (``PARKING_AHEAD_M``)."""
    occupancy = parking_occupancy(inputs.density)
    s_lo, s_hi = inputs.start_s - PARKING_AHEAD_M[0], inputs.end_s + PARKING_AHEAD_M[1]
    out: list[Mesh] = []
    for index, piece, side in sides(network):
        placed: list[tuple[float, Mesh]] = []
        s = piece.s_start + float(rng.uniform(0.0, 6.0))
        while s < piece.line.length and occupancy > 0:
            length, width, build = vehicles.parked_vehicle(own_rng(rng))
            parks = rng.random() < occupancy
            gap = float(rng.uniform(*(DRIVEWAY_GAP_M if rng.random() < DRIVEWAY_SHARE else PARKED_GAP_M)))
            t = side * (corridor_half_width(piece) + PARKED_SETBACK_M + width / 2)
            spot = Spot(index, s + length / 2, t, facing_yaw(side), length / 2 + 0.1, width / 2 + 0.1)
            seen = s_lo < spot.s < s_hi if index == 0 else spot.s < piece.s_start + PARKING_ARM_M
            if parks and seen and _clear_of_junctions(clear, piece, spot) \
                    and try_place(clear, piece, spot):
                placed.append((s, transformed(build(), spot.T_world_local)))
            s += length + gap
        label = "left" if side > 0 else "right"
        out += _grouped(placed, f"parked cars {label} piece {index}", "vehicle")
    return out


def _clear_of_junctions(clear: Clearance, piece: RoadPiece, spot: Spot) -> bool:
    """Whether ``spot``'s ends keep JUNCTION_GAP_M from every other piece's corridor."""
    ends = np.array([pose_on_road(piece.line, spot.s + ds, spot.t, 0.0)[:2, 3] for ds in (-spot.half_x, spot.half_x)])
    return not clear.on_road(ends, margin=JUNCTION_GAP_M, skip=spot.index)


SIGNAL_BACK_M = 1.5  # a traffic signal stands this far before the crossing road's corridor, on the sidewalk
SIGNAL_CLEAR_OF_LAMP_M = 1.5  # and steps back from a street lamp this close
AMBER_SHARE = 0.15  # the junctions caught with their signals changing


def signal_poses(inputs: RoadsideInputs, network: RoadNetwork) -> list[tuple[int, float, float, float, float]]:
    """(piece index, s, t, sidewalk height, yaw) of a traffic signal at each approach to the junction: on the
    approaching traffic's sidewalk (right-hand traffic), SIGNAL_BACK_M before the crossing corridor, its lamps
    towards that traffic."""
    if len(network.pieces) < 2:
        return []
    main = network.main
    poses = []
    for sign in (-1.0, 1.0):  # main-road traffic along +s (sign -1: its sidewalk on the right) and along -s
        kerb = sidewalk_kerb(main)
        if kerb is not None:
            s = inputs.junction_s + sign * (corridor_half_width(network.pieces[1]) + SIGNAL_BACK_M)
            poses.append((0, s, sign * (kerb[0] + 0.6), kerb[1], 0.0 if sign < 0 else np.pi))
    for index, arm in enumerate(network.pieces[1:], start=1):  # the arms' traffic comes towards the main road
        kerb = sidewalk_kerb(arm)
        if kerb is not None:
            poses.append((index, corridor_half_width(main) + SIGNAL_BACK_M, kerb[0] + 0.6, kerb[1], np.pi))
    return poses


def traffic_signals(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance,
                    rng: np.random.Generator) -> list[Mesh]:
    """A traffic signal at each approach to a town junction (``signal_poses``): the main road's approaches show one
    aspect, the arms' the other (red against green, or amber while changing)."""
    main_aspect = "green" if rng.random() < 0.5 else "red"
    other = "red" if main_aspect == "green" else "green"
    if rng.random() < AMBER_SHARE:
        main_aspect = "amber"
    lamps = [(index, s) for _, index, s, _ in streetlight_poses(network, clear, STREETLIGHT_SPACING_M)]
    out: list[Mesh] = []
    for index, s, t, h, yaw in signal_poses(inputs, network):
        piece = network.pieces[index]
        away = -1.0 if index == 0 and yaw == 0.0 else 1.0  # back from the junction along the piece
        for _ in range(4):
            if not any(i == index and abs(s - s_lamp) < SIGNAL_CLEAR_OF_LAMP_M for i, s_lamp in lamps):
                break
            s += away * SIGNAL_CLEAR_OF_LAMP_M
        T_world_local = pose_on_road(piece.line, s, t, yaw, h)
        if clear.on_road(T_world_local[None, :2, 3], margin=1.0, skip=index):
            continue
        aspect = main_aspect if index == 0 else other
        out.append(transformed(props.traffic_signal(aspect, name=f"traffic signal {len(out) + 1}"), T_world_local))
    return out


@dataclass(frozen=True)
class TunnelHill:
    """The hill around a tunnel's portal (m): how far it reaches back over the mouth, its crest's height over
    the road, its width beside the tube."""

    depth: float = 12.0
    crest: float = 16.0
    width: float = 45.0


TUNNEL_HILL = TunnelHill()


def tunnel(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator) -> tuple[list[Mesh], float]:
    """The tunnel mouth 150-250 m ahead of the ego start, and the hill and dark tube it leads into, following
    the road to a dark end wall at the road's end. Returns the meshes and the portal's s."""
    line = network.main.line
    s_portal = float(min(inputs.start_s + rng.uniform(150.0, 250.0), line.length - 30.0))
    opening = corridor_half_width(network.main) + 0.2
    hill_depth, crest, hill_width = TUNNEL_HILL.depth, TUNNEL_HILL.crest, TUNNEL_HILL.width
    portal = props.tunnel_portal(2 * opening, TUNNEL_HEIGHT_M, hill_height=crest, hill_depth=hill_depth,
                                 hill_width=hill_width)
    meshes = [transformed(portal, pose_on_road(line, s_portal, 0.0))]
    s_in = np.append(np.arange(s_portal + 6.0, line.length, 5.0), line.length)
    s_hill = np.append(np.arange(s_portal + hill_depth - 0.5, line.length, 5.0), line.length)
    dark = (0.03, 0.03, 0.03)
    section = props.hill_profile(opening + 0.4, hill_width, crest)
    for side in (-1.0, 1.0):
        wall = [(side * opening, -0.2), (side * (opening + 0.4), -0.2), (side * (opening + 0.4), TUNNEL_HEIGHT_M + 0.4),
                (side * opening, TUNNEL_HEIGHT_M + 0.4)]
        meshes.append(swept(line, s_in, wall, dark, name="tunnel wall", kind="tunnel"))
        hill = swept(line, s_hill, section * (side, 1.0), name="hillside", kind="terrain")
        hill.colors = props.earth_colors(hill.vertices[hill.faces].mean(1)).astype(np.float32)
        meshes.append(hill)
    roof = [(-opening - 0.4, TUNNEL_HEIGHT_M), (opening + 0.4, TUNNEL_HEIGHT_M), (opening + 0.4, crest),
            (-opening - 0.4, crest)]
    meshes.append(swept(line, s_in, roof, props.EARTH[0], name="tunnel roof", kind="tunnel"))
    end = [(-opening, -0.2), (opening, -0.2), (opening, TUNNEL_HEIGHT_M), (-opening, TUNNEL_HEIGHT_M)]
    meshes.append(swept(line, [line.length - 0.5, line.length], end, dark, name="tunnel end", kind="tunnel"))
    return meshes, s_portal


# Utility poles along rural and suburban roads: a row of wooden poles on one side of the main road, each with a
# cross-arm and porcelain insulators, two or three wires sagging between neighbours (``structures.power_lines``).
UTILITY_POLE_SPACING_M = (35.0, 50.0)
UTILITY_WIRE_HEIGHT_M = (8.5, 11.0)  # the wires' height on the cross-arm; the pole reaches 0.6 m above: 9-12 m
UTILITY_WIRES = (2, 3)
UTILITY_WIRE_SPACING_M = 0.7
UTILITY_SAG_PER_M = 0.02  # mid-span sag per metre of span
UTILITY_SEEN_M = (30.0, 250.0)  # along the main road from this far behind the ego's start to this far beyond its end
UTILITY_WIRE_SEGMENT_M = 8.0  # wires are seen from afar: longer straight pieces than the shadow illusion's
UTILITY_CLEAR_M = 1.5  # half the width of the strip under the wires kept clear of crowns (m)
UTILITY_POLE_HALF_M = 0.2


def utility_lines(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator,
                  setback: tuple[float, float], clear_under: bool) -> list[Mesh]:
    """A row of utility poles with wires on a drawn side of the main road, ``setback`` (min, max) m beyond its
    corridor, along the stretch the ego sees (``UTILITY_SEEN_M``); a pole that cannot stand (a junction mouth,
    another prop) is left out and its wires span over. With ``clear_under`` the strip under the wires is taken, so
    no crown grows through them (a rural line's cleared way; street trees stand under suburban wires)."""
    piece = network.main
    side = 1 if rng.random() < 0.5 else -1
    spacing = float(rng.uniform(*UTILITY_POLE_SPACING_M))
    height = float(rng.uniform(*UTILITY_WIRE_HEIGHT_M))
    n_wires = int(rng.integers(UTILITY_WIRES[0], UTILITY_WIRES[1] + 1))
    beyond = float(rng.uniform(*setback))
    t_row = side * (corridor_half_width(piece) + beyond)
    s0 = max(0.0, inputs.start_s - UTILITY_SEEN_M[0])
    s1 = min(piece.line.length, inputs.end_s + UTILITY_SEEN_M[1])
    # A straight span is a chord: on a bend it must not reach in over the corridor (sagitta span^2 / 8R).
    bend = float(np.abs(piece.line.curvature).max())
    spacing = min(spacing, float(np.sqrt(8.0 * (beyond - CLEAR_MARGIN_M) / max(bend, 1e-9))))
    if s1 - s0 < spacing:
        return []
    gaps = list(piece.gaps)
    standing = []
    for s in pole_stations(s0, s1, spacing):
        spot = Spot(0, float(s), t_row, 0.0, UTILITY_POLE_HALF_M, UTILITY_POLE_HALF_M)
        if try_place(clear, piece, spot):
            standing.append(spot.T_world_local[:3, 3])
        else:
            gaps.append((float(s) - 0.5, float(s) + 0.5, side))
    if len(standing) < 2:
        return []
    across = np.array([-UTILITY_CLEAR_M, UTILITY_CLEAR_M])
    for a, b in zip(standing[:-1], standing[1:]) if clear_under else ():  # the strip under each span
        normal = np.array([a[1] - b[1], b[0] - a[0]]) / max(float(np.linalg.norm(b[:2] - a[:2])), 1e-9)
        clear.take(np.array([a[:2] + across[0] * normal, b[:2] + across[0] * normal, b[:2] + across[1] * normal,
                             a[:2] + across[1] * normal]))
    return [power_lines(piece.line, s0, s1, (t_row,), n_wires, 0.02, height, pole_spacing=spacing,
                        wire_spacing=UTILITY_WIRE_SPACING_M, sag=UTILITY_SAG_PER_M * spacing,
                        ground=ground_height(piece, t_row), gaps=gaps, insulators=True,
                        segment_m=UTILITY_WIRE_SEGMENT_M, name="utility lines")]


def _urban(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator, clear: Clearance) -> list[Mesh]:
    density, night = inputs.density, inputs.night

    def block(r: np.random.Generator) -> tuple[float, float, Callable[[], Mesh]]:
        width, depth = float(r.uniform(12.0, 28.0)), float(r.uniform(10.0, 18.0))
        height = float(r.choice([9.6, 12.8, 16.0, 19.2, 25.6]))
        shop = bool(r.random() < 0.5)
        return width, depth, lambda: buildings.building(r, width, depth, height, shopfront=shop, lit=night)

    meshes = streetlights(network, clear, STREETLIGHT_SPACING_M, emissive=night)
    if density > 0:  # a few street trees first, parked cars between them; the blocks fill the frontage behind
        meshes += greenery(inputs, network, clear, rng, 45.0 / np.sqrt(density), (0.2, 1.0), bush_share=0.0,
                           conifer_share=0.1)
        meshes += parked_cars(inputs, network, clear, own_rng(rng))
        meshes += rows_of(network, clear, rng, block, (0.5 + PARKING_ROW_M, 2.5 + PARKING_ROW_M),
                          (1.0 / density, 10.0 / density), "building")
        meshes += street_furniture(network, clear, own_rng(rng))
    meshes += traffic_signals(inputs, network, clear, own_rng(rng))
    return meshes + passers_by(inputs, network, clear, own_rng(rng))


def _suburban(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator, clear: Clearance) -> list[Mesh]:
    density, night = inputs.density, inputs.night
    if density <= 0:
        return []

    def home(r: np.random.Generator) -> tuple[float, float, Callable[[], Mesh]]:
        width, depth = float(r.uniform(8.0, 14.0)), float(r.uniform(7.0, 10.0))
        return width, depth, lambda: buildings.house(r, width, depth, lit=night)

    meshes = streetlights(network, clear, STREETLIGHT_SPACING_M, emissive=night)
    meshes += parked_cars(inputs, network, clear, own_rng(rng))  # on the verge; the trees and houses around them
    meshes += utility_lines(inputs, network, clear, own_rng(rng), (PARKING_ROW_M + 0.8, PARKING_ROW_M + 1.8),
                            clear_under=False)
    meshes += greenery(inputs, network, clear, rng, 14.0 / density, (0.5, 3.0), bush_share=0.4)
    meshes += rows_of(network, clear, rng, home, (5.0, 10.0), (6.0 / density, 16.0 / density), "house")
    meshes += street_furniture(network, clear, own_rng(rng))
    meshes += traffic_signals(inputs, network, clear, own_rng(rng))
    return meshes + passers_by(inputs, network, clear, own_rng(rng))


def _highway(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator, clear: Clearance) -> list[Mesh]:
    meshes = barriers(network, clear)
    if inputs.density > 0:
        meshes += greenery(inputs, network, clear, rng, 22.0 / inputs.density, (6.0, 35.0), bush_share=0.35,
                           conifer_share=0.5)
    return meshes


def _rural(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator, clear: Clearance) -> list[Mesh]:
    density, night = inputs.density, inputs.night
    if density <= 0:
        return []

    def farm(r: np.random.Generator) -> tuple[float, float, Callable[[], Mesh]]:
        width, depth = float(r.uniform(9.0, 16.0)), float(r.uniform(7.0, 11.0))
        return width, depth, lambda: buildings.house(r, width, depth, storeys=1, lit=night, name="farmhouse")

    meshes = utility_lines(inputs, network, clear, own_rng(rng), (1.0, 2.5), clear_under=True)
    meshes += greenery(inputs, network, clear, rng, 10.0 / density, (1.0, 30.0), bush_share=0.45)
    meshes += rows_of(network, clear, rng, farm, (25.0, 45.0), (90.0 / density, 200.0 / density), "farmhouse")
    return meshes


def _tunnel_approach(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator,
                     clear: Clearance) -> list[Mesh]:
    from .backdrop import wooded_ridge  # the backdrop builds on this module (its clearance): imported when used

    meshes, s_portal = tunnel(inputs, network, rng)
    clear.closed_s.append((s_portal - 11.0, network.main.line.length))  # the hill claims the ground
    if inputs.density > 0:
        meshes += greenery(inputs, network, clear, rng, 12.0 / inputs.density, (0.5, 20.0), bush_share=0.5,
                           conifer_share=0.6)
    return meshes + wooded_ridge(network, s_portal, TUNNEL_HILL.crest, corridor_half_width(network.main) + 0.6,
                                 TUNNEL_HILL.width, own_rng(rng))


SCENES: dict[str, Callable[[RoadsideInputs, RoadNetwork, np.random.Generator, Clearance], list[Mesh]]] = {
    "urban": _urban,
    "suburban": _suburban,
    "highway": _highway,
    "rural": _rural,
    "tunnel_approach": _tunnel_approach,
}


def roadside_meshes(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator) -> list[Mesh]:
    """World-frame meshes of everything beside the road for the scene kind and density of ``inputs``, and the
    backdrop beyond it (``backdrop.py``: hills, tree lines, hedgerows, roofs behind roofs), drawn after it."""
    from .backdrop import backdrop_meshes  # the backdrop builds on this module (its clearance): imported when used

    clear = Clearance(network)
    meshes = SCENES[inputs.kind](inputs, network, rng, clear)
    return meshes + backdrop_meshes(inputs, network, clear, own_rng(rng))
