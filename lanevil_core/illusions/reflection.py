"""Reflection illusions: a wet road mirrors a low sun, street lamps at night, and glossy vehicles.

Each one wets the road (global wetness plus puddle layers, which the renderer shades as water with Fresnel
reflection and a glossy lobe) and adds what gets reflected: the sun placed low ahead, lit lamps, or cars.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, StrictBool, StrictFloat, StrictInt

from ..world.environment import (
    HEADLIGHT_INTENSITY,
    NIGHT_EXPOSURE,
    NIGHT_HORIZON,
    NIGHT_ZENITH,
    is_night,
    sun_direction,
)
from ..world.primitives import pose_on_road, transformed
from ..world.scene import PointLight, SurfaceLayer
from ..world.structures import streetlight, streetlight_lamp_offset
from ..world.vehicles import car, van
from .base import RGB, Category, CompileContext, Illusion, Level, register

PUDDLE_TEXEL_M = 0.1
WATER_RGBA = (0.012, 0.013, 0.015, 0.35)  # standing water darkens the asphalt under its mirror
LAMP_COLORS: dict[str, tuple[float, float, float]] = {"white": (1.0, 0.95, 0.88), "yellow": (1.0, 0.62, 0.22)}
LAMP_INTENSITY = 45.0  # radiance scale at 1 m: lights a road 8 m below to about the level of an overcast day
VEHICLE_AHEAD_M = 13.0  # the first glossy vehicle stands this far ahead of the ego start


def puddle_mask(rng: np.random.Generator, shape: tuple[int, int], coverage: float, blob_m: float) -> np.ndarray:
    """(rows, cols) float32 in [0, 1]: soft-edged puddles covering about ``coverage`` of the area."""
    if coverage <= 0.0:
        return np.zeros(shape, np.float32)
    rows, cols = shape
    cells = max(int(blob_m / PUDDLE_TEXEL_M), 2)
    grid = rng.standard_normal((rows // cells + 3, cols // cells + 3))
    # Bilinear upsampling of a coarse random grid gives smooth blob shapes.
    y = np.arange(rows) / cells
    x = np.arange(cols) / cells
    y0, x0 = np.floor(y).astype(int), np.floor(x).astype(int)
    fy, fx = (y - y0)[:, None], (x - x0)[None, :]
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)
    field = (grid[y0][:, x0] * (1 - fy) * (1 - fx) + grid[y0 + 1][:, x0] * fy * (1 - fx)
             + grid[y0][:, x0 + 1] * (1 - fy) * fx + grid[y0 + 1][:, x0 + 1] * fy * fx)
    threshold = np.quantile(field, 1.0 - coverage)
    return np.clip((field - threshold) * 4.0, 0.0, 1.0).astype(np.float32)


def _wet_road(ctx: CompileContext, rng: np.random.Generator, s0: float, length: float, wetness: float,
              puddles: float, blob_m: float, name: str) -> None:
    """Wet the whole road and lay puddles over the carriageway from ``s0`` for ``length`` metres (none where that
    stretch is empty: an illusion placed beyond the end of the drive)."""
    ctx.env.wetness = max(ctx.env.wetness, wetness)
    piece = ctx.network.main
    t0 = -piece.half_width - 0.5
    rows = int(length / PUDDLE_TEXEL_M)
    if rows < 1:
        return
    cols = int((2 * piece.half_width + 1.0) / PUDDLE_TEXEL_M)
    wet = puddle_mask(rng, (rows, cols), puddles, blob_m)
    rgba = np.empty((rows, cols, 4), np.float32)
    rgba[..., :3] = WATER_RGBA[:3]
    rgba[..., 3] = wet * WATER_RGBA[3]
    ctx.add_layer(SurfaceLayer(piece=0, s0=s0, t0=t0, texel=PUDDLE_TEXEL_M, rgba=rgba, wet=wet, over_paint=True,
                               name=name))


def _drive_end(ctx: CompileContext) -> float:
    drive = ctx.drive
    return min(drive.end_s + 80.0, drive.road_length)


def _road_heading_deg(ctx: CompileContext, s: float) -> float:
    return float(np.degrees(ctx.network.main.line.heading_at(s)))


def _set_sun(ctx: CompileContext, azimuth: float, altitude: float, intensity: float) -> None:
    ctx.env.sun_dir_world = sun_direction(azimuth, altitude)
    ctx.env.sun_intensity = intensity * (1.0 - 0.85 * ctx.env.cloudiness)


@dataclass(frozen=True)
class SunlightReflectionLevel(Level):
    """What one severity level of ``SunlightReflection`` sets."""

    sun_altitude: float
    sun_intensity: float
    wetness: float
    puddles: float


@register
class SunlightReflection(Illusion):
    """Driving into a low sun on a wet road: specular glare and puddle mirrors wash out the lines."""

    CATEGORY: ClassVar[Category] = "reflection"
    SETS_SUN: ClassVar[bool] = True
    # The sun stands ahead and sinks with the level while the road grows wetter, the puddles wider and the sun
    # harder. It never stands higher than the case's own day sun (``glare_altitude``): on a sunset a level-1 sun of
    # 24 deg lifted the road out of the buildings' shade, a change that outweighed the level-2 glare.
    SEVERITY: ClassVar[tuple[SunlightReflectionLevel, ...]] = (
        SunlightReflectionLevel(sun_altitude=24.0, sun_intensity=1.0, wetness=0.35, puddles=0.08),
        SunlightReflectionLevel(sun_altitude=17.0, sun_intensity=1.15, wetness=0.5, puddles=0.16),
        SunlightReflectionLevel(sun_altitude=12.0, sun_intensity=1.3, wetness=0.65, puddles=0.25),
        SunlightReflectionLevel(sun_altitude=10.0, sun_intensity=1.5, wetness=0.8, puddles=0.35),
        SunlightReflectionLevel(sun_altitude=8.0, sun_intensity=2.0, wetness=0.95, puddles=0.45),
    )

    type: Literal["sunlight_reflection"] = "sunlight_reflection"
    sun_offset: StrictFloat = Field(
        0.0, ge=-45, le=45, description="sun azimuth relative to the road heading (degrees)"
    )
    length: StrictFloat = Field(150.0, gt=5, le=1000, description="extent of the puddled stretch (m)")
    puddle_size: StrictFloat = Field(1.6, gt=0.2, le=10, description="typical puddle size (m)")

    def level(self) -> SunlightReflectionLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def glare_altitude(self, case_sun_altitude: float) -> float:
        """The sun's altitude (degrees): the level's, but no higher than a day case's own sun and no lower than the
        level-5 sun for it (a sunset case's levels 1 and 2 share its sun); a night case takes the table's."""
        table = self.level().sun_altitude
        if is_night(case_sun_altitude):
            return table
        return min(table, max(case_sun_altitude, self.SEVERITY[-1].sun_altitude))

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        s0 = self.start_s(ctx.drive) - 20.0
        heading = _road_heading_deg(ctx, s0 + 40.0)
        _set_sun(ctx, heading + self.sun_offset, self.glare_altitude(ctx.case_sun_altitude), level.sun_intensity)
        ctx.env.penumbra = min(ctx.env.penumbra, 0.01)
        _wet_road(ctx, ctx.rng(self.seed), max(s0, 0.0), self.length, level.wetness, level.puddles,
                  self.puddle_size, "sun-glare puddles")


@dataclass(frozen=True)
class StreetlightReflectionLevel(Level):
    """What one severity level of ``StreetlightReflection`` sets."""

    daylight: float
    wetness: float
    puddles: float
    lamp_scale: float
    spacing: float


@register
class StreetlightReflection(Illusion):
    """Dusk to night, white or yellow street lamps, a wet road: long light streaks run down the asphalt."""

    CATEGORY: ClassVar[Category] = "reflection"
    SETS_SUN: ClassVar[bool] = True
    # daylight: what is left of the day's sky light (1 = the case's day, 0 = full night). The level takes the scene
    # from late dusk to deep night while the road gets wetter and the lamps denser, so the streaks of the lamps
    # stand out ever more against the darkening road and the paint.
    SEVERITY: ClassVar[tuple[StreetlightReflectionLevel, ...]] = (
        StreetlightReflectionLevel(daylight=0.45, wetness=0.35, puddles=0.05, lamp_scale=0.8,
                                   spacing=40.0),  # late dusk
        StreetlightReflectionLevel(daylight=0.30, wetness=0.5, puddles=0.12, lamp_scale=0.9, spacing=34.0),
        StreetlightReflectionLevel(daylight=0.18, wetness=0.65, puddles=0.2, lamp_scale=1.0, spacing=28.0),
        StreetlightReflectionLevel(daylight=0.08, wetness=0.8, puddles=0.3, lamp_scale=1.2, spacing=22.0),
        StreetlightReflectionLevel(daylight=0.0, wetness=0.95, puddles=0.4, lamp_scale=1.45, spacing=17.0),  # wet night
    )

    type: Literal["streetlight_reflection"] = "streetlight_reflection"
    lamp_color: Literal["white", "yellow"] = "yellow"
    sides: Literal["left", "right", "both"] = "both"
    spacing: StrictFloat | None = Field(None, gt=5, le=100, description="lamp spacing (m); empty = from the severity")
    height: StrictFloat = Field(8.0, ge=4, le=14, description="lamp height (m)")
    length: StrictFloat | None = Field(None, gt=10, le=2000, description="extent (m); empty = to the end of the drive")
    headlights: StrictBool = Field(True, description="the ego's own headlights light the road ahead")

    def level(self) -> StreetlightReflectionLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        env = ctx.env
        daylight = float(level.daylight)
        dusk = daylight**2  # sky light falls off faster than the eye adapts
        env.night, env.sun_intensity = True, 0.0
        env.exposure = NIGHT_EXPOSURE + (1.0 - NIGHT_EXPOSURE) * daylight
        env.ambient = 0.01 + (max(env.ambient, 0.01) - 0.01) * dusk
        env.sky_zenith = (NIGHT_ZENITH + (env.sky_zenith - NIGHT_ZENITH) * dusk).astype(np.float32)
        env.sky_horizon = (NIGHT_HORIZON + (env.sky_horizon - NIGHT_HORIZON) * dusk).astype(np.float32)
        env.headlights = HEADLIGHT_INTENSITY if self.headlights else 0.0
        s0 = max(self.start_s(ctx.drive) - 20.0, 0.0)
        s1 = s0 + self.length if self.length is not None else _drive_end(ctx)
        spacing = self.spacing if self.spacing is not None else level.spacing
        color = LAMP_COLORS[self.lamp_color]
        piece = ctx.network.main
        t_pole = piece.half_width + 1.2
        sides = {"left": (1,), "right": (-1,), "both": (1, -1)}[self.sides]
        pole = streetlight(self.height, lamp_color=color, emissive=True)
        offset = streetlight_lamp_offset(self.height)
        for side in sides:
            for k, s in enumerate(np.arange(s0 + (spacing / 2 if side > 0 else 0.0), s1, spacing)):
                T_world_local = pose_on_road(piece.line, float(s), side * t_pole, yaw=0.0 if side < 0 else np.pi)
                ctx.add_mesh(transformed(pole, T_world_local).renamed(f"streetlight {side:+d} {k}"))
                p_world = T_world_local[:3, :3] @ offset + T_world_local[:3, 3]
                ctx.add_light(PointLight(p_world, np.array(color, np.float32),
                                         LAMP_INTENSITY * level.lamp_scale, name=f"lamp {side:+d} {k}",
                                         beam="street"))
        _wet_road(ctx, ctx.rng(self.seed), s0, s1 - s0, level.wetness, level.puddles, 1.4, "night puddles")


@dataclass(frozen=True)
class VehicleReflectionLevel(Level):
    """What one severity level of ``VehicleReflection`` sets."""

    count: int
    gloss: float
    wetness: float
    puddles: float
    sun_altitude: float


@register
class VehicleReflection(Illusion):
    """Glossy vehicles ahead mirrored in a wet road, their paint catching a low sun."""

    CATEGORY: ClassVar[Category] = "reflection"
    SETS_SUN: ClassVar[bool] = True
    SEVERITY: ClassVar[tuple[VehicleReflectionLevel, ...]] = (
        VehicleReflectionLevel(count=1, gloss=0.55, wetness=0.4, puddles=0.08, sun_altitude=30.0),
        VehicleReflectionLevel(count=2, gloss=0.65, wetness=0.55, puddles=0.15, sun_altitude=24.0),
        VehicleReflectionLevel(count=3, gloss=0.75, wetness=0.7, puddles=0.22, sun_altitude=18.0),
        VehicleReflectionLevel(count=4, gloss=0.85, wetness=0.85, puddles=0.3, sun_altitude=13.0),
        VehicleReflectionLevel(count=6, gloss=0.95, wetness=1.0, puddles=0.4, sun_altitude=9.0),
    )

    type: Literal["vehicle_reflection"] = "vehicle_reflection"
    count: StrictInt | None = Field(None, ge=1, le=20, description="vehicles ahead; empty = from the severity")
    gap: StrictFloat = Field(14.0, ge=6, le=60, description="distance between vehicles along the road (m)")
    color: RGB | None = Field(None, description="linear RGB paint, each channel 0..1; empty = varied")
    length: StrictFloat = Field(150.0, gt=5, le=1000, description="extent of the wet stretch (m)")

    def level(self) -> VehicleReflectionLevel:
        """This illusion's row of ``SEVERITY``."""
        return self.SEVERITY[self.severity - 1]

    def compile(self, ctx: CompileContext) -> None:
        level = self.level()
        rng = ctx.rng(self.seed)
        s_first = self.s if self.s is not None else ctx.drive.start_s + VEHICLE_AHEAD_M
        piece = ctx.network.main
        heading = _road_heading_deg(ctx, s_first)
        _set_sun(ctx, heading + 20.0, level.sun_altitude, 1.3)
        count = self.count if self.count is not None else level.count
        lanes = ctx.network.lanes_per_direction
        palette = ((0.02, 0.02, 0.025), (0.6, 0.6, 0.62), (0.35, 0.02, 0.02), (0.02, 0.06, 0.25), (0.8, 0.8, 0.78))
        for k in range(count):
            lane = (ctx.drive.lane + k) % lanes
            s = s_first + k * self.gap * (0.6 if k % 2 else 1.0) + float(rng.uniform(0.0, 3.0))
            t = ctx.network.lane_center_t(lane) + float(rng.uniform(-0.3, 0.3))
            paint = self.color if self.color is not None else palette[int(rng.integers(len(palette)))]
            body = van(paint) if k % 4 == 3 else car(paint)
            body.gloss = level.gloss
            ctx.add_mesh(transformed(body, pose_on_road(piece.line, s, t)).renamed(f"glossy vehicle {k}"))
        _wet_road(ctx, rng, max(s_first - 25.0, 0.0), self.length, level.wetness, level.puddles, 1.8,
                  "wet road")
