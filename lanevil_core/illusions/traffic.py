"""Traffic obstruction: pedestrians, vehicles and bicycles standing on the road and hiding the lane lines.

Participants are static meshes on the main road. The first stands ``distance`` m ahead of the ego's start, the
rest follow in groups spread over the drive so later frames still see some. The ego's own path (its lane
centre +- ``EGO_CLEAR_M`` from its start to past its last position) stays free, so nothing is driven through;
participants crowd the lines beside it and the lanes next to it instead. Severity raises the number of
participants, brings the first one closer and puts more of them on the lane lines.

The ``vehicle`` type's ``mesh_file`` puts a user's glTF/GLB/OBJ model in place of the procedural bodies. It is a
file NAME, never a path (``world.user_meshes``); ``compile_scene`` reads it from the meshes folder it is given (a
case file's ``meshes/`` folder for the library and CLI, the server's ``<data dir>/uploads/``) into
``CompileContext.user_meshes``, so this module reads no files.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, StrictBool, StrictFloat, StrictInt, field_validator

from ..world import people, vehicles
from ..world.primitives import pose_on_road, rotation_z, transformed
from ..world.scene import Mesh
from ..world.user_meshes import (  # noqa: F401  # the user-mesh names as this module has always offered them
    MAX_OBSTACLE_FACES,
    MESH_NAME,
    MESH_NAME_RULE,
    MESH_SUFFIXES,
    is_mesh_name,
    load_obstacle,
    mesh_path,
    srgb_to_linear,
)
from .base import BEYOND_DRIVE_M, RGB, Category, CompileContext, EgoDrive, Illusion, Level, MeshFileError, register

EGO_CLEAR_M = 1.3  # half width of the ego's free path about its lane centre
EGO_CLEAR_AHEAD_M = 12.0  # the free path runs this far past the ego's last position
ROAD_END_MARGIN_M = 10.0
NUDGES = (0.0, 1.0, -1.0, 2.0, -2.0)  # along-road moves, in footprint lengths, tried against crowding
GROUP_DEPTH_M = 5.0  # members of a group stand up to this far beyond its station


# Footprint and height (length, width, height) of each procedural vehicle (m).
VEHICLE_SIZE: dict[str, tuple[float, float, float]] = {"car": (4.5, 1.8, 1.45), "van": (5.2, 2.0, 2.3),
                                                       "truck": (8.0, 2.5, 3.4)}
VEHICLE_COLORS = ((0.45, 0.03, 0.03), (0.6, 0.6, 0.6), (0.03, 0.03, 0.035), (0.05, 0.12, 0.4),
                  (0.3, 0.3, 0.32), (0.7, 0.55, 0.05), (0.02, 0.15, 0.06), (0.75, 0.75, 0.72))


@dataclass(frozen=True)
class Slot:
    """Where one participant stands on the main road: road frame (s, t), yaw from the road heading (rad)."""

    s: float
    t: float
    yaw: float


class Footprints:
    """The ego's free path and the ground participants took so far, in the main road's (s, t) frame."""

    def __init__(self, drive: EgoDrive, t_ego: float) -> None:
        self.path_s = (drive.start_s - 3.0, drive.end_s + EGO_CLEAR_AHEAD_M)
        self.t_ego = t_ego
        self.taken: list[tuple[float, float, float, float]] = []  # s, t, half extents along s and t

    @staticmethod
    def extents(yaw: float, half_x: float, half_y: float) -> tuple[float, float]:
        """Half extents along s and t of a footprint turned by ``yaw``."""
        c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
        return c * half_x + s * half_y, s * half_x + c * half_y

    def on_path(self, slot: Slot, ext_s: float, ext_t: float) -> bool:
        s0, s1 = self.path_s
        return slot.s + ext_s > s0 and slot.s - ext_s < s1 and abs(slot.t - self.t_ego) < EGO_CLEAR_M + ext_t

    def off_path(self, slot: Slot, ext_t: float) -> Slot:
        """The slot moved sideways, away from the ego's lane centre, just far enough to clear its path."""
        side = 1.0 if slot.t >= self.t_ego else -1.0
        return Slot(slot.s, self.t_ego + side * (EGO_CLEAR_M + ext_t + 0.05), slot.yaw)

    def place(self, slot: Slot, half_x: float, half_y: float, reach: float) -> Slot | None:
        """Claim ground for a footprint at ``slot`` (moved off the ego's path if needed, inwards when it sticks
        out past the paved edge |t| = ``reach``, and along the road by up to ``NUDGES`` when another participant
        stands there), or None if its centre lies off the paved road or it finds no free ground."""
        ext_s, ext_t = self.extents(slot.yaw, half_x, half_y)
        if self.on_path(slot, ext_s, ext_t):
            slot = self.off_path(slot, ext_t)
        if abs(slot.t) > reach or ext_t > reach:
            return None
        if abs(slot.t) + ext_t > reach:  # e.g. someone on the edge line beside a kerb: just inside the edge
            slot = Slot(slot.s, math.copysign(reach - ext_t, slot.t), slot.yaw)
            if self.on_path(slot, ext_s, ext_t):
                return None
        for nudge in NUDGES:
            moved = Slot(slot.s + nudge * (ext_s + 0.3), slot.t, slot.yaw)
            if self.on_path(moved, ext_s, ext_t):
                continue
            if all(abs(moved.s - s) >= ext_s + es + 0.1 or abs(moved.t - t) >= ext_t + et + 0.1
                   for s, t, es, et in self.taken):
                self.taken.append((moved.s, moved.t, ext_s, ext_t))
                return moved
        return None


