"""Classical detectors: the ground homography agrees with the renderer's camera, and both baselines reach a
measured accuracy floor on small renders of clean stock cases."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.camera import ego_camera
from lanevil_core.case import Case, load_case
from lanevil_core.cli import main
from lanevil_core.detect import DETECTORS, GroundCamera, detect_split
from lanevil_core.detect.common import lane_columns
from lanevil_core.images import png_bytes
from lanevil_core.labels.lanes import tusimple_record
from lanevil_core.metrics.tusimple import score_image, summarize
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.world.road_layout import build_network

SCENES = Path(__file__).resolve().parents[2] / "scenes" / "00_clean"
CLEAN = ("00_straight_urban", "01_bend_suburban", "05_t_junction_urban")
FRAMES = (0, 25)
SIZE = (320, 180)
# Measured at 320x180 on these six frames: hough 0.944, birdseye 0.993 (640x360 over all nine clean cases,
# frames 0/25/49: hough 0.909, birdseye 0.959).
ACCURACY_FLOOR = {"hough": 0.88, "birdseye": 0.95}


@pytest.mark.parametrize("pitch_deg", [0.0, 4.0])
def test_ground_homography_matches_the_render_camera(pitch_deg):
    case = Case.model_validate({"road": {"type": "straight"}, "camera": {"pitch": pitch_deg}})
    camera = ego_camera(case, build_network(case.road, case.scene.kind), 0)
    ground = GroundCamera(camera.intrinsics, case.camera.z, math.radians(pitch_deg))
    x_ground, z_ground = np.array([-5.25, 0.0, 1.75, 3.0]), np.array([8.0, 20.0, 45.0, 120.0])
    # Straight road heading +X: forward = +x, right = -y, the road 3 m below the camera.
    p_world = camera.p_world_camera + np.stack([z_ground, -x_ground, np.full(4, -case.camera.z)], axis=1)
    uv_render, _ = camera.project(p_world)
    road_z = camera.p_world_camera[2] - case.camera.z
    assert abs(road_z) < 1e-6  # the straight road is flat at z = 0
    assert ground.project_ground(x_ground, z_ground) == pytest.approx(uv_render, abs=1e-6)
    rows = uv_render[:, 1]
    assert ground.ground_z_of_row(rows) == pytest.approx(z_ground, rel=1e-9)


def test_lane_columns_floor_inside_the_image():
    assert lane_columns(np.array([0.0, 10.7, 319.99, 320.0, -0.1, np.nan]), 320) == [0, 10, 319, -2, -2, -2]


@pytest.fixture(scope="module")
def clean_frames():
    frames = []
    for name in CLEAN:
        scene = compile_scene(load_case(SCENES / f"{name}.json"))
        for index in FRAMES:
            frame = render_frame(scene, index, SIZE)
            frames.append((frame.rgb, tusimple_record(scene, index, frame, f"{name}/{index:06d}.png")))
    return frames


@pytest.mark.parametrize("method", sorted(DETECTORS))
def test_detector_accuracy_floor_on_clean_frames(clean_frames, method):
    scores = []
    for rgb, record in clean_frames:
        lanes = DETECTORS[method](rgb, record["h_samples"])
        assert all(len(lane) == len(record["h_samples"]) for lane in lanes) and len(lanes) <= 5
        scores.append(score_image(lanes, record["lanes"], record["h_samples"], 0.0))
    assert summarize(scores).accuracy >= ACCURACY_FLOOR[method]


@pytest.mark.parametrize("method", sorted(DETECTORS))
def test_detectors_are_deterministic_and_find_nothing_on_a_blank_image(clean_frames, method):
    rgb, record = clean_frames[0]
    detector = DETECTORS[method]
    assert detector(rgb, record["h_samples"]) == detector(rgb.copy(), record["h_samples"])
    assert detector(np.full_like(rgb, 90), record["h_samples"]) == []


def _write_split(split: Path, frames) -> list[str]:
    """A split folder of PNG frames and their label file; returns the label lines."""
    lines = []
    for rgb, record in frames:
        (split / record["raw_file"]).parent.mkdir(parents=True, exist_ok=True)
        (split / record["raw_file"]).write_bytes(png_bytes(rgb))
        lines.append(json.dumps(record))
    (split / "test_label.json").write_text("\n".join(lines) + "\n")
    return lines


def test_detect_command_over_a_split(clean_frames, tmp_path, capsys):
    split = tmp_path / "test"
    lines = _write_split(split, clean_frames[:2])
    out = tmp_path / "preds.json"
    assert main(["detect", str(split), "--method", "birdseye", "--out", str(out), "--fixed-run-time", "1"]) == 0
    first = out.read_bytes()
    records = [json.loads(line) for line in first.decode().splitlines()]
    assert [r["raw_file"] for r in records] == [json.loads(line)["raw_file"] for line in lines]
    assert all(r["run_time"] == 1.0 and r["h_samples"] == clean_frames[0][1]["h_samples"] for r in records)
    assert main(["detect", str(split), "--method", "birdseye", "--out", str(out), "--fixed-run-time", "1"]) == 0
    assert out.read_bytes() == first
    (split / "test_label.json").unlink()  # without labels: every image, rows from its height
    assert [r["raw_file"] for r in detect_split(split, "hough")] == sorted(r["raw_file"] for r in records)
    capsys.readouterr()
    assert main(["detect", str(tmp_path / "missing"), "--method", "hough", "--out", str(out)]) == 2
    assert "not a split folder" in capsys.readouterr().err


def test_detect_several_methods_reads_each_image_once_and_writes_what_single_runs_write(tmp_path, clean_frames,
                                                                                        capsys):
    split = tmp_path / "split"
    _write_split(split, clean_frames[:2])
    fixed = ["--fixed-run-time", "1"]
    for method in ("hough", "birdseye"):
        assert main(["detect", str(split), "--method", method, "--out", str(tmp_path / f"{method}.json"), *fixed]) == 0
    both = tmp_path / "both"
    assert main(["detect", str(split), "--method", "hough", "--method", "birdseye", "--out", str(both), *fixed]) == 0
    for method in ("hough", "birdseye"):
        assert (both / f"{method}.json").read_bytes() == (tmp_path / f"{method}.json").read_bytes()
    capsys.readouterr()
    assert main(["detect", str(split), "--method", "hough", "--method", "hough", "--out", str(both)]) == 2
    assert "named twice" in capsys.readouterr().err
    assert main(["detect", str(split), "--method", "hough", "--method", "birdseye", "--weights", str(tmp_path),
                 "--out", str(both)]) == 2
    assert "--weights" in capsys.readouterr().err
    assert main(["detect", str(split), "--method", "hough", "--method", "birdseye",
                 "--out", str(tmp_path / "hough.json")]) == 2
    assert "a folder" in capsys.readouterr().err
    assert main(["detect", str(split), "--method", "hough", "--out", str(both)]) == 2
    assert "a predictions file (it is a folder)" in capsys.readouterr().err
