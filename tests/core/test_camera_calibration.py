"""A user's camera from a calibration file: round trips through the renderer's own projection, and --camera."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.camera import mounted_camera
from lanevil_core.camera.bonnet import edge_rows
from lanevil_core.camera.calibration import CalibrationError, camera_choice, load_camera
from lanevil_core.camera.lens import distort
from lanevil_core.case import Bonnet, Camera, parse_case
from lanevil_core.cli import main
from lanevil_core.dataset import Settings, build_plan, discover_cases

SCENES = Path(__file__).resolve().parents[2] / "scenes"
LENS = [-0.06, 0.01, 0.0, 0.0]


def pixel(camera: Camera, x_ideal: float, y_ideal: float) -> tuple[float, float]:
    """Continuous pixel of ideal normalised coordinates through the camera's lens."""
    x, y = distort(np.array([x_ideal]), np.array([y_ideal]), camera.lens.coefficients)
    cx = camera.cx if camera.cx is not None else camera.width / 2
    cy = camera.cy if camera.cy is not None else camera.height / 2
    return cx + camera.focal_px * float(x[0]), cy + camera.focal_px * float(y[0])


def write(tmp_path, data) -> Path:
    path = tmp_path / "mycam.json"
    path.write_text(json.dumps(data))
    return path


def test_a_horizon_row_gives_the_preset_s_pitch(tmp_path) -> None:
    preset = Camera.model_validate({"preset": "tusimple"})
    _, horizon = pixel(preset, 0.0, -math.tan(math.radians(preset.pitch)))
    camera = load_camera(write(tmp_path, {"image_size": [1280, 720], "hfov": 62.0, "distortion": LENS,
                                          "height": 1.55, "x": 1.6, "horizon_row": horizon}))
    assert camera.pitch == pytest.approx(3.5, abs=1e-3) and camera.yaw == 0.0
    assert camera.focal_px == pytest.approx(preset.focal_px) and camera.lens == preset.lens
    assert (camera.z, camera.x, camera.width, camera.height) == (1.55, 1.6, 1280, 720)


def test_a_vanishing_point_gives_pitch_and_yaw(tmp_path) -> None:
    truth = Camera(width=1280, height=720, focal=1000.0, cx=630.0, cy=350.0, z=1.4, pitch=2.0, yaw=3.0,
                   lens={"k1": -0.06, "k2": 0.01})
    pitch, yaw = math.radians(2.0), math.radians(3.0)
    vanishing = pixel(truth, math.tan(yaw) / math.cos(pitch), -math.tan(pitch))
    camera = load_camera(write(tmp_path, {"image_size": [1280, 720], "K": [[1000, 0, 630], [0, 1000.5, 350], [0, 0, 1]],
                                          "distortion": LENS, "height": 1.4, "vanishing_point": list(vanishing)}))
    assert camera.pitch == pytest.approx(2.0, abs=1e-3) and camera.yaw == pytest.approx(3.0, abs=1e-3)
    # and the renderer's camera puts the road's far end at that pixel
    far_vehicle = np.array([1e6, 0.0, truth.z])
    rendered = mounted_camera(camera, np.eye(4), (1280, 720))
    uv, _ = rendered.project(far_vehicle[None])
    assert uv[0] == pytest.approx(vanishing, abs=0.05)


def test_a_bonnet_row_gives_the_bonnet_s_reach(tmp_path) -> None:
    truth = Camera(width=1280, height=720, fov=58.0, z=1.35, x=0.6, pitch=-3.0, lens={"k1": -0.12, "k2": 0.03},
                   bonnet=Bonnet(reach=2.3, drop=0.5))
    assert truth.bonnet is not None
    row = float(edge_rows(mounted_camera(truth, np.eye(4), (1280, 720)), truth, truth.bonnet)[640])
    camera = load_camera(write(tmp_path, {"image_size": [1280, 720], "hfov": 58.0, "height": 1.35, "x": 0.6,
                                          "pitch": -3.0, "distortion": [-0.12, 0.03, 0.0, 0.0], "bonnet_row": row}))
    assert camera.bonnet is not None and camera.bonnet.drop == 0.5
    assert camera.bonnet.reach == pytest.approx(2.3, abs=0.02)  # the centre column's pixel centre is 0.5 px off


