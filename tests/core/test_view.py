"""The view window (``detect.view``, ``lanevil adapt --method view``): the geometry puts any camera's vanishing
point and ego lane where the stock camera has them, the window is cut and mapped back exactly, and the command
measures a rendered stock camera as the stock camera."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from PIL import Image

from lanevil_core.case import load_case
from lanevil_core.cli import main
from lanevil_core.detect.lane_slots import LaneLine
from lanevil_core.detect.learned import LearnedDetector, network_input, shipped_model_dir
from lanevil_core.detect.model_spec import ModelSpecError
from lanevil_core.detect.view import (
    STOCK_VANISHING,
    STOCK_WEDGE,
    VIEW_FILE,
    WINDOW_HEIGHT,
    WINDOW_WIDTH,
    View,
    ViewError,
    measure_view,
    view_input,
    window_for,
)
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame

ROOT = Path(__file__).resolve().parents[2]
ASPECT = 720.0 / 1280.0


def camera_lines(vanishing: tuple[float, float], wedge: float, lanes: int = 4) -> list[LaneLine]:
    """The lines of a flat straight road seen by a camera centred in its lane: line ``i`` (lane widths from the
    camera) opens from the vanishing point at ``i * wedge`` per unit of height."""
    vanish_x, vanish_y = vanishing
    y = np.linspace(vanish_y + 0.05, 1.0, 12)
    offsets = np.arange(lanes) - (lanes - 1) / 2.0
    return [LaneLine(np.column_stack([vanish_x + i * wedge * (y - vanish_y), y])) for i in offsets]


def to_window(point: tuple[float, float], window: tuple[float, float, float, float]) -> tuple[float, float]:
    left, top, right, bottom = window
    return (point[0] - left) / (right - left), (point[1] - top) / (bottom - top)


def test_the_stock_camera_sees_the_whole_frame() -> None:
    assert window_for(STOCK_VANISHING, STOCK_WEDGE) == pytest.approx((0.0, 0.0, 1.0, 1.0))
    assert window_for(STOCK_VANISHING, None) == pytest.approx((0.0, 0.0, 1.0, 1.0))


@settings(max_examples=60, deadline=None)
@given(st.floats(0.35, 0.65), st.floats(0.3, 0.62), st.floats(0.4, 1.3))
def test_a_measured_camera_is_shown_as_the_stock_camera(vanish_x: float, vanish_y: float, wedge: float) -> None:
    height = 2.0 - 2.0 * vanish_y  # the frame's bottom stays the window's, the vanishing point halfway down
    assume(WINDOW_WIDTH[0] < wedge * height / STOCK_WEDGE < WINDOW_WIDTH[1])  # not held back by the limits
    frames = [camera_lines((vanish_x, vanish_y), wedge) for _ in range(3)]
    view = measure_view(frames, ASPECT)
    assert view.vanishing == pytest.approx((vanish_x, vanish_y), abs=1e-6)
    assert view.wedge == pytest.approx(wedge, rel=1e-6)
    # the vanishing point lands where the stock camera has it, and the ego lane opens as there
    assert to_window((vanish_x, vanish_y), view.window) == pytest.approx(STOCK_VANISHING, abs=1e-6)
    left, top, right, bottom = view.window
    assert wedge * (bottom - top) / (right - left) == pytest.approx(STOCK_WEDGE, rel=1e-6)
    # lines read in the window come back to where they are in the frame
    for line in frames[0]:
        inside = LaneLine(np.column_stack([(line.points[:, 0] - left) / (right - left),
                                           (line.points[:, 1] - top) / (bottom - top)]))
        assert view.to_frame(inside).points == pytest.approx(line.points, abs=1e-9)


def test_a_far_off_measurement_is_followed_only_so_far() -> None:
    left, top, right, bottom = window_for((0.5, -0.2), 5.0)
    assert (bottom - top, right - left) == pytest.approx((WINDOW_HEIGHT[1], WINDOW_WIDTH[1]))
    left, top, right, bottom = window_for((0.5, 0.9), 0.05)
    assert (bottom - top, right - left) == pytest.approx((WINDOW_HEIGHT[0], WINDOW_WIDTH[0]))


def test_too_few_frames_with_lines_are_refused() -> None:
    with pytest.raises(ViewError, match="frames: only 1 of 2 frames"):
        measure_view([camera_lines((0.5, 0.5), 0.6), camera_lines((0.5, 0.5), 0.6)[:1]], ASPECT)


def test_the_window_is_cut_where_it_lies() -> None:
    """A dot in the frame appears in the network's input where the window maps it; outside the frame the edge
    pixel is repeated; the whole frame as window is the plain resize."""
    frame = np.zeros((360, 640, 3), np.uint8)
    frame[180 - 4:180 + 4, 480 - 4:480 + 4] = 255  # a dot centred at (0.75, 0.5) of the frame
    view = View((0.25, -0.5, 1.25, 1.0))
    seen = view_input(frame, view, (320, 180)).astype(float)[..., 0]
    rows, cols = np.nonzero(seen > 60)
    weights = seen[rows, cols]
    centre = ((cols + 0.5) @ weights / weights.sum() / 320, (rows + 0.5) @ weights / weights.sum() / 180)
    assert centre == pytest.approx(to_window((0.75, 0.5), view.window), abs=0.01)
    frame[:8] = 200  # the top rows are repeated above the frame
    assert (view_input(frame, view, (320, 180))[:50, 10:300] == 200).all()
    whole = network_input(frame, (320, 180), View((0.0, 0.0, 1.0, 1.0)))
    assert np.abs(whole - network_input(frame, (320, 180))).max() <= 1.0 / 255.0 + 1e-6


def test_a_bad_view_file_is_refused_naming_the_window(tmp_path: Path) -> None:
    model = tmp_path / "ufld"
    shutil.copytree(shipped_model_dir("ufld"), model)
    (model / VIEW_FILE).write_text(json.dumps({"window": [0.5, 0.0, 0.2, 1.0]}))
    with pytest.raises(ModelSpecError, match="window"):
        LearnedDetector(model)
    with pytest.raises(ViewError, match="window"):
        View((0.0, 0.0, 1.0, float("nan")))


def _stock_frames(folder: Path) -> Path:
    scene = compile_scene(load_case(ROOT / "scenes" / "00_clean" / "00_straight_urban.json"))
    folder.mkdir()
    for frame in (10, 40, 70):
        Image.fromarray(render_frame(scene, frame, (640, 360)).rgb).save(folder / f"{frame:03d}.png")
    return folder


def test_adapt_view_measures_the_stock_camera_as_the_stock_camera(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    frames = _stock_frames(tmp_path / "mine")
    out = tmp_path / "ufld-view"
    assert main(["adapt", "--weights", "ufld", "--frames", str(frames), "--out", str(out), "--method", "view",
                 "--camera-height", "3.0", "--quiet"]) == 0
    assert "window [" in capsys.readouterr().out
    view = View.load(out)
    assert view is not None and view.frames >= 2
    assert view.window == pytest.approx((0.0, 0.0, 1.0, 1.0), abs=0.08)  # the stock camera: 3 m up, level
    with Image.open(out / "view.png") as picture:  # the window drawn on one of the frames, to check by eye
        assert picture.size == (640, 360)
    summary = json.loads((out / "training.json").read_text())
    assert summary["method"] == "view" and summary["camera_height"] == 3.0
    labels = tmp_path / "labels.json"
    assert main(["detect", str(frames), "--method", "ufld", "--weights", str(out), "--out", str(labels)]) == 0
    assert len(labels.read_text().splitlines()) == 3


@pytest.mark.parametrize(("extra", "message"), [
    (["--camera-height", "1.5"], "--camera-height: only with --method view"),
    (["--method", "view", "--lane-width", "3.6"], "--lane-width: only with --camera-height"),
    (["--method", "view", "--camera-height", "40"], "--camera-height 40.0: give the height in metres"),
])
def test_adapt_view_refuses_bad_flags_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  extra: list[str], message: str) -> None:
    assert main(["adapt", "--weights", "ufld", "--frames", str(tmp_path), "--out", str(tmp_path / "o"), *extra]) == 2
    assert message in capsys.readouterr().err


def test_adapt_view_on_frames_without_a_road_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    frames = tmp_path / "grey"
    frames.mkdir()
    for index in range(3):
        Image.fromarray(np.full((360, 640, 3), 120, np.uint8)).save(frames / f"{index}.png")
    assert main(["adapt", "--weights", "ufld", "--frames", str(frames), "--out", str(tmp_path / "o"), "--method",
                 "view"]) == 2
    assert "frames: only 0 of 3 frames" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
