"""The stock library at the paper's scale: enough originals per type, spread over roads, scenes, paint, weather
and cameras, in one folder per original with stable readable ids."""

from __future__ import annotations

import re
from collections import Counter

from lanevil_core.illusions import REGISTRY
from lanevil_core.library.stock import (
    ORIGINAL_FILE,
    ORIGINALS,
    illusion_cases,
    level_file,
    original_case,
    original_folder,
    original_id,
    perturbed_case,
)
from lanevil_core.typed import LINE_TYPES, ROAD_TYPES, SCENE_KINDS

ORIGINAL_ID = re.compile(r"^\d\d_(straight|bend|s_curve|uphill|downhill|t_junction|crossroad)_"
                         r"(urban|suburban|highway|rural|tunnel)_[a-z_]+$")


def _originals() -> list[tuple[str, int]]:
    return [(name, index) for name in REGISTRY for index in range(len(ORIGINALS[name]))]


def test_at_least_94_originals_and_six_per_type() -> None:
    assert set(ORIGINALS) == set(REGISTRY)
    assert len(_originals()) >= 94
    assert min(len(originals) for originals in ORIGINALS.values()) >= 6
    assert len(illusion_cases()) == 6 * len(_originals()) >= 560


def test_originals_cover_roads_scenes_paint_weather_and_cameras() -> None:
    cases = [original_case(name, index) for name, index in _originals()]
    assert {case.road.type for case in cases} == set(ROAD_TYPES)
    assert {case.scene.kind for case in cases} == set(SCENE_KINDS)
    assert {m.type for case in cases for m in case.road.markings} == set(LINE_TYPES) - {"none"}
    assert {case.road.lanes_per_direction for case in cases} == {1, 2, 3}
    assert len({(case.weather.model_dump_json(), case.sun.altitude) for case in cases}) >= 8  # weathers, times of day
    assert {o.camera for originals in ORIGINALS.values() for o in originals} > {None}
    assert Counter(o.camera for originals in ORIGINALS.values() for o in originals)[None] > 0.8 * len(cases)
    for name in REGISTRY:  # each type on several road types and at least two kinds of scene
        mine = [original_case(name, index) for index in range(len(ORIGINALS[name]))]
        assert len({case.road.type for case in mine}) >= 5 and len({case.scene.kind for case in mine}) >= 2, name


def test_ids_are_stable_readable_and_unique() -> None:
    assert original_id("fence_shadow", 0) == "00_uphill_rural_noon"
    assert original_folder("fence_shadow", 2) == "30_shadow/fence_shadow/02_bend_rural_sunset"
    for name in REGISTRY:
        ids = [original_id(name, index) for index in range(len(ORIGINALS[name]))]
        assert len(set(ids)) == len(ids) and all(ORIGINAL_ID.fullmatch(i) for i in ids), ids
    folder = original_folder("vehicle", 1)
    assert {f"{folder}/{ORIGINAL_FILE}", f"{folder}/{level_file(3)}"} <= set(illusion_cases())


def test_a_perturbed_case_differs_from_its_original_only_in_its_illusion() -> None:
    for name, index in _originals():
        original, perturbed = original_case(name, index), perturbed_case(name, 4, index)
        assert not original.illusions and [(i.type, i.severity) for i in perturbed.illusions] == [(name, 4)]
        strip = {"title", "description", "illusions"}
        assert original.model_dump(exclude=strip) == perturbed.model_dump(exclude=strip), (name, index)


def test_layout_names_the_type_and_case_of_either_layout() -> None:
    from pathlib import PurePosixPath

    from lanevil_core.library.benchmark_layout import case_name, folder_type

    per_original = PurePosixPath("30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    per_type = PurePosixPath("30_shadow/fence_shadow/03_level3.json")
    clean = PurePosixPath("00_clean/00_straight_urban.json")
    assert [folder_type(p) for p in (per_original, per_type, clean)] == ["fence_shadow", "fence_shadow", None]
    assert [str(case_name(p)) for p in (per_original, per_type, clean)] == [
        "00_uphill_rural_noon/03_level3", "03_level3", "00_straight_urban"]
