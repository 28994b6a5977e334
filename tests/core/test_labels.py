"""Lane labels: projection geometry, row crossings, lane choice, occlusion, formats, agreement with the paint."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from lanevil_core.camera import ego_camera
from lanevil_core.illusions import REGISTRY
from lanevil_core.labels import lanes as L
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.world.paint import DOUBLE_LINE_SPACING_M
from lanevil_core.world.scene import FIRST_OBJECT_ID, ID_ROAD


def _tusimple_labels(scene, camera, frame=None):
    rows = np.asarray(L.h_samples_for(camera.intrinsics.height), np.float64)
    return L.lane_labels(scene, camera, rows + 0.5, frame)


def test_tusimple_grid_is_the_standard_56_rows():
    assert L.TUSIMPLE_H_SAMPLES[0] == 160 and L.TUSIMPLE_H_SAMPLES[-1] == 710
    assert len(L.TUSIMPLE_H_SAMPLES) == 56
    assert L.h_samples_for(720) == list(L.TUSIMPLE_H_SAMPLES)
    assert L.h_samples_for(360) == [y // 2 for y in L.TUSIMPLE_H_SAMPLES]


def test_straight_road_matches_the_pinhole_formula(make_case):
    # Flat straight road, camera h metres up looking along it: a line at lateral offset y (left positive)
    # crosses image row v at u = cx - fx * y * (v - cy) / (fy * h).
    case = make_case(camera={"width": 1280, "height": 720, "y": 0.3})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 7)
    k = camera.intrinsics
    labels = _tusimple_labels(scene, camera)
    assert [label.boundary.t_road for label in labels] == [7.0, 3.5, 0.0, -3.5, -7.0]
    t_camera = scene.network.lane_center_t(0) + 0.3
    for label in labels:
        v = label.v_image
        u = k.cx - k.fx * (label.boundary.t_road - t_camera) * (v - k.cy) / (k.fy * case.camera.z)
        depth = k.fy * case.camera.z / (v - k.cy)
        inside = (v > k.cy) & (u >= 0) & (u < k.width)
        near = inside & (depth < L.RANGE_M - 5)  # the far end of the sampled range may or may not be reached
        assert label.valid[near].all() and not label.valid[~inside].any()
        np.testing.assert_allclose(label.x_image[near], u[near], atol=0.02)
        columns = L.tusimple_columns(label)
        assert all(c == int(np.floor(x)) for c, x in zip(columns, label.x_image) if np.isfinite(x))
        assert all(c == L.NO_POINT for c, x in zip(columns, label.x_image) if not np.isfinite(x))


def test_ego_lane_at_the_bottom_row_default_camera(make_case):
    case = make_case(camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    labels = _tusimple_labels(scene, ego_camera(case, scene.network, 0))
    bottom = {label.boundary.t_road: L.tusimple_columns(label)[-1] for label in labels}
    # Row 710 (centre 710.5) lies 640 * 3 / 350.5 = 5.48 m ahead; the ego lane's edges are 1.75 m either side.
    assert bottom[0.0] == int(np.floor(640 - 1.75 * 350.5 / 3))
    assert bottom[-3.5] == int(np.floor(640 + 1.75 * 350.5 / 3))
    assert bottom[7.0] == L.NO_POINT


def test_bend_crossings_reproject_onto_their_rows(make_case):
    case = make_case(road={"type": "bend", "radius": 60.0, "turn": "right"}, ego={"start_s": 30.0})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 20)
    labels = _tusimple_labels(scene, camera)
    assert len(labels) >= 3
    line = scene.network.main.line
    for label in labels:
        ok = label.valid
        assert ok.sum() >= 2
        uv, depth = camera.project(line.to_world(label.s_road[ok], label.boundary.t_road))
        np.testing.assert_allclose(uv[:, 1], label.v_image[ok], atol=0.05)
        np.testing.assert_allclose(uv[:, 0], label.x_image[ok], atol=0.05)
        np.testing.assert_allclose(depth, label.depth[ok], rtol=1e-3)
    # Left to right on every row where two neighbouring lanes both have a point.
    xs = np.array([label.x_image for label in labels])
    both = np.isfinite(xs[:-1]) & np.isfinite(xs[1:])
    assert np.all(xs[1:][both] > xs[:-1][both])


def _view(v_image, s_road=None):
    v_image = np.asarray(v_image, np.float64)
    n = len(v_image)
    s_road = np.arange(n, dtype=np.float64) if s_road is None else np.asarray(s_road, np.float64)
    uv = np.stack([np.arange(n, dtype=np.float64) * 10.0, v_image], axis=-1)
    return L.BoundaryInView(0, 0.0, "white_solid", s_road, uv, s_road + 5.0)


def test_nearest_crossing_is_the_first_walking_out():
    # The polyline goes up the image, comes back down (behind a crest) and rises again.
    view = _view([100.0, 80.0, 60.0, 70.0, 90.0, 50.0, 30.0])
    x, s, depth = L.nearest_crossings(view, np.array([85.0, 65.0, 40.0, 120.0]))
    np.testing.assert_allclose(x[:3], [7.5, 17.5, 55.0])
    np.testing.assert_allclose(s[:3], [0.75, 1.75, 5.5])
    np.testing.assert_allclose(depth[:3], s[:3] + 5.0)
    assert np.isnan(x[3]) and np.isnan(s[3])


def test_nearest_crossing_skips_samples_behind_the_camera():
    view = _view([np.nan, np.nan, 60.0, 40.0])
    x, _, _ = L.nearest_crossings(view, np.array([70.0, 50.0]))
    assert np.isnan(x[0]) and x[1] == pytest.approx(25.0)


def test_five_nearest_lanes_are_chosen_left_to_right(make_case):
    case = make_case(road={"lanes_per_direction": 3}, ego={"lane": 1}, camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    labels = _tusimple_labels(scene, ego_camera(case, scene.network, 0))
    # Ego lane 1 spans t = -3.5 .. -7; its neighbours outward, ties resolved to the left.
    assert [label.boundary.t_road for label in labels] == [3.5, 0.0, -3.5, -7.0, -10.5]
    assert [label.boundary.index for label in labels] == [2, 3, 4, 5, 6]


def test_lanes_with_fewer_than_two_points_are_dropped(make_case):
    case = make_case(camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 0)
    assert L.lane_labels(scene, camera, np.array([710.5])) == []
    # At row 710 the leftmost line (8.75 m left of the camera) is off the image: one point only.
    labels = L.lane_labels(scene, camera, np.array([450.5, 710.5]))
    assert [label.boundary.t_road for label in labels] == [3.5, 0.0, -3.5, -7.0]


def _fake_frame(camera, depth_value, object_id):
    k = camera.intrinsics
    return SimpleNamespace(
        camera=camera,
        depth=np.full((k.height, k.width), depth_value, np.float32),
        object_id=np.full((k.height, k.width), object_id, np.int32),
    )


def test_object_in_front_keeps_the_point_but_marks_it_hidden(make_case):
    case = make_case(camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 0)
    clear = _tusimple_labels(scene, camera)
    blocked = _tusimple_labels(scene, camera, _fake_frame(camera, 1.0, FIRST_OBJECT_ID))
    for a, b in zip(clear, blocked):
        np.testing.assert_array_equal(a.x_image, b.x_image)
        assert a.visible.any() and not b.visible.any()


def test_road_closer_than_the_point_hides_it(make_case):
    case = make_case(camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 0)
    crest = _fake_frame(camera, 1.0, ID_ROAD)
    assert _tusimple_labels(scene, camera, crest) == []
    same = _fake_frame(camera, 0.0, ID_ROAD)
    same.depth = np.full_like(same.depth, np.inf)  # road behind the point: nothing hides it
    assert len(_tusimple_labels(scene, camera, same)) == 5


def test_junction_mouth_has_no_edge_label(make_case):
    case = make_case(road={"type": "t_junction", "lanes_per_direction": 1, "junction_s": 40.0},
                     camera={"width": 1280, "height": 720})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 0)
    right_edge = [label for label in _tusimple_labels(scene, camera) if label.boundary.t_road == -3.5][0]
    s0, s1, _ = scene.network.main.gaps[0]
    s = right_edge.s_road[right_edge.valid]
    assert not np.any((s > s0) & (s < s1))
    assert np.any(s < s0) and np.any(s > s1)


def test_tusimple_record_and_culane_lines_formats(make_case):
    case = make_case(camera={"width": 1640, "height": 590})
    scene = compile_scene(case)
    camera = ego_camera(case, scene.network, 3)
    frame = _fake_frame(camera, np.inf, ID_ROAD)
    record = L.tusimple_record(scene, 3, frame, "000003.png", h_samples=list(L.TUSIMPLE_H_SAMPLES[:43]))
    parsed = json.loads(json.dumps(record))
    assert set(parsed) == {"raw_file", "lanes", "h_samples", "visibility", "line_types", "frame", "image_size"}
    assert parsed["image_size"] == [1640, 590]
    assert parsed["frame"] == 3 and len(parsed["lanes"]) == len(parsed["line_types"]) <= L.MAX_LANES
    assert parsed["line_types"] == ["white_solid", "white_dashed", "yellow_double_solid", "white_dashed",
                                    "white_solid"]
    for lane, flags in zip(parsed["lanes"], parsed["visibility"]):
        assert len(lane) == len(flags) == 43
        assert all(isinstance(x, int) and (x == -2 or 0 <= x < 1640) for x in lane)
        assert all(flag == (x != -2) for x, flag in zip(lane, flags))
    text = L.culane_lines(scene, frame)
    lanes = text.splitlines()
    assert text.endswith("\n") and 2 <= len(lanes) <= 4
    for lane in lanes:
        values = lane.split(" ")
        xs, ys = values[0::2], [int(y) for y in values[1::2]]
        assert all(len(x.split(".")[1]) == 2 for x in xs)
        assert ys == sorted(ys, reverse=True) and all(y % 10 == 0 and 270 <= y <= 590 for y in ys)
        assert np.all(np.diff(ys) == -10)  # contiguous rows on a flat straight road


# ---------------------------------------------------------------------------------------------- against the pixels

def _paint_score(rgb: np.ndarray) -> np.ndarray:
    """(H, W) float: high on white paint (bright) and on yellow paint (red + green well above blue)."""
    rgb = rgb.astype(np.float64)
    return np.maximum(rgb.mean(axis=-1), 0.5 * (rgb[..., 0] + rgb[..., 1]) - rgb[..., 2] + 60.0)


def _stripe_center(score_row: np.ndarray, column: int, reach: int) -> float | None:
    """Centre (column coordinate) of the paint run within 2 px of ``column``, or None if no paint is there.

    Paint must beat the road surface ``reach`` px to either side (the darker side, each the median of 5 px there, so
    a thin dark joint of a concrete road does not count) by a clear margin; the run is where the score exceeds the
    half-way level between the two.
    """
    width = len(score_row)
    window = range(max(column - 2, 0), min(column + 3, width))
    peak = max(window, key=lambda i: score_row[i])
    sides = [score_row[max(column - reach - 4, 0):max(column - reach + 1, 1)],
             score_row[min(column + reach, width - 1):min(column + reach + 5, width)]]
    asphalt = min(float(np.median(side)) for side in sides)
    if score_row[peak] < asphalt + 25.0:
        return None
    level = 0.5 * (score_row[peak] + asphalt)
    a = b = peak
    while a > 0 and score_row[a - 1] > level:
        a -= 1
    while b < width - 1 and score_row[b + 1] > level:
        b += 1
    return 0.5 * (a + b)


def _paint_errors(case, frame_index, size=(640, 360)):
    """|label x - painted stripe centre| (px) at every visible label point on paint at least 2 px wide."""
    from lanevil_core.render import render_frame

    scene = compile_scene(case)
    frame = render_frame(scene, frame_index, size)
    camera, line = frame.camera, scene.network.main.line
    k = camera.intrinsics
    rows = np.arange(k.height // 2 + 5, k.height, 5)
    score = _paint_score(frame.rgb)
    errors = []
    for label in L.lane_labels(scene, camera, rows + 0.5, frame):
        marking = scene.case.road.markings[label.boundary.index]
        double = marking.type.endswith(("double_solid", "solid_dashed"))
        offset = (marking.width + DOUBLE_LINE_SPACING_M) / 2 if double else 0.0
        for j in np.flatnonzero(label.visible):
            s_road, depth = label.s_road[j], label.depth[j]
            in_dash = 0.3 < s_road % (marking.dash + marking.gap) < marking.dash - 0.3
            if k.fx * marking.width / depth < 2.0 or (marking.type.endswith("dashed") and not in_dash):
                continue
            reach = int(np.ceil(k.fx * (marking.width / 2 + 0.25) / depth)) + 2
            centers = []
            for t_road in {label.boundary.t_road + offset, label.boundary.t_road - offset}:
                uv, _ = camera.project(line.to_world(s_road, t_road))
                centers.append(_stripe_center(score[rows[j]], int(round(uv[0] - 0.5)), reach))
            assert None not in centers, f"no paint at row {rows[j]} near x={label.x_image[j]:.1f} ({marking.type})"
            errors.append(abs(np.mean(centers) - (label.x_image[j] - 0.5)))
    return np.array(errors)


@pytest.mark.parametrize("road", [{"type": "straight"}, {"type": "bend", "radius": 80.0, "turn": "left"}])
def test_labels_sit_on_the_rendered_paint(make_case, road):
    case = make_case(road=road, ego={"start_s": 20.0})
    for frame_index in (0, 40):
        errors = _paint_errors(case, frame_index)
        assert len(errors) > 60
        assert errors.max() < 2.0 and errors.mean() < 0.6, (errors.max(), errors.mean())


def test_labels_sit_on_the_paint_of_a_concrete_road(make_case):
    # A highway: its wide slab shoulder keeps the shaded kerb face (as dark as asphalt) away from the edge lines, and
    # white paint, since yellow on pale concrete is too faint for ``_paint_score``.
    white = ["white_solid", "white_dashed", "white_double_solid", "white_dashed", "white_solid"]
    case = make_case(road={"pavement": "concrete", "markings": white}, scene={"kind": "highway"},
                     ego={"start_s": 20.0})
    for frame_index in (0, 40):
        errors = _paint_errors(case, frame_index)
        assert len(errors) > 60
        assert errors.max() < 2.0 and errors.mean() < 0.6, (errors.max(), errors.mean())


@pytest.fixture(scope="module")
def clean_record():
    from lanevil_core.case import Case
    from lanevil_core.render import render_frame

    case = Case.model_validate({"camera": {"width": 320, "height": 180}, "ego": {"frames": 50},
                                "scene": {"density": 0.0}})
    scene = compile_scene(case)
    return L.tusimple_record(scene, 5, render_frame(scene, 5), "a.png")


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_labels_do_not_move_when_illusions_are_added(make_case, clean_record, name):
    from lanevil_core.render import render_frame

    case = make_case(illusions=[{"type": name, "severity": 5}])
    scene = compile_scene(case)
    record = L.tusimple_record(scene, 5, render_frame(scene, 5), "a.png")
    assert record["lanes"] == clean_record["lanes"]
    assert record["line_types"] == clean_record["line_types"]


@pytest.mark.parametrize("camera", [
    {"fov": 70.0, "z": 1.5, "pitch": -2.0, "lens": {"k1": -0.15, "k2": 0.04, "p1": 0.002}},
    {"fov": 58.0, "z": 1.35, "pitch": -3.0, "roll": 1.5, "lens": {"k1": -0.12, "k2": 0.03},
     "bonnet": {"reach": 2.3, "drop": 0.5}},
])
def test_labels_sit_on_the_paint_through_a_distorting_lens_and_a_bonnet(make_case, camera):
    case = make_case(camera={"width": 320, "height": 180, **camera}, ego={"start_s": 20.0})
    for frame_index in (0, 40):
        errors = _paint_errors(case, frame_index)
        assert len(errors) > 40
        assert errors.max() < 2.0 and errors.mean() < 0.6, (errors.max(), errors.mean())


def test_labels_stop_at_the_bonnet(make_case):
    from lanevil_core.render import render_frame
    from lanevil_core.world.scene import ID_EGO

    case = make_case(camera={"preset": "dashcam", "width": 640, "height": 360, "sensor": None})
    scene = compile_scene(case)
    frame = render_frame(scene, 10)
    assert (frame.object_id == ID_EGO).mean() > 0.01  # the bonnet is in view
    rows = np.arange(180, 360, 2) + 0.5
    labels = L.lane_labels(scene, frame.camera, rows, frame)
    assert labels
    hidden_rows = 0
    for label in labels:
        for j in np.flatnonzero(label.valid):
            assert frame.object_id[int(rows[j]), int(label.x_image[j])] != ID_EGO
        ideal = L.label_boundary(label.boundary, rows, (640, 360))  # without the frame: no bonnet test
        hidden_rows += int((ideal.valid & ~label.valid).sum())
    assert hidden_rows > 0  # some rows of the lines run under the bonnet and are dropped
