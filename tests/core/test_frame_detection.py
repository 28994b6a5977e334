"""A detector on one rendered frame: catalog, scoring at any size, and the detection colour of the overlay."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.detect import catalog as detector_catalog
from lanevil_core.detect.catalog import available_detector, detector_info, detector_infos, detector_version
from lanevil_core.detect.frame_detection import detect_frame, score_frame_lanes
from lanevil_core.detect.learned import BUNDLED_MODELS
from lanevil_core.detect.split import METHODS
from lanevil_core.labels.lanes import h_samples_for, tusimple_record
from lanevil_core.labels.overlay import DETECTION_COLOR, LANE_COLORS, draw_detections, draw_lanes
from lanevil_core.metrics.formats import LaneFileError
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame


def test_catalog_lists_every_method_once() -> None:
    infos = detector_infos()
    assert [info.name for info in infos] == [*METHODS, *BUNDLED_MODELS]
    kinds = {info.name: info.kind for info in infos}
    assert kinds["hough"] == kinds["birdseye"] == "classical" and kinds["ufld"] == "learned"
    ufld = detector_info("ufld")
    assert ufld.available and ufld.model is not None and ufld.model["input_size"] == [320, 180]
    assert ufld.version.startswith("ufld@") and detector_version("hough") == "hough"


def test_unknown_and_missing_detectors_say_so(monkeypatch, tmp_path) -> None:
    with pytest.raises(LaneFileError, match="^detector: unknown detector 'yolo'"):
        detector_info("yolo")
    monkeypatch.setattr(detector_catalog, "SHIPPED_MODELS", tmp_path)
    info = detector_info("ufld")
    assert not info.available and "no ufld model" in (info.reason or "") and info.model is None
    with pytest.raises(LaneFileError, match="^detector: ufld is not available"):
        available_detector("ufld")
    assert detector_info("hough").available


def test_score_is_taken_on_the_tusimple_grid() -> None:
    rows = h_samples_for(360)
    gt = [[100 + j for j in range(len(rows))], [500 - j for j in range(len(rows))]]
    assert score_frame_lanes(gt, gt, rows, (640, 360)).accuracy == 1.0
    # 8 px at 640 wide are 16 px at 1280: inside the 20 px tolerance; 12 px (24 at 1280) are not
    near = [[x + 8 for x in lane] for lane in gt]
    far = [[x + 12 for x in lane] for lane in gt]
    assert score_frame_lanes(near, gt, rows, (640, 360)).accuracy == 1.0
    far_score = score_frame_lanes(far, gt, rows, (640, 360))
    assert far_score.accuracy == 0.0 and far_score.fn == 1.0
    none = score_frame_lanes([], gt, rows, (640, 360))
    assert (none.accuracy, none.fp, none.fn) == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("method", ["ufld", "hough"])
def test_detect_frame_on_a_render(make_case, method: str) -> None:
    case = make_case()
    scene = compile_scene(case)
    frame = render_frame(scene, 0, (320, 180))
    record = tusimple_record(scene, 0, frame, raw_file="000000.png")
    found = detect_frame(method, frame.rgb, record)
    assert found.detector == method and found.size == (320, 180) and found.h_samples == h_samples_for(180)
    assert found.gt_lanes == record["lanes"] and 0.0 <= found.accuracy <= 1.0
    assert all(len(lane) == len(found.h_samples) for lane in found.lanes)
    assert set(found.as_dict()) >= {"detector", "lanes", "h_samples", "gt_lanes", "accuracy", "fp", "fn",
                                    "run_time_ms"}


def test_detections_are_drawn_in_their_own_color() -> None:
    assert DETECTION_COLOR not in LANE_COLORS
    # no ground-truth colour is near magenta (a hue between red and blue with little green)
    assert all(not (r > 200 and b > 200 and g < 100) for r, g, b in LANE_COLORS)
    image = np.zeros((90, 160, 3), np.uint8)
    rows = list(range(30, 90, 10))
    lanes = [[40] * len(rows), [-2] * len(rows)]
    drawn = draw_detections(image, lanes, rows)
    colors = {tuple(c) for c in drawn.reshape(-1, 3)} - {(0, 0, 0)}
    assert colors and all(c[1] < 60 and c[0] > 100 and c[2] > 100 for c in colors)  # magenta (antialiased)
    labelled = draw_lanes(drawn, {"lanes": lanes, "h_samples": rows})
    assert tuple(labelled[50, 40]) == LANE_COLORS[0]  # a label's dot sits on top of the band


def test_detection_modules_import_no_web_framework() -> None:
    code = ("import sys, lanevil_core.detect.catalog, lanevil_core.detect.frame_detection; "
            "print(','.join(m for m in ('fastapi', 'viser', 'uvicorn', 'starlette', 'torch') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parents[2])
    assert out.stdout.strip() == ""
