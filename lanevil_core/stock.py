"""The stock case library: clean cases covering every road type, line type and scene kind, and for every
illusion type an original case with its perturbed cases at levels 1-5.

This module is the source of the JSON files under ``scenes/`` (``lanevil library --out scenes`` writes them);
a perturbed case differs from its original only in its ``illusions`` list.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .case import Case, case_json, parse_case, write_atomic
from .illusions import REGISTRY
from .presets import preset_values

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

# The original (clean) case each illusion type is shown on: road, scene, preset, sun azimuth.
_BASES: dict[str, tuple[dict[str, Any], str, str, float]] = {
    "road_crack": ({"type": "straight"}, "suburban", "CloudyNoon", 30.0),
    "road_repair": ({"type": "bend", "turn": "right", "radius": 220.0}, "urban", "ClearNoon", 30.0),
    "tire_marks": ({"type": "straight", "lanes_per_direction": 3}, "highway", "ClearNoon", 100.0),
    "guard_rail": ({"type": "bend", "turn": "left", "radius": 200.0}, "highway", "ClearNoon", 200.0),
    "pedestrian": ({"type": "crossroad", "junction_s": 60.0}, "urban", "ClearNoon", 30.0),
    "vehicle": ({"type": "straight", "lanes_per_direction": 3}, "highway", "ClearNoon", 30.0),
    "bicycle": ({"type": "s_curve", "radius": 160.0}, "suburban", "ClearNoon", 60.0),
    "streetlight_shadow": ({"type": "straight"}, "urban", "ClearNoon", 0.0),
    "fence_shadow": ({"type": "uphill", "grade": 0.04}, "rural", "ClearNoon", 0.0),
    "rail_shadow": ({"type": "straight"}, "urban", "ClearNoon", 0.0),
    "wire_shadow": ({"type": "bend", "turn": "right", "radius": 260.0}, "rural", "ClearNoon", 0.0),
    "sunlight_reflection": ({"type": "straight"}, "suburban", "ClearNoon", 30.0),
    "streetlight_reflection": ({"type": "t_junction", "junction_s": 90.0}, "suburban", "ClearNight", 30.0),
    "vehicle_reflection": ({"type": "downhill", "grade": 0.04}, "suburban", "ClearNoon", 30.0),
}


def clean_cases() -> dict[str, Case]:
    """Relative path (under scenes/) -> clean case."""
    return {f"00_clean/{name}.json": _case(title, description, road, scene, preset, azimuth, lanes_markings=marks)
            for name, (title, description, road, scene, preset, azimuth, marks) in _CLEAN.items()}


def original_case(illusion_type: str) -> Case:
    """The clean case an illusion type is shown on."""
    road, scene, preset, azimuth = _BASES[illusion_type]
    label = illusion_type.replace("_", " ")
    return _case(f"{label.capitalize()}: original", f"The clean case for the {label} illusion.", road, scene,
                 preset, azimuth)


def perturbed_case(illusion_type: str, severity: int) -> Case:
    """The original case with one illusion of ``illusion_type`` at ``severity``."""
    base = original_case(illusion_type)
    label = illusion_type.replace("_", " ")
    illusion = REGISTRY[illusion_type](severity=severity)  # type: ignore[call-arg]  # each type's default names it
    return base.model_copy(update={
        "title": f"{label.capitalize()}: level {severity}",
        "description": f"The {label} illusion at severity {severity} of 5 on its original case.",
        "illusions": [illusion],
    })


def illusion_cases() -> dict[str, Case]:
    """Relative path -> case, for every illusion type: the original and levels 1-5."""
    cases: dict[str, Case] = {}
    for name, cls in REGISTRY.items():
        folder = f"{CATEGORY_FOLDERS[cls.CATEGORY]}/{name}"
        cases[f"{folder}/00_original.json"] = original_case(name)
        for level in LEVELS:
            cases[f"{folder}/{level:02d}_level{level}.json"] = perturbed_case(name, level)
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
