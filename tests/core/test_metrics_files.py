"""``lanevil eval``: output and one-line errors (exit 2) naming the file and line of a bad record."""

from __future__ import annotations

import json

import pytest

from lanevil_core.cli import main

ROWS = list(range(160, 720, 10))


def record(raw_file: str, lanes: list[list[int]], **extra) -> str:
    return json.dumps({"raw_file": raw_file, "lanes": lanes, "h_samples": ROWS, **extra})


def lane(x: int) -> list[int]:
    return [x] * len(ROWS)


@pytest.fixture
def gt_file(tmp_path):
    path = tmp_path / "gt.json"
    path.write_text(record("a.png", [lane(300), lane(600)]) + "\n" + record("b.png", [lane(500)]) + "\n")
    return path


def run_eval(tmp_path, gt_file, pred_lines: list[str], *flags: str) -> int:
    pred = tmp_path / "pred.json"
    pred.write_text("".join(line + "\n" for line in pred_lines))
    return main(["eval", "--gt", str(gt_file), "--pred", str(pred), *flags])


def error_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("lanevil: error: ")
    return err


def test_eval_prints_the_summary(tmp_path, gt_file, capsys):
    pred = [record("a.png", [lane(300)], run_time=5), record("b.png", [lane(500)], run_time=5)]
    assert run_eval(tmp_path, gt_file, pred, "--json", "--f1", "clrnet") == 0
    result = json.loads(capsys.readouterr().out)
    # a: 1 of 2 matched -> acc 0.5, FP 0, FN 0.5; b: perfect.
    assert result["accuracy"] == pytest.approx(0.75) and result["fn"] == pytest.approx(0.25)
    assert result["fp"] == 0.0 and result["f1_variant"] == "clrnet" and result["images"] == 2
    assert run_eval(tmp_path, gt_file, pred) == 0
    assert "Accuracy 75.00 %" in capsys.readouterr().out


@pytest.mark.parametrize("pred_lines, needle", [
    (['{"raw_file": "a.png", "lanes": [], "run_time": 1}', "{not json"], "pred.json:2: invalid JSON"),
    (['{"lanes": [], "run_time": 1}'], "pred.json:1: missing raw_file"),
    (['{"raw_file": "a.png", "lanes": []}', '{"raw_file": "b.png", "lanes": [], "run_time": 1}'],
     "pred.json:1: missing run_time"),
    ([record("a.png", [], run_time=1), record("c.png", [], run_time=1)], "pred.json:2: raw_file 'c.png' is not in"),
    ([record("a.png", [], run_time=1)], "gt.json:2: no prediction for raw_file 'b.png'"),
    ([record("a.png", [], run_time=1), record("a.png", [], run_time=1)], "pred.json:2: duplicate raw_file 'a.png'"),
    (['{"raw_file": "a.png", "lanes": [], "h_samples": [1, 2], "run_time": 1}', record("b.png", [], run_time=1)],
     "pred.json:1: h_samples mismatch with"),
    (['{"raw_file": "a.png", "lanes": [[1, 2, 3]], "run_time": 1}', record("b.png", [], run_time=1)],
     "pred.json:1: lanes[0] has 3 points but the ground truth has 56 h_samples"),
    (['{"raw_file": "a.png", "lanes": [["x"]], "run_time": 1}'], "pred.json:1: lanes[0] must be a list of numbers"),
])
def test_bad_prediction_files_exit_2_naming_the_line(tmp_path, gt_file, capsys, pred_lines, needle):
    assert run_eval(tmp_path, gt_file, pred_lines) == 2
    assert needle in error_line(capsys)


def test_bad_gt_and_missing_files(tmp_path, capsys):
    gt = tmp_path / "gt.json"
    gt.write_text(record("a.png", [lane(1)]) + "\n" + json.dumps({"raw_file": "b.png", "lanes": [[1]],
                                                                   "h_samples": [1, 2]}) + "\n")
    assert run_eval(tmp_path, gt, [record("a.png", [], run_time=1)]) == 2
    assert "gt.json:2: lanes[0] has 1 points but h_samples has 2" in error_line(capsys)
    assert main(["eval", "--gt", str(tmp_path / "nope.json"), "--pred", str(gt)]) == 2
    assert "nope.json: no such file" in error_line(capsys)
    assert main(["eval", "--gt", str(gt), "--pred", str(tmp_path), "--metric", "culane"]) == 2
    assert "two TuSimple JSON files or two CULane folders" in error_line(capsys)


def test_culane_folder_errors(tmp_path, capsys):
    gt, pred = tmp_path / "gt", tmp_path / "pred"
    gt.mkdir(), pred.mkdir()
    (gt / "a.lines.txt").write_text("1 2 3\n")
    assert main(["eval", "--gt", str(gt), "--pred", str(pred), "--metric", "culane"]) == 2
    assert "a.lines.txt:1: expected finite x y pairs" in error_line(capsys)
    (gt / "a.lines.txt").write_text("10 500 20 400\n")
    (pred / "b.lines.txt").write_text("10 500 20 400\n")
    assert main(["eval", "--gt", str(gt), "--pred", str(pred), "--metric", "culane"]) == 2
    assert "b.lines.txt: prediction for an image not in the ground truth" in error_line(capsys)


def test_records_of_smaller_renders_are_scored_on_the_1280_grid(tmp_path):
    from lanevil_core.labels.lanes import h_samples_for
    from lanevil_core.metrics import score_tusimple_files

    rows = h_samples_for(360)
    gt, pred = tmp_path / "gt.json", tmp_path / "pred.json"
    for size, name in ((None, "native"), ([640, 360], "grid")):
        extra = {"image_size": size} if size else {}
        gt.write_text(json.dumps({"raw_file": "a.png", "lanes": [[300] * len(rows)], "h_samples": rows, **extra}))
        # 15 px off at 640 wide: inside 20 px at the render's own size, 30 px (outside) on the 1280x720 grid
        pred.write_text(json.dumps({"raw_file": "a.png", "lanes": [[315] * len(rows)], "run_time": 1}))
        accuracy = score_tusimple_files(gt, pred)[0].score.accuracy
        assert accuracy == (1.0 if name == "native" else 0.0), name


def test_a_640_render_records_its_size_and_a_1280_render_stays_standard():
    from lanevil_core.labels.lanes import image_size_field

    assert image_size_field((640, 360)) == {"image_size": [640, 360]}
    assert image_size_field((1280, 720)) == {}
