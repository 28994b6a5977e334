"""Junction markings: crosswalks, stop and give-way lines and lane-use arrows painted at a junction's approaches, to
the road's marking standard; exact box filtering of painted polygons; they change no label and nothing off the
junction."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.case import Case
from lanevil_core.labels import lanes as L
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.surface import box_overlap, paint, polygon_coverage
from lanevil_core.typed import MARKING_STANDARD_NAMES
from lanevil_core.world import paint as paint_module
from lanevil_core.world.arrow_shapes import arrow_parts, lane_heads
from lanevil_core.world.junction_markings import JUNCTION_STANDARDS, Mark, approaches, junction_marks
from lanevil_core.world.paint import MAX_CORNERS, POLYGON, POLYGON_CORNERS, STRIPE_COLUMNS, mark_row, stripe_index

ASPHALT = 0.055
APPROACH_REACH_M = 30.0  # crosswalk, stop line and arrows lie within this of the junction's mouth


def _polygon_row(corners: np.ndarray) -> np.ndarray:
    row = np.zeros(STRIPE_COLUMNS)
    padded = np.concatenate([corners, np.repeat(corners[-1:], MAX_CORNERS - len(corners), axis=0)])
    row[POLYGON_CORNERS:] = padded.ravel()
    row[5] = POLYGON
    return row


def _supersampled(corners: np.ndarray, s: float, t: float, fs: float, ft: float, n: int = 400) -> float:
    """Share of the footprint inside the convex polygon, on an n x n grid of the footprint."""
    grid_s, grid_t = np.meshgrid(s + ((np.arange(n) + 0.5) / n - 0.5) * fs, t + ((np.arange(n) + 0.5) / n - 0.5) * ft)
    inside = np.ones_like(grid_s, bool)
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        if np.allclose(a, b):
            continue
        inside &= (b[0] - a[0]) * (grid_t - a[1]) - (b[1] - a[1]) * (grid_s - a[0]) >= 0.0
    return float(inside.mean())


@settings(deadline=None, max_examples=60)
@given(s=st.floats(-1.5, 1.5), t=st.floats(-1.5, 1.5), fs=st.floats(0.01, 2.0), ft=st.floats(0.01, 2.0))
def test_a_polygon_is_box_filtered_exactly(s: float, t: float, fs: float, ft: float) -> None:
    """The painted share of a pixel is the area of the polygon inside its footprint (a head and a bent stem)."""
    for corners in (np.array([[0.0, -0.5], [0.0, 0.5], [1.0, 0.0]]),
                    np.array([[-0.8, -0.2], [0.3, -0.6], [0.9, 0.4], [-0.4, 0.5]])):
        exact = polygon_coverage(_polygon_row(corners), s, t, fs, ft)
        assert exact == pytest.approx(_supersampled(corners, s, t, fs, ft), abs=0.01)


def test_an_upright_square_polygon_covers_as_a_stripe_does() -> None:
    corners = np.array([[1.0, -0.3], [4.0, -0.3], [4.0, 0.3], [1.0, 0.3]])
    for s, t, fs, ft in ((1.05, 0.28, 0.3, 0.1), (3.9, -0.2, 2.0, 0.5), (2.0, 0.0, 0.01, 0.01), (0.0, 0.0, 9.0, 9.0)):
        stripe = box_overlap(s, fs, 1.0, 4.0) * box_overlap(t, ft, -0.3, 0.3)
        assert polygon_coverage(_polygon_row(corners), s, t, fs, ft) == pytest.approx(stripe, abs=1e-12)


def test_arrows_are_convex_counter_clockwise_parts_with_the_heads_asked_for() -> None:
    for heads in ({"straight"}, {"left"}, {"right"}, {"straight", "left"}, {"straight", "right"}, {"left", "right"}):
        parts = arrow_parts(heads, 5.0)
        for part in parts:
            edges = np.roll(part, -1, axis=0) - part
            cross = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
            assert len(part) in (3, 4) and (cross >= -1e-12).all()
        corners = np.concatenate(parts)
        assert corners[:, 0].min() == pytest.approx(-5.0 - 0.5 * 0.035 * 5.0)  # the stem's tail, overlap and all
        assert (corners[:, 1].max() > 1.0) == ("left" in heads)
        assert (corners[:, 1].min() < -1.0) == ("right" in heads)
        assert (corners[:, 0].max() > -0.01) == ("straight" in heads)
    with pytest.raises(ValueError, match="heads"):
        arrow_parts({"up"}, 5.0)


def test_lanes_share_the_moves() -> None:
    all_moves = {"left", "straight", "right"}
    assert [lane_heads(all_moves, k, 2) for k in range(2)] == [{"straight", "left"}, {"straight", "right"}]
    assert [lane_heads({"straight", "right"}, k, 2) for k in range(2)] == [{"straight"}, {"straight", "right"}]
    assert [lane_heads({"left", "right"}, k, 2) for k in range(2)] == [{"left"}, {"right"}]
    assert lane_heads(all_moves, 0, 1) == all_moves


def test_every_standard_sizes_the_junction_with_a_source() -> None:
    assert set(JUNCTION_STANDARDS) == set(MARKING_STANDARD_NAMES)
    for row in JUNCTION_STANDARDS.values():
        assert row.source and row.give_way in ("teeth", "broken")
        assert 0.1 <= row.stop_width <= 0.7 and 2.5 <= row.crosswalk_width <= 5.0 and 2.0 <= row.arrow_length <= 8.0


@pytest.mark.parametrize("road_type", ["t_junction", "crossroad"])
def test_town_approaches_get_crosswalk_stop_line_and_arrows_near_the_junction(
        make_case: Callable[..., Case], road_type: str) -> None:
    case = make_case(road={"type": road_type}, scene={"kind": "urban", "density": 0.0})
    network = compile_scene(case).network
    marks = junction_marks(network, "custom")
    assert len(approaches(network)) == len(network.pieces) + 1
    mouth = {piece: s for piece, s in ((a.piece, a.s_edge) for a in approaches(network)) if piece}
    for mark in marks:
        s_road = mark.corners_st[:, 0]
        if mark.piece == 0:
            assert np.abs(s_road - case.road.junction_s).max() < APPROACH_REACH_M
        else:
            assert s_road.max() < mouth[mark.piece] + APPROACH_REACH_M
        assert np.abs(mark.corners_st[:, 1]).max() <= network.main.half_width + 1e-9
    arrows = [mark for mark in marks if not mark.upright]
    assert arrows and len({mark.piece for mark in arrows}) == len(network.pieces)


def test_an_open_road_junction_gives_way_on_its_arms_only(make_case: Callable[..., Case]) -> None:
    network = compile_scene(make_case(road={"type": "crossroad"}, scene={"kind": "rural"})).network
    marks = junction_marks(network, "us_mutcd")
    assert marks and {mark.piece for mark in marks} == {1, 2}
    assert all(len(mark.corners_st) == 3 for mark in marks)  # MUTCD yield-line teeth
    assert all(mark.corners_st[:, 1].min() > 0 for mark in marks)  # across the lanes coming towards the main road
    assert all(mark.upright for mark in junction_marks(network, "de_urban"))  # a broken Wartelinie


def test_a_road_without_junction_paints_only_its_lines(make_case: Callable[..., Case]) -> None:
    scene = compile_scene(make_case(scene={"kind": "urban"}))
    assert junction_marks(scene.network, "custom") == []
    assert (scene.paint.stripes(scene.network)[:, 11] >= 0).all()


def test_marks_are_deterministic_and_follow_the_paint_switch(make_case: Callable[..., Case]) -> None:
    case = make_case(road={"type": "crossroad"}, scene={"kind": "suburban"})
    first, again = (compile_scene(case).paint.stripes(compile_scene(case).network) for _ in range(2))
    assert first.tobytes() == again.tobytes() and (first[:, 11] < 0).sum() > 20
    off = compile_scene(make_case(road={"type": "crossroad", "paint": False}, scene={"kind": "suburban"}))
    assert len(off.paint.stripes(off.network)) == 0


def test_a_mark_row_paints_white_over_the_asphalt() -> None:
    corners = np.array([[0.0, -1.0], [2.0, -1.0], [1.0, 1.0]])
    row = np.array([mark_row(Mark(0, corners), 0.0)])
    inside = paint(row, 0, 1, 1.0, 0.0, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)
    outside = paint(row, 0, 1, 0.2, 0.8, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)
    assert inside[0] == pytest.approx(0.70) and outside[0] == ASPHALT


def _crossroad(make_case: Callable[..., Case]) -> Case:
    return make_case(road={"type": "crossroad", "junction_s": 70.0}, scene={"kind": "suburban", "density": 0.0},
                     camera={"width": 640, "height": 360}, sun={"altitude": 60.0})


def test_labels_do_not_change_with_the_junction_markings(make_case: Callable[..., Case],
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    case = _crossroad(make_case)
    frames, records = [], []
    for marked in (True, False):
        if not marked:
            monkeypatch.setattr(paint_module, "junction_marks", lambda network, standard: [])
        scene = compile_scene(case)
        frame = render_frame(scene, 28)
        frames.append(frame.rgb)
        records.append(L.tusimple_record(scene, 28, frame, "a.png")["lanes"])
    assert records[0] == records[1]
    assert not np.array_equal(frames[0], frames[1])


def test_crosswalk_bars_and_stop_line_are_brighter_than_the_asphalt_between(make_case: Callable[..., Case]) -> None:
    """Pixel check: at the projected centre of each crosswalk bar in the ego's lanes the frame is brighter than
    half way between two bars, and on the stop line brighter than a metre before it."""
    scene = compile_scene(_crossroad(make_case))
    frame = render_frame(scene, 28)
    luma = frame.rgb.astype(float).mean(axis=2)
    line = scene.network.main.line
    table = JUNCTION_STANDARDS["custom"]
    ego_approach = next(a for a in approaches(scene.network) if a.piece == 0 and a.direction > 0)
    s_mid = ego_approach.s_edge - 0.5 * table.crosswalk_width
    bars = [mark for mark in junction_marks(scene.network, "custom")
            if mark.piece == 0 and mark.upright and np.isclose(mark.corners_st[:, 0].max(), ego_approach.s_edge)]
    centres = sorted(float(mark.corners_st[:, 1].mean()) for mark in bars)

    def at(s_road: float, t_road: float) -> float:
        uv, _depth = frame.camera.project(line.to_world(s_road, t_road, 0.0))
        return float(luma[int(uv[1]), int(uv[0])])

    ego_bars = [t for t in centres if -scene.network.main.half_width + 0.5 < t < -0.5]
    assert len(ego_bars) >= 3
    for t_bar in ego_bars:
        assert at(s_mid, t_bar) > at(s_mid, t_bar + 0.5 * (table.bar_width + table.bar_gap)) + 40
    s_stop = ego_approach.s_edge - table.crosswalk_width - table.stop_before_crosswalk - 0.5 * table.stop_width
    assert at(s_stop, -2.6) > at(s_stop - 1.0, -2.6) + 40


def test_the_paint_mesh_draws_every_mark(make_case: Callable[..., Case]) -> None:
    """The glTF scene and the editor get the marks too: each upright rectangle as quads, each polygon as a fan of
    its corners less two triangles."""
    scene = compile_scene(make_case(road={"type": "t_junction"}, scene={"kind": "urban"}))
    plain = make_case(road={"type": "t_junction"}, scene={"kind": "urban"})
    marks = junction_marks(scene.network, "custom")
    vertices, faces, _colors = scene.paint.mesh(scene.network)
    stripes = scene.paint.stripes(scene.network)
    polygons = stripes[stripes[:, 5] == POLYGON]
    fans = sum(len(mark.corners_st) - 2 for mark in marks if not mark.upright)
    assert len(polygons) == sum(not mark.upright for mark in marks) and fans > 0
    lines_only = compile_scene(plain.model_copy(update={"road": plain.road.model_copy(update={"type": "straight"})}))
    assert len(faces) > len(lines_only.paint.mesh(lines_only.network)[1]) + fans
    assert faces.max() < len(vertices)


@pytest.mark.parametrize("standard", ["custom", "us_mutcd"])
def test_every_slot_of_the_stripe_table_starts_in_order_along_the_road(make_case: Callable[..., Case],
                                                                       standard: str) -> None:
    """The shader stops at the first row of a slot that starts beyond the pixel: every slot's rows (a boundary's,
    or the junction's) are sorted by where they start."""
    markings = ["white_solid", "botts_dots", "yellow_double_solid", "white_dashed", "white_solid"]
    scene = compile_scene(make_case(road={"type": "crossroad", "markings": markings, "marking_standard": standard},
                                    scene={"kind": "urban"}))
    stripes = scene.paint.stripes(scene.network)
    index = stripe_index(stripes, len(scene.network.pieces), len(markings))
    for lo, hi in index.reshape(-1, 2):
        assert (np.diff(stripes[lo:hi, 3]) >= 0).all()
