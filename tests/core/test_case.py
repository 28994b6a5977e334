"""Case model: validation messages name the field, presets fill numbers, saves are atomic."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from lanevil_core.case import Case, CaseError, case_json, case_schema, load_case, parse_case, save_case

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("data", "field"), [
    ({"road": {"lane_width": 1.0}}, "road.lane_width"),
    ({"road": {"type": "roundabout"}}, "road.type"),
    ({"road": {"markings": ["white_solid"]}}, "road"),
    ({"road": {"markings": ["white_solid", "pink_dashed", "yellow_double_solid", "white_dashed", "white_solid"]}},
     "road.markings.1"),
    ({"ego": {"frames": 20}}, "ego.frames"),
    ({"ego": {"lane": 5}}, "ego.lane"),
    ({"sun": {"altitude": 120}}, "sun.altitude"),
    ({"illusions": [{"type": "meteor"}]}, "illusions.0"),
    ({"colour": "red"}, "colour"),
])
def test_errors_name_the_field(data: dict, field: str) -> None:
    with pytest.raises(CaseError) as info:
        parse_case(data)
    message = str(info.value)
    assert field in message and "\n" not in message


def test_preset_fills_numbers_and_explicit_fields_win() -> None:
    case = parse_case({"preset": "WetSunset", "sun": {"azimuth": 90.0}, "weather": {"cloudiness": 40}})
    assert case.sun.altitude == 15 and case.sun.azimuth == 90.0
    assert case.weather.precipitation_deposits == 50 and case.weather.cloudiness == 40
    assert "preset" not in json.loads(case_json(case))
    with pytest.raises(CaseError, match="unknown weather preset"):
        parse_case({"preset": "Sunny"})


def test_unreadable_and_broken_files(tmp_path: Path) -> None:
    with pytest.raises(CaseError, match="cannot read"):
        load_case(tmp_path / "missing.json")
    broken = tmp_path / "broken.json"
    broken.write_text('{"road": ')
    with pytest.raises(CaseError, match="not valid JSON"):
        load_case(broken)


def test_save_is_atomic_and_round_trips(tmp_path: Path) -> None:
    case = parse_case({"road": {"type": "bend"}, "illusions": [{"type": "wire_shadow", "severity": 2}]})
    path = tmp_path / "case.json"
    save_case(case, path)
    assert load_case(path) == case
    assert [p.name for p in tmp_path.iterdir()] == ["case.json"]  # no temp file left behind


def test_drive_must_fit_on_the_road() -> None:
    with pytest.raises(CaseError, match="ego"):
        parse_case({"road": {"length": 100}, "ego": {"speed": 30, "frames": 300}})


def test_schema_is_a_discriminated_union_and_the_committed_copy_is_current() -> None:
    schema = case_schema()
    items = schema["properties"]["illusions"]["items"]
    assert items["discriminator"]["propertyName"] == "type"
    assert len(items["discriminator"]["mapping"]) == 14
    committed = json.loads((ROOT / "docs" / "case.schema.json").read_text())
    assert committed == json.loads(json.dumps(schema)), "run `lanevil schema --out docs/case.schema.json`"


def test_default_case_is_the_benchmark_camera() -> None:
    camera = Case().camera
    assert (camera.width, camera.height, camera.fov, camera.x, camera.z, camera.pitch) == (1280, 720, 90.0, 1.0,
                                                                                              3.0, 0.0)
    assert Case().ego.fps == 10