@dataclass(frozen=True)
class TrafficLevel(Level):
    """What every traffic level sets: how many participants, and how far ahead of the ego start the first stands
    (m)."""

    count: int
    distance: float


class TrafficIllusion(Illusion):
    """Fields and placement shared by the traffic illusions (not registered itself)."""

    CATEGORY: ClassVar[Category] = "traffic"

    count: StrictInt | None = Field(None, ge=1, le=100, description="number of participants; empty = severity table")
    distance: StrictFloat | None = Field(
        None, ge=3, le=300, description="distance of the first one ahead of the ego start (m); empty = severity table"
    )
    spacing: StrictFloat | None = Field(
        None, gt=0, le=200,
        description="distance between successive groups along the road (m); empty = spread over the drive",
    )

    SEVERITY: ClassVar[tuple[TrafficLevel, ...]]

    def level(self) -> TrafficLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def participants(self) -> int:
        return int(self.level().count if self.count is None else self.count)

    def first_s(self, drive: EgoDrive) -> float:
        """Where the first group stands: ``s`` if given, else ``distance`` (or the table's) ahead of the start."""
        if self.s is not None:
            return self.s
        return drive.start_s + float(self.level().distance if self.distance is None else self.distance)

    def group_stations(self, ctx: CompileContext, groups: int) -> list[float]:
        """s of every group: from the first, ``spacing`` apart, or spread evenly up to ``BEYOND_DRIVE_M`` past
        the ego's last position."""
        drive, length = ctx.drive, ctx.network.main.line.length
        first = self.first_s(drive)
        if self.spacing is not None:
            step = self.spacing
        else:
            reach = drive.end_s + BEYOND_DRIVE_M
            step = max((reach - first) / max(groups - 1, 1), 8.0)
        stations = [first + k * step for k in range(groups)]
        return [s for s in stations if s < length - ROAD_END_MARGIN_M]

    def crowd_slots(self, ctx: CompileContext, rng: np.random.Generator, group: int, on_lines: float,
                    yaw_of: Callable[[np.random.Generator, float], float], total: int) -> list[Slot]:
        """Slots for ``total`` people or bikes in groups of ``group`` across the road: a share ``on_lines``
        straddle lane lines (the ego lane's own first), the rest stand in the lanes beside it."""
        stations = self.group_stations(ctx, math.ceil(total / group))
        lines, centres = line_order(ctx), lane_centres(ctx)
        slots = []
        for g, station in enumerate(stations):
            members = range(g * group, min((g + 1) * group, total))
            lined = [i for i in members if on_line(i, on_lines)]
            for k, index in enumerate(members):
                s = station + (rng.uniform(0.0, GROUP_DEPTH_M) if k else 0.0)
                if index in lined:
                    t = lines[(lined.index(index) + g) % len(lines)]
                else:
                    t = centres[(k - len(lined) + g) % len(centres)] + rng.uniform(-0.5, 0.5)
                slots.append(Slot(s, t, yaw_of(rng, t)))
        return slots

    def nested_crowd(self, ctx: CompileContext, rng: np.random.Generator,
                     yaw_of: Callable[[np.random.Generator, float], float]) -> list[Slot]:
        """The first ``participants()`` slots of the most severe level's crowd: every level is the same crowd
        thinned out, so a higher level only adds people (level 1 is a mild version of level 5)."""
        full = self.SEVERITY[-1]
        if not isinstance(full, CrowdLevel):
            raise TypeError(f"{type(self).__name__}'s table has no crowd (group, on_lines)")
        # group and on_lines are fields of the crowd types (Pedestrian, Bicycle) that call this
        group = self.group or int(full.group)  # type: ignore[attr-defined]
        share = float(full.on_lines if self.on_lines is None else self.on_lines)  # type: ignore[attr-defined]
        count = self.participants()
        slots = self.crowd_slots(ctx, rng, group, share, yaw_of, max(count, int(full.count)))
        # Take the groups' members in turn (the first of every group, then the second ...), so a thin crowd
        # still has people all along the drive.
        order = sorted(range(len(slots)), key=lambda i: (i % group, i // group))
        return [slots[i] for i in order[:count]]

    def add_crowd(self, ctx: CompileContext, slots: list[Slot], make: Callable[[int], Mesh],
                  follow_grade: bool = True) -> None:
        """Build participant ``index`` with ``make`` for every slot and put it there, squeezed off the ego's path
        and inside the paved road (slots with no room are skipped)."""
        free = Footprints(ctx.drive, ctx.network.lane_center_t(ctx.drive.lane))
        for index, slot in enumerate(slots):
            mesh = make(index)
            placed = free.place(slot, *half_extents(mesh), ctx.network.main.paved_reach)
            if placed is not None:
                self.add(ctx, mesh, placed, index, follow_grade=follow_grade)

    def add(self, ctx: CompileContext, mesh: Mesh, slot: Slot, index: int, follow_grade: bool = True) -> None:
        """Put a local-frame participant at ``slot``, pitched with the road's grade (wheels on the slope)
        unless it stands upright (people)."""
        line = ctx.network.main.line
        T_world_local = pose_on_road(line, slot.s, slot.t, slot.yaw)
        if follow_grade:
            pitch = math.atan(float(line.grade_at(slot.s)) * math.cos(slot.yaw))
            c, s = math.cos(pitch), math.sin(pitch)
            T_world_local = T_world_local @ np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1.0]])
        placed = transformed(mesh, T_world_local)
        placed.name = f"{self.type} {index + 1}"
        placed.heading = float(line.heading_at(slot.s)) + slot.yaw
        ctx.add_mesh(placed)


