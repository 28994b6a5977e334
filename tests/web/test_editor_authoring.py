"""Authoring a case in the editor's panel: every field of the case model has an input (walked from the model's JSON
schema), bounds and refusals show in place, and a new lane count keeps the markings' styles."""

from __future__ import annotations

from typing import Any

import pytest

from app.editor import EditError, EditorTab
from app.editor.panels.start import matching, recent
from lanevil_core.case import Marking, case_schema, default_markings, resize_markings

SKIPPED = {("schema_version",), ("illusions",)}  # fixed, and the Illusions panel's own inputs


def schema_paths(schema: dict[str, Any]) -> set[tuple[str, ...]]:
    """The path of every leaf field of the case model (list items and optional models walked into)."""
    defs = schema.get("$defs", {})

    def resolve(node: dict[str, Any]) -> dict[str, Any]:
        if "$ref" in node:
            return resolve(defs[node["$ref"].rsplit("/", 1)[-1]])
        if "anyOf" in node:  # an optional model: its non-null branch
            branches = [resolve(b) for b in node["anyOf"] if b.get("type") != "null"]
            return next((b for b in branches if "properties" in b), branches[0])
        if node.get("type") == "array" and "properties" in resolve(node.get("items", {})):
            return resolve(node["items"])
        return node

    def walk(node: dict[str, Any], prefix: tuple[str, ...]) -> set[tuple[str, ...]]:
        node = resolve(node)
        if "properties" not in node or prefix in SKIPPED:
            return {prefix}
        found: set[tuple[str, ...]] = set()
        for name, child in node["properties"].items():
            found |= walk(child, (*prefix, name))
        return found

    return {path for path in walk(schema, ()) if path not in SKIPPED}


def panel_paths(tab: EditorTab) -> set[tuple[str, ...]]:
    return set().union(*(panel.field_paths() for panel in (tab.cases, tab.road, tab.scene, tab.sun, tab.camera)))


def test_every_case_model_field_has_an_input_in_the_panel(tab: EditorTab) -> None:
    fields = schema_paths(case_schema())
    assert {("road", "markings", "type"), ("camera", "sensor", "noise"), ("weather", "fog_density"),
            ("ego", "frames"), ("seed",), ("description",)} <= fields  # the walk reaches nested and listed fields
    missing = fields - panel_paths(tab)
    assert not missing, f"case fields without a panel input: {sorted(missing)}"


def test_inputs_carry_the_model_s_bounds(tab: EditorTab) -> None:
    lanes = tab.road.section.inputs.handles["lanes_per_direction"]
    assert (lanes.min, lanes.max) == (1, 4) and "(1 – 4)" in lanes.hint
    frames = tab.scene.ego.inputs.handles["frames"]
    assert (frames.min, frames.max) == (50, 300)


def test_a_refused_value_is_shown_in_place_and_the_input_goes_back(tab: EditorTab) -> None:
    start = tab.scene.ego.inputs.handles["start_s"]
    before = tab.case.ego.start_s
    start.value = tab.case.road.length  # the drive would run past the end of the road
    assert tab.case.ego.start_s == before and start.value == before
    error = tab.scene.ego.error
    assert error.visible and "keep 60 m of road ahead" in error.content
    assert "keep 60 m of road ahead" in tab.status.content  # and on the status line
    start.value = before + 1
    assert tab.case.ego.start_s == before + 1 and not error.visible


def test_a_new_lane_count_keeps_the_markings_styles_and_the_ego_on_the_road(tab: EditorTab) -> None:
    tab.road.line_types[0].value = "none"
    tab.road.line_types[2].value = "yellow_solid"
    tab.road.line_types[3].value = "botts_dots"
    tab.scene.ego.inputs.handles["lane"].value = 1
    tab.road.section.inputs.handles["lanes_per_direction"].value = 3
    road = tab.case.road
    assert [m.type for m in road.markings] == ["none", "white_dashed", "white_dashed", "yellow_solid", "botts_dots",
                                               "botts_dots", "white_solid"]
    assert len(tab.road.line_types) == 7 and tab.road.line_types[4].value == "botts_dots"
    tab.road.section.inputs.handles["lanes_per_direction"].value = 1
    assert [m.type for m in tab.case.road.markings] == ["none", "yellow_solid", "white_solid"]
    assert tab.case.ego.lane == 0


