"""Closed-loop driving: pose camera, bicycle model, lane estimate, controllers, the loop, summary and command."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from lanevil_core import cli
from lanevil_core.camera import VehiclePose, ego_camera, mounted_camera, pose_camera
from lanevil_core.case import load_case, save_case
from lanevil_core.drive import (
    DriveSettings,
    DriveStep,
    DriveTrace,
    PurePursuit,
    Route,
    Stanley,
    VehicleParams,
    VehicleState,
    advance,
    drive_case,
    estimate_lane,
    summarize,
)
from lanevil_core.drive.lane_estimate import LanePath
from lanevil_core.labels.lanes import h_samples_for, lane_labels, tusimple_columns
from lanevil_core.pipeline.compile import compile_scene, ego_drive
from lanevil_core.world.road_layout import build_network

SCENES = Path(__file__).resolve().parents[2] / "scenes"
SMALL = (320, 180)


# ---------------------------------------------------------------------------------------------- pose and camera

@pytest.mark.parametrize("road", [{"type": "uphill"}, {"type": "bend", "turn": "right"}])
def test_pose_camera_at_the_scripted_pose_is_the_ego_camera(make_case, road):
    case = make_case(road=road)
    network = build_network(case.road, case.scene.kind)
    for frame in (0, 30, 49):
        scripted = ego_camera(case, network, frame)
        route = Route.of_case(case, network)
        s_road = case.ego_s(frame)
        p_world = network.main.line.to_world(s_road, route.t_center)
        pose = VehiclePose(float(p_world[0]), float(p_world[1]), float(network.main.line.heading_at(s_road)))
        assert np.allclose(pose_camera(case, network, pose).T_world_camera, scripted.T_world_camera, atol=1e-6)


def test_station_inverts_the_road_frame(make_case):
    case = make_case(road={"type": "s_curve", "radius": 60.0})
    line = build_network(case.road, case.scene.kind).main.line
    for s_road, t_road in [(5.0, -1.75), (95.3, 4.2), (181.0, -6.0), (260.0, 0.4)]:
        assert np.allclose(line.station(line.to_world(s_road, t_road)), (s_road, t_road), atol=1e-4)


# ---------------------------------------------------------------------------------------------- vehicle model

def test_constant_steering_drives_a_circle_of_radius_l_over_tan_delta():
    params = VehicleParams(max_steer_rate=10.0)
    delta = 0.1
    state = VehicleState(0.0, 0.0, 0.0, delta, 10.0)
    radius = params.wheelbase_m / math.tan(delta)
    # The rear axle turns about (-b, R); the origin, b ahead of it, about the same centre at sqrt(R^2 + b^2).
    center = np.array([-params.rear_axle_m, radius])
    for _ in range(40):
        state = advance(state, delta, 0.1, params)
        assert abs(np.hypot(state.x - center[0], state.y - center[1]) - math.hypot(radius, params.rear_axle_m)) < 1e-9
    assert abs(state.yaw - math.atan2(math.sin(40.0 / radius), math.cos(40.0 / radius))) < 1e-9


def test_steering_is_rate_limited_and_clamped():
    params = VehicleParams()
    state = advance(VehicleState(0.0, 0.0, 0.0, 0.0, 10.0), 1.0, 0.1, params)
    assert state.steer == pytest.approx(params.max_steer_rate * 0.1)
    for _ in range(100):
        state = advance(state, 1.0, 0.1, params)
    assert state.steer == pytest.approx(params.max_steer)
    straight = advance(VehicleState(1.0, 2.0, 0.5, 0.0, 10.0), 0.0, 0.1, params)
    assert (straight.x, straight.y) == pytest.approx((1.0 + math.cos(0.5), 2.0 + math.sin(0.5)))


# ---------------------------------------------------------------------------------------------- controllers

def test_pure_pursuit_and_stanley_hold_a_circle_and_turn_towards_the_path():
    params = VehicleParams()
    radius = 150.0
    # The circle through the rear axle, tangent to the heading: y = R - sqrt(R^2 - (x + b)^2) in the vehicle frame.
    x = np.linspace(0.0, 40.0, 200)
    y = radius - np.sqrt(radius**2 - (x + params.rear_axle_m) ** 2)
    circle = LanePath(tuple(np.polynomial.polynomial.polyfit(x, y, 3)))
    assert PurePursuit().steer(circle, 10.0, params) == pytest.approx(math.atan(params.wheelbase_m / radius), rel=0.02)
    left = LanePath((0.5, 0.0))
    for controller in (PurePursuit(), Stanley()):
        assert controller.steer(left, 10.0, params) > 0
        assert controller.steer(LanePath((-0.5, 0.0)), 10.0, params) < 0
        assert controller.steer(LanePath((0.0, 0.0)), 10.0, params) == pytest.approx(0.0, abs=1e-12)


# ---------------------------------------------------------------------------------------------- lane estimate

@pytest.mark.parametrize("offset, yaw", [(0.0, 0.0), (0.4, 0.0), (-0.3, 0.02)])
def test_lane_estimate_from_projected_labels_finds_the_true_offset(make_case, offset, yaw):
    case = make_case()
    scene = compile_scene(case)
    route = Route.of_case(case, scene.network)
    size = (640, 360)
    p_world = scene.network.main.line.to_world(40.0, route.t_center + offset)
    pose = VehiclePose(float(p_world[0]), float(p_world[1]), yaw)
    rows = h_samples_for(size[1])
    labels = lane_labels(scene, pose_camera(case, scene.network, pose, size), np.asarray(rows, float) + 0.5)
    lanes = [tusimple_columns(label) for label in labels]
    estimate = estimate_lane(lanes, rows, mounted_camera(case.camera, np.eye(4), size))
    assert estimate is not None and estimate.left_seen and estimate.right_seen
    assert estimate.lateral_offset == pytest.approx(offset, abs=0.03)
    assert estimate.heading_error == pytest.approx(yaw, abs=0.006)
    assert estimate.width == pytest.approx(case.road.lane_width, abs=0.05)


def test_one_boundary_gives_the_center_half_a_lane_away(make_case):
    case = make_case()
    scene = compile_scene(case)
    route = Route.of_case(case, scene.network)
    p_world = scene.network.main.line.to_world(40.0, route.t_center)
    pose = VehiclePose(float(p_world[0]), float(p_world[1]), 0.0)
    rows = h_samples_for(360)
    labels = lane_labels(scene, pose_camera(case, scene.network, pose, (640, 360)), np.asarray(rows, float) + 0.5)
    right_only = [tusimple_columns(label) for label in labels if label.boundary.t_road < route.t_center]
    estimate = estimate_lane(right_only[:1], rows, mounted_camera(case.camera, np.eye(4), (640, 360)), 3.5)
    assert estimate is not None and estimate.right_seen and not estimate.left_seen
    assert estimate.lateral_offset == pytest.approx(0.0, abs=0.03)
    assert estimate_lane([], rows, mounted_camera(case.camera, np.eye(4), (640, 360))) is None


# ---------------------------------------------------------------------------------------------- the loop

def test_ground_truth_keeps_the_lane_and_the_trace_is_deterministic(make_case):
    case = make_case(road={"type": "bend", "radius": 80.0}, ego={"start_s": 45.0})
    settings = DriveSettings(detector="gt", seconds=2.0, size=SMALL)
    first = drive_case(case, settings)
    second = drive_case(case, settings)
    assert len(first.steps) == 20 and first.ended == "time"
    assert max(abs(step.deviation) for step in first.steps) < 0.10
    assert [step.deviation for step in first.steps] == [step.deviation for step in second.steps]
    assert 18.0 < first.steps[-1].s_road - 45.0 < 19.05  # 1 m a step along the lane, inside the bend
    assert all(step.accuracy == 1.0 and step.source == "both" for step in first.steps)


def test_a_vehicle_pushed_off_its_lane_steers_back(make_case):
    # Start 0.5 m left of the lane centre: the trace records it and the controller brings it back.
    trace = drive_case(make_case(), DriveSettings(detector="gt", seconds=4.0, size=SMALL, controller="stanley",
                                                  start_offset_m=0.5))
    deviation = [step.deviation for step in trace.steps]
    assert deviation[0] == pytest.approx(0.5, abs=1e-6)
    assert abs(deviation[-1]) < 0.15
    assert trace.steps[0].steer_command < 0


def _trace(make_case, deviations, span=None, fps=10.0):
    case = make_case(ego={"fps": fps})
    network = build_network(case.road, case.scene.kind)
    steps = [DriveStep(i, i / fps, 10.0 + i, -1.75 + d, d, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, d, 1.0, 2, "both", 0.0, 0.0)
             for i, d in enumerate(deviations)]
    return DriveTrace(case, DriveSettings(), steps, Route.of_case(case, network), span, "time")


def test_summary_applies_the_paper_criterion(make_case):
    early = summarize(_trace(make_case, [0.0] * 12 + [0.3] * 5))
    assert early.success and early.t_view == 0.0 and early.t_exceed == pytest.approx(1.2)
    late = summarize(_trace(make_case, [0.0] * 30 + [0.3] * 5))
    assert not late.success and late.t_exceed == pytest.approx(3.0)
    # The illusion starts at s = 80: in view (50 m) once the camera (1 m ahead) reaches s = 30, i.e. at step 19.
    viewed = summarize(_trace(make_case, [0.0] * 30 + [-0.3] * 5, span=(80.0, 120.0)))
    assert viewed.t_view == pytest.approx(1.9) and viewed.success
    departed = summarize(_trace(make_case, [0.0, 0.9, -6.0]))
    assert departed.lane_departure and departed.t_departure == pytest.approx(0.1) and departed.off_road
    assert early.verdict.startswith("LANE LOST") and late.verdict.startswith("LANE KEPT at first")
    assert viewed.verdict == "ATTACK SUCCEEDED"
    kept = summarize(_trace(make_case, [0.1] * 40, span=(80.0, 120.0)))
    assert kept.verdict == "LANE KEPT (attack failed)"
    assert summarize(_trace(make_case, [0.0] * 5)).verdict == "LANE KEPT"


def test_illusion_span_covers_the_illusion():
    from lanevil_core.drive.illusion_view import illusion_span

    case = load_case(SCENES / "10_road_damage" / "tire_marks" / "00_straight_highway_noon" / "03_level3.json")
    s0, s1 = illusion_span(compile_scene(case))
    start = case.illusions[0].start_s(ego_drive(case))
    assert s0 == pytest.approx(start, abs=2.0) and s1 > s0 + 10
    assert illusion_span(compile_scene(load_case(SCENES / "00_clean" / "00_straight_urban.json"))) is None



def test_suite_files_an_original_under_the_type_its_folders_name():
    from lanevil_core.drive.suite import case_group

    folder = SCENES / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon"
    assert case_group(load_case(folder / "00_original.json"), folder / "00_original.json") == (
        "shadow", "fence_shadow", 0)
    assert case_group(load_case(folder / "03_level3.json"), folder / "03_level3.json")[2] == 3
    clean = SCENES / "00_clean" / "00_straight_urban.json"
    assert case_group(load_case(clean), clean)[1] == "straight"

# ---------------------------------------------------------------------------------------------- command

def test_drive_command_writes_trace_summary_plots_and_video(tmp_path, make_case, capsys):
    path = tmp_path / "case.json"
    save_case(make_case(), path)
    out = tmp_path / "drive"
    assert cli.main(["drive", str(path), "--detector", "gt", "--seconds", "1", "--size", "320x180",
                     "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["steps"] == 10 and summary["max_abs_deviation"] < 0.01 and summary["success"] is False
    assert cli.main(["drive", str(path), "--detector", "gt", "--seconds", "1", "--size", "320x180", "--no-video",
                     "--out", str(tmp_path / "words")]) == 0
    assert capsys.readouterr().out.startswith("LANE KEPT: max |deviation|")  # not "no success"
    assert summary["deviation_threshold_m"] == 0.285 and summary["success_window_s"] == 2.5
    names = {p.name for p in out.iterdir()}
    assert {"trace.csv", "summary.json", "trace.png", "path.png"} <= names
    assert "drive.mp4" in names or "drive.gif" in names
    rows = (out / "trace.csv").read_text().splitlines()
    assert rows[0].startswith("frame,time,s,t,deviation,heading_error,steer") and len(rows) == 11


@pytest.mark.parametrize("argv, message", [
    (["drive", "--detector", "gt", "--out", "x"], "give one case file or --suite DIR"),
    (["drive", "missing.json", "--detector", "gt", "--out", "x"], "missing.json: cannot read"),
    (["drive", "--suite", "nowhere", "--detector", "gt", "--out", "x"], "--suite nowhere: no such folder"),
    (["drive", "c.json", "--detector", "gt", "--seconds", "0", "--out", "x"], "--seconds"),
])
def test_drive_user_errors_exit_2_with_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted((SCENES / "00_clean").glob("*.json")), ids=lambda p: p.stem)
@pytest.mark.parametrize("controller", ["pure_pursuit", "stanley"])
def test_ground_truth_keeps_every_clean_road_type_within_10_cm(path, controller):
    trace = drive_case(load_case(path), DriveSettings(detector="gt", controller=controller))
    assert trace.ended == "time"
    assert max(abs(step.deviation) for step in trace.steps) < 0.10
