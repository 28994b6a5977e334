"""TuSimple metric: hand-computed cases for every quirk of the official script, F1 variants, and a literal
restatement of the official ``LaneEval.bench`` as an oracle on random images."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lanevil_core.metrics.tusimple import (
    ImageScore,
    f1_clrnet,
    f1_ganet,
    lane_tolerance,
    line_accuracy,
    score_image,
    summarize,
)

ROWS = list(range(160, 720, 10))  # 56 rows


def vertical(x: float, rows: list[int] = ROWS) -> list[float]:
    return [x] * len(rows)


def official_bench(pred, gt, y_samples, running_time):
    """The official ``LaneEval.bench`` (lane.py), restated line by line with numpy's least squares."""
    if running_time > 200 or len(gt) + 2 < len(pred):
        return 0.0, 0.0, 1.0
    angles = []
    for x_gts in gt:
        xs, ys = np.array(x_gts, float), np.array(y_samples, float)
        xs, ys = xs[xs >= 0], ys[xs >= 0]
        angles.append(np.arctan(np.polyfit(ys, xs, 1)[0]) if len(xs) > 1 else 0)
    threshs = [20 / np.cos(angle) for angle in angles]
    line_accs, fp, fn, matched = [], 0.0, 0.0, 0.0
    for x_gts, thresh in zip(gt, threshs):
        accs = []
        for x_preds in pred:
            p = np.array([v if v >= 0 else -100 for v in x_preds])
            g = np.array([v if v >= 0 else -100 for v in x_gts])
            accs.append(np.sum(np.where(np.abs(p - g) < thresh, 1.0, 0.0)) / len(g))
        max_acc = np.max(accs) if len(accs) > 0 else 0.0
        if max_acc < 0.85:
            fn += 1
        else:
            matched += 1
        line_accs.append(max_acc)
    fp = len(pred) - matched
    if len(gt) > 4 and fn > 0:
        fn -= 1
    s = sum(line_accs)
    if len(gt) > 4:
        s -= min(line_accs)
    return (s / max(min(4.0, len(gt)), 1.0), fp / len(pred) if len(pred) > 0 else 0.0,
            fn / max(min(len(gt), 4.0), 1.0))


def test_identical_lanes_score_perfectly():
    gt = [vertical(300), vertical(600), vertical(900)]
    assert score_image(gt, gt, ROWS, 10.0) == ImageScore(1.0, 0.0, 0.0)


def test_tolerance_grows_with_the_lane_angle():
    rows = list(range(0, 100, 10))
    slanted = [float(y) for y in rows]  # x = y: 45 degrees, tolerance 20 / cos 45 = 28.28 px
    assert lane_tolerance(slanted, rows) == pytest.approx(20 * math.sqrt(2))
    shifted = [x + 25 for x in slanted]
    assert line_accuracy(shifted, slanted, lane_tolerance(slanted, rows)) == 1.0
    upright = vertical(50, rows)  # tolerance 20 px: the same 25 px shift misses every row
    assert line_accuracy([x + 25 for x in upright], upright, lane_tolerance(upright, rows)) == 0.0
    # Only valid points enter the fit: missing points (-2) do not tilt the line.
    assert lane_tolerance([-2, -2, *slanted[2:]], rows) == pytest.approx(20 * math.sqrt(2))
    assert lane_tolerance([-2] * 9 + [40], rows) == 20.0  # fewer than two points: theta = 0


def test_missing_points_count_as_minus_100_on_both_sides():
    rows = list(range(10))
    gt = [-2, -2, -2, -2, 100, 100, 100, 100, 100, 100]
    assert line_accuracy([-2] * 4 + [105] * 6, gt, 20.0) == 1.0  # missing in both = a hit
    assert line_accuracy([100] * 10, gt, 20.0) == 0.6  # a point where the GT has none = a miss
    assert line_accuracy([-81] * 4 + [100] * 6, gt, 20.0) == 1.0  # any negative x reads as -100
    assert line_accuracy([0] * 4 + [100] * 6, gt, 20.0) == 0.6  # x = 0 is a point, 100 px from -100
    score = score_image([[100] * 10], [gt], rows, 0.0)
    assert score == ImageScore(0.6, 1.0, 1.0)  # best 0.6 < 0.85: unmatched, its prediction is an FP


def test_match_threshold_is_inclusive_at_085():
    rows = list(range(20))
    gt = [vertical(100, rows)]
    hit17 = [[100.0] * 17 + [300.0] * 3]  # 17/20 = 0.85 -> matched
    hit16 = [[100.0] * 16 + [300.0] * 4]  # 0.80 -> not matched
    assert score_image(hit17, gt, rows, 0.0) == ImageScore(0.85, 0.0, 0.0)
    assert score_image(hit16, gt, rows, 0.0) == ImageScore(0.8, 1.0, 1.0)


