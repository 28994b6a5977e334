"""Tests generated from the illusion registry: every type x severity level."""

from __future__ import annotations

import dataclasses
import json
from typing import Any

import numpy as np
import pytest

from lanevil_core.case import Case, case_json, parse_case
from lanevil_core.illusions import CATEGORIES, REGISTRY
from lanevil_core.labels.lanes import tusimple_record
from lanevil_core.library.stock import original_case, perturbed_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.pipeline.illusion_effect import band_change, lane_band
from lanevil_core.render import render_frame
from lanevil_core.world.scene import Mesh, PointLight, SurfaceLayer

TYPES = list(REGISTRY)
LEVELS = [1, 2, 3, 4, 5]
SIZE = (320, 180)
# Level 5 on the stock case must visibly change the lane band: at least this share of its pixels changes by more
# than illusion_effect.CHANGED_LEVEL (measured 0.08 for pedestrians up to 0.98 for the fence shadow).
MIN_LEVEL5_SHARE = 0.05


def test_registry_is_the_benchmark_taxonomy() -> None:
    expected = {
        "road_damage": {"road_crack", "road_repair", "tire_marks", "guard_rail"},
        "traffic": {"pedestrian", "vehicle", "bicycle"},
        "shadow": {"streetlight_shadow", "fence_shadow", "rail_shadow", "wire_shadow"},
        "reflection": {"sunlight_reflection", "streetlight_reflection", "vehicle_reflection"},
    }
    assert len(REGISTRY) == 14
    assert {c: {n for n, cls in REGISTRY.items() if cls.CATEGORY == c} for c in CATEGORIES} == expected


@pytest.mark.parametrize("name", TYPES)
def test_severity_table_has_five_rows_of_one_frozen_type(name: str) -> None:
    illusion: Any = REGISTRY[name]  # each family its own row type
    table = illusion.SEVERITY
    assert len(table) == 5
    assert all(type(row) is type(table[0]) for row in table)
    assert type(table[0]).__dataclass_params__.frozen and dataclasses.is_dataclass(table[0])
    assert illusion(severity=2).level() is table[1]


@pytest.mark.parametrize("name", TYPES)
def test_minimal_spec_is_valid_in_any_case(name: str) -> None:
    case = parse_case({"road": {"type": "bend"}, "illusions": [{"type": name, "severity": 3}]})
    assert case.illusions[0].type == name


@pytest.mark.parametrize("name", TYPES)
def test_bad_severity_names_the_field(name: str) -> None:
    with pytest.raises(ValueError, match=r"illusions\.0\..*severity"):
        parse_case({"illusions": [{"type": name, "severity": 9}]})


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("name", TYPES)
def test_json_round_trip(name: str, level: int) -> None:
    case = perturbed_case(name, level)
    again = parse_case(json.loads(case_json(case)))
    assert again == case
    assert case_json(again) == case_json(case)


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("name", TYPES)
def test_compile_is_deterministic(name: str, level: int) -> None:
    a, b = compile_scene(perturbed_case(name, level)), compile_scene(perturbed_case(name, level))
    assert len(a.meshes) == len(b.meshes) and len(a.layers) == len(b.layers) and len(a.lights) == len(b.lights)
    for m, n in zip(a.meshes, b.meshes):
        assert np.array_equal(m.vertices, n.vertices) and np.array_equal(m.colors, n.colors)
    for layer_a, layer_b in zip(a.layers, b.layers):
        assert np.array_equal(layer_a.rgba, layer_b.rgba)
    parts: list[Mesh | SurfaceLayer | PointLight] = [*a.meshes, *a.layers, *a.lights]
    added = sum(item.source >= 0 for item in parts)
    assert added > 0, "an illusion must add something to the 3D world"


def _render(case: Case) -> tuple[np.ndarray, dict]:
    scene = compile_scene(case.model_copy(update={"camera": case.camera.model_copy(
        update={"width": SIZE[0], "height": SIZE[1]})}))
    frame = render_frame(scene, 0)
    return frame.rgb, tusimple_record(scene, 0, frame, raw_file="000000.png")


@pytest.mark.slow
@pytest.mark.parametrize("name", TYPES)
def test_effect_is_deterministic_keeps_labels_and_changes_the_lane_band(name: str) -> None:
    """Every level renders the same bytes twice and keeps the lane labels; level 5 changes the lane band. That
    the change rises with the level is tests/core/test_severity_ladders.py's (on clean stock cases)."""
    original, record0 = _render(original_case(name))
    band = lane_band(record0["lanes"], record0["h_samples"], (original.shape[1], original.shape[0]))
    assert band.sum() > 500
    for level in LEVELS:
        rgb, record = _render(perturbed_case(name, level))
        again, _ = _render(perturbed_case(name, level))
        assert np.array_equal(rgb, again), f"{name} level {level} is not deterministic"
        assert record["lanes"] == record0["lanes"], f"{name} level {level} moved the lane labels"
    share = band_change(original, rgb, band).share
    assert share > MIN_LEVEL5_SHARE, f"{name}: level 5 barely changes the lane band ({share:.3f})"
