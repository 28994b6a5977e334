"""Shadow illusions: structures beside and above the road whose sun shadows fall across the lanes.

Each illusion builds real meshes (``structures``) and sets the sun; the shadows themselves come only from the
renderer's sun shadow map. Severity lowers the sun (longer shadows), raises its intensity and narrows the
penumbra (harder, darker edges) and makes the structure denser or bigger; the fence keeps one sun at every level
and grows the fence only.

The sun's default azimuth is chosen from the road heading at the illusion: the sun stands on the structure's side,
``sun_ahead`` degrees from square-on towards the ego's direction of travel, so shadows reach across the lanes and
back towards the camera.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, ClassVar, Literal

import numpy as np
from pydantic import Field, StrictFloat

from ..world.environment import sun_direction
from ..world.primitives import pose_on_road, transformed
from ..world.structures import (
    SlotDirection,
    clear_runs,
    fence,
    ground_height,
    outside_gaps,
    overhead_rail,
    power_lines,
    streetlight,
)
from .base import Category, CompileContext, EgoDrive, Illusion, Level, register

if TYPE_CHECKING:
    from ..world.road_geometry import ReferenceLine
    from ..world.road_layout import RoadPiece

Side = Literal["left", "right"]
Albedo = Annotated[float, Field(ge=0.0, le=1.0)]
STRUCTURES_BEYOND_DRIVE_M = 40.0  # structures reach this far past the ego's last position (the shadow types'
# own reach; base.BEYOND_DRIVE_M is that of crowds and road damage)
ROAD_END_MARGIN_M = 5.0
MAX_AHEAD_DEG = 75.0  # the sun never stands further ahead than this when its azimuth is solved for
# props already standing beside the road that our posts must not hit
UPRIGHT_KINDS = ("streetlight", "pole", "street_furniture")
UPRIGHT_CLEARANCE_M = 1.5
MIN_FENCE_SUN_DEG = 10.0  # the fence shadow's solved sun sinks no lower than this
FENCE_EDGE_LANES = 0.5  # the level-5 fence's shadow ends this many ego lane widths past the lane's near line


@dataclass(frozen=True)
class ShadowLevel(Level):
    """What every shadow level sets: the sun (degrees above the horizon, luminance) and the shadow's softness."""

    sun_altitude: float
    sun_intensity: float
    penumbra: float  # metres of blur at 1 m from the occluder


@dataclass(frozen=True)
class SunAheadLevel(ShadowLevel):
    """A shadow level whose sun bearing comes from the table: ``sun_ahead`` degrees from square-on to the road
    towards the direction of travel."""

    sun_ahead: float


class SunShadowIllusion(Illusion):
    """Fields and sun handling shared by the shadow illusions (not registered itself)."""

    CATEGORY: ClassVar[Category] = "shadow"
    SETS_SUN: ClassVar[bool] = True

    sun_altitude: StrictFloat | None = Field(
        None, ge=2, le=89, description="sun altitude (degrees); empty = from the severity table"
    )
    sun_azimuth: StrictFloat | None = Field(
        None, ge=-360, le=360,
        description="sun azimuth (degrees, CCW from world +X); empty = chosen from the road heading so shadows "
        "fall across the lanes",
    )
    sun_intensity: StrictFloat | None = Field(
        None, ge=0, le=3, description="direct sun luminance (1 = clear noon); empty = from the severity table"
    )

    SEVERITY: ClassVar[tuple[ShadowLevel, ...]]

    def level(self) -> ShadowLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def altitude(self) -> float:
        """Sun altitude (degrees): the override or the table's."""
        return float(self.level().sun_altitude if self.sun_altitude is None else self.sun_altitude)

    def apply_sun(self, ctx: CompileContext, s_road: float, side_sign: float, ahead: float | None = None,
                  altitude: float | None = None) -> None:
        """Set the environment's sun from the table row or the overrides.

        ``side_sign`` is +1 when the shadow-casting structure stands left of the road, -1 when right; ``ahead``
        (degrees from square-on towards the direction of travel) defaults to the table's ``sun_ahead``,
        ``altitude`` to ``altitude()``.
        """
        level = self.level()
        altitude = self.altitude() if altitude is None else altitude
        azimuth = self.sun_azimuth
        if azimuth is None:
            heading_deg = float(np.degrees(ctx.network.main.line.heading_at(s_road)))
            if ahead is None:
                if not isinstance(level, SunAheadLevel):
                    raise TypeError(f"{type(self).__name__}'s table has no sun_ahead: pass ahead")
                ahead = level.sun_ahead
            azimuth = heading_deg + side_sign * (90.0 - ahead)
        ctx.env.sun_dir_world = sun_direction(azimuth, altitude)
        ctx.env.sun_intensity = float(level.sun_intensity if self.sun_intensity is None else self.sun_intensity)
        ctx.env.penumbra = float(level.penumbra)

    def extent(self, drive: EgoDrive, length: float | None) -> tuple[float, float]:
        """(s0, s1) along the main road: from ``start_s`` over ``length``, or to past the end of the drive."""
        s0 = self.start_s(drive)
        s1 = s0 + length if length is not None else drive.end_s + STRUCTURES_BEYOND_DRIVE_M
        s1 = min(s1, drive.road_length - ROAD_END_MARGIN_M)
        return s0, max(s1, s0 + 1.0)