def half_extents(mesh: Mesh) -> tuple[float, float]:
    """Half extents (m) along local X and Y of a local-frame mesh's footprint about its origin."""
    reach = np.abs(mesh.vertices[:, :2]).max(0)
    return float(reach[0]), float(reach[1])


def line_order(ctx: CompileContext) -> list[float]:
    """t of the main road's lane lines nearest the ego's lane centre first (the ego lane's own lines lead)."""
    t_ego = ctx.network.lane_center_t(ctx.drive.lane)
    boundaries = [float(t) for t in ctx.network.main.boundaries_t]
    return sorted(boundaries, key=lambda t: (abs(t - t_ego), t))


def lane_centres(ctx: CompileContext) -> list[float]:
    """t of every lane centre of both directions, nearest the ego's lane first (the ego lane itself last)."""
    t_ego = ctx.network.lane_center_t(ctx.drive.lane)
    b = ctx.network.main.boundaries_t
    centres = [float(t) for t in 0.5 * (b[:-1] + b[1:]) if abs(t - t_ego) > 1e-6]
    return sorted(centres, key=lambda t: (abs(t - t_ego), t)) + [t_ego]


def on_line(index: int, share: float) -> bool:
    """Whether participant ``index`` stands on a line when ``share`` of them do (the first one does first)."""
    return math.ceil((index + 1) * share - 1e-9) > math.ceil(index * share - 1e-9)


@dataclass(frozen=True)
class CrowdLevel(TrafficLevel):
    """What one severity level of a crowd (``Pedestrian``, ``Bicycle``) sets."""

    group: int
    on_lines: float


