"""Road damage: cracks, repairs and sealant, tire marks on the main road's surface, and guard rails beside it.

Surface damage becomes ``SurfaceLayer`` textures on road piece 0: crack stains and repainted repairs lie under the
paint; open cracks, patches laid after the paint, sealant and rubber over it. Guard rails are W-beam meshes swept
along the road, whose bright top edge and shadow run parallel to the lane lines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, StrictBool, StrictFloat, StrictInt

from ..typed import MATERIALS
from ..world import surface_textures as tex
from ..world.environment import sun_direction
from ..world.paint import MATERIAL_ALBEDO
from ..world.scene import SurfaceLayer
from ..world.structures import ground_height, guard_rail
from .base import BEYOND_DRIVE_M, Category, CompileContext, EgoDrive, Illusion, Level, register

if TYPE_CHECKING:
    from ..typed import Float32Array

MAX_LAYER_TEXELS = 4_000_000  # one SurfaceLayer's texture at most; longer damage is split along s
PAINT_CLEARANCE_M = 0.12  # lateral gap from a lane line's centre to damage that runs "right beside" it
# Default start of surface damage ahead of the ego: the 1280x720, 90 deg camera 3 m up first sees the road ~6 m
# ahead of the vehicle, so damage starting here is in view from the first frame.
NEAR_AHEAD_M = 6.0
COUNT_LENGTH_M = 80.0  # the length of road the damage counts of a severity table are for
INCIDENT_SPACING_M = 40.0  # tire marks: one incident's marks every this many metres along the stretch


@dataclass(frozen=True)
class _Area:
    """The textured part of the main road: s from ``s0``, t from ``t0``, (rows, cols) texels of ``texel`` m."""

    s0: float
    t0: float
    texel: float
    shape: tuple[int, int]

    @property
    def length_m(self) -> float:
        """How far the texture runs along the road (m)."""
        return self.shape[0] * self.texel

    def local_t(self, t_road: float) -> float:
        """Texture column coordinate (m from the texture corner) of road-frame ``t_road``."""
        return t_road - self.t0


class _SurfaceDamage(Illusion):
    """Shared placement of damage drawn on the main road's surface, across the carriageway where the ego looks."""

    CATEGORY: ClassVar[Category] = "road_damage"
    TEXEL: ClassVar[float] = 0.03

    extent: StrictFloat | None = Field(
        None, gt=0, le=400,
        description="length along the road (m); empty = to 30 m past the ego's last position (every frame sees it)"
    )
    margin: StrictFloat = Field(0.5, ge=0, le=5, description="reach beyond each carriageway edge (m)")

    def start_s(self, drive: EgoDrive) -> float:
        """Where along the road the damage starts: by default where the ego camera's view of the road begins."""
        return self.s if self.s is not None else drive.start_s + NEAR_AHEAD_M

    def end_s(self, drive: EgoDrive) -> float:
        """Where the damage ends: ``extent`` past its start, by default ``BEYOND_DRIVE_M`` past the drive."""
        s0 = self.start_s(drive)
        return s0 + self.extent if self.extent is not None else max(drive.end_s + BEYOND_DRIVE_M, s0 + 1.0)

    def _area(self, ctx: CompileContext) -> _Area | None:
        """Where the texture lies, or None when nothing of the road is left past the start."""
        main = ctx.network.main
        s0 = self.start_s(ctx.drive)
        s1 = min(self.end_s(ctx.drive), main.line.length)
        t0 = -main.half_width - self.margin
        rows = int(np.floor((s1 - s0) / self.TEXEL))
        cols = int(np.ceil(2 * (main.half_width + self.margin) / self.TEXEL))
        return _Area(s0, t0, self.TEXEL, (rows, cols)) if rows >= 2 else None

    def _emit(self, ctx: CompileContext, area: _Area, rgba: Float32Array, wet: Float32Array | None,
              over_paint: bool, name: str) -> None:
        """Add the texture as layers of at most MAX_LAYER_TEXELS each, skipping stretches with nothing drawn."""
        rows_per_layer = max(MAX_LAYER_TEXELS // area.shape[1], 1)
        for part, start in enumerate(range(0, area.shape[0], rows_per_layer)):
            rows = slice(start, min(start + rows_per_layer, area.shape[0]))
            chunk_wet = None if wet is None else np.ascontiguousarray(wet[rows])
            if not rgba[rows, :, 3].any() and (chunk_wet is None or not chunk_wet.any()):
                continue
            ctx.add_layer(SurfaceLayer(piece=0, s0=area.s0 + start * area.texel, t0=area.t0, texel=area.texel,
                                       rgba=np.ascontiguousarray(rgba[rows]), wet=chunk_wet, over_paint=over_paint,
                                       name=f"{name} {part + 1}"))


def _setting(illusion: Illusion, key: str) -> Any:
    """The field ``key`` where the user set it, else the value of the illusion's severity row."""
    value = getattr(illusion, key)
    return getattr(illusion.level(), key) if value is None else value


def _ego_center_t(ctx: CompileContext) -> float:
    return ctx.network.lane_center_t(ctx.drive.lane)


def _lines_near_ego(ctx: CompileContext) -> list[float]:
    """t of every lane boundary, nearest to the ego lane's centre first."""
    center = _ego_center_t(ctx)
    return sorted((float(t) for t in ctx.network.main.boundaries_t), key=lambda t: (abs(t - center), t))


def _lanes_near_ego(ctx: CompileContext) -> list[float]:
    """t of every lane centre (both directions), the ego lane first, then outwards."""
    bounds = ctx.network.main.boundaries_t
    centers = 0.5 * (bounds[1:] + bounds[:-1])
    ego = _ego_center_t(ctx)
    return sorted((float(t) for t in centers), key=lambda t: (abs(t - ego), t))


def _beside(lines_t: list[float], count: int, gaps: np.ndarray) -> list[float]:
    """``count`` positions just beside the given lines, alternately on their -t and +t sides."""
    return [lines_t[k % len(lines_t)] + (-1.0 if k % 2 == 0 else 1.0) * float(gaps[k % len(gaps)])
            for k in range(count)]


# ---------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RoadCrackLevel(Level):
    """What one severity level of ``RoadCrack`` sets."""

    density: float
    width: float
    darkness: float
    along_lines: int
    alligator_share: float
    joints: int
    spall: float
    paint_wear: float


@register
class RoadCrack(_SurfaceDamage):
    """Dark branching cracks in the asphalt: transverse, longitudinal and alligator, and at the higher levels
    failed paving joints under the lane lines. The stained, spalled rims lie under the paint; the open cracks
    split the paint of the lines they cross, and the lines' paint flakes off the failing surface."""

    TEXEL: ClassVar[float] = 0.02
    # density: cracks per 100 m^2; width: core width of a main crack (1-3 cm); along_lines: long cracks right
    # beside the lane lines nearest the ego; joints: those lines whose paving joint has failed into a band of
    # alligator cracking along the line; spall: broken-down crack edges (wider, darker stained rims);
    # paint_wear: mean share of the lane lines' paint flaked off the failing surface (every line in the area).
    SEVERITY: ClassVar[tuple[RoadCrackLevel, ...]] = (
        RoadCrackLevel(density=0.8, width=0.010, darkness=0.60, along_lines=0, alligator_share=0.00,
                       joints=0, spall=0.0, paint_wear=0.0),  # hairline cracks, paint intact
        RoadCrackLevel(density=1.5, width=0.014, darkness=0.70, along_lines=0, alligator_share=0.10,
                       joints=0, spall=0.1, paint_wear=0.15),
        RoadCrackLevel(density=2.5, width=0.018, darkness=0.80, along_lines=1, alligator_share=0.15,
                       joints=1, spall=0.25, paint_wear=0.3),  # a failed joint, the lines flaking
        RoadCrackLevel(density=4.0, width=0.024, darkness=0.90, along_lines=2, alligator_share=0.20,
                       joints=2, spall=0.5, paint_wear=0.55),
        RoadCrackLevel(density=8.0, width=0.030, darkness=1.00, along_lines=6, alligator_share=0.25,
                       joints=5, spall=1.0, paint_wear=0.85),  # failing pavement, most of the paint gone
    )

    type: Literal["road_crack"] = "road_crack"
    kind: Literal["mixed", "transverse", "longitudinal", "alligator"] = Field(
        "mixed", description="crack pattern (mixed = mostly transverse, some longitudinal and alligator)")
    density: StrictFloat | None = Field(None, ge=0, le=20, description="cracks per 100 m^2; empty = from severity")
    width: StrictFloat | None = Field(None, ge=0.003, le=0.1, description="core width of a main crack (m)")
    darkness: StrictFloat | None = Field(None, ge=0, le=1, description="opacity of the crack core")
    along_lines: StrictInt | None = Field(None, ge=0, le=12, description="long cracks right beside lane lines")
    joints: StrictInt | None = Field(None, ge=0, le=12, description="lane lines with failed joints cracked along them")
    paint_wear: StrictFloat | None = Field(None, ge=0, le=1, description="mean share of the lines' paint flaked off")

    def level(self) -> RoadCrackLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        area = self._area(ctx)
        if area is None:
            return
        rng = ctx.rng(self.seed)
        crack_rng = np.random.default_rng(int(rng.integers(0, 2**63 - 1)))
        gaps = rng.uniform(PAINT_CLEARANCE_M, 2.5 * PAINT_CLEARANCE_M, size=8)
        lines = _lines_near_ego(ctx)
        along = [area.local_t(t) for t in _beside(lines, _setting(self, "along_lines"), gaps)]
        joints = [area.local_t(t) for t in lines[:_setting(self, "joints")]]
        density = _setting(self, "density")
        shares = self._shares(self.level().alligator_share)
        layers = tex.crack_layers(crack_rng, area.shape, area.texel,
                                  {kind: density * share for kind, share in shares.items()},
                                  _setting(self, "width"), _setting(self, "darkness"), along, ctx.env.wetness,
                                  joint_t=joints, spall=self.level().spall)
        self._emit(ctx, area, layers.stains, None, over_paint=False, name="crack stains")
        self._emit(ctx, area, layers.cracks, layers.wet, over_paint=True, name="cracks")
        wear = _setting(self, "paint_wear")
        if wear > 0:
            rgba, _ = tex.worn_paint(np.random.default_rng(int(rng.integers(0, 2**63 - 1))), area.shape, area.texel,
                                     [area.local_t(t) for t in lines], wear,
                                     MATERIAL_ALBEDO[MATERIALS.index(ctx.network.main.carriageway)])
            self._emit(ctx, area, rgba, None, over_paint=True, name="worn paint")

    def _shares(self, alligator_share: float) -> dict[tex.CrackKind, float]:
        """Share of the density that goes to each crack kind."""
        if self.kind != "mixed":
            return {kind: float(kind == self.kind) for kind in tex.CRACK_KINDS}
        rest = 1.0 - alligator_share
        return {"transverse": 0.65 * rest, "longitudinal": 0.35 * rest, "alligator": alligator_share}


@dataclass(frozen=True)
class RoadRepairLevel(Level):
    """What one severity level of ``RoadRepair`` sets."""

    patches: int
    strips: int
    parallel: int
    trenches: int
    unpainted: int
    size: float
    contrast: float
    strip_width: float
    bright_share: float
    ghosts: int
    ghost_opacity: float


@register
class RoadRepair(_SurfaceDamage):
    """Repair patches of fresher, darker asphalt, trench reinstatements along the lane lines, strips of crack
    sealant, some running along the lines, ghosts of old lane lines ground off when the lanes were moved, and at
    the higher levels fresh patches across the lines whose paint has not been restored yet."""

    # patches: rectangles and pothole fills (patches, strips and unpainted count per COUNT_LENGTH_M of road, so a
    # longer stretch has as many per metre); parallel: sealant strips beside lane lines; trenches: long narrow
    # reinstatements (joint inlays) along the lane lines nearest the ego, repainted: the line runs over them;
    # unpainted: patches laid across those lines after the paint, so the line breaks off there; size: patch
    # size scale; contrast: fresh-asphalt darkness and opacity; ghosts: old lane lines (the ego's first) ground
    # off when the lanes were moved, left as pale scoured stripes GHOST_SHIFT_LANES of a lane beside today's
    # lines, each as opaque as ghost_opacity (the classic wrong line to follow at road works).
    SEVERITY: ClassVar[tuple[RoadRepairLevel, ...]] = (
        RoadRepairLevel(patches=2, strips=2, parallel=0, trenches=0, unpainted=0, size=0.80, contrast=0.35,
                        strip_width=0.05, bright_share=0.00, ghosts=0, ghost_opacity=0.0),  # a few fresh patches
        RoadRepairLevel(patches=4, strips=3, parallel=0, trenches=0, unpainted=0, size=0.90, contrast=0.50,
                        strip_width=0.06, bright_share=0.15, ghosts=1, ghost_opacity=0.30),  # one faint ghost
        RoadRepairLevel(patches=6, strips=5, parallel=1, trenches=1, unpainted=1, size=1.00, contrast=0.65,
                        strip_width=0.07, bright_share=0.30, ghosts=2, ghost_opacity=0.45),  # trench, ego's ghosts
        RoadRepairLevel(patches=8, strips=7, parallel=2, trenches=2, unpainted=3, size=1.10, contrast=0.80,
                        strip_width=0.09, bright_share=0.40, ghosts=4, ghost_opacity=0.75),
        RoadRepairLevel(patches=11, strips=9, parallel=4, trenches=5, unpainted=6, size=1.30, contrast=1.00,
                        strip_width=0.12, bright_share=0.50, ghosts=6, ghost_opacity=0.95),  # the old layout
    )
    GHOST_SHIFT_LANES: ClassVar[float] = 0.4  # the old lanes lay this share of a lane width to the right

    type: Literal["road_repair"] = "road_repair"
    patches: StrictInt | None = Field(
        None, ge=0, le=200, description="repair patches (rectangles and pothole fills) per 80 m"
    )
    strips: StrictInt | None = Field(None, ge=0, le=200, description="free-running sealant strips per 80 m")
    parallel: StrictInt | None = Field(None, ge=0, le=12, description="sealant strips right beside lane lines")
    trenches: StrictInt | None = Field(None, ge=0, le=8, description="long narrow trench patches along lane lines")
    unpainted: StrictInt | None = Field(
        None, ge=0, le=12, description="patches across lane lines, paint not restored, per 80 m"
    )
    size: StrictFloat | None = Field(None, gt=0, le=4, description="patch size scale (1 = 0.8-4.4 m long)")
    contrast: StrictFloat | None = Field(None, ge=0, le=1, description="how much darker the fresh asphalt is")
    strip_width: StrictFloat | None = Field(None, ge=0.02, le=0.5, description="sealant strip width (m)")
    bright_share: StrictFloat | None = Field(None, ge=0, le=1, description="share of strips in bright weathered filler")
    ghosts: StrictInt | None = Field(None, ge=0, le=12, description="old lane lines ground off beside today's lines")
    ghost_opacity: StrictFloat | None = Field(
        None, ge=0, le=1, description="how much of a ghost line's paler stone shows"
    )

    def level(self) -> RoadRepairLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        area = self._area(ctx)
        if area is None:
            return
        v = replace(self.level(), **{row.name: _setting(self, row.name) for row in fields(self.level())})
        rng = ctx.rng(self.seed)
        patch_rng, strip_rng, unpainted_rng = (np.random.default_rng(int(b))
                                               for b in rng.integers(0, 2**63 - 1, size=3))
        gaps = rng.uniform(1.5 * PAINT_CLEARANCE_M, 3.5 * PAINT_CLEARANCE_M, size=8)
        swing = rng.uniform(-0.15, 0.15, size=8)  # a trench follows its line within a few centimetres
        lines = _lines_near_ego(ctx)
        trench_t = [area.local_t(lines[k % len(lines)] + float(swing[k % 8])) for k in range(v.trenches)]
        per = area.length_m / COUNT_LENGTH_M  # the counts are per COUNT_LENGTH_M of road

        def scaled(count: int) -> int:  # at least one where the level has any
            return max(min(count, 1), round(count * per))

        v = replace(v, patches=scaled(v.patches), strips=scaled(v.strips), unpainted=scaled(v.unpainted))
        rectangles = (v.patches + 1) // 2 + v.patches // 4
        rgba, _ = tex.patches(patch_rng, area.shape, area.texel, rectangles=rectangles,
                              blobs=v.patches - rectangles, trench_t=trench_t, size_scale=v.size,
                              contrast=v.contrast)
        self._emit(ctx, area, rgba, None, over_paint=False, name="repair patches")
        across_t = [area.local_t(lines[k % len(lines)]) for k in range(v.unpainted)]
        rgba, _ = tex.patches(unpainted_rng, area.shape, area.texel, rectangles=0, blobs=0, across_t=across_t,
                              size_scale=v.size, contrast=v.contrast)
        self._emit(ctx, area, rgba, None, over_paint=True, name="unpainted patches")
        parallel_t = [area.local_t(t) for t in _beside(lines, v.parallel, gaps)]
        rgba, _ = tex.patches(strip_rng, area.shape, area.texel, rectangles=0, blobs=0, strips=v.strips,
                              parallel_t=parallel_t, contrast=v.contrast, strip_width_m=v.strip_width,
                              bright_share=v.bright_share)
        self._emit(ctx, area, rgba, None, over_paint=True, name="sealant")
        ghost_rng = np.random.default_rng(int(rng.integers(0, 2**63 - 1)))
        shift = self.GHOST_SHIFT_LANES * ctx.network.lane_width
        ghost_t = [area.local_t(lines[k % len(lines)] - shift) for k in range(v.ghosts)]
        rgba, _ = tex.ghost_lines(ghost_rng, area.shape, area.texel, ghost_t, opacity=v.ghost_opacity)
        self._emit(ctx, area, rgba, None, over_paint=False, name="ghost markings")


@dataclass(frozen=True)
class TireMarksLevel(Level):
    """What one severity level of ``TireMarks`` sets."""

    straight: int
    swerve: int
    yaw: int
    on_line: int
    darkness: float
    track_width: float
    cluster: float


@register
class TireMarks(_SurfaceDamage):
    """Dark rubber tire tracks from emergency braking, swerves across lane lines and sideways yaw slides."""

    TEXEL: ClassVar[float] = 0.04
    # on_line: straight marks of a vehicle braking astride a lane line, one track running along the paint;
    # cluster: how tightly an incident's marks bunch at its site (0 = spread over the INCIDENT_SPACING_M after
    # it; 0.9 = all start within its first tenth, most of them already under way there, so the rubber is at its
    # darkest in the camera's first view). The level's marks repeat as one incident every INCIDENT_SPACING_M
    # along the stretch, so every frame of the drive has some ahead.
    SEVERITY: ClassVar[tuple[TireMarksLevel, ...]] = (
        TireMarksLevel(straight=1, swerve=0, yaw=0, on_line=0, darkness=0.45, track_width=0.18,
                       cluster=0.0),
        TireMarksLevel(straight=2, swerve=0, yaw=0, on_line=0, darkness=0.55, track_width=0.19,
                       cluster=0.3),
        TireMarksLevel(straight=2, swerve=1, yaw=0, on_line=1, darkness=0.68, track_width=0.20,
                       cluster=0.55),
        TireMarksLevel(straight=4, swerve=2, yaw=1, on_line=2, darkness=0.82, track_width=0.21,
                       cluster=0.75),
        TireMarksLevel(straight=6, swerve=4, yaw=2, on_line=4, darkness=0.95, track_width=0.22,
                       cluster=0.9),
    )
    HALF_GAUGE_M: ClassVar[float] = 0.82  # a car's track centre to its wheel tracks

    type: Literal["tire_marks"] = "tire_marks"
    straight: StrictInt | None = Field(None, ge=0, le=40, description="straight braking marks")
    swerve: StrictInt | None = Field(None, ge=0, le=40, description="swerving marks that cross a lane line")
    yaw: StrictInt | None = Field(None, ge=0, le=40, description="curved sideways-sliding marks")
    darkness: StrictFloat | None = Field(None, ge=0, le=1, description="peak opacity of the rubber")
    track_width: StrictFloat | None = Field(None, ge=0.1, le=0.4, description="width of one tire track (m)")
    length_min: StrictFloat = Field(20.0, gt=1, le=200, description="shortest mark (m)")
    length_max: StrictFloat = Field(45.0, gt=1, le=200, description="longest mark (m)")

    def level(self) -> TireMarksLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        area = self._area(ctx)
        if area is None:
            return
        straight, swerve, yaw = (_setting(self, key) for key in ("straight", "swerve", "yaw"))
        on_line = min(self.level().on_line, straight)
        lanes, lines = _lanes_near_ego(ctx), _lines_near_ego(ctx)
        astride = [lines[k % len(lines)] + (1.0 if k % 2 else -1.0) * self.HALF_GAUGE_M for k in range(on_line)]
        center_t = ([lanes[k % len(lanes)] for k in range(straight - on_line)] + astride
                    + [lanes[k % len(lanes)] for k in range(swerve)]
                    + [lanes[(k + 1) % len(lanes)] for k in range(yaw)])
        rng = ctx.rng(self.seed)
        rgba = None
        for site in range(max(1, math.ceil(area.length_m / INCIDENT_SPACING_M))):
            lo, hi = self._starts(min(INCIDENT_SPACING_M, area.length_m), self.level().cluster)
            marks, _ = tex.tire_marks(
                rng if site == 0 else np.random.default_rng(int(rng.integers(0, 2**63 - 1))), area.shape,
                area.texel, straight=straight, swerve=swerve, yaw=yaw,
                center_t=[area.local_t(t) for t in center_t], swerve_m=ctx.network.lane_width,
                length_m=(min(self.length_min, self.length_max), max(self.length_min, self.length_max)),
                darkness=_setting(self, "darkness"), track_width_m=_setting(self, "track_width"),
                start_m=(lo + site * INCIDENT_SPACING_M, hi + site * INCIDENT_SPACING_M))
            rgba = marks if rgba is None else tex.composite(marks, rgba)
        assert rgba is not None
        self._emit(ctx, area, rgba, None, over_paint=True, name="tire marks")

    def _starts(self, span_m: float, cluster: float) -> tuple[float, float]:
        """s range (m from the incident's site) of one incident's mark starts: the whole ``span_m`` at
        ``cluster`` 0, shrinking and reaching back up to half the shortest mark before the site as ``cluster``
        grows."""
        lead = 0.5 * cluster * min(self.length_min, self.length_max)
        return -lead, -lead + (1.0 - cluster) * span_m


# ---------------------------------------------------------------------------------------------------------------

_Unit = Annotated[float, Field(ge=0, le=1)]
RAIL_TOP_M = 0.75  # height of a W-beam's top edge above the ground
MEDIAN_RAIL_T = 0.45  # a median rail stands just left of the centre line, clear of its paint
SUN_SWING_RAD = np.radians(30.0)  # the shadow-casting sun stands this far behind the cross-road direction


@dataclass(frozen=True)
class GuardRailLevel(Level):
    """What one severity level of ``GuardRail`` sets."""

    offset: float
    far_side: bool
    median: bool
    albedo: float
    shadow_m: float


@register
class GuardRail(Illusion):
    """W-beam guard rails along the road edge whose bright top edge and shadow run parallel to the lane lines."""

    CATEGORY: ClassVar[Category] = "road_damage"
    SETS_SUN: ClassVar[bool] = True  # its rails throw their shadow over the lanes (levels with shadow_m)
    # offset: gap between the carriageway edge and the rail (m); far_side: a second rail along the other edge;
    # median: a rail just left of the centre line; shadow_m: how far across the road (from the rail nearest
    # the ego) the sun throws the shadow of its top edge (0 = the case's sun is kept). Level 1 keeps the case's
    # light (one rail set back: barely a mark on the lanes); from level 2 one sun on the main rail's side throws its
    # shadow over the lane beside it, the same sun at every level, so what rises is the rails: closer to the lanes,
    # brighter (new galvanised steel), and more of them, their edges and shadows ever nearer the lane lines. (A sun
    # sinking with the level would shade a street canyon's whole road and lower the change there.)
    SEVERITY: ClassVar[tuple[GuardRailLevel, ...]] = (
        GuardRailLevel(offset=2.4, far_side=False, median=False, albedo=0.30, shadow_m=0.0),  # one rail, set back
        GuardRailLevel(offset=1.8, far_side=False, median=False, albedo=0.38, shadow_m=2.5),
        GuardRailLevel(offset=0.9, far_side=True, median=False, albedo=0.62, shadow_m=2.5),  # both edges
        GuardRailLevel(offset=0.5, far_side=True, median=False, albedo=0.72, shadow_m=2.5),
        GuardRailLevel(offset=0.1, far_side=True, median=True, albedo=0.85, shadow_m=2.5),  # and the median
    )

    type: Literal["guard_rail"] = "guard_rail"
    side: Literal["right", "left"] = Field("right", description="road edge of the main rail")
    offset: StrictFloat | None = Field(
        None, ge=0, le=30, description="gap between the carriageway edge and the rail (m)"
    )
    extent: StrictFloat = Field(130.0, gt=1, le=1000, description="length along the road (m)")
    far_side: StrictBool | None = Field(None, description="also a rail along the other edge")
    median: StrictBool | None = Field(None, description="also a rail just left of the centre line")
    color: tuple[_Unit, _Unit, _Unit] | None = Field(None, description="linear albedo of the steel; empty = grey")
    shadow_m: StrictFloat | None = Field(
        None, ge=0, le=20, description="shadow reach across the road (m); 0 = keep sun"
    )
    post_spacing: StrictFloat = Field(2.0, ge=0.5, le=10, description="distance between posts (m)")

    def level(self) -> GuardRailLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def start_s(self, drive: EgoDrive) -> float:
        """Where along the road the rails start: by default beside the ego, so they line the whole view."""
        return self.s if self.s is not None else drive.start_s

    def compile(self, ctx: CompileContext) -> None:
        main = ctx.network.main
        s0 = self.start_s(ctx.drive)
        s1 = min(s0 + self.extent, main.line.length)
        if s1 - s0 < 1.0:
            return
        color = self.color if self.color is not None else (self.level().albedo,) * 3
        rails_t = self._rails_t(ctx)
        for index, t_rail in enumerate(rails_t):
            median = abs(t_rail) < main.half_width
            for a, b in _open_spans(s0, s1, [(g0, g1) for g0, g1, side in main.gaps if median or side * t_rail > 0]):
                ctx.add_mesh(guard_rail(main.line, a, b, t_rail, ground_height(main, t_rail), self.post_spacing,
                                        (float(color[0]), float(color[1]), float(color[2])),
                                        name=f"guard rail {index + 1}"))
        shadow_m = _setting(self, "shadow_m")
        if shadow_m > 0:
            # The sun stands on the side of the main rail and throws its shadow over the lanes beside it; the same
            # sun at every level, whatever rails the level adds and wherever it sets them: it is solved for a rail
            # top over the carriageway's surface, not over the verge at this level's offset (a verge a few cm
            # lower tilted the sun between levels, and the change of the roadside's shadows drowned a level's step).
            ctx.env.sun_dir_world = _shadow_sun(float(main.line.heading_at(0.5 * (s0 + s1))),
                                                1.0 if rails_t[0] >= 0 else -1.0, RAIL_TOP_M, shadow_m)

    def _rails_t(self, ctx: CompileContext) -> list[float]:
        """Lateral positions of the rails: main side first, then the far side and the median if asked for."""
        edge = ctx.network.main.half_width + _setting(self, "offset")
        sign = -1.0 if self.side == "right" else 1.0
        rails = [sign * edge]
        if _setting(self, "far_side"):
            rails.append(-sign * edge)
        if _setting(self, "median"):
            rails.append(MEDIAN_RAIL_T)
        return rails


def _open_spans(s0: float, s1: float, gaps: list[tuple[float, float]], shortest: float = 2.0
                ) -> list[tuple[float, float]]:
    """The parts of [s0, s1] outside every gap (junction mouths a rail must leave open), at least ``shortest`` m."""
    spans, start = [], s0
    for g0, g1 in sorted(gaps):
        if g0 > start:
            spans.append((start, min(g0, s1)))
        start = max(start, g1)
    spans.append((start, s1))
    return [(a, b) for a, b in spans if b - a >= shortest]


def _shadow_sun(heading: float, side: float, height: float, reach: float) -> np.ndarray:
    """(3,) unit direction to a sun on the ``side`` (+1 left, -1 right) of a road heading ``heading`` (rad) that
    throws the shadow of an edge ``height`` m up ``reach`` m across the road."""
    azimuth = heading + side * (np.pi / 2 + SUN_SWING_RAD)
    altitude = np.arctan2(height * np.cos(SUN_SWING_RAD), reach)
    return sun_direction(float(np.degrees(azimuth)), float(np.degrees(altitude)))
