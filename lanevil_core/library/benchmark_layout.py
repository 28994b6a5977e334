"""Names of the published LanEvil dataset layout: ``<Category>/<Type>/<case>/000000.png … labels.json``, where
``<case>`` is ``<original>/<level file stem>`` for the stock library's one folder per original case
(``Shadow/Fence/00_uphill_rural_noon/03_level3``).

The one place mapping the registry's illusion types (``road_crack``, …) to the benchmark's folder names
(``RoadDamage/RoadCrack``, …). Dataset generation, exports and the web API all build paths from here.

A case holding illusions of several types is filed under ``Mixed/<CategoryType>+<CategoryType>/<case>``
(``Mixed/ShadowFence+ReflectionSunLight/...``, types in registry order); its type name is the registry types
joined by ``+`` (``fence_shadow+sunlight_reflection``) and its category ``mixed``, so the API, the study and the
reports group it on its own rather than under its first illusion.
"""

from __future__ import annotations

from pathlib import PurePosixPath

from ..case import Case
from ..illusions import REGISTRY

CATEGORY_FOLDERS: dict[str, str] = {
    "road_damage": "RoadDamage",
    "traffic": "TrafficObstruction",
    "shadow": "Shadow",
    "reflection": "Reflection",
}
TYPE_FOLDERS: dict[str, str] = {
    "road_crack": "RoadCrack",
    "road_repair": "RoadRepair",
    "tire_marks": "TireMarks",
    "guard_rail": "GuardRail",
    "pedestrian": "Pedestrian",
    "bicycle": "Bicycle",
    "vehicle": "Vehicle",
    "streetlight_shadow": "StreetLight",
    "fence_shadow": "Fence",
    "rail_shadow": "Rail",
    "wire_shadow": "Wire",
    "sunlight_reflection": "SunLight",
    "streetlight_reflection": "StreetLight",
    "vehicle_reflection": "Vehicle",
}
CLEAN_FOLDER = "Clean"  # cases with no illusion and no illusion type to file them under
MIXED_FOLDER = "Mixed"  # cases holding illusions of several types
MIXED_CATEGORY = "mixed"
TYPE_JOIN = "+"
LABELS_FILE = "labels.json"


def frame_file(index: int, suffix: str = ".png") -> str:
    """``000000.png``: the benchmark's six-digit frame file name."""
    return f"{index:06d}{suffix}"


def illusion_folder(illusion_type: str) -> PurePosixPath:
    """``Category/Type`` of a registry type, e.g. ``streetlight_shadow`` -> ``Shadow/StreetLight``."""
    if illusion_type not in REGISTRY:
        raise KeyError(f"unknown illusion type {illusion_type!r}")
    return PurePosixPath(CATEGORY_FOLDERS[REGISTRY[illusion_type].CATEGORY], TYPE_FOLDERS[illusion_type])


def case_types(case: Case, fallback: str | None = None) -> tuple[str, ...]:
    """The distinct illusion types a case holds, in registry order; ``(fallback,)`` for a case with none (an
    original filed by its folders), ``()`` for a clean case."""
    if not case.illusions:
        return (fallback,) if fallback is not None else ()
    held = {illusion.type for illusion in case.illusions}
    return tuple(name for name in REGISTRY if name in held)


def case_illusion_type(case: Case, fallback: str | None = None) -> str | None:
    """The type a case is filed under: its illusions' type (several joined by ``+``: a mixed case), else
    ``fallback`` (an original's type), else None."""
    types = case_types(case, fallback)
    return TYPE_JOIN.join(types) if types else None


def type_category(type_name: str) -> str:
    """The category of a type name from ``case_illusion_type``: the registry's, or ``mixed``."""
    return MIXED_CATEGORY if TYPE_JOIN in type_name else REGISTRY[type_name].CATEGORY


def case_filing(case: Case, fallback: str | None = None) -> tuple[str, str] | None:
    """(category folder, type folder) a case is filed under; None for a clean case."""
    types = case_types(case, fallback)
    if not types:
        return None
    if len(types) == 1:
        return CATEGORY_FOLDERS[REGISTRY[types[0]].CATEGORY], TYPE_FOLDERS[types[0]]
    return MIXED_FOLDER, TYPE_JOIN.join(str(illusion_folder(name)).replace("/", "") for name in types)


def case_folder(case: Case, name: str | PurePosixPath, fallback_type: str | None = None) -> PurePosixPath:
    """``Category/Type/name`` for a case (``Mixed/...`` for several types); clean cases with no type go under
    ``Clean/name``."""
    filing = case_filing(case, fallback_type)
    if filing is None:
        return PurePosixPath(CLEAN_FOLDER, name)
    return PurePosixPath(*filing) / name


def folder_type(relative: PurePosixPath) -> str | None:
    """The illusion type a case file's folders name: its parent (``fence_shadow/00_original.json``) or, with one
    folder per original case, its grandparent (``fence_shadow/00_uphill_rural_noon/00_original.json``)."""
    for folder in (relative.parent.name, relative.parent.parent.name):
        if folder in REGISTRY:
            return folder
    return None


def case_name(relative: PurePosixPath) -> PurePosixPath:
    """A case file's name below its type folder, without suffix: ``00_uphill_rural_noon/03_level3`` (one folder
    per original), ``03_level3`` (one folder per type) or the file's stem when no type folder names it."""
    stem = PurePosixPath(relative.stem)
    if relative.parent.name in REGISTRY or folder_type(relative) is None:
        return stem
    return relative.parent.name / stem
