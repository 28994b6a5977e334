"""Markings as on real roads: marking standards (dash, gap, widths per country and road class), round raised Botts'
dots, and worn paint's ragged edges and seeded chips; the labels follow the lines whatever their style."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from lanevil_core.case import Case
from lanevil_core.labels import lanes as L
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import Frame, render_frame
from lanevil_core.render.surface import dot_coverage, paint
from lanevil_core.typed import MARKING_STANDARD_NAMES
from lanevil_core.world.marking_standards import MARKING_STANDARDS
from lanevil_core.world.paint import BOTTS_DOT_DIAMETER_M, BOTTS_DOT_SPACING_M, PAINT_WEAR, STRIPE_COLUMNS, dash_spans

ASPHALT = 0.055
RIGHT_LANE_LINE = 3  # boundaries of a two-lane-per-direction road, left to right: edge, lane, centre, lane, edge


def _runs(painted: np.ndarray, s_road: np.ndarray) -> list[tuple[float, float]]:
    """[start, end) stations of every whole run of True in ``painted`` sampled at ``s_road``."""
    step = np.diff(painted.astype(np.int8))
    starts, ends = s_road[1:][step == 1], s_road[1:][step == -1]
    ends = ends[ends > starts[0]]
    return list(zip(starts[:len(ends)], ends[:len(starts)], strict=False))


def test_every_standard_name_has_a_table_row() -> None:
    assert set(MARKING_STANDARDS) | {"custom"} == set(MARKING_STANDARD_NAMES)
    assert all(row.source and row.dash_m > 0 and row.gap_m > 0 for row in MARKING_STANDARDS.values())


@pytest.mark.parametrize("standard", sorted(MARKING_STANDARDS))
def test_a_standard_paints_its_dash_and_gap(make_case: Callable[..., Case], standard: str) -> None:
    """The dash and period of the right lane line, measured in the painted quads (glTF, editor) and in the shader's
    paint along the line, equal the table's; the lane line and the edge take the table's widths."""
    row = MARKING_STANDARDS[standard]  # type: ignore[index]
    scene = compile_scene(make_case(road={"marking_standard": standard, "length": 300.0}))
    t_line = float(scene.network.main.boundaries_t[RIGHT_LANE_LINE])
    s_road = np.arange(20.0, 120.0, 0.01)
    stripes = scene.paint.stripes(scene.network)
    lo = np.flatnonzero(stripes[:, 11] == RIGHT_LANE_LINE)
    painted = np.array([paint(stripes, lo[0], lo[-1] + 1, s, t_line, 0.005, 0.005, 0.0, 0.0, 0.0, 0.0, 0.0)[0]
                        for s in s_road]) > 0.5
    dashes = _runs(painted, s_road)
    assert len(dashes) >= 3
    np.testing.assert_allclose([b - a for a, b in dashes], row.dash_m, atol=0.02)
    np.testing.assert_allclose(np.diff([a for a, _ in dashes]), row.dash_m + row.gap_m, atol=0.02)

    vertices, faces, _colors = scene.paint.mesh(scene.network)
    s_vertex, t_vertex, _h = scene.network.main.line.road_coordinates(vertices)
    near = np.abs(t_vertex - t_line) < 0.5
    quads = np.round(np.sort(np.unique(np.round(s_vertex[near], 3))), 3)
    assert np.isclose(np.diff(quads).max(), row.gap_m, atol=0.02)  # the longest jump between quads is a gap
    own = scene.case.road.markings[RIGHT_LANE_LINE].width  # the width of a standard that names none
    assert np.isclose(np.ptp(t_vertex[near]), row.line_width_m or own, atol=1e-3)
    edge = np.abs(t_vertex - float(scene.network.main.boundaries_t[-1])) < 0.5
    assert np.isclose(np.ptp(t_vertex[edge]), row.edge_width_m or row.line_width_m or own, atol=1e-3)


def test_custom_keeps_every_markings_own_numbers(make_case: Callable[..., Case]) -> None:
    case = make_case(road={"markings": [{"type": "white_dashed", "dash": 2.5, "gap": 5.5, "width": 0.2}] * 5})
    assert case.road.marking_standard == "custom"
    scene = compile_scene(case)
    assert scene.paint.markings == tuple(case.road.markings)


def test_a_standard_changes_no_label(make_case: Callable[..., Case]) -> None:
    records = []
    for standard in ("custom", "de_autobahn"):
        scene = compile_scene(make_case(road={"marking_standard": standard}))
        frame = render_frame(scene, 5)
        records.append(L.tusimple_record(scene, 5, frame, "a.png")["lanes"])
    assert records[0] == records[1]


@pytest.mark.parametrize("bad", ["atlantis", "", 3, None])
def test_an_unknown_standard_is_refused_naming_the_field(make_case: Callable[..., Case], bad: Any) -> None:
    with pytest.raises(ValidationError, match="marking_standard"):
        make_case(road={"marking_standard": bad})


def _dots_row(wear: float = 0.0) -> np.ndarray:
    row = np.zeros((1, STRIPE_COLUMNS))
    radius = BOTTS_DOT_DIAMETER_M / 2
    row[0, :11] = [0, 0.0, radius, 0.0, 100.0, 2, BOTTS_DOT_DIAMETER_M, BOTTS_DOT_SPACING_M, 0.7, 0.7, 0.67]
    row[0, PAINT_WEAR] = wear
    return row


def test_botts_dots_are_round() -> None:
    """Sharp pixels: inside the disc painted, at the corner of its bounding square bare asphalt."""
    r = BOTTS_DOT_DIAMETER_M / 2
    centre = 10 * BOTTS_DOT_SPACING_M + r
    inside = paint(_dots_row(), 0, 1, centre + 0.6 * r, 0.6 * r, 0.002, 0.002, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)
    corner = paint(_dots_row(), 0, 1, centre + 0.85 * r, 0.85 * r, 0.002, 0.002, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)
    between = paint(_dots_row(), 0, 1, centre + 0.5 * BOTTS_DOT_SPACING_M, 0.0, 0.002, 0.002, ASPHALT, ASPHALT,
                    ASPHALT, 0.0, 0.0)
    assert inside[0] > 0.4
    assert corner[0] == ASPHALT and between[0] == ASPHALT


@settings(deadline=None)
@given(ds=st.floats(-0.3, 0.3), dt=st.floats(-0.3, 0.3))
def test_a_dot_seen_from_far_keeps_its_area(ds: float, dt: float) -> None:
    """A footprint wider than twice the dot sees the dot's area spread over it (no shimmer, no lost dots)."""
    r = BOTTS_DOT_DIAMETER_M / 2
    foot = 1.0
    coverage, shade = dot_coverage(ds, dt, foot, foot, r)
    assert np.isclose(coverage, np.pi * r * r / foot**2, rtol=1e-9)
    assert 0.7 < shade < 1.0


