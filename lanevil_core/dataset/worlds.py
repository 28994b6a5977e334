"""Structured world draws of train variations: what the world looks like while its labels stay exact.

``lanevil dataset --vary-world`` draws, per train variation, the scene kind and density (and with it the kerbs,
barriers and walls of that kind's cross-section), the sun (day, low sun, dusk, night), clouds, fog, a wet or dry
road, the carriageway's material and colour, the lane width, the bends' radius and the slopes' grade, traffic
in the lanes (a ``vehicle`` illusion: its vehicles stand in every lane, the ego's beyond its drive, and hide the
lines they stand on from the labels too), and the markings' manual (``road.marking_standard``: dash, gap, widths),
Botts' dots in place of the broken lane lines and the paint's wear. ``--vary-world --heldout`` draws from
``HELDOUT_WORLD`` instead: the same ranges on the axes in ``SHARED_AXES``, ranges disjoint from the train draw's on
every other axis (cameras, lane widths, bends, grades, road colours, marking standards, paint wear), so a validation
split made with it measures how a detector does on cameras, roads, materials and markings it never saw. Both tables
are below, side by side; ``docs/learning.md`` prints them.

Every draw uses its own stream, ``default_rng([seed, index, WORLD_STREAM])``, and always the same number of draws,
so the variation's other draws (markings, ego lane and start, ``--vary-camera``'s camera) stay what they were; the
markings' draws come last on it (after the held-out camera's), so the world drawn before them stays as it was too.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ..camera.variation import HEIGHT_M, HFOV_DEG, PITCH_DEG, MountSpans, Spans, pick_spans, random_camera
from ..presets import sun_intensity
from ..typed import SCENE_KINDS, MarkingStandardName, SceneKind
from ..world.environment import is_night

WORLD_STREAM = 1  # third seed word of the world draws (the variation's own draws use [seed, index])
VEHICLE = "vehicle"
DAY_LABELS: tuple[tuple[float, str], ...] = ((5.0, "Dusk"), (20.0, "LowSun"), (90.0, "Day"))  # below this: name
DASHED_LANE_LINE, BOTTS_DOTS = "white_dashed", "botts_dots"  # a broken lane line: painted dashes, or dots


@dataclass(frozen=True)
class WorldRanges:
    """What one world draw may pick. ``Spans`` are one or more (lo, hi) intervals, each value as likely as its
    interval's length (``camera.variation.pick_spans``); shares are probabilities per variation.

    Attributes:
        scene_kinds: roadside kinds, one drawn uniformly (the kind sets kerbs, barriers, walls and props).
        density: roadside props (1 = typical).
        sun_altitude_deg: degrees above the horizon; at or below -2 it is night (lamps and headlights on).
        sun_azimuth_deg: degrees, 0 = ahead at the start.
        cloudiness, fog_density: the case's weather fields.
        wet_share: share of wet roads; wetness, puddles, rain: their ranges on a wet road (a dry one has none).
        concrete_share: share of concrete-slab roads (the rest asphalt).
        asphalt_albedo, concrete_albedo: grey level of the carriageway (linear albedo; asphalt's own is 0.055,
            weathered slabs' 0.21); tint: the red and blue channels moved by up to this share (warm or cool).
        lane_width_m: lane width (m); the lane count stays the variation's own draw.
        bend_radius_m: radius of bends and S-curves (m); grade: slope of uphill and downhill roads.
        traffic_share: share of variations with traffic; traffic_severities: the ``vehicle`` illusion's levels,
            one drawn.
        camera: field of view, mount height and pitch of the cameras (the train world leaves the camera to
            ``--vary-camera``, whose ranges these are; the held-out world draws its own).
        draws_camera: whether the world draws the camera (through ``camera.variation.random_camera``).
        marking_standards: the marking manuals (``road.marking_standard``; ``custom``: the markings' own dash 3 m,
            gap 9 m, width 0.15 m), one drawn uniformly.
        botts_share: share of variations whose broken lane lines (white dashes or dots in the variation's own
            draw; not the edges, not the centre line) are Botts' dots, in groups standing in for the standard's
            dashes; the rest are dashes (the labels stay: the same boundaries).
        worn_share: share of variations with worn paint (the rest fresh); paint_wear: its wear (``Marking.wear``),
            the same on every line of the variation.
    """

    scene_kinds: tuple[SceneKind, ...]
    density: Spans
    sun_altitude_deg: Spans
    sun_azimuth_deg: Spans
    cloudiness: Spans
    fog_density: Spans
    wet_share: float
    wetness: Spans
    puddles: Spans
    rain: Spans
    tint: Spans
    traffic_share: float
    traffic_severities: tuple[int, ...]
    concrete_share: float
    asphalt_albedo: Spans
    concrete_albedo: Spans
    lane_width_m: Spans
    bend_radius_m: Spans
    grade: Spans
    camera: MountSpans
    draws_camera: bool
    marking_standards: tuple[MarkingStandardName, ...]
    botts_share: float
    worn_share: float
    paint_wear: Spans


TRAIN_WORLD = WorldRanges(
    scene_kinds=SCENE_KINDS,
    density=((0.3, 2.0),),
    sun_altitude_deg=((-25.0, -8.0), (-2.0, 70.0)),  # night 19 %, dusk 8 %, low sun 17 %, day 56 %
    sun_azimuth_deg=((0.0, 360.0),),
    cloudiness=((0.0, 90.0),),
    fog_density=((0.5, 8.0),),
    wet_share=0.3,
    wetness=((40.0, 100.0),),
    puddles=((0.0, 50.0),),
    rain=((0.0, 40.0),),
    tint=((-0.06, 0.06),),
    traffic_share=0.5,
    traffic_severities=(1, 2, 3, 4, 5),
    concrete_share=0.3,
    asphalt_albedo=((0.035, 0.10),),  # fresh black to grey aged asphalt
    concrete_albedo=((0.16, 0.30),),  # weathered to clean concrete slabs
    lane_width_m=((2.9, 4.0),),
    bend_radius_m=((120.0, 900.0),),
    grade=((0.02, 0.07),),
    camera=MountSpans(fov_deg=(HFOV_DEG,), height_m=(HEIGHT_M,), pitch_deg=(PITCH_DEG,)),
    draws_camera=False,
    marking_standards=("custom", "us_mutcd", "de_autobahn", "de_urban", "cn_fast", "jp_expressway"),  # gaps 6-12 m
    botts_share=0.5,  # as often as the plain split's dots (its lane lines: dashes or dots alike)
    worn_share=0.6,
    paint_wear=((0.05, 0.6),),
)

HELDOUT_WORLD = WorldRanges(
    scene_kinds=TRAIN_WORLD.scene_kinds,
    density=TRAIN_WORLD.density,
    sun_altitude_deg=TRAIN_WORLD.sun_altitude_deg,
    sun_azimuth_deg=TRAIN_WORLD.sun_azimuth_deg,
    cloudiness=TRAIN_WORLD.cloudiness,
    fog_density=TRAIN_WORLD.fog_density,
    wet_share=TRAIN_WORLD.wet_share,
    wetness=TRAIN_WORLD.wetness,
    puddles=TRAIN_WORLD.puddles,
    rain=TRAIN_WORLD.rain,
    tint=TRAIN_WORLD.tint,
    traffic_share=TRAIN_WORLD.traffic_share,
    traffic_severities=TRAIN_WORLD.traffic_severities,
    concrete_share=TRAIN_WORLD.concrete_share,
    asphalt_albedo=((0.11, 0.15),),  # faded light-grey asphalt, lighter than any train asphalt
    concrete_albedo=((0.32, 0.40),),  # new, bright concrete
    lane_width_m=((2.6, 2.85), (4.1, 4.6)),  # narrower and wider lanes
    bend_radius_m=((60.0, 110.0),),  # sharper bends
    grade=((0.085, 0.12),),  # steeper hills
    camera=MountSpans(fov_deg=((34.0, 42.0), (104.0, 118.0)),  # tele and wide lenses
                      height_m=((0.9, 1.15), (3.6, 4.2)),  # a low sports car, a tall truck cab
                      pitch_deg=((-4.0, -2.5), (6.5, 8.0))),  # tilted up, tilted down
    draws_camera=True,
    marking_standards=("cn_slow", "jp_general"),  # the short-gap manuals: 2 m / 4 m and 5 m / 5 m
    botts_share=TRAIN_WORLD.botts_share,
    worn_share=TRAIN_WORLD.worn_share,
    paint_wear=((0.75, 0.85),),  # beyond every train split's wear (--vary-camera's too): old, flaking paint
)

WORLDS: dict[str, WorldRanges] = {"train": TRAIN_WORLD, "heldout": HELDOUT_WORLD}
# Axes on which the held-out draw takes the train draw's ranges (time of day, weather, roadside and traffic vary
# alike in both); every other axis of the tables is disjoint (tests/core/test_worlds.py checks it).
SHARED_AXES: tuple[str, ...] = (
    "scene_kinds", "density", "sun_altitude_deg", "sun_azimuth_deg", "cloudiness", "fog_density", "wet_share",
    "wetness", "puddles", "rain", "tint", "traffic_share", "traffic_severities", "concrete_share", "draws_camera",
    "botts_share", "worn_share",
)
HELDOUT_AXES: tuple[str, ...] = tuple(f.name for f in fields(WorldRanges) if f.name not in SHARED_AXES)
DRAWS = 20
MARKING_DRAWS = 4  # drawn after DRAWS and the camera


def day_label(altitude_deg: float) -> str:
    """``Night``, ``Dusk``, ``LowSun`` or ``Day`` for a sun altitude (names a variation's folder)."""
    if is_night(altitude_deg):
        return "Night"
    return next(name for below, name in DAY_LABELS if altitude_deg < below)


def world_rng(seed: int, index: int) -> np.random.Generator:
    """The world draws' own stream of variation ``index``."""
    return np.random.default_rng([seed, index, WORLD_STREAM])


def _surface(u: np.ndarray, ranges: WorldRanges) -> tuple[str, tuple[float, float, float]]:
    """(pavement, linear RGB albedo of the carriageway) from three uniform draws."""
    concrete = bool(u[0] < ranges.concrete_share)
    grey = pick_spans(u[1], ranges.concrete_albedo if concrete else ranges.asphalt_albedo, 4)
    tint = pick_spans(u[2], ranges.tint, 4)
    color = (round(grey * (1.0 + tint), 4), grey, round(grey * (1.0 - tint), 4))
    return ("concrete" if concrete else "asphalt"), color


def _marking_draw(u: np.ndarray, ranges: WorldRanges) -> tuple[MarkingStandardName, dict[str, Any]]:
    """(marking standard, ``{"botts_dots": bool, "wear": float}``) from ``MARKING_DRAWS`` uniform draws."""
    standard = ranges.marking_standards[int(u[0] * len(ranges.marking_standards))]
    wear = pick_spans(u[3], ranges.paint_wear, 2) if u[2] < ranges.worn_share else 0.0
    return standard, {"botts_dots": bool(u[1] < ranges.botts_share), "wear": wear}


def draw_world(rng: np.random.Generator, ranges: WorldRanges, size: tuple[int, int]) -> dict[str, Any]:
    """Case fields of one world drawn from ``ranges`` (always ``DRAWS`` uniform draws, plus ``random_camera``'s
    when the world draws the camera, then ``MARKING_DRAWS``): ``scene``, ``weather``, ``sun``, ``road`` (fields to
    update), ``illusions``, ``markings`` (what ``world_markings`` does to the variation's markings) and, for a world
    that draws it, ``camera`` for an image of ``size``."""
    u = rng.uniform(0.0, 1.0, DRAWS)
    altitude = pick_spans(u[2], ranges.sun_altitude_deg, 1)
    cloud = pick_spans(u[4], ranges.cloudiness, 1)
    wet = bool(u[6] < ranges.wet_share)
    weather = {
        "cloudiness": cloud,
        "precipitation": pick_spans(u[7], ranges.rain, 1) if wet else 0.0,
        "precipitation_deposits": pick_spans(u[8], ranges.puddles, 1) if wet else 0.0,
        "wetness": pick_spans(u[9], ranges.wetness, 1) if wet else 0.0,
        "fog_density": pick_spans(u[5], ranges.fog_density, 2),
        "fog_distance": 0.0,
    }
    pavement, color = _surface(u[10:13], ranges)
    road = {"pavement": pavement, "surface_color": color, "lane_width": pick_spans(u[13], ranges.lane_width_m, 2),
            "radius": pick_spans(u[14], ranges.bend_radius_m, 1), "grade": pick_spans(u[15], ranges.grade, 3)}
    illusions = []
    if u[16] < ranges.traffic_share:
        severity = ranges.traffic_severities[int(u[17] * len(ranges.traffic_severities))]
        illusions.append({"type": VEHICLE, "severity": severity, "seed": int(u[18] * 2**32),
                          "lights_on": bool(is_night(altitude))})
    world: dict[str, Any] = {
        "scene": {"kind": ranges.scene_kinds[int(u[0] * len(ranges.scene_kinds))],
                  "density": pick_spans(u[1], ranges.density, 2)},
        "weather": weather,
        "sun": {"altitude": altitude, "azimuth": pick_spans(u[3], ranges.sun_azimuth_deg, 1),
                "intensity": sun_intensity(altitude, cloud)},
        "road": road,
        "illusions": illusions,
    }
    if ranges.draws_camera:
        world["camera"] = random_camera(rng, size, ranges.camera)
    road["marking_standard"], world["markings"] = _marking_draw(rng.uniform(0.0, 1.0, MARKING_DRAWS), ranges)
    return world


def world_markings(markings: list[dict[str, Any]], drawn: dict[str, Any]) -> list[dict[str, Any]]:
    """The variation's markings (dicts, left to right: edge, lane lines, centre line, lane lines, edge) under a
    world's marking draw: every line's wear, and its broken lane lines as Botts' dots (``botts_dots``) or as
    dashes. Every other type stays (an unpainted boundary stays unpainted), so the labels are those of the same
    lines."""
    centre = (len(markings) - 1) // 2

    def line_type(index: int, marking: dict[str, Any]) -> str:
        broken = index not in (0, centre, len(markings) - 1) and marking["type"] in (DASHED_LANE_LINE, BOTTS_DOTS)
        if not broken:
            return str(marking["type"])
        return BOTTS_DOTS if drawn["botts_dots"] else DASHED_LANE_LINE

    return [{**marking, "type": line_type(index, marking), "wear": drawn["wear"]}
            for index, marking in enumerate(markings)]


def world_parameters(world: dict[str, Any]) -> dict[str, Any]:
    """What a variation's manifest entry says of its world draw (its paint wear and marking types are the entry's
    own ``paint_wear`` and ``markings``)."""
    traffic = [illusion["severity"] for illusion in world["illusions"] if illusion["type"] == VEHICLE]
    return {"scene": world["scene"]["kind"], "density": world["scene"]["density"],
            "wetness": world["weather"]["wetness"], "cloudiness": world["weather"]["cloudiness"],
            "surface_color": list(world["road"]["surface_color"]), "traffic": traffic[0] if traffic else 0,
            "day": day_label(world["sun"]["altitude"]), "marking_standard": world["road"]["marking_standard"],
            "botts_dots": world["markings"]["botts_dots"]}
