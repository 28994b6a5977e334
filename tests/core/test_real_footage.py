"""``experiments/real_footage.py`` without the footage: its label loader, the split files it writes and ego scoring
on them.

A tiny synthetic label file stands in for ``experiments/real_labels.json``; the committed file itself is checked for
shape (two ego lines per frame, one either side of the centre), never downloaded or decoded.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.labels.lanes import h_samples_for
from lanevil_core.metrics.ego import ego_lanes
from lanevil_core.metrics.evaluate import evaluate
from lanevil_core.metrics.formats import LaneRecord

BENCH = Path(__file__).resolve().parents[2] / "experiments"


@pytest.fixture(scope="module")
def real_footage(load_script):
    return load_script("experiments/real_footage.py")


def straight(rows: list[int], bottom_x: float, slope: float, top: int) -> list[int]:
    """x per row of a straight line meeting the last row at ``bottom_x``; -2 above row ``top``."""
    return [round(bottom_x + slope * (y - rows[-1])) if y >= top else -2 for y in rows]


def synthetic_labels(path: Path) -> list[dict]:
    """Two highway frames (1280x720 and 960x540) and one hard frame, each with its ego pair."""
    frames = []
    for split, source, (width, height) in (("highway", "test_videos/clip.mp4#5", (1280, 720)),
                                           ("highway", "test_images/still.jpg", (960, 540)),
                                           ("hard", "test_videos/hard.mp4#12", (1280, 720))):
        rows = h_samples_for(height)
        top = rows[len(rows) // 2]
        lanes = [straight(rows, 0.3 * width, -0.9, top), straight(rows, 0.75 * width, 0.9, top)]
        frames.append({"split": split, "source": source, "image_size": [width, height], "how": "tracked",
                       "h_samples": rows, "lanes": lanes})
    path.write_text(json.dumps({"footage": "synthetic", "frames": frames}))
    return frames


def test_raw_file_names(real_footage):
    assert real_footage.raw_file("test_videos/project_video03.mp4#78") == "project_video03_0078.png"
    assert real_footage.raw_file("test_images/test1.jpg") == "test1.jpg"


def test_the_loader_refuses_a_lane_of_the_wrong_length(real_footage, tmp_path):
    frames = synthetic_labels(tmp_path / "labels.json")
    frames[0]["lanes"][0] = frames[0]["lanes"][0][:-1]
    (tmp_path / "labels.json").write_text(json.dumps({"frames": frames}))
    with pytest.raises(ValueError, match="one x per h_sample"):
        real_footage.load_labels(tmp_path / "labels.json")


def test_split_files_score_with_the_ego_metric_in_each_frames_own_pixels(real_footage, tmp_path):
    synthetic_labels(tmp_path / "labels.json")
    frames = real_footage.load_labels(tmp_path / "labels.json")
    paths = real_footage.write_label_files(frames, tmp_path / "cache")
    assert sorted(paths) == ["hard", "highway"]
    records = [json.loads(line) for line in paths["highway"].read_text().splitlines()]
    assert [r["raw_file"] for r in records] == ["clip_0005.png", "still.jpg"]
    assert records[1]["image_size"] == [960, 540] and records[1]["h_samples"] == h_samples_for(540)

    # A prediction 20 px off every line matches (the 960x540 frame too: 20 of its own pixels), 21 px does not;
    # the other frame predicts only its left line.
    def predictions(shift: int) -> Path:
        path = tmp_path / f"pred_{shift}.json"
        lines = [{"raw_file": records[0]["raw_file"], "lanes": [records[0]["lanes"][0]]},
                 {"raw_file": records[1]["raw_file"],
                  "lanes": [[x + shift if x >= 0 else x for x in lane] for lane in records[1]["lanes"]]}]
        path.write_text("".join(json.dumps(line) + "\n" for line in lines))
        return path

    near = evaluate(tmp_path / "cache" / "highway", predictions(20), "ego")
    assert (near["images"], near["ego_lines"], near["matched"]) == (2, 4, 3)
    assert near["match_share"] == 0.75 and near["point_accuracy"] == 0.75
    far = evaluate(tmp_path / "cache" / "highway", predictions(21), "ego")
    assert far["matched"] == 1 and far["pixel_thresh"] == 20.0 and far["match_share_thresh"] == 0.85


def test_the_committed_labels_have_an_ego_pair_in_every_frame(real_footage):
    frames = real_footage.load_labels()
    assert {f["split"] for f in frames} == {"highway", "hard"}
    assert min(sum(f["split"] == split for f in frames) for split in ("highway", "hard")) >= 30
    for frame in frames:
        width, height = frame["image_size"]
        assert frame["h_samples"] == h_samples_for(height)
        record = LaneRecord(real_footage.raw_file(frame["source"]), frame["lanes"], frame["h_samples"], None, 1, {})
        assert ego_lanes(record, width) == {"left": 0, "right": 1}, frame["source"]
        assert all(-2 == x or 0 <= x < width for lane in frame["lanes"] for x in lane)


def test_the_label_fit_finds_two_painted_lines_on_a_synthetic_road():
    """``experiments/real_labels_fit.py`` on a grey road with a yellow left line and a dashed white right line."""
    sys.path.insert(0, str(BENCH))
    try:
        import real_labels_fit as fit
    finally:
        sys.path.remove(str(BENCH))
    camera = fit.Camera((640, 400), 700, 420)
    bgr = np.full((720, 1280, 3), 90, np.uint8)
    left, right = (lambda y: 640 - 1.6 * (y - 400)), (lambda y: 640 + 1.5 * (y - 400))
    for y in range(410, 720):
        width = max(1, round((y - 400) / 25))
        bgr[y, round(left(y)) - width:round(left(y)) + width + 1] = (0, 200, 230)  # yellow (BGR)
        if (y // 40) % 2 == 0:  # dashes
            bgr[y, round(right(y)) - width:round(right(y)) + width + 1] = (235, 235, 235)
    rows, lanes = fit.fit_frame(bgr, camera, {})
    assert rows == h_samples_for(720)
    for lane, line in zip(lanes, (left, right), strict=True):
        labelled = [(x, y) for x, y in zip(lane, rows, strict=True) if x >= 0]
        assert len(labelled) >= 20 and labelled[-1][1] == 700  # down to the bottom road row
        assert max(abs(x - line(y)) for x, y in labelled) <= 3


def test_cached_predictions_of_an_older_model_are_detected_again(real_footage, tmp_path):
    import os

    from lanevil_core.detect.learned import shipped_model_dir

    pred = tmp_path / "highway_ufld.json"
    assert real_footage.stale(pred, "ufld") and real_footage.stale(pred, "hough")
    pred.write_text("")
    model_time = (shipped_model_dir("ufld") / "model.onnx").stat().st_mtime
    os.utime(pred, (model_time + 60, model_time + 60))
    assert not real_footage.stale(pred, "ufld")
    os.utime(pred, (model_time - 60, model_time - 60))  # written before the model was retrained
    assert real_footage.stale(pred, "ufld") and not real_footage.stale(pred, "hough")
