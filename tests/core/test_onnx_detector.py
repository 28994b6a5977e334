"""ONNX models with a standard head: the three decoders, and a lane-line mask model trained here and exported."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

from lanevil_core.cli import main
from lanevil_core.detect.catalog import detector_info
from lanevil_core.detect.onnx_detector import Sidecar, network_input
from lanevil_core.detect.registry import ENV_DETECTORS, detector_for
from lanevil_core.detect.standard_heads import decode_mask_head, decode_polynomial_head, decode_row_anchor_head
from lanevil_core.labels.lanes import h_samples_for
from lanevil_core.metrics.formats import LaneFileError

FRAME_SIZE = (320, 180)
ROWS = h_samples_for(180)


def line_frame(lines: list[tuple[tuple[int, int], tuple[int, int]]], size=FRAME_SIZE, dashed=False) -> np.ndarray:
    """A dark (H, W, 3) frame with white lines 3 px wide between pixel points ``(x, y)``."""
    rgb = np.full((size[1], size[0], 3), 50, np.uint8)
    for start, end in lines:
        cv2.line(rgb, start, end, (255, 255, 255), 3)
    if dashed:  # cut every line into dashes: 12 rows on, 8 off
        rows = np.arange(size[1])
        rgb[(rows % 20) >= 12] = 50
    return rgb


def x_on(line, y: float) -> float:
    """x of the segment ``line`` at pixel row ``y``."""
    (x0, y0), (x1, y1) = line
    return x0 + (x1 - x0) * (y - y0) / (y1 - y0)


def test_row_anchor_head_reads_ufld_scores() -> None:
    grid, rows, lanes = 10, 4, 2
    scores = np.full((grid + 1, rows, lanes), -10.0)
    scores[grid, :, 1] = 10.0  # lane 1 absent everywhere
    for r in range(rows):
        scores[3 + r, r, 0] = 10.0  # lane 0 in cell 3, 4, 5, 6 going down
    rows_norm = np.array([0.2, 0.4, 0.6, 0.8])
    (line,) = decode_row_anchor_head(scores, rows_norm)
    assert np.allclose(line[:, 1], rows_norm) and np.allclose(line[:, 0], (np.arange(3, 7) + 0.5) / grid, atol=1e-3)
    with pytest.raises(ValueError, match="row_anchors"):
        decode_row_anchor_head(scores, rows_norm[:3])


def test_polynomial_head_reads_lstr_curves() -> None:
    scores = np.array([[0.0, 5.0], [5.0, 0.0]])  # query 0 is a lane, query 1 is not
    curves = np.array([[0.4, 1.0, 0.0, -1.0, 0.0, 0.1, 0.5, 0.0], [0.4, 1.0, 0, -1, 0, 0.9, 0, 0]])
    (line,) = decode_polynomial_head(scores, curves)
    assert line[0, 1] == pytest.approx(0.4) and line[-1, 1] == pytest.approx(1.0)
    assert np.allclose(line[:, 0], 0.1 + 0.5 * line[:, 1])


def test_mask_head_clusters_dashed_lines_into_lanes() -> None:
    lines = [((30, 179), (140, 60)), ((300, 179), (180, 60))]
    gray = line_frame(lines, dashed=True)[..., 0] > 128
    found = decode_mask_head(gray[None].astype(np.float64), logits=False)
    assert len(found) == 2
    for polyline, line in zip(sorted(found, key=lambda p: p[-1, 0]), lines, strict=True):
        u = polyline[:, 0] * FRAME_SIZE[0]
        v = polyline[:, 1] * FRAME_SIZE[1]
        assert np.abs(u - 0.5 - np.array([x_on(line, y - 0.5) for y in v])).max() < 1.5
        assert v.min() < 75 and v.max() > 170  # the dashes are joined over the whole line


def test_the_sidecar_is_checked_field_by_field(tmp_path) -> None:
    for data, message in (({"input_size": [64, 64]}, "head is missing"),
                          ({"head": "boxes", "input_size": [64, 64]}, "head 'boxes'"),
                          ({"head": "mask", "input_size": [64]}, "input_size: expected a list of 2"),
                          ({"head": "mask", "input_size": [64, 64], "crop": [0, 0.5, 1, 0.2]}, "crop"),
                          ({"head": "row_anchors", "input_size": [64, 64]}, "needs row_anchors"),
                          ({"head": "mask", "input_size": [64, 64], "colour": "rgb"}, "unknown field 'colour'")):
        with pytest.raises(LaneFileError, match=message):
            Sidecar.from_dict(data, "s.json")
    sidecar = Sidecar.from_dict({"head": "mask", "input_size": [8, 8], "crop": [0, 0.5, 1, 1], "color_order": "bgr",
                                 "mean": [0.5, 0.5, 0.5], "std": [0.5, 0.5, 0.5]}, "s.json")
    rgb = np.zeros((32, 16, 3), np.uint8)
    rgb[16:, :, 0] = 255  # red in the kept bottom half
    batch = network_input(rgb, sidecar)
    assert batch.shape == (1, 3, 8, 8) and batch.dtype == np.float32
    assert np.all(batch[0, 2] == 1.0) and np.all(batch[0, 0] == -1.0)  # red is the last channel in bgr


def test_a_trained_mask_model_finds_the_lines(mask_model, tmp_path, monkeypatch, capsys) -> None:
    path = mask_model
    lines = [((40, 179), (140, 70)), ((290, 179), (190, 70))]
    rgb = line_frame(lines)
    lanes = detector_for(f"onnx:{path}")(rgb, ROWS)
    assert len(lanes) == 2
    for lane, line in zip(sorted(lanes, key=lambda lane: lane[-1]), lines, strict=True):
        rows = [h for h, x in zip(ROWS, lane, strict=True) if x >= 0]
        assert min(rows) <= 75 and max(rows) >= 170  # the crop's top is row 45: nothing above it is seen
        error = [abs(x - x_on(line, h)) for h, x in zip(ROWS, lane, strict=True) if x >= 0]
        assert max(error) <= 4.0, error
    assert detector_for(f"onnx:{path}")(np.full_like(rgb, 50), ROWS) == []
    monkeypatch.setenv(ENV_DETECTORS, f"seg-real=onnx:{path}")
    info = detector_info("seg-real")
    assert (info.kind, info.available, info.real_trained) == ("onnx", True, True)
    split = tmp_path / "test"
    split.mkdir()
    cv2.imwrite(str(split / "000000.png"), rgb[..., ::-1])
    (split / "test_label.json").write_text(json.dumps({"raw_file": "000000.png", "lanes": [], "h_samples": ROWS}))
    out = tmp_path / "pred.json"
    assert main(["detect", str(split), "--method", "seg-real", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["lanes"] == lanes
    path.with_suffix(".json").unlink()
    capsys.readouterr()
    assert main(["detect", str(split), "--method", f"onnx:{tmp_path / 'other.onnx'}", "--out", str(out)]) == 2
    assert "no ONNX model at" in capsys.readouterr().err


def constant_model(tmp_path, outputs: dict[str, np.ndarray], sidecar: dict) -> Path:
    """An ONNX model whose outputs are fixed tensors (the image only touches them times zero), and its sidecar."""
    torch = pytest.importorskip("torch")

    class Constant(torch.nn.Module):  # type: ignore[name-defined]
        def __init__(self) -> None:
            super().__init__()
            self.values = torch.nn.ParameterList([torch.nn.Parameter(torch.tensor(v[None], dtype=torch.float32))
                                                  for v in outputs.values()])

        def forward(self, image):
            return tuple(value + 0.0 * image.mean() for value in self.values)

    path = tmp_path / "constant.onnx"
    width, height = sidecar["input_size"]
    with torch.no_grad(), warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(Constant(), torch.zeros(1, 3, height, width), str(path), input_names=["image"],
                          output_names=list(outputs), dynamo=False)
    (tmp_path / "constant.json").write_text(json.dumps(sidecar))
    return path


def test_a_row_anchor_model_s_lanes_land_in_the_frame_through_the_crop(tmp_path) -> None:
    scores = np.full((11, 4, 2), -10.0)
    scores[4, :, 0] = 10.0  # lane 0 in cell 4 of 10 at every anchor: x_norm 0.45
    scores[10, :, 1] = 10.0  # lane 1 absent
    path = constant_model(tmp_path, {"row_scores": scores}, {
        "head": "row_anchors", "input_size": [80, 40], "crop": [0, 0.5, 1, 1], "row_anchors": [10, 20, 30, 39]})
    (lane,) = detector_for(f"onnx:{path}")(line_frame([]), ROWS)
    # the crop is rows 90..180; anchors at input rows 10..39 of 40 are frame rows 112.5 .. 177.75
    seen = {h: x for h, x in zip(ROWS, lane, strict=True) if x >= 0}
    assert min(seen) == 112 and max(seen) == 175 and set(seen.values()) == {144}  # u_image 0.45 * 320


def test_a_polynomial_model_s_curves_are_sampled_in_frame_pixels(tmp_path) -> None:
    curves = np.array([[0.2, 1.0, 0.0, -1.0, 0.0, 0.25, 0.5, 0.0], [0.2, 1.0, 0.0, -1.0, 0.0, 0.9, 0.0, 0.0]])
    path = constant_model(tmp_path, {"pred_logits": np.array([[0.0, 5.0], [5.0, 0.0]]), "pred_curves": curves},
                          {"head": "polynomial", "input_size": [64, 36], "outputs": ["pred_logits", "pred_curves"]})
    (lane,) = detector_for(f"onnx:{path}")(line_frame([]), ROWS)
    for h, x in zip(ROWS, lane, strict=True):
        y = (h + 0.5) / 180
        if y >= 0.2 + 0.01:
            assert abs(x - math.floor((0.25 + 0.5 * y) * 320)) <= 1, (h, x)
        elif y < 0.2 - 0.01:
            assert x == -2


def test_detect_writes_the_mask_model_s_masks_for_the_pixel_metric(mask_model, tmp_path, capsys) -> None:
    lines = [((40, 179), (140, 70)), ((290, 179), (190, 70))]
    split = tmp_path / "test"
    split.mkdir()
    rgb = line_frame(lines)
    cv2.imwrite(str(split / "000000.png"), rgb[..., ::-1])
    gt_lanes = [[math.floor(x_on(line, h + 0.5) + 0.5) if h >= 70 else -2 for h in ROWS] for line in lines]
    (split / "test_label.json").write_text(json.dumps({"raw_file": "000000.png", "lanes": gt_lanes, "h_samples": ROWS,
                                                       "image_size": list(FRAME_SIZE)}))
    masks = tmp_path / "masks"
    assert main(["detect", str(split), "--method", f"onnx:{mask_model}", "--out", str(tmp_path / "p.json"),
                 "--masks", str(masks)]) == 0
    written = cv2.imread(str(masks / "000000.png"), cv2.IMREAD_GRAYSCALE)
    assert written is not None
    mask = written > 0
    painted = rgb[..., 0] == 255
    seen = painted.copy()
    seen[:45] = False  # the sidecar crops the top quarter
    assert mask.shape == painted.shape and not mask[:45].any()
    assert (mask & seen).sum() > 0.8 * seen.sum() and (mask & painted).sum() > 0.5 * mask.sum()
    capsys.readouterr()
    assert main(["eval", "--gt", str(split), "--pred", str(masks), "--metric", "pixel", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["f1"] > 0.5
    out = ["--out", str(tmp_path / "q.json"), "--masks", str(masks)]
    assert main(["detect", str(split), "--method", "hough", *out]) == 2
    assert "not an ONNX model with a mask head" in capsys.readouterr().err
    assert main(["detect", str(split), "--method", f"onnx:{mask_model}", "--method", "hough", *out]) == 2
    assert "only with a single --method" in capsys.readouterr().err
