"""CULane metric: mask IoU of 30 px wide interpolated lanes, one-to-one matching at IoU > 0.5, pooled F1."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.labels.lanes import CULANE_SIZE
from lanevil_core.metrics.culane import (
    MatchCounts,
    interpolate_lane,
    iou_matrix,
    lane_mask,
    match_image,
    summarize,
)
from lanevil_core.metrics.evaluate import evaluate


def lane(x_bottom: float, x_top: float, n: int = 8) -> list[tuple[float, float]]:
    ys = np.linspace(580, 300, n)
    xs = np.linspace(x_bottom, x_top, n)
    return [(float(x), float(y)) for x, y in zip(xs, ys)]


def test_interpolation_runs_end_to_end_of_the_lane():
    points = [(100.0, 500.0), (150.0, 400.0), (220.0, 300.0), (300.0, 200.0)]
    fine = interpolate_lane(points)
    assert fine.shape == (16, 2)  # 3 segments x 5 + 1, evenly spaced in the spline parameter
    assert fine[0] == pytest.approx(points[0]) and fine[-1] == pytest.approx(points[-1])
    assert np.all(np.diff(fine[:, 1]) < 0)  # monotone along the lane, no overshoot loops


def test_lane_mask_is_30_px_wide():
    mask = lane_mask(interpolate_lane([(800.0, 580.0), (800.0, 300.0)]), CULANE_SIZE)
    row = mask[450]
    assert 29 <= int(row.sum()) <= 31 and row[800]


def test_identical_lanes_are_true_positives():
    lanes = [lane(400, 700), lane(1200, 900)]
    assert match_image(lanes, lanes, CULANE_SIZE) == MatchCounts(2, 0, 0)


def test_a_lane_shifted_100_px_is_a_false_positive_and_a_false_negative():
    assert match_image([lane(500, 800)], [lane(400, 700)], CULANE_SIZE) == MatchCounts(0, 1, 1)
    ious = iou_matrix([lane(410, 710)], [lane(400, 700)], CULANE_SIZE)
    assert 0.5 < ious[0, 0] < 0.8  # 10 px of a 30 px band: IoU 20/40


def test_matching_is_one_to_one():
    gt = [lane(400, 700)]
    two_on_one = [lane(400, 700), lane(405, 705)]  # both overlap the GT lane strongly
    assert match_image(two_on_one, gt, CULANE_SIZE) == MatchCounts(1, 1, 0)
    assert match_image(gt, two_on_one, CULANE_SIZE) == MatchCounts(1, 0, 1)


def test_assignment_maximises_total_iou():
    gt = [lane(400, 700), lane(440, 740)]
    pred = [lane(420, 720), lane(445, 745)]  # greedy would give pred 0 to gt 0 and leave pred 1 to gt 1 anyway
    counts = match_image(pred, gt, CULANE_SIZE)
    assert counts.tp + counts.fn == 2 and counts.tp + counts.fp == 2


def test_pooled_f1():
    summary = summarize([MatchCounts(3, 1, 0), MatchCounts(1, 0, 2), MatchCounts(0, 0, 0)])
    assert (summary.tp, summary.fp, summary.fn, summary.images) == (4, 1, 2, 3)
    assert summary.precision == pytest.approx(0.8) and summary.recall == pytest.approx(4 / 6)
    assert summary.f1 == pytest.approx(2 * 0.8 * (4 / 6) / (0.8 + 4 / 6))
    assert summarize([MatchCounts(0, 2, 3)]).f1 == 0.0


def _write_lines(path, lanes):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(" ".join(f"{x:.2f} {y:.0f}" for x, y in points) + "\n" for points in lanes))


def test_culane_folders_missing_prediction_is_an_empty_image(tmp_path):
    gt, pred = tmp_path / "gt", tmp_path / "pred"
    _write_lines(gt / "a" / "000000.lines.txt", [lane(400, 700), lane(1200, 900)])
    _write_lines(gt / "a" / "000001.lines.txt", [lane(400, 700)])
    _write_lines(pred / "a" / "000000.lines.txt", [lane(400, 700), lane(900, 900, 2)])
    result = evaluate(gt, pred, "culane")
    assert (result["tp"], result["fp"], result["fn"], result["images"]) == (1, 1, 2, 2)


def test_culane_metric_on_tusimple_files(tmp_path):
    rows = list(range(160, 720, 10))
    gt_lane = [600 + (y - 160) // 2 for y in rows]
    far = [x + 100 for x in gt_lane]
    (tmp_path / "gt.json").write_text(f'{{"raw_file": "a.png", "lanes": [{gt_lane}], "h_samples": {rows}}}\n')
    (tmp_path / "pred.json").write_text(f'{{"raw_file": "a.png", "lanes": [{gt_lane}, {far}]}}\n')
    result = evaluate(tmp_path / "gt.json", tmp_path / "pred.json", "culane")
    assert (result["tp"], result["fp"], result["fn"]) == (1, 1, 0)