@pytest.mark.parametrize("standard", ["custom", "us_mutcd"])
def test_a_standard_groups_botts_dots_into_its_dashes(make_case: Callable[..., Case], standard: str) -> None:
    """Under a standard a Botts'-dot line stands in for its broken line (MUTCD 3B.14): three dots 1.2 m apart in
    each 10 ft dash, a group every 40 ft; a custom road keeps one dot every 1.2 m."""
    markings = ["white_solid", "white_dashed", "yellow_double_solid", "botts_dots", "white_solid"]
    scene = compile_scene(make_case(road={"markings": markings, "marking_standard": standard}))
    rows = scene.paint.stripes(scene.network)
    rows = rows[rows[:, 11] == RIGHT_LANE_LINE]
    starts = np.array([a for row in rows for a, _ in dash_spans(row[3], row[4], 2, row[6], row[7])])
    steps = set(np.round(np.diff(starts), 6))
    if standard == "custom":
        assert steps == {BOTTS_DOT_SPACING_M}
        return
    period = MARKING_STANDARDS["us_mutcd"].dash_m + MARKING_STANDARDS["us_mutcd"].gap_m
    assert steps == {BOTTS_DOT_SPACING_M, round(period - 2 * BOTTS_DOT_SPACING_M, 6)}
    np.testing.assert_allclose(np.diff(starts[::3]), period)