def test_each_gt_lane_takes_its_best_prediction_not_one_to_one():
    gt = [vertical(100), vertical(110)]
    pred = [vertical(105)]  # within 20 px of both GT lanes
    score = score_image(pred, gt, ROWS, 0.0)
    assert score.accuracy == 1.0 and score.fn == 0.0
    assert score.fp == -1.0  # (1 prediction - 2 matched) / 1: the official script's FP goes negative


def test_more_than_four_gt_lanes_drop_the_lowest_and_one_miss():
    gt = [vertical(x) for x in (100, 300, 500, 700, 900)]
    four = [vertical(x) for x in (100, 300, 500, 700)]
    assert score_image(four, gt, ROWS, 0.0) == ImageScore(1.0, 0.0, 0.0)
    three = [vertical(x) for x in (100, 300, 500)]
    assert score_image(three, gt, ROWS, 0.0) == ImageScore(0.75, 0.0, 0.25)  # (3 - 0) / 4; FN (2 - 1) / 4
    partial = [vertical(x) for x in (100, 300, 500, 700)] + [[900.0] * 28 + [2000.0] * 28]
    assert score_image(partial, gt, ROWS, 0.0).accuracy == 1.0  # 4 + 0.5 - min 0.5 over 4


def test_too_many_predictions_or_slow_images_score_zero():
    gt = [vertical(300)]
    three = [vertical(300), vertical(700), vertical(900)]  # 1 + 2: still scored
    assert score_image(three, gt, ROWS, 0.0) == ImageScore(1.0, 2 / 3, 0.0)
    four = three + [vertical(1100)]
    assert score_image(four, gt, ROWS, 0.0) == ImageScore(0.0, 0.0, 1.0)
    assert score_image(gt, gt, ROWS, 200.0) == ImageScore(1.0, 0.0, 0.0)  # 200 ms is allowed
    assert score_image(gt, gt, ROWS, 200.01) == ImageScore(0.0, 0.0, 1.0)


def test_empty_sides():
    gt = [vertical(300), vertical(600)]
    assert score_image([], gt, ROWS, 0.0) == ImageScore(0.0, 0.0, 1.0)  # 2 unmatched / 2
    assert score_image([vertical(300)], [], ROWS, 0.0) == ImageScore(0.0, 1.0, 0.0)
    assert score_image([], [], ROWS, 0.0) == ImageScore(0.0, 0.0, 0.0)


def test_f1_variants():
    assert f1_ganet(0.2, 0.1) == pytest.approx(2 * 0.8 * 0.9 / 1.7)  # P = 1 - FP, R = 1 - FN
    assert f1_clrnet(0.2, 0.1) == pytest.approx(16 / 19)  # tp 0.8: P = 0.8 / 1.0, R = 0.8 / 0.9
    assert f1_ganet(0.0, 0.0) == f1_clrnet(0.0, 0.0) == 1.0
    assert f1_ganet(1.0, 1.0) == 0.0 and f1_clrnet(1.0, 0.0) == 0.0  # zero denominators read as 0


def test_summary_is_the_per_image_mean_and_f1_of_the_means():
    scores = [ImageScore(1.0, 0.0, 0.0), ImageScore(0.5, 0.5, 0.25), ImageScore(0.0, 0.0, 1.0)]
    summary = summarize(scores, "clrnet")
    assert (summary.accuracy, summary.fp, summary.fn) == pytest.approx((0.5, 1 / 6, 5 / 12))
    assert summary.f1 == pytest.approx(f1_clrnet(1 / 6, 5 / 12))
    assert summary.images == 3 and summary.f1_variant == "clrnet"


def test_matches_the_official_bench_on_random_images():
    rng = np.random.default_rng(7)
    rows = list(range(160, 720, 10))
    for _ in range(400):
        n_gt, n_pred = int(rng.integers(0, 7)), int(rng.integers(0, 8))
        gt = []
        for _ in range(n_gt):
            lane = (rng.uniform(0, 1280) + rng.uniform(-2, 2) * (np.array(rows) - 400)).round()
            lane[rng.random(len(rows)) < 0.3] = -2
            gt.append(lane.tolist())
        pred = []
        for _ in range(n_pred):
            base = np.array(gt[int(rng.integers(0, n_gt))]) if n_gt and rng.random() < 0.7 else np.full(56, 640.0)
            lane = np.where(base >= 0, base + rng.normal(0, 15, len(rows)), -2).round()
            lane[rng.random(len(rows)) < 0.1] = -2
            pred.append(lane.tolist())
        run_time = float(rng.choice([5.0, 200.0, 250.0], p=[0.8, 0.1, 0.1]))
        ours = score_image(pred, gt, rows, run_time)
        assert (ours.accuracy, ours.fp, ours.fn) == pytest.approx(official_bench(pred, gt, rows, run_time), abs=1e-12)