def side_sign(side: Side) -> float:
    """+1 for the left of the road, -1 for the right."""
    return 1.0 if side == "left" else -1.0


def roadside_t(piece: RoadPiece, offset: float, sign: float) -> float:
    """t of a point ``offset`` metres beyond the paved edge (carriageway plus a shoulder paved like it)."""
    return sign * (piece.paved_reach + offset)


def blocked(ctx: CompileContext, piece: RoadPiece) -> list[tuple[float, float, int]]:
    """``piece.gaps`` plus a short gap around the foot of every lamp or pole already standing beside the piece."""
    gaps = list(piece.gaps)
    for mesh in ctx.meshes:
        if mesh.kind in UPRIGHT_KINDS:
            s_road, t_road, h_road = _road_frame(piece.line, mesh.vertices)
            feet = (h_road < -0.05) & (np.abs(t_road) < piece.half_width + 15.0)  # only footings dip below the road
            for s_foot, side in {(round(float(a), 1), 1 if b > 0 else -1) for a, b in zip(s_road[feet], t_road[feet])}:
                gaps.append((s_foot - UPRIGHT_CLEARANCE_M, s_foot + UPRIGHT_CLEARANCE_M, side))
    return gaps


def _road_frame(line: ReferenceLine, p_world: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n,) s, t, h of world points (n, 3): nearest 1 m sample of the line, refined along its tangent."""
    xy, s_samples = line.xy[::10], line.s[::10]
    s_near = s_samples[np.argmin(((p_world[:, None, :2] - xy[None]) ** 2).sum(-1), axis=1)]
    origin, tangent, _ = line.frame(s_near)
    flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
    s_road = s_near + ((p_world[:, :2] - origin[:, :2]) * flat).sum(1)
    origin, _, left = line.frame(s_road)
    return s_road, ((p_world - origin) * left).sum(1), p_world[:, 2] - origin[:, 2]


SUNWARD_KINDS = ("building",)  # roadside props tall enough to shade the whole road at a low sun
SUNWARD_SHADOW_M = 120.0  # how far ahead of a stretch a building's low-sun shadow can fall back onto it


def clear_sunward(ctx: CompileContext, piece: RoadPiece, s0: float, s1: float, sign: float) -> None:
    """Leave out the buildings on side ``sign`` of the road beside [s0, s1 + SUNWARD_SHADOW_M]: with the sun on
    that side and ahead, their shadows would fall back over the stretch."""
    def shades(mesh_vertices: np.ndarray) -> bool:
        s_road, t_road, _ = _road_frame(piece.line, mesh_vertices)
        return bool(np.sign(t_road.mean()) == sign and s_road.max() > s0 and s_road.min() < s1 + SUNWARD_SHADOW_M)

    ctx.meshes[:] = [mesh for mesh in ctx.meshes if mesh.kind not in SUNWARD_KINDS or not shades(mesh.vertices)]


@dataclass(frozen=True)
class StreetlightShadowLevel(SunAheadLevel):
    """What one severity level of ``StreetlightShadow`` sets."""

    spacing: float
    pole_height: float
    pole_radius: float
    arm: float


@register
class StreetlightShadow(SunShadowIllusion):
    """Rows of street lamps whose shadows, poles and arms, stripe the lanes."""

    # A low sun from the lamps' side and ahead (``sun_ahead`` from square-on), so each pole throws a long shadow
    # back along the road at a shallow angle (20 deg) to the lanes: neighbouring poles' shadows run parallel, a
    # lane-like spacing * tan(90 - sun_ahead) apart across the road (11 m to 4 m over the levels), dark lines that
    # cross the lanes and run along them. The sun sinks with the level (26 to 14 deg), the lamps grow taller and
    # closer, so the shadows grow longer (pole height / tan(altitude): 14 m to 44 m), reach over more lanes and
    # stripe more of the road. Buildings on the lamps' side along the stretch are left out (``clear_sunward``):
    # their own shadows at so low a sun would cover the road and swallow the poles'.
    SEVERITY: ClassVar[tuple[StreetlightShadowLevel, ...]] = (
        StreetlightShadowLevel(sun_altitude=26.0, sun_ahead=70.0, sun_intensity=1.1, penumbra=0.010, spacing=30.0,
                               pole_height=7.0, pole_radius=0.12, arm=1.2),  # sparse lamps, shadows into one lane
        StreetlightShadowLevel(sun_altitude=22.0, sun_ahead=70.0, sun_intensity=1.25, penumbra=0.008, spacing=22.0,
                               pole_height=8.0, pole_radius=0.15, arm=1.5),
        StreetlightShadowLevel(sun_altitude=19.0, sun_ahead=70.0, sun_intensity=1.35, penumbra=0.007, spacing=17.0,
                               pole_height=9.0, pole_radius=0.17, arm=1.8),
        StreetlightShadowLevel(sun_altitude=16.0, sun_ahead=70.0, sun_intensity=1.4, penumbra=0.006, spacing=14.0,
                               pole_height=10.0, pole_radius=0.18, arm=2.0),
        StreetlightShadowLevel(sun_altitude=14.0, sun_ahead=70.0, sun_intensity=1.5, penumbra=0.005, spacing=11.0,
                               pole_height=11.0, pole_radius=0.20,
                               arm=2.2),  # tall dense lamps, long shadows: lane-like stripes over every lane
    )

    type: Literal["streetlight_shadow"] = "streetlight_shadow"
    side: Literal["left", "right", "both"] = Field("right", description="which roadside the lamps stand on")
    length: StrictFloat | None = Field(
        None, gt=0, le=2000, description="extent along the road (m); empty = to 40 m past the end of the drive"
    )
    offset: StrictFloat = Field(0.8, ge=0.3, le=20, description="lateral distance beyond the paved edge (m)")
    spacing: StrictFloat | None = Field(
        None, ge=10, le=100, description="distance between lamps (m); empty = from the table"
    )

    def level(self) -> StreetlightShadowLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        piece = ctx.network.main
        s0, s1 = self.extent(ctx.drive, self.length)
        spacing = self.spacing if self.spacing is not None else level.spacing
        signs = (-1.0, 1.0) if self.side == "both" else (side_sign(self.side),)
        self.apply_sun(ctx, s0, signs[0])
        clear_sunward(ctx, piece, s0, s1, signs[0])
        gaps = blocked(ctx, piece)
        for k, sign in enumerate(signs):
            s_poles = np.arange(s0 + 0.5 * spacing * k, s1, spacing)
            t_pole = roadside_t(piece, self.offset, sign)
            yaw = 0.0 if sign < 0 else np.pi  # the arm reaches over the road
            lamp = streetlight(level.pole_height, level.arm, pole_radius=level.pole_radius)
            for index, s_pole in enumerate(s_poles[outside_gaps(s_poles, t_pole, gaps)]):
                pose = pose_on_road(piece.line, float(s_pole), t_pole, yaw, ground_height(piece, t_pole))
                mesh = transformed(lamp, pose)
                mesh.name = f"streetlight {'left' if sign > 0 else 'right'} {index + 1}"
                ctx.add_mesh(mesh)


@dataclass(frozen=True)
class FenceShadowLevel(SunAheadLevel):
    """What one severity level of ``FenceShadow`` sets."""

    height: float
    board: float  # height of each horizontal board (m)
    gap: float  # gap between boards (m): a line of light on the road, parallel to the lanes


@register
class FenceShadow(SunShadowIllusion):
    """A board fence beside the road: its low-sun shadow shades the lanes, with lines of light along them."""

    # A board fence (horizontal boards with narrow gaps between them) under a low sun nearly square-on from its
    # side: the fence's shadow lies across the lanes and each gap lets through a line of light parallel to them, a
    # bright lane-like line in the shade where the real paint falls dark (a camera exposed for the sunlit road).
    # One sun at every level (bearing, hardness, and altitude solved from the road so that the shadow of the
    # level-5 fence ends in the middle of the ego lane: ``FENCE_EDGE_LANES``; the table's altitude is the highest
    # it may stand, ``MIN_FENCE_SUN_DEG`` the lowest); only the fence grows with the level, its boards laid from the
    # bottom, so each level's fence is the one before with more board on top and its shade holds the one before:
    # from beside the ego lane (level 1) into it, with more lines of light. (A sun hardening with the level
    # brightened the sunlit road back towards the original's and moved the roadside's shadows, and boards hung
    # from the top moved the lines of light on and off the edge line from level to level: the lane band's change
    # then fell at two steps on four originals.) A shadow edge in the lane, with lines of light in the shade, fools
    # the detectors more than a shade over the whole lane.
    SEVERITY: ClassVar[tuple[FenceShadowLevel, ...]] = (
        FenceShadowLevel(sun_altitude=50.0, sun_ahead=5.0, sun_intensity=1.5, penumbra=0.008, height=1.2,
                         board=0.95, gap=0.16),  # a low fence: its shadow beside the ego lane
        FenceShadowLevel(sun_altitude=50.0, sun_ahead=5.0, sun_intensity=1.5, penumbra=0.008, height=1.7,
                         board=0.95, gap=0.16),
        FenceShadowLevel(sun_altitude=50.0, sun_ahead=5.0, sun_intensity=1.5, penumbra=0.008, height=2.2,
                         board=0.95, gap=0.16),
        FenceShadowLevel(sun_altitude=50.0, sun_ahead=5.0, sun_intensity=1.5, penumbra=0.008, height=2.65,
                         board=0.95, gap=0.16),
        FenceShadowLevel(sun_altitude=50.0, sun_ahead=5.0, sun_intensity=1.5, penumbra=0.008, height=3.1,
                         board=0.95, gap=0.16),  # tall: shade to the ego lane's middle, lines of light in it
    )

    type: Literal["fence_shadow"] = "fence_shadow"
    side: Side = Field("right", description="which roadside the fence stands on")
    length: StrictFloat | None = Field(
        None, gt=0, le=2000, description="extent along the road (m); empty = to 40 m past the end of the drive"
    )
    offset: StrictFloat = Field(0.8, ge=0.3, le=20, description="lateral distance beyond the paved edge (m)")
    color: tuple[Albedo, Albedo, Albedo] = Field((0.13, 0.085, 0.05), description="linear albedo of the slats")

    def level(self) -> FenceShadowLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        piece = ctx.network.main
        sign = side_sign(self.side)
        s0, s1 = self.extent(ctx.drive, self.length)
        t_fence = roadside_t(piece, self.offset, sign)
        self.apply_sun(ctx, s0, sign, altitude=None if self.sun_altitude is not None else
                       self._solved_altitude(ctx, t_fence, sign))
        for index, (a, b) in enumerate(clear_runs(s0, s1, t_fence, blocked(ctx, piece))):
            ctx.add_mesh(fence(piece.line, a, b, t_fence, level.height, level.board, level.gap,
                               ground=ground_height(piece, t_fence), color=self.color, boards=True,
                               name=f"fence {index + 1}"))

    def _solved_altitude(self, ctx: CompileContext, t_fence: float, sign: float) -> float:
        """The sun altitude (degrees) at which the top of the level-5 fence's shadow falls ``FENCE_EDGE_LANES`` ego
        lane widths past the lane's near line, within [MIN_FENCE_SUN_DEG, the table's altitude]."""
        top = self.SEVERITY[-1]
        width = ctx.network.lane_width
        t_near = ctx.network.lane_center_t(ctx.drive.lane) + sign * width / 2
        across = abs(t_fence - t_near) + FENCE_EDGE_LANES * width
        solved = float(np.degrees(np.arctan2(top.height, across)))
        return float(np.clip(solved, MIN_FENCE_SUN_DEG, self.level().sun_altitude))


@dataclass(frozen=True)
class RailShadowLevel(SunAheadLevel):
    """What one severity level of ``RailShadow`` sets."""

    deck_length: float
    slots_along: SlotDirection
    slot_width: float
    slot_pitch: float
    deck_depth: float


@register
class RailShadow(SunShadowIllusion):
    """An elevated slotted rail deck over the road: a shaded road with bright lines where light comes through."""

    # One sun bearing and altitude and one slot pattern (slots along the road: bright lines parallel to the
    # lanes) at every level; the deck, starting at the same place, grows longer while the sun hardens (brighter,
    # crisper edges), so each level's striped shade holds the one before with starker slots.
    SEVERITY: ClassVar[tuple[RailShadowLevel, ...]] = (
        RailShadowLevel(sun_altitude=50.0, sun_ahead=72.0, sun_intensity=0.9, penumbra=0.010, deck_length=5.0,
                        slots_along="s", slot_width=0.24, slot_pitch=1.4, deck_depth=0.35),  # a narrow footbridge
        RailShadowLevel(sun_altitude=50.0, sun_ahead=72.0, sun_intensity=1.1, penumbra=0.008, deck_length=10.0,
                        slots_along="s", slot_width=0.24, slot_pitch=1.4, deck_depth=0.35),
        RailShadowLevel(sun_altitude=50.0, sun_ahead=72.0, sun_intensity=1.3, penumbra=0.006, deck_length=16.0,
                        slots_along="s", slot_width=0.24, slot_pitch=1.4, deck_depth=0.35),
        RailShadowLevel(sun_altitude=50.0, sun_ahead=72.0, sun_intensity=1.5, penumbra=0.005, deck_length=23.0,
                        slots_along="s", slot_width=0.24, slot_pitch=1.4, deck_depth=0.35),
        RailShadowLevel(sun_altitude=50.0, sun_ahead=72.0, sun_intensity=1.7, penumbra=0.004, deck_length=30.0,
                        slots_along="s", slot_width=0.24, slot_pitch=1.4, deck_depth=0.35),  # a slotted viaduct
    )

    type: Literal["rail_shadow"] = "rail_shadow"
    side: Side = Field("right", description="side the sun leans towards (the shadow shifts the other way)")
    deck_length: StrictFloat | None = Field(
        None, ge=3, le=80, description="length of the deck along the road (m); empty = from the table"
    )
    clearance: StrictFloat = Field(5.5, ge=4.5, le=15, description="height of the deck's underside above the road (m)")
    margin: StrictFloat = Field(3.0, ge=0.5, le=15, description="how far the deck reaches beyond each paved edge (m)")

    def level(self) -> RailShadowLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        piece = ctx.network.main
        deck_length = self.deck_length if self.deck_length is not None else level.deck_length
        s_center = min(self.start_s(ctx.drive) + deck_length / 2,
                       ctx.drive.road_length - ROAD_END_MARGIN_M - deck_length / 2)
        self.apply_sun(ctx, s_center, side_sign(self.side))
        span = 2.0 * abs(roadside_t(piece, self.margin, 1.0))
        ctx.add_mesh(overhead_rail(piece.line, s_center, span, deck_length, level.slot_width, level.slot_pitch,
                                   self.clearance, slots_along=level.slots_along, deck_depth=level.deck_depth,
                                   gaps=piece.gaps, name="overhead rail"))


@dataclass(frozen=True)
class WireShadowLevel(ShadowLevel):
    """What one severity level of ``WireShadow`` sets."""

    n_wires: int
    wire_radius: float
    wire_spacing: float
    height: float
    cross_every: int
    cross_skew: float


@register
class WireShadow(SunShadowIllusion):
    """Power lines beside and across the road: thin dark lines on the lanes and bright bands between pairs."""

    # More and thicker wires under a harder sun; wires start to cross the road, then diagonally. The sun's
    # azimuth is solved so the wires along the road shadow the ego's lane (see ``_sun_ahead``).
    # cross_every: every n-th pole sends wires across the road (0 = none; smaller = more crossings).
    SEVERITY: ClassVar[tuple[WireShadowLevel, ...]] = (
        WireShadowLevel(sun_altitude=55.0, sun_intensity=0.8, penumbra=0.010, n_wires=2, wire_radius=0.020,
                        wire_spacing=1.2, height=8.0, cross_every=0, cross_skew=0.0),
        WireShadowLevel(sun_altitude=52.0, sun_intensity=0.95, penumbra=0.008, n_wires=2, wire_radius=0.028,
                        wire_spacing=1.0, height=8.5, cross_every=3, cross_skew=0.0),
        WireShadowLevel(sun_altitude=50.0, sun_intensity=1.1, penumbra=0.006, n_wires=3, wire_radius=0.035,
                        wire_spacing=0.9, height=9.0, cross_every=2, cross_skew=6.0),
        WireShadowLevel(sun_altitude=47.0, sun_intensity=1.3, penumbra=0.004, n_wires=3, wire_radius=0.045,
                        wire_spacing=0.8, height=9.0, cross_every=1, cross_skew=10.0),
        WireShadowLevel(sun_altitude=45.0, sun_intensity=1.5, penumbra=0.003, n_wires=4, wire_radius=0.055,
                        wire_spacing=0.7, height=9.5, cross_every=1, cross_skew=12.0),
    )

    type: Literal["wire_shadow"] = "wire_shadow"
    side: Side = Field("right", description="which roadside the main pole row stands on")
    length: StrictFloat | None = Field(
        None, gt=0, le=2000, description="extent along the road (m); empty = to 40 m past the end of the drive"
    )
    offset: StrictFloat = Field(
        1.0, ge=0.3, le=30, description="lateral distance of the poles beyond the paved edge (m)"
    )
    wire_radius: StrictFloat | None = Field(
        None, ge=0.02, le=0.2, description="half the wire thickness (m); empty = from the table"
    )
    pole_spacing: StrictFloat = Field(35.0, ge=15, le=80, description="distance between poles (m)")

    def level(self) -> WireShadowLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        piece = ctx.network.main
        sign = side_sign(self.side)
        s0, s1 = self.extent(ctx.drive, self.length)
        t_row = roadside_t(piece, self.offset, sign)
        sag = 0.25 + 0.01 * self.pole_spacing
        self.apply_sun(ctx, s0, sign, self._sun_ahead(ctx, t_row, level.height - sag / 2))
        t_poles = (t_row, roadside_t(piece, self.offset, -sign)) if level.cross_every else (t_row,)
        radius = self.wire_radius if self.wire_radius is not None else level.wire_radius
        ctx.add_mesh(power_lines(piece.line, s0, s1, t_poles, level.n_wires, radius, level.height,
                                 pole_spacing=self.pole_spacing, wire_spacing=level.wire_spacing, sag=sag,
                                 cross_every=level.cross_every, cross_skew=level.cross_skew * -sign,
                                 ground=ground_height(piece, t_row), gaps=blocked(ctx, piece),
                                 name="power lines"))

    def _sun_ahead(self, ctx: CompileContext, t_row: float, height: float) -> float:
        """Degrees ahead of square-on that put the shadow of wires ``height`` m up at ``t_row`` on the centre of
        the ego's lane (as far across as the sun's altitude allows)."""
        t_target = ctx.network.lane_center_t(ctx.drive.lane)
        reach = abs(t_row - t_target)
        along = reach * np.tan(np.radians(self.altitude())) / height  # cos(ahead) that lands the shadow there
        return float(np.degrees(np.arccos(np.clip(along, np.cos(np.radians(MAX_AHEAD_DEG)), 1.0))))
