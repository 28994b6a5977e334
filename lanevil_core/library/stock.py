"""The stock case library: clean cases covering every road type, line type and scene kind, and for every
illusion type several original (basic) cases spread over road types, scenes, paint, weather, time of day and
cameras, each with its perturbed cases at levels 1-5.

This module is the source of the JSON files under ``scenes/`` (``lanevil library --out scenes`` writes them);
a perturbed case differs from its original only in its ``illusions`` list. Layout:
``scenes/<NN_category>/<type>/<original id>/00_original.json`` and ``01_level1.json`` ... ``05_level5.json``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

from ..case import Case, case_json, parse_case
from ..files import write_atomic
from ..illusions import REGISTRY
from ..presets import preset_values
from ..typed import LineType, SceneKind

CATEGORY_FOLDERS = {"road_damage": "10_road_damage", "traffic": "20_traffic", "shadow": "30_shadow",
                    "reflection": "40_reflection"}
LEVELS = (1, 2, 3, 4, 5)


def _case(title: str, description: str, road: dict[str, Any], scene: str, preset: str, azimuth: float = 30.0,
          seed: int = 0, lanes_markings: list[str] | None = None) -> Case:
    values = preset_values(preset)
    sun = {**values["sun"], "azimuth": azimuth}
    road = dict(road)
    if lanes_markings is not None:
        road["markings"] = lanes_markings
    data = {"title": title, "description": description, "road": road, "scene": {"kind": scene},
            "weather": values["weather"], "sun": sun, "seed": seed}
    return parse_case(data, source=title)


# name -> (title, description, road, scene kind, preset, sun azimuth, markings left to right)
_CLEAN: dict[str, tuple[str, str, dict[str, Any], str, str, float, list[str] | None]] = {
    "00_straight_urban": (
        "Straight urban avenue", "Two lanes each way between office blocks, yellow double centre line, clear noon.",
        {"type": "straight"}, "urban", "ClearNoon", 30.0, None),
    "01_bend_suburban": (
        "Suburban left bend", "A 150 m radius left bend past houses and trees, single yellow centre line.",
        {"type": "bend", "turn": "left"},
        "suburban", "CloudyNoon", 120.0,
        ["white_solid", "white_dashed", "yellow_solid", "white_dashed", "white_solid"]),
    "02_s_curve_rural": (
        "Rural S-curve", "One lane each way through fields, dashed yellow centre line you may overtake across.",
        {"type": "s_curve", "lanes_per_direction": 1, "radius": 120.0, "lane_width": 3.3},
        "rural", "ClearSunset", 200.0, ["white_solid", "yellow_dashed", "white_solid"]),
    "03_uphill_highway": (
        "Highway climb", "Three lanes each way climbing a 6 % grade, white double line in the median.",
        {"type": "uphill", "lanes_per_direction": 3, "lane_width": 3.6},
        "highway", "ClearNoon", 60.0,
        ["white_solid", "white_dashed", "white_dashed", "white_double_solid", "white_dashed", "white_dashed",
         "white_solid"]),
    "04_downhill_suburban": (
        "Suburban descent", "Two lanes each way going down a 5 % grade; solid-dashed centre line.",
        {"type": "downhill", "grade": 0.05},
        "suburban", "WetCloudyNoon", 300.0,
        ["white_solid", "white_dashed", "yellow_solid_dashed", "white_dashed", "white_solid"]),
    "05_t_junction_urban": (
        "Urban T-junction", "A side street joins from the right; the edge line breaks at its mouth.",
        {"type": "t_junction", "junction_s": 60.0},
        "urban", "ClearNoon", 150.0,
        ["white_solid", "white_dashed", "white_solid_dashed", "white_dashed", "white_solid"]),
    "06_crossroad_suburban": (
        "Suburban crossroad", "A four-way crossing with stop lines on the side roads, soft rain.",
        {"type": "crossroad", "junction_s": 70.0},
        "suburban", "SoftRainNoon", 45.0, None),
    "07_straight_tunnel_approach": (
        "Tunnel approach", "Two lanes each way towards a tunnel portal in a hillside, double yellow line.",
        {"type": "straight"}, "tunnel_approach", "CloudySunset", 250.0, None),
    "08_bend_highway_botts": (
        "Highway bend with Botts' dots", "A right bend where raised dots replace the dashed lane lines.",
        {"type": "bend", "turn": "right", "radius": 250.0, "lanes_per_direction": 3},
        "highway", "ClearNoon", 330.0,
        ["white_solid", "botts_dots", "botts_dots", "yellow_double_solid", "botts_dots", "botts_dots",
         "white_solid"]),
}


def clean_cases() -> dict[str, Case]:
    """Relative path (under scenes/) -> clean case."""
    return {f"00_clean/{name}.json": _case(title, description, road, scene, preset, azimuth, lanes_markings=marks)
            for name, (title, description, road, scene, preset, azimuth, marks) in _CLEAN.items()}


Lines = tuple[LineType, LineType]  # (lane line, centre line) paint


class Original(NamedTuple):
    """What distinguishes one original (clean) case of an illusion type from another: road, scene, weather preset,
    sun azimuth, ``lines`` = (lane line, centre line) paint with white solid edges (None = the road's default),
    ``camera`` = a camera preset (None = the paper's default camera), the ego's lane."""

    road: dict[str, Any]
    scene: SceneKind
    preset: str
    azimuth: float = 30.0
    lines: Lines | None = None
    camera: str | None = None
    lane: int = 0


def _o(road_type: str, scene: SceneKind, preset: str, azimuth: float = 30.0,
       lines: Lines | None = None, camera: str | None = None, lane: int = 0,
       **road: Any) -> Original:
    """An ``Original`` on a road of ``road_type`` with the other road fields in ``road``."""
    return Original({"type": road_type, **road}, scene, preset, azimuth, lines, camera, lane)


# Lane line and centre line pairs, so that each type's originals meet most of the nine paint types.
_WD_YD2: Lines = ("white_dashed", "yellow_double_solid")
_WD_YS: Lines = ("white_dashed", "yellow_solid")
_WD_YSD: Lines = ("white_dashed", "yellow_solid_dashed")
_WD_WSD: Lines = ("white_dashed", "white_solid_dashed")
_WD_WD2: Lines = ("white_dashed", "white_double_solid")
_BD_YD2: Lines = ("botts_dots", "yellow_double_solid")
_BD_WD2: Lines = ("botts_dots", "white_double_solid")
_ONE_YD: Lines = ("white_dashed", "yellow_dashed")  # one lane each way: only the centre line shows
_ONE_YS: Lines = ("white_dashed", "yellow_solid")
_ONE_YSD: Lines = ("white_dashed", "yellow_solid_dashed")

# The originals of every illusion type, the first one its representative (shown by the demo site and the editor,
# and the single original of earlier libraries, unchanged). Physically sensible homes: traffic participants off
# the motorway but cars everywhere; guard rails on highways, mountain roads and tunnel approaches; a slotted rail
# deck over built-up roads; fences in open country (where no house or tree shades the road under their low sun);
# sun shadows and sun glare under a sun that can shine; lamp streaks at dusk and night; vehicle mirrors on wet
# roads.
ORIGINALS: dict[str, tuple[Original, ...]] = {
    "road_crack": (
        _o("straight", "suburban", "CloudyNoon"),
        _o("bend", "rural", "ClearSunset", 210.0, _ONE_YD, turn="left", radius=180.0, lanes_per_direction=1,
           lane_width=3.3),
        _o("s_curve", "highway", "WetCloudyNoon", 80.0, _BD_YD2, radius=300.0, lanes_per_direction=3,
           lane_width=3.6, lane=1),
        _o("uphill", "urban", "ClearNoon", 150.0, _WD_YSD, grade=0.05),
        _o("downhill", "rural", "MidRainyNoon", 40.0, _ONE_YS, grade=0.06, lanes_per_direction=1, lane_width=3.2),
        _o("t_junction", "urban", "CloudySunset", 260.0, _WD_WSD, camera="dashcam", junction_s=65.0),
        _o("crossroad", "suburban", "SoftRainNoon", 320.0, None, junction_s=75.0),
    ),
    "road_repair": (
        _o("bend", "urban", "ClearNoon", turn="right", radius=220.0),
        _o("straight", "highway", "CloudyNoon", 120.0, _WD_WD2, camera="tusimple", lanes_per_direction=3,
           lane_width=3.6),
        _o("s_curve", "rural", "ClearSunset", 250.0, _ONE_YD, radius=140.0, lanes_per_direction=1,
           lane_width=3.3),
        _o("uphill", "suburban", "WetNoon", 60.0, _WD_YS, grade=0.05),
        _o("downhill", "urban", "CloudySunset", 300.0, _WD_WSD, grade=0.04),
        _o("crossroad", "urban", "ClearNoon", 200.0, _WD_YSD, junction_s=70.0),
        _o("straight", "tunnel_approach", "CloudyNoon", 250.0),
    ),
    "tire_marks": (
        _o("straight", "highway", "ClearNoon", 100.0, lanes_per_direction=3),
        _o("bend", "highway", "CloudyNoon", 40.0, _BD_YD2, turn="left", radius=300.0, lanes_per_direction=3,
           lane_width=3.6, lane=1),
        _o("s_curve", "rural", "ClearSunset", 190.0, _ONE_YD, radius=150.0, lanes_per_direction=1,
           lane_width=3.3),
        _o("uphill", "highway", "WetCloudyNoon", 230.0, _WD_WD2, grade=0.05),
        _o("downhill", "rural", "ClearNoon", 330.0, _ONE_YS, grade=0.06, lanes_per_direction=1),
        _o("t_junction", "suburban", "CloudyNoon", 140.0, _WD_YSD, junction_s=80.0),
        _o("straight", "tunnel_approach", "ClearSunset", 280.0, _WD_WSD),
    ),
    "guard_rail": (
        _o("bend", "highway", "ClearNoon", 200.0, turn="left", radius=200.0),
        _o("straight", "highway", "CloudyNoon", 110.0, _WD_WD2, camera="carla", lanes_per_direction=3,
           lane_width=3.6, lane=1),
        _o("s_curve", "rural", "ClearSunset", 230.0, _ONE_YD, radius=160.0, lanes_per_direction=1, lane_width=3.3),
        _o("uphill", "highway", "ClearNoon", 70.0, _BD_YD2, grade=0.04, lanes_per_direction=3, lane_width=3.6),
        _o("downhill", "rural", "ClearNoon", 300.0, _ONE_YSD, grade=0.07, lanes_per_direction=1),
        _o("t_junction", "rural", "ClearNoon", 160.0, _WD_YS, junction_s=90.0),
        _o("straight", "tunnel_approach", "CloudySunset", 250.0, _WD_WSD),
    ),
    "pedestrian": (
        _o("crossroad", "urban", "ClearNoon", junction_s=60.0),
        _o("straight", "urban", "CloudyNoon", 80.0, _WD_YS, camera="culane"),
        _o("t_junction", "suburban", "ClearSunset", 240.0, _WD_WSD, junction_s=75.0),
        _o("bend", "suburban", "SoftRainNoon", 120.0, _WD_YSD, turn="left", radius=150.0),
        _o("s_curve", "rural", "CloudyNoon", 300.0, _ONE_YD, radius=140.0, lanes_per_direction=1, lane_width=3.3),
        _o("uphill", "urban", "WetCloudyNoon", 20.0, _WD_WD2, grade=0.05),
        _o("downhill", "urban", "ClearNight", 30.0, None, grade=0.04),
    ),
    "vehicle": (
        _o("straight", "highway", "ClearNoon", lanes_per_direction=3),
        _o("bend", "highway", "CloudyNoon", 330.0, _BD_WD2, camera="tusimple", turn="right", radius=250.0,
           lanes_per_direction=3, lane_width=3.6, lane=1),
        _o("s_curve", "rural", "ClearSunset", 200.0, _WD_YSD, radius=150.0),
        _o("uphill", "suburban", "WetNoon", 100.0, _WD_YS, grade=0.05),
        _o("downhill", "highway", "CloudySunset", 260.0, _WD_WD2, grade=0.05),
        _o("crossroad", "urban", "ClearNoon", 45.0, _WD_WSD, junction_s=75.0),
        _o("straight", "tunnel_approach", "CloudyNoon", 250.0, _WD_YSD),
    ),
    "bicycle": (
        _o("s_curve", "suburban", "ClearNoon", 60.0, radius=160.0),
        _o("straight", "urban", "ClearNoon", 150.0, _WD_YSD, camera="dashcam"),
        _o("bend", "rural", "ClearSunset", 220.0, _ONE_YD, turn="left", radius=120.0, lanes_per_direction=1,
           lane_width=3.3),
        _o("uphill", "suburban", "CloudyNoon", 30.0, _WD_YS, grade=0.05),
        _o("downhill", "rural", "WetNoon", 280.0, _ONE_YS, grade=0.05, lanes_per_direction=1),
        _o("t_junction", "urban", "CloudySunset", 250.0, _WD_WSD, junction_s=70.0),
        _o("crossroad", "suburban", "SoftRainNoon", 130.0, _WD_WD2, junction_s=80.0),
    ),
    "streetlight_shadow": (
        _o("straight", "urban", "ClearNoon", 0.0),
        _o("bend", "suburban", "ClearNoon", 0.0, _WD_YS, turn="right", radius=200.0),
        _o("straight", "highway", "ClearSunset", 0.0, _WD_WD2, camera="tusimple", lanes_per_direction=3,
           lane_width=3.6, lane=1),
        _o("uphill", "suburban", "WetNoon", 0.0, _WD_YSD, grade=0.04),
        _o("downhill", "urban", "ClearNoon", 0.0, _BD_YD2, grade=0.04),
        _o("t_junction", "suburban", "ClearSunset", 0.0, _WD_WSD, junction_s=90.0),
        _o("straight", "tunnel_approach", "ClearNoon", 0.0),
    ),
    "fence_shadow": (
        _o("uphill", "rural", "ClearNoon", 0.0, grade=0.04),
        _o("straight", "rural", "ClearNoon", 0.0, _WD_YS),
        _o("bend", "rural", "ClearSunset", 0.0, _ONE_YD, turn="left", radius=180.0, lanes_per_direction=1,
           lane_width=3.3),
        _o("s_curve", "rural", "WetNoon", 0.0, _WD_YSD, radius=200.0),
        _o("downhill", "rural", "ClearNoon", 0.0, _ONE_YS, grade=0.05, lanes_per_direction=1),
        _o("straight", "highway", "ClearNoon", 0.0, _BD_WD2, camera="carla", lanes_per_direction=3,
           lane_width=3.6),
        _o("crossroad", "rural", "ClearNoon", 0.0, _WD_WSD, junction_s=90.0),
    ),
    "rail_shadow": (
        _o("straight", "urban", "ClearNoon", 0.0),
        _o("bend", "highway", "ClearNoon", 0.0, _BD_YD2, turn="left", radius=250.0, lanes_per_direction=3,
           lane_width=3.6),
        _o("straight", "suburban", "ClearSunset", 0.0, _WD_YS),
        _o("uphill", "urban", "WetNoon", 0.0, _WD_YSD, grade=0.04),
        _o("downhill", "highway", "ClearNoon", 0.0, _WD_WD2, camera="tusimple", grade=0.04),
        _o("crossroad", "urban", "ClearNoon", 0.0, _WD_WSD, junction_s=90.0),
        _o("straight", "tunnel_approach", "CloudyNoon", 0.0),
    ),
    "wire_shadow": (
        _o("bend", "rural", "ClearNoon", 0.0, turn="right", radius=260.0),
        _o("straight", "rural", "ClearNoon", 0.0, _ONE_YD, lanes_per_direction=1, lane_width=3.3),
        _o("s_curve", "suburban", "ClearSunset", 0.0, _WD_YS, radius=220.0),
        _o("uphill", "suburban", "ClearNoon", 0.0, _WD_YSD, grade=0.05),
        _o("downhill", "rural", "WetNoon", 0.0, _ONE_YSD, grade=0.05, lanes_per_direction=1),
        _o("t_junction", "rural", "ClearNoon", 0.0, _WD_WSD, junction_s=90.0),
        _o("crossroad", "suburban", "ClearNoon", 0.0, _WD_WD2, camera="dashcam", junction_s=90.0),
    ),
    "sunlight_reflection": (
        _o("straight", "suburban", "ClearNoon"),
        _o("bend", "highway", "WetNoon", 30.0, _BD_YD2, turn="left", radius=250.0, lanes_per_direction=3,
           lane_width=3.6),
        _o("s_curve", "rural", "WetSunset", 30.0, _ONE_YD, radius=150.0, lanes_per_direction=1),
        _o("uphill", "urban", "WetNoon", 30.0, _WD_YSD, grade=0.04),
        _o("downhill", "suburban", "ClearSunset", 30.0, _WD_YS, grade=0.05),
        _o("crossroad", "urban", "WetSunset", 30.0, _WD_WSD, camera="dashcam", junction_s=80.0),
        _o("straight", "tunnel_approach", "ClearSunset", 30.0, _WD_WD2),
    ),
    "streetlight_reflection": (
        _o("t_junction", "suburban", "ClearNight", junction_s=90.0),
        _o("straight", "urban", "WetNight", 30.0, _WD_YSD),
        _o("bend", "highway", "ClearNight", 30.0, _BD_WD2, turn="right", radius=250.0, lanes_per_direction=3,
           lane_width=3.6),
        _o("crossroad", "urban", "SoftRainSunset", 30.0, _WD_WSD, junction_s=80.0),
        _o("downhill", "suburban", "WetSunset", 30.0, _WD_YS, grade=0.05),
        _o("s_curve", "suburban", "ClearNight", 30.0, _WD_WD2, camera="tusimple", radius=200.0),
        _o("straight", "tunnel_approach", "ClearNight", 30.0, _ONE_YD, lanes_per_direction=1),
    ),
    "vehicle_reflection": (
        _o("downhill", "suburban", "ClearNoon", grade=0.04),
        _o("straight", "highway", "WetNoon", 30.0, _WD_WD2, lanes_per_direction=3, lane_width=3.6),
        _o("bend", "urban", "WetCloudyNoon", 30.0, _WD_YSD, turn="left", radius=200.0),
        _o("s_curve", "rural", "WetSunset", 30.0, _ONE_YD, radius=160.0, lanes_per_direction=1),
        _o("uphill", "highway", "SoftRainNoon", 30.0, _BD_YD2, grade=0.04, lanes_per_direction=3, lane_width=3.6),
        _o("t_junction", "urban", "WetNoon", 30.0, _WD_WSD, junction_s=80.0),
        _o("straight", "tunnel_approach", "WetSunset", 30.0, _WD_YS, camera="dashcam"),
    ),
}

# A word for the time of day and weather of each preset, for case ids.
_TIME_WORDS = {"ClearNoon": "noon", "CloudyNoon": "cloudy", "WetNoon": "wet", "WetCloudyNoon": "wet_cloudy",
               "SoftRainNoon": "rain", "MidRainyNoon": "rain", "HardRainNoon": "heavy_rain",
               "ClearSunset": "sunset", "CloudySunset": "dusk", "WetSunset": "wet_sunset",
               "SoftRainSunset": "rainy_dusk", "ClearNight": "night", "WetNight": "wet_night"}
_PRESET_WORDS = {"ClearNoon": "clear noon", "CloudyNoon": "cloudy noon", "WetNoon": "wet road at noon",
                 "WetCloudyNoon": "wet cloudy noon", "SoftRainNoon": "soft rain", "MidRainyNoon": "steady rain",
                 "HardRainNoon": "hard rain", "ClearSunset": "clear sunset", "CloudySunset": "cloudy dusk",
                 "WetSunset": "wet road at sunset", "SoftRainSunset": "rain at dusk", "ClearNight": "clear night",
                 "WetNight": "wet night"}


def original_id(illusion_type: str, index: int) -> str:
    """The stable, readable id of an original, e.g. ``03_bend_suburban_sunset``: its index among its type's
    originals, road type, scene kind (``tunnel`` for a tunnel approach) and time of day / weather."""
    spec = ORIGINALS[illusion_type][index]
    scene = "tunnel" if spec.scene == "tunnel_approach" else spec.scene
    return f"{index:02d}_{spec.road['type']}_{scene}_{_TIME_WORDS[spec.preset]}"


def _markings(lanes_per_direction: int, lines: Lines) -> list[str]:
    lane_line, centre = lines
    inner = [lane_line] * (lanes_per_direction - 1)
    return ["white_solid", *inner, centre, *inner, "white_solid"]


def _words(spec: Original) -> str:
    road = spec.road["type"].replace("_", " ")
    scene = spec.scene.replace("_", " ")
    lanes = spec.road.get("lanes_per_direction", 2)
    camera = f", {spec.camera} camera" if spec.camera else ""
    return (f"a {road} {scene} road, {lanes} lane{'s' if lanes > 1 else ''} each way, "
            f"{_PRESET_WORDS[spec.preset]}{camera}")


def original_case(illusion_type: str, index: int = 0) -> Case:
    """Original ``index`` of an illusion type (0 = its representative): the clean case it is shown on."""
    spec = ORIGINALS[illusion_type][index]
    label = illusion_type.replace("_", " ")
    lanes = spec.road.get("lanes_per_direction", 2)
    marks = _markings(lanes, spec.lines) if spec.lines is not None else None
    case = _case(f"{label.capitalize()}: original {original_id(illusion_type, index)}",
                 f"The clean case for the {label} illusion: {_words(spec)}.", spec.road, spec.scene, spec.preset,
                 spec.azimuth, lanes_markings=marks)
    if spec.camera is None and spec.lane == 0:
        return case
    data = case.model_dump()
    if spec.camera is not None:
        data["camera"] = {"preset": spec.camera}
    data["ego"]["lane"] = spec.lane
    return parse_case(data, source=case.title)


def perturbed_case(illusion_type: str, severity: int, index: int = 0) -> Case:
    """Original ``index`` of ``illusion_type`` with one illusion of that type at ``severity``."""
    base = original_case(illusion_type, index)
    label = illusion_type.replace("_", " ")
    illusion = REGISTRY[illusion_type](severity=severity)  # type: ignore[call-arg]  # each type's default names it
    return base.model_copy(update={
        "title": f"{label.capitalize()}: level {severity} on {original_id(illusion_type, index)}",
        "description": f"The {label} illusion at severity {severity} of 5 on "
                       f"{_words(ORIGINALS[illusion_type][index])}.",
        "illusions": [illusion],
    })


def original_folder(illusion_type: str, index: int = 0) -> str:
    """``30_shadow/fence_shadow/00_uphill_rural_noon``: the folder of one original and its levels under scenes/."""
    category = CATEGORY_FOLDERS[REGISTRY[illusion_type].CATEGORY]
    return f"{category}/{illusion_type}/{original_id(illusion_type, index)}"


ORIGINAL_FILE = "00_original.json"


def level_file(level: int) -> str:
    """``03_level3.json``: a perturbed case's file name in its original's folder."""
    return f"{level:02d}_level{level}.json"


def illusion_cases() -> dict[str, Case]:
    """Relative path -> case, for every original of every illusion type: the original and levels 1-5."""
    cases: dict[str, Case] = {}
    for name in REGISTRY:
        for index in range(len(ORIGINALS[name])):
            folder = original_folder(name, index)
            cases[f"{folder}/{ORIGINAL_FILE}"] = original_case(name, index)
            for level in LEVELS:
                cases[f"{folder}/{level_file(level)}"] = perturbed_case(name, level, index)
    return cases


def library() -> dict[str, Case]:
    """Every stock case by its path relative to ``scenes/``."""
    return {**clean_cases(), **illusion_cases()}


def write_library(root: Path) -> list[Path]:
    """Write every stock case under ``root`` (atomically); return the written paths."""
    written = []
    for relative, case in library().items():
        path = root / relative
        write_atomic(path, case_json(case).encode("utf-8"))
        written.append(path)
    return written