@register
class Pedestrian(TrafficIllusion):
    """People crossing or standing on the road, on the lane lines and in the lanes beside the ego's."""

    # count: people; group: people per crossing group; distance: first group ahead of the ego start (m);
    # on_lines: share of the people standing on a lane line. Every level is the first ``count`` people of the same
    # crowd (groups of 11 from 14 m ahead, spread over the whole drive, 80 % on the lines), so a level only adds
    # people, and every frame of the drive has a group ahead of it. Level 5 is a busy street: seven crossing
    # crowds over both of the ego's lane lines and the lines beyond, the next always within about 20 m.
    SEVERITY: ClassVar[tuple[CrowdLevel, ...]] = (
        CrowdLevel(count=4, group=11, distance=14.0, on_lines=0.8),  # a few people on the ego's lines
        CrowdLevel(count=11, group=11, distance=14.0, on_lines=0.8),  # one or two in every group
        CrowdLevel(count=22, group=11, distance=14.0, on_lines=0.8),  # small groups across the lanes
        CrowdLevel(count=44, group=11, distance=14.0, on_lines=0.8),  # crossing crowds all along the drive
        CrowdLevel(count=77, group=11, distance=14.0, on_lines=0.8),  # crowds over every line, all along
    )
    type: Literal["pedestrian"] = "pedestrian"
    motion: Literal["crossing", "standing"] = Field("crossing", description="walking across the road or standing")
    group: StrictInt | None = Field(None, ge=1, le=12, description="people per group; empty = the level-5 crowd's")
    on_lines: StrictFloat | None = Field(
        None, ge=0, le=1, description="share of people standing on a lane line; empty = severity table"
    )
    shirt_colors: list[RGB] | None = Field(None, description="shirt colours (linear RGB), cycled; empty = random")
    height: StrictFloat = Field(1.75, ge=1.0, le=2.1, description="body height (m), varied by +-6 %")

    def level(self) -> CrowdLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        rng = ctx.rng(self.seed)
        crossing = self.motion == "crossing"

        def yaw_of(r: np.random.Generator, t: float) -> float:
            if crossing:
                return float(np.pi / 2 if r.random() < 0.5 else -np.pi / 2)
            return float(np.pi + r.uniform(-0.6, 0.6))

        def person(index: int) -> Mesh:
            shirt = None if not self.shirt_colors else self.shirt_colors[index % len(self.shirt_colors)]
            height = self.height * float(rng.uniform(0.94, 1.06))
            return people.pedestrian(rng, shirt=shirt, height=height, walking=crossing)

        self.add_crowd(ctx, self.nested_crowd(ctx, rng, yaw_of), person, follow_grade=False)


@register
class Bicycle(TrafficIllusion):
    """Cyclists riding along the lane lines (or crossing the road) beside the ego's path."""

    # count: cyclists; group: cyclists side by side; distance: first group ahead of the ego start (m);
    # on_lines: share of cyclists riding on a lane line. Every level is the first ``count`` riders of the same
    # club ride (groups of 10 from 14 m ahead, spread over the whole drive, 80 % on the lines), so a level only
    # adds riders, and every frame of the drive has riders ahead of it. Level 5 is the whole ride: seven groups
    # over the road, most of it on the lane lines, the next always within about 20 m.
    SEVERITY: ClassVar[tuple[CrowdLevel, ...]] = (
        CrowdLevel(count=4, group=10, distance=14.0, on_lines=0.8),  # a few riders on the ego's lines
        CrowdLevel(count=10, group=10, distance=14.0, on_lines=0.8),  # one or two in every group
        CrowdLevel(count=20, group=10, distance=14.0, on_lines=0.8),  # small bunches across the lanes
        CrowdLevel(count=40, group=10, distance=14.0, on_lines=0.8),  # bunches all along the drive
        CrowdLevel(count=70, group=10, distance=14.0, on_lines=0.8),  # the club ride over every line, all along
    )
    type: Literal["bicycle"] = "bicycle"
    motion: Literal["riding", "crossing"] = Field("riding", description="riding along the road or crossing it")
    group: StrictInt | None = Field(None, ge=1, le=12, description="cyclists per group; empty = the level-5 crowd's")
    on_lines: StrictFloat | None = Field(
        None, ge=0, le=1, description="share of cyclists on a lane line; empty = severity table"
    )
    frame_colors: list[RGB] | None = Field(None, description="bicycle frame colours (linear RGB), cycled")

    def level(self) -> CrowdLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        rng = ctx.rng(self.seed)
        riding = self.motion == "riding"

        def yaw_of(r: np.random.Generator, t: float) -> float:
            if riding:  # keep to the road's right: those left of the centre line ride towards the ego
                return float(r.uniform(-0.05, 0.05) + (np.pi if t > 0 else 0.0))
            return float(np.pi / 2 if r.random() < 0.5 else -np.pi / 2)

        def cyclist(index: int) -> Mesh:
            color = None if not self.frame_colors else self.frame_colors[index % len(self.frame_colors)]
            return people.bicycle_with_rider(rng, frame_color=color)

        self.add_crowd(ctx, self.nested_crowd(ctx, rng, yaw_of), cyclist)