def _along_line(scene: Any, frame: Frame, s_road: np.ndarray) -> np.ndarray:
    """Grey value of the frame at the right lane line's centre, at stations ``s_road``."""
    t_line = float(scene.network.main.boundaries_t[RIGHT_LANE_LINE])
    uv, _depth = frame.camera.project(scene.network.main.line.to_world(s_road, t_line, 0.0))
    col, row = np.round(uv[:, 0] - 0.5).astype(int), np.round(uv[:, 1] - 0.5).astype(int)
    return frame.rgb[row, col].astype(float).mean(axis=-1)


def test_botts_dots_render_as_dots_and_keep_the_solid_lines_label(make_case: Callable[..., Case]) -> None:
    frames, records, grey = {}, {}, {}
    for line in ("white_solid", "botts_dots"):
        markings = ["white_solid", "white_dashed", "yellow_double_solid", line, "white_solid"]
        scene = compile_scene(make_case(road={"markings": markings}, camera={"width": 640, "height": 360}))
        frames[line] = render_frame(scene, 0)
        records[line] = L.tusimple_record(scene, 0, frames[line], "a.png")["lanes"]
        s_ego = scene.ego.s_road(0)
        grey[line] = _along_line(scene, frames[line], np.arange(s_ego + 8.0, s_ego + 14.0, 0.02))
    assert records["botts_dots"] == records["white_solid"]
    asphalt = np.median(grey["botts_dots"])  # the dots cover less than a tenth of the line
    solid_share = np.mean(grey["white_solid"] > asphalt + 40)
    dot_share = np.mean(grey["botts_dots"] > asphalt + 40)
    assert solid_share > 0.95
    assert 0.0 < dot_share < 0.4


def test_fresh_paint_ignores_the_edge_noise() -> None:
    row = _dots_row()
    row[0, 2], row[0, 5] = 0.075, 0  # a solid line 0.15 m wide
    for t in (0.0, 0.07, 0.074, 0.08):
        assert paint(row, 0, 1, 5.0, t, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 1.0) == \
            paint(row, 0, 1, 5.0, t, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)


def test_worn_paint_has_ragged_edges_and_a_whole_middle() -> None:
    """Where the edge noise bites, a worn line's edge is bare and its middle still painted."""
    row = _dots_row(wear=0.8)
    row[0, 2], row[0, 5] = 0.075, 0

    def grey(t: float, ragged: float) -> float:
        return paint(row, 0, 1, 5.0, t, 0.005, 0.005, ASPHALT, ASPHALT, ASPHALT, -0.5, ragged)[0]

    assert grey(0.065, 1.0) == ASPHALT < grey(0.065, 0.0)
    assert grey(0.0, 1.0) == grey(0.0, 0.0) > ASPHALT


def _worn(make_case: Callable[..., Case], seed: int) -> tuple[Frame, Any]:
    markings = [{"type": name, "wear": 0.6} for name in
                ("white_solid", "white_dashed", "yellow_double_solid", "white_dashed", "white_solid")]
    scene = compile_scene(make_case(seed=seed, road={"markings": markings}))
    frame = render_frame(scene, 5)
    return frame, L.tusimple_record(scene, 5, frame, "a.png")["lanes"]


def test_wear_is_the_same_under_a_seed_and_differs_under_another(make_case: Callable[..., Case]) -> None:
    first, labels = _worn(make_case, 3)
    again, _ = _worn(make_case, 3)
    other, other_labels = _worn(make_case, 4)
    assert np.array_equal(first.rgb, again.rgb)
    assert other_labels == labels
    assert not np.array_equal(first.rgb, other.rgb)


@pytest.mark.parametrize("road", [{"markings": [{"type": "white_solid", "wear": 1.5}] * 5},
                                  {"markings": [{"type": "white_solid", "wear": -0.1}] * 5},
                                  {"markings": [{"type": "dotted"}] * 5}])
def test_bad_marking_values_are_refused_naming_the_field(make_case: Callable[..., Case], road: dict) -> None:
    with pytest.raises(ValidationError, match=r"markings\.0\.(wear|type)"):
        make_case(road=road)