@pytest.mark.parametrize(("data", "message"), [
    ({"image_size": [1280, 720], "hfov": 60}, "height: Field required"),
    ({"image_size": [1280, 720], "hfov": 60, "fx": 900, "height": 1.5}, "give the focal length once"),
    ({"image_size": [1280, 720], "hfov": 60, "height": 1.5, "pitch": 1, "horizon_row": 300}, "pitch and horizon_row"),
    ({"image_size": [1280, 720], "fx": 900, "fy": 960, "height": 1.5}, "square pixels"),
    ({"image_size": [1280, 720], "hfov": 60, "height": 1.5, "bonnet_row": 100}, "above the horizon"),
    ({"image_size": [1280, 720], "hfov": 60, "height": 9.0}, "z: Input should be less than or equal to 6"),
    ({"image_size": [1280, 720], "hfov": 60, "height": 1.5, "colour": 1}, "colour: Extra inputs"),
])
def test_a_bad_calibration_is_one_line_naming_the_field(tmp_path, data, message) -> None:
    with pytest.raises(CalibrationError, match=message):
        load_camera(write(tmp_path, data))


def test_dataset_cases_are_seen_through_the_calibrated_camera(tmp_path, capsys) -> None:
    path = write(tmp_path, {"image_size": [1280, 720], "hfov": 62.0, "height": 1.55, "horizon_row": 300,
                            "sensor": {"noise": 1.0}})
    fields, label = camera_choice(str(path))
    assert label == "mycam.json" and camera_choice("dashcam")[1] == "dashcam"
    sources = discover_cases(SCENES / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon")
    plan = build_plan(sources, Settings(frames_per_case=1, sampling="even", camera=str(path)))
    for planned in plan.cases:
        assert parse_case(planned.case_text).camera.model_dump() == fields and planned.source["camera"] == label
    dashcam = Camera.model_validate({"preset": "dashcam"}).model_dump()
    plan = build_plan(sources, Settings(frames_per_case=1, sampling="even", camera="dashcam"))
    assert all(parse_case(planned.case_text).camera.model_dump() == dashcam for planned in plan.cases)
    assert main(["dataset", "--cases", str(SCENES), "--out", str(tmp_path / "out"), "--camera",
                 str(tmp_path / "none.json")]) == 2
    assert "--camera" in capsys.readouterr().err
    assert main(["dataset", "--cases", str(SCENES), "--out", str(tmp_path / "out"), "--camera", "fisheye"]) == 2
    assert "unknown camera preset 'fisheye'" in capsys.readouterr().err


def test_the_vanishing_point_of_synthetic_lanes_is_where_they_meet() -> None:
    from lanevil_core.camera.vanishing import vanishing_point

    truth = (652.0, 290.0)
    rows = list(range(300, 720, 10))
    records = []
    for shift in (-30.0, 0.0, 25.0):  # three frames, the lanes' bottoms shifted as the car drifts
        lanes = [[math.floor(truth[0] + (h + 0.5 - truth[1]) * (slope + shift / 430)) for h in rows]
                 for slope in (-1.6, -0.5, 0.6, 1.7)]
        records.append((lanes, rows))
    u, v = vanishing_point(records)
    assert u == pytest.approx(truth[0], abs=1.0) and v == pytest.approx(truth[1], abs=1.0)
    with pytest.raises(ValueError, match="two lanes that meet"):
        vanishing_point([([[100] * len(rows)], rows)])


def test_lane_labels_of_rendered_straight_frames_give_the_pitch(tmp_path) -> None:
    from lanevil_core.labels.lanes import tusimple_record
    from lanevil_core.pipeline.compile import compile_scene
    from lanevil_core.render import render_frame

    data = json.loads((SCENES / "00_clean" / "00_straight_urban.json").read_text())
    data["camera"] = {"width": 640, "height": 360, "fov": 62.0, "z": 1.55, "x": 1.6, "pitch": 2.5}
    case = parse_case(data)
    scene = compile_scene(case)
    labels = tmp_path / "straight.json"
    lines = []
    for index in (0, 20):
        frame = render_frame(scene, index, (640, 360))
        lines.append(json.dumps(tusimple_record(scene, index, frame, f"{index}.png")))
    labels.write_text("\n".join(lines) + "\n")
    camera = load_camera(write(tmp_path, {"image_size": [640, 360], "hfov": 62.0, "height": 1.55,
                                          "lane_labels": "straight.json"}))
    assert camera.pitch == pytest.approx(2.5, abs=0.05) and abs(camera.yaw) < 0.1  # measured: 2.498, -0.002
    with pytest.raises(CalibrationError, match="lane_labels: .*no such file"):
        load_camera(write(tmp_path, {"image_size": [640, 360], "hfov": 62.0, "height": 1.55,
                                     "lane_labels": "missing.json"}))