def test_all_lines_and_nested_camera_fields_edit_the_case(tab: EditorTab) -> None:
    tab.road.lines.handles["wear"].value = 0.4
    assert {m.wear for m in tab.case.road.markings} == {0.4}
    tab.camera.sensor.value = True
    tab.camera.more.inputs.children["sensor"].handles["white_balance"].value = 4000.0
    assert tab.case.camera.sensor is not None and tab.case.camera.sensor.white_balance == 4000.0
    tab.sun.weather_numbers.inputs.handles["fog_density"].value = 35.0
    tab.scene.seed.value = 7
    assert tab.case.weather.fog_density == 35.0 and tab.case.seed == 7


@pytest.mark.parametrize("lanes", [1, 2, 3, 4])
def test_resized_defaults_are_the_defaults(lanes: int) -> None:
    for before in (1, 2, 3, 4):
        assert resize_markings(default_markings(before), lanes) == default_markings(lanes)
    custom = [Marking(type=t) for t in ("none", "botts_dots", "yellow_solid", "white_solid_dashed", "white_solid")]
    resized = resize_markings(custom, lanes)
    assert len(resized) == 2 * lanes + 1 and resized[lanes].type == "yellow_solid" and resized[0].type == "none"


def test_editing_without_an_open_case_says_what_to_do(tab: EditorTab) -> None:
    tab.session = None
    with pytest.raises(EditError, match="open a case first"):
        tab.road.set_field(("length",), 500.0)


SHADOW = "fence_shadow-00_uphill_rural_noon-03_level3"


def settled(tab: EditorTab) -> None:
    assert tab.preview.wait_idle(120.0)


def owner_note(tab: EditorTab) -> str:
    """The sun panel's line as it reads (markdown escapes removed)."""
    return tab.sun.owner.content.replace("\\", "")


def test_one_sun_the_panel_says_who_sets_it_and_asks_before_an_illusion_overrides_it(tab: EditorTab) -> None:
    tab.cases.case_id.value = SHADOW  # a fence shadow: its own sun, which the sliders set
    settled(tab)
    assert "Sun set by illusion **0: fence_shadow** (the sliders set its sun)" in owner_note(tab)
    assert not tab.sun.altitude.disabled
    assert tab.illusions.place("sunlight_reflection", 60.0, -1.75) is None  # asked first, nothing placed yet
    assert tab.illusions.pending_sun is not None and len(tab.case.illusions) == 1
    assert tab.illusions.answer_sun(False) is None and len(tab.case.illusions) == 1  # Cancel keeps the case
    tab.illusions.place("sunlight_reflection", 60.0, -1.75)
    assert tab.illusions.answer_sun(True) == 1 and [i.type for i in tab.case.illusions] == [
        "fence_shadow", "sunlight_reflection"]
    settled(tab)
    note = owner_note(tab)
    assert "Sun set by illusion **1: sunlight_reflection**" in note and "overrides the sun of 0: fence_shadow" in note
    assert tab.sun.altitude.disabled and tab.sun.azimuth.disabled  # they would not move the rendered sun
    assert tab.illusions.place("road_crack", 80.0, -1.75) == 2  # no sun of its own: placed at once


def test_the_start_screen_offers_new_recent_and_a_searchable_library(tab: EditorTab) -> None:
    start = tab.start
    assert start is not None and start.modal is not None
    rows = {row.case_id: row for row in start.rows}
    shadow = rows[SHADOW]
    assert (shadow.category, shadow.type, shadow.original) == ("shadow", "fence_shadow", "00_uphill_rural_noon")
    assert rows["clean-00_straight_urban"].original == "-"
    start.category.value = "shadow"
    assert list(start.type.options) == ["(any)", "fence_shadow"]
    start.search.value = "level3 uphill"
    assert [label.split(" — ")[0] for label in start.case.options] == [SHADOW]
    thumbnail = start.show_thumbnail()
    assert thumbnail is not None
    thumbnail.join(120)
    assert start.thumbnail.image is not None and start.thumbnail.image.shape == (180, 320, 3)
    assert start.thumbnail.image.std() > 10  # a rendered road, not the grey placeholder
    start.open(start._chosen())
    assert tab.session is not None and tab.session.case_id == SHADOW and start.modal is None
    tab.cases.title.value = "touched"
    tab.cases.save()
    assert recent(tab.state.store.list())[0].id == SHADOW  # the case saved last comes first


def test_the_start_screen_creates_a_new_case(tab: EditorTab) -> None:
    start = tab.start
    assert start is not None
    start.road.value = "bend"
    case_id = start.new_case()
    assert tab.session is not None and tab.session.case_id == case_id and tab.case.road.type == "bend"
    assert matching(start.rows, "(any)", "(any)", "no-such-words") == []
