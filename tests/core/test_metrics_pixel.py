"""The pixel lane-line metric against an independent, pixel-by-pixel implementation on small fixtures."""

from __future__ import annotations

import json
import math

import cv2
import numpy as np
import pytest

from lanevil_core.cli import main
from lanevil_core.metrics.evaluate import evaluate
from lanevil_core.metrics.pixel import lane_mask

SIZE = (64, 36)
ROWS = list(range(8, 36, 3))  # 10 rows
GT = [
    {"raw_file": "a.png", "image_size": list(SIZE), "h_samples": ROWS, "lanes": [
        [-2, 10, 11, 12, 13, 14, 15, 16, 17, 18],  # a straight lane from row 11 down
        [40, 42, -2, -2, 48, 50, -2, 54, 56, 60],  # broken twice, a lone point at row 26
    ]},
    {"raw_file": "b.png", "image_size": list(SIZE), "h_samples": ROWS, "lanes": []},  # no lane at all
]
PRED = [
    {"raw_file": "a.png", "h_samples": ROWS, "lanes": [[-2, 11, 12, 13, 14, 15, 16, 17, 18, 19],
                                                      [-2, -2, -2, -2, 30, 31, 32, 33, 34, 35]]},
    {"raw_file": "b.png", "h_samples": ROWS, "lanes": [[5, 5, 5, -2, -2, -2, -2, -2, -2, -2]]},
]
LINE_WIDTH = 60.0  # at 720 rows: 3 px at 36 rows


def reference_pixels(lanes, rows, size, width) -> set[tuple[int, int]]:
    """Every (col, row) whose centre is within width/2 of a lane's polyline, by looping over pixels and pieces."""
    pieces = []
    for lane in lanes:
        points = [(x, h) if x >= 0 else None for x, h in zip(lane, rows)]
        for i, p in enumerate(points):
            if p is None:
                continue
            nxt = points[i + 1] if i + 1 < len(points) else None
            prev = points[i - 1] if i > 0 else None
            if nxt is not None:
                pieces.append((p, nxt))
            elif prev is None:
                pieces.append((p, p))

    def distance(c, r, a, b) -> float:
        (ax, ay), (bx, by) = a, b
        length2 = (bx - ax) ** 2 + (by - ay) ** 2
        t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((c - ax) * (bx - ax) + (r - ay) * (by - ay)) / length2))
        return math.hypot(c - (ax + t * (bx - ax)), r - (ay + t * (by - ay)))

    return {(c, r) for r in range(size[1]) for c in range(size[0])
            if any(distance(c, r, a, b) <= width / 2 for a, b in pieces)}


def reference_summary(pred_sets, gt_sets) -> dict[str, float]:
    tp = sum(len(p & g) for p, g in zip(pred_sets, gt_sets))
    fp = sum(len(p - g) for p, g in zip(pred_sets, gt_sets))
    fn = sum(len(g - p) for p, g in zip(pred_sets, gt_sets))
    return {"tp": tp, "fp": fp, "fn": fn, "iou": tp / (tp + fp + fn), "f1": 2 * tp / (2 * tp + fp + fn),
            "precision": tp / (tp + fp), "recall": tp / (tp + fn)}


@pytest.fixture
def files(tmp_path):
    gt, pred = tmp_path / "gt.json", tmp_path / "pred.json"
    gt.write_text("".join(json.dumps(r) + "\n" for r in GT))
    pred.write_text("".join(json.dumps(r) + "\n" for r in PRED))
    return gt, pred


def test_the_line_mask_is_the_pixels_near_the_polyline() -> None:
    width = LINE_WIDTH * SIZE[1] / 720
    for record in GT + PRED:
        mask = lane_mask(record["lanes"], ROWS, SIZE, width)  # type: ignore[arg-type]
        expected = reference_pixels(record["lanes"], ROWS, SIZE, width)
        assert {(int(c), int(r)) for r, c in zip(*np.nonzero(mask))} == expected


def test_lane_files_score_as_the_reference_does(files) -> None:
    gt, pred = files
    result = evaluate(gt, pred, "pixel", line_width=LINE_WIDTH)
    width = LINE_WIDTH * SIZE[1] / 720
    expected = reference_summary([reference_pixels(r["lanes"], ROWS, SIZE, width) for r in PRED],
                                 [reference_pixels(r["lanes"], ROWS, SIZE, width) for r in GT])
    assert result["metric"] == "pixel" and result["images"] == 2 and result["line_width"] == LINE_WIDTH
    for key, value in expected.items():
        assert result[key] == pytest.approx(value), key
    assert 0 < result["iou"] < result["f1"] < 1


def test_a_folder_of_masks_scores_as_the_reference_does(files, tmp_path, capsys) -> None:
    gt, _ = files
    masks = tmp_path / "masks"
    masks.mkdir()
    rng = np.random.default_rng(3)
    pred_sets = []
    for record in GT:
        mask = (rng.random((SIZE[1], SIZE[0])) < 0.1).astype(np.uint8) * 255
        cv2.imwrite(str(masks / record["raw_file"]), mask)
        pred_sets.append({(int(c), int(r)) for r, c in zip(*np.nonzero(mask))})
    width = LINE_WIDTH * SIZE[1] / 720
    expected = reference_summary(pred_sets, [reference_pixels(r["lanes"], ROWS, SIZE, width) for r in GT])
    assert main(["eval", "--gt", str(gt), "--pred", str(masks), "--metric", "pixel", "--line-width", "60",
                 "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    for key, value in expected.items():
        assert result[key] == pytest.approx(value), key
    cv2.imwrite(str(masks / "b.png"), np.zeros((10, 10), np.uint8))
    assert main(["eval", "--gt", str(gt), "--pred", str(masks), "--metric", "pixel"]) == 2
    assert "a 10x10 mask for a 64x36 image" in capsys.readouterr().err
    assert main(["eval", "--gt", str(gt), "--pred", str(masks), "--line-width", "3"]) == 2
    assert "only with --metric pixel" in capsys.readouterr().err


def test_perfect_and_empty_predictions(files, tmp_path, capsys) -> None:
    gt, _ = files
    assert evaluate(gt, gt, "pixel")["iou"] == 1.0
    assert main(["eval", "--gt", str(gt), "--pred", str(gt), "--metric", "pixel"]) == 0
    assert "Pixel lane lines (8 px at 720 rows)  images 2  IoU 100.00 %" in capsys.readouterr().out
    empty = tmp_path / "empty.json"
    empty.write_text("".join(json.dumps({**r, "lanes": []}) + "\n" for r in PRED))
    result = evaluate(gt, empty, "pixel")
    assert result["iou"] == result["f1"] == result["recall"] == 0.0 and result["fp"] == 0