@dataclass(frozen=True)
class VehicleLevel(TrafficLevel):
    """What one severity level of ``Vehicle`` sets."""

    per_row: int
    large: float
    lane_change: float


@register
class Vehicle(TrafficIllusion):
    """Cars, vans and trucks standing in the lanes beside the ego's, some changing lanes across a line, and in
    the ego's lane beyond the end of its drive."""

    # count: vehicles; per_row: vehicles side by side in different lanes; distance: first row ahead of the ego
    # start (m); large: share of vans and trucks (mixed kind); lane_change: share straddling a lane line.
    # The first row stands at the same place at every level; the level adds rows, vehicles side by side, large
    # vehicles and lane changes, so more of the lines ahead are hidden.
    SEVERITY: ClassVar[tuple[VehicleLevel, ...]] = (
        VehicleLevel(count=1, per_row=1, distance=16.0, large=0.0, lane_change=0.0),  # one car beside the ego
        VehicleLevel(count=2, per_row=1, distance=16.0, large=0.2, lane_change=0.0),  # a second row, vans
        VehicleLevel(count=4, per_row=2, distance=16.0, large=0.3, lane_change=0.2),  # pairs side by side
        VehicleLevel(count=8, per_row=2, distance=16.0, large=0.4, lane_change=0.3),  # a queue with vans
        VehicleLevel(count=15, per_row=3, distance=16.0, large=0.6, lane_change=0.4),  # dense traffic, trucks
    )
    # Lanes relative to the ego's (+1 = next lane to its right, -1 = to its left), tried in this order.
    LANE_ORDER: ClassVar[tuple[int, ...]] = (1, -1, -2, 2, -3, 3, 0, -4, 4, -5, 5, -6, 6, -7, 7)

    type: Literal["vehicle"] = "vehicle"
    kind: Literal["mixed", "car", "van", "truck"] = Field("mixed", description="vehicle type; mixed = by severity")
    per_row: StrictInt | None = Field(None, ge=1, le=8, description="vehicles side by side; empty = severity table")
    lane_change: StrictFloat | None = Field(
        None, ge=0, le=1, description="share of vehicles straddling a lane line; empty = severity table"
    )
    colors: list[RGB] | None = Field(None, description="body colours (linear RGB), cycled; empty = random")
    lights_on: StrictBool = Field(False, description="headlights and tail lights glow")
    mesh_file: str | None = Field(
        None, description="glTF/GLB/OBJ model used instead of the procedural bodies, scaled to the vehicle size: "
        "a file name in the uploads folder (`POST /api/meshes`; a case file's `meshes/` folder on the command line)",
        json_schema_extra={"pattern": MESH_NAME.pattern},
    )

    @field_validator("mesh_file")
    @classmethod
    def _mesh_file_is_a_name(cls, value: str | None) -> str | None:
        if value is not None and not is_mesh_name(value):
            raise ValueError(MESH_NAME_RULE)
        return value

    def level(self) -> VehicleLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def load_mesh(self, ctx: CompileContext) -> Mesh:
        """The ``mesh_file`` model as ``compile_scene`` read it (``ctx.user_meshes``); ``MeshFileError`` naming the
        field when it was not read."""
        mesh = ctx.user_meshes.get(ctx.source)
        if mesh is None:
            raise MeshFileError(f"illusions.{ctx.source}.{self.type}.mesh_file",
                                f"{self.mesh_file!r} was not read (compile_scene reads a case's meshes)")
        return mesh

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        rng = ctx.rng(self.seed)
        per_row = self.per_row or int(level.per_row)
        lane_change = float(level.lane_change if self.lane_change is None else self.lane_change)
        total = self.participants()
        stations = self.group_stations(ctx, math.ceil(total / per_row))
        free = Footprints(ctx.drive, ctx.network.lane_center_t(ctx.drive.lane))
        loaded = self.load_mesh(ctx) if self.mesh_file else None
        index = 0
        for row, s in enumerate(stations):
            for lane_t in self._row_lanes(ctx, s, per_row, row):
                if index >= total:
                    return
                kind = self._kind(rng, float(level.large))
                length, width, height = VEHICLE_SIZE[kind]
                s_vehicle, reach = s + rng.uniform(-2.0, 2.0), ctx.network.main.paved_reach
                changing = on_line(index, lane_change)
                placed = free.place(self._slot(ctx, rng, s_vehicle, lane_t, changing), length / 2, width / 2, reach)
                if placed is None and changing:  # no room to change lanes: keep to the lane
                    placed = free.place(self._slot(ctx, rng, s_vehicle, lane_t, False), length / 2, width / 2, reach)
                if placed is not None:
                    self.add(ctx, self._body(rng, kind, index, loaded), placed, index)
                index += 1

    def _row_lanes(self, ctx: CompileContext, s: float, per_row: int, row: int) -> list[float]:
        """Lane centres (t) of one row: lanes beside the ego's, the ego's own only past its free path."""
        network, drive = ctx.network, ctx.drive
        n = network.lanes_per_direction
        ego_index = n + drive.lane  # lanes numbered left to right over both directions
        free_beyond = drive.end_s + EGO_CLEAR_AHEAD_M + VEHICLE_SIZE["truck"][0]
        lanes = []
        for offset in self.LANE_ORDER:
            j = ego_index + offset
            if 0 <= j < 2 * n and (offset != 0 or s > free_beyond):
                lanes.append(float((n - j - 0.5) * network.lane_width))
        shift = row % max(len(lanes), 1)
        return (lanes[shift:] + lanes[:shift])[:per_row]

    def _slot(self, ctx: CompileContext, rng: np.random.Generator, s: float, lane_t: float, changing: bool) -> Slot:
        """A vehicle in the lane at ``lane_t``, facing its direction of travel, or straddling the line it is
        changing over (never one of the ego lane's lines or a road edge)."""
        yaw = 0.0 if lane_t < 0 else np.pi
        t = lane_t + rng.uniform(-0.25, 0.25)
        if changing:
            t_ego = ctx.network.lane_center_t(ctx.drive.lane)
            inner = [float(b) for b in ctx.network.main.boundaries_t[1:-1]
                     if abs(abs(b - lane_t) - ctx.network.lane_width / 2) < 1e-6
                     and abs(abs(b - t_ego) - ctx.network.lane_width / 2) > 1e-6]
            if inner:
                line = inner[int(rng.integers(len(inner)))]
                t = line + 0.15 * (lane_t - line)
                steer = 0.12 if (line > lane_t) == (yaw == 0.0) else -0.12
                yaw += steer
        return Slot(s, t, float(yaw))

    def _kind(self, rng: np.random.Generator, large: float) -> str:
        if self.kind != "mixed":
            return self.kind
        u = rng.random()
        return "truck" if u < large / 2 else "van" if u < large else "car"

    def _body(self, rng: np.random.Generator, kind: str, index: int, loaded: Mesh | None) -> Mesh:
        length, width, height = VEHICLE_SIZE[kind]
        if loaded is not None:
            return scaled_to(loaded, (length, width, height))
        palette = self.colors or VEHICLE_COLORS
        color = palette[index % len(palette)] if self.colors else palette[int(rng.integers(len(palette)))]
        if kind == "truck":
            return vehicles.truck(color, lights_on=self.lights_on)
        if kind == "van":
            return vehicles.van(color, lights_on=self.lights_on)
        return vehicles.car(color, lights_on=self.lights_on)


def scaled_to(mesh: Mesh, size: tuple[float, float, float]) -> Mesh:
    """A copy of a local-frame mesh scaled uniformly to fit inside ``size`` (length, width, height) (m)."""
    extent = np.maximum(mesh.vertices.max(0) - mesh.vertices.min(0), 1e-9)
    k = float(np.min(np.asarray(size) / extent))
    T = rotation_z(0.0)
    T[:3, :3] *= k
    return transformed(mesh, T)
