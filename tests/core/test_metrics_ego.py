"""The ego line match on synthetic TuSimple records, and ``lanevil eval --metric ego``."""

from __future__ import annotations

import json

import pytest

from lanevil_core import cli
from lanevil_core.metrics.ego import EGO_MATCH_SHARE, ego_lanes, ego_line_match, summarize_ego
from lanevil_core.metrics.evaluate import evaluate
from lanevil_core.metrics.formats import LaneRecord

ROWS = [float(y) for y in range(160, 720, 10)]  # 56 rows, the TuSimple grid


def line(bottom_x: float, slope: float = 0.0, rows: list[float] = ROWS) -> list[float]:
    """x per row of a straight lane meeting the bottom row (710) at ``bottom_x``."""
    return [bottom_x + slope * (y - rows[-1]) for y in rows]


def record(lanes: list[list[float]], **extra) -> LaneRecord:
    return LaneRecord("f.jpg", lanes, ROWS, 1.0, 1, extra)


def _one_pred(lane: list[float]) -> LaneRecord:
    return record([lane])


GT = record([line(200, -0.8), line(500, -0.1), line(800, 0.1), line(1100, 0.8)])


def test_the_ego_pair_is_nearest_the_center_on_each_side():
    assert ego_lanes(GT, 1280) == {"left": 1, "right": 2}
    shuffled = record([line(800, 0.3), line(1100, 0.8), line(600, -0.1), line(200, -0.8)])
    assert ego_lanes(shuffled, 1280) == {"left": 2, "right": 0}
    assert ego_lanes(record([line(900)]), 1280) == {"right": 0}


def test_the_ego_pair_uses_the_line_extended_to_the_bottom_row():
    upper = [x if y < 450 else -2.0 for x, y in zip(line(700, -0.5), ROWS, strict=True)]  # ends at y 440
    # Its lowest labelled point (x 835) lies right of the lane at bottom-x 660, but extended it meets the
    # bottom row at 700: nearer the centre than 660 is not, so it stays the right line only by extension.
    gt = record([line(560), upper, line(1000)])
    assert upper[ROWS.index(440.0)] == pytest.approx(835.0)
    assert ego_lanes(gt, 1280) == {"left": 0, "right": 1}


def test_exact_prediction_matches_both_ego_lines():
    scores = ego_line_match(GT, record(GT.lanes))
    assert [(s.side, s.lane, s.matched, s.point_accuracy) for s in scores] == [
        ("left", 1, True, 1.0), ("right", 2, True, 1.0)]


def test_a_line_shifted_25_px_is_not_matched_and_20_px_is():
    shifted = [[x + 25 for x in GT.lanes[1]], GT.lanes[2]]
    left, right = ego_line_match(GT, record(shifted))
    assert (left.matched, left.point_accuracy) == (False, 0.0) and right.matched
    left, _ = ego_line_match(GT, record([[x + 20 for x in GT.lanes[1]], GT.lanes[2]]))
    assert left.matched


def test_a_prediction_covering_80_percent_of_the_rows_is_not_matched():
    partial = list(GT.lanes[1])
    cut = round(0.2 * len(ROWS))
    partial[:cut] = [-2.0] * cut
    left, _ = ego_line_match(GT, record([partial, GT.lanes[2]]))
    assert left.point_accuracy == pytest.approx(0.8, abs=0.01) and left.point_accuracy < EGO_MATCH_SHARE
    assert not left.matched


def test_only_the_labelled_rows_count():
    short = [x if y >= 400 else -2.0 for x, y in zip(GT.lanes[1], ROWS, strict=True)]
    gt = record([short, GT.lanes[2]])
    left, _ = ego_line_match(gt, record([GT.lanes[1], GT.lanes[2]]))  # predicted further up than labelled
    assert left.matched and left.point_accuracy == 1.0


def test_summary_pools_every_ego_line():
    images = [ego_line_match(GT, record(GT.lanes)), ego_line_match(GT, record([])), ego_line_match(record([]), GT)]
    summary = summarize_ego(images)
    assert (summary.images, summary.ego_lines, summary.matched) == (3, 4, 2)
    assert summary.match_share == 0.5 and summary.point_accuracy == 0.5


def test_eval_metric_ego(tmp_path, capsys):
    gt_path, pred_path = tmp_path / "gt.json", tmp_path / "pred.json"
    gt_lines = [{"raw_file": f"{i}.jpg", "h_samples": ROWS, "lanes": GT.lanes} for i in range(2)]
    pred_lines = [{"raw_file": "0.jpg", "lanes": GT.lanes},
                  {"raw_file": "1.jpg", "lanes": [[x + 25 for x in lane] for lane in GT.lanes]}]
    gt_path.write_text("".join(json.dumps(line) + "\n" for line in gt_lines))
    pred_path.write_text("".join(json.dumps(line) + "\n" for line in pred_lines))  # no run_time: not needed
    result = evaluate(gt_path, pred_path, "ego")
    assert result["metric"] == "ego" and result["ego_lines"] == 4 and result["match_share"] == 0.5
    assert cli.main(["eval", "--gt", str(gt_path), "--pred", str(pred_path), "--metric", "ego"]) == 0
    assert "matched 2 (50.00 %)" in capsys.readouterr().out


def test_eval_metric_ego_on_a_smaller_frame_is_scored_in_its_own_pixels(tmp_path):
    rows = [y / 2 for y in ROWS]
    lanes = [[x / 2 for x in lane] for lane in GT.lanes]  # ego pair at bottom x 250 and 400, centre 320
    gt_path, pred_path = tmp_path / "gt.json", tmp_path / "pred.json"
    gt_path.write_text(json.dumps({"raw_file": "0.jpg", "h_samples": rows, "lanes": lanes,
                                   "image_size": [640, 360]}) + "\n")
    for shift, matched in ((12, 2), (20, 2), (21, 0)):  # 20 of the frame's own pixels, not of the 1280 grid
        pred_path.write_text(json.dumps({"raw_file": "0.jpg", "lanes": [[x + shift for x in lane] for lane in lanes]})
                             + "\n")
        assert evaluate(gt_path, pred_path, "ego")["matched"] == matched
