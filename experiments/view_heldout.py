"""The view window (``lanevil adapt --method view``) on held-out cameras: each family read through its camera's
measured view, against the whole frame, and against the view measured from the labels (the best a measurement can
do).

A ``lanevil dataset --vary-world --heldout`` split draws a camera per case (its fov, height, pitch, yaw and roll
outside the train ranges) and renders 5 frames of each; a case's frames are one camera. A split rendered through
a car-height preset (``--vary-world --camera tusimple`` or ``dashcam``) asks the same of real cameras' geometry.
Per case the view is measured from the reference detector's readings of its frames (``--reference``, no label read)
and, for scale, from its labels; every model then reads the case's frames through each. Scored with the ego line
match and TuSimple accuracy over the whole split. Synthetic frames only: this is what chooses whether and how the
view is used.

    .venv/bin/python experiments/view_heldout.py --split out/transfer/val-heldout/train \\
        [--models ufld laneatt scnn bezier ganet seg seg-transfer NAME=MODEL_DIR] [--reference seg-transfer]
        [--modes frame measured-vp+height]
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from lanevil_core.detect.lane_slots import lane_lines
from lanevil_core.detect.learned import LearnedDetector, lanes_of, shipped_model_dir
from lanevil_core.detect.split import read_rgb
from lanevil_core.detect.view import View, ViewError, measure_view, window_for
from lanevil_core.metrics.ego import ego_line_match, summarize_ego
from lanevil_core.metrics.formats import LaneRecord, read_tusimple
from lanevil_core.metrics.tusimple import score_image

MODES = ("frame", "measured", "labels", "measured-vp", "labels-vp", "measured-vp+height", "crop", "half")
KEEP = {"crop": 1.0, "half": 0.5}  # how much of the network's proportions a fixed window keeps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--split", type=Path, required=True)
    parser.add_argument("--models", nargs="+", default=["ufld", "laneatt", "scnn", "bezier", "ganet", "seg",
                                                        "seg-transfer"])
    parser.add_argument("--reference", default="seg-transfer")
    parser.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES))
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    records = read_tusimple(next(args.split.glob("*label*.json")), "gt")
    cases: dict[str, list[LaneRecord]] = defaultdict(list)
    for record in records:
        cases[record.raw_file.split("/")[0]].append(record)
    images = {record.raw_file: read_rgb(args.split / record.raw_file) for record in records}
    height, width = next(iter(images.values())).shape[:2]
    aspect = height / width

    reference = LearnedDetector(shipped_model_dir(args.reference))
    views: dict[str, dict[str, View | None]] = {}
    for case, frames in cases.items():
        read = [[line for line in reference.lines(images[r.raw_file]) if line is not None] for r in frames]
        labelled = [lane_lines(r.lanes, r.h_samples, (width, height)) for r in frames]
        views[case] = {"frame": None}
        for mode, lines in (("measured", read), ("labels", labelled)):
            try:
                views[case][mode] = measure_view(lines, aspect)
            except ViewError:
                views[case][mode] = None
            found_view = views[case][mode]
            views[case][f"{mode}-vp"] = None if found_view is None or found_view.vanishing is None else \
                View(window_for(found_view.vanishing, None), found_view.vanishing, None, found_view.frames)
        measured = views[case]["measured"]
        case_file = json.loads((args.split / case / "case.json").read_text())  # the camera as rendered
        wedge = aspect * case_file["road"]["lane_width"] / case_file["camera"]["z"]
        views[case]["measured-vp+height"] = None if measured is None or measured.vanishing is None else \
            View(window_for(measured.vanishing, wedge), measured.vanishing, wedge, measured.frames)
    found = {mode: sum(views[c][mode] is not None for c in cases) for mode in ("measured", "labels")}
    print(f"{len(cases)} cameras: view measured for {found['measured']} from {args.reference}'s readings, "
          f"{found['labels']} from labels", flush=True)
    errors = [np.subtract(views[c]["measured"].window, views[c]["labels"].window) for c in cases
              if views[c]["measured"] is not None and views[c]["labels"] is not None]
    if errors:
        print("median |window error| (left, top, right, bottom):", np.round(np.median(np.abs(errors), axis=0), 3))

    table: dict[str, dict[str, dict[str, float]]] = {}
    for name in args.models:
        label, _, folder = name.partition("=")  # NAME=MODEL_DIR scores a model folder that is not shipped
        detector = LearnedDetector(Path(folder) if folder else shipped_model_dir(name))
        table[name.partition("=")[0]] = {}
        for mode in args.modes:
            scores, accuracy = [], []
            for case, frames in cases.items():
                view = _kept(aspect, detector, KEEP[mode]) if mode in KEEP else views[case][mode]
                for record in frames:
                    lines = detector.lines(images[record.raw_file]) if view is None else \
                        _read_through(detector, images[record.raw_file], view)
                    lanes = lanes_of(detector.spec, lines, record.h_samples, (width, height), view)
                    pred = LaneRecord(record.raw_file, [list(map(float, lane)) for lane in lanes],
                                      record.h_samples, 0.0, 0, {})
                    scores.append(ego_line_match(record, pred, width))
                    accuracy.append(_accuracy(record, pred, width))
            summary = summarize_ego(scores)
            table[name.partition("=")[0]][mode] = {"ego": round(100 * summary.match_share, 1),
                                 "points": round(100 * summary.point_accuracy, 1),
                                 "accuracy": round(100 * float(np.mean(accuracy)), 1)}
        row = "  ".join(f"{mode}: {v['ego']:4.1f}/{v['accuracy']:4.1f}" for mode, v in table[label].items())
        print(f"{label:13s} {row}", flush=True)
    if args.json is not None:
        args.json.write_text(json.dumps({"views": {c: {m: (v.as_dict() if v else None) for m, v in vs.items()}
                                                   for c, vs in views.items()}, "table": table}, indent=2))


def _accuracy(gt: LaneRecord, pred: LaneRecord, width: int) -> float:
    """TuSimple accuracy of one image on the 1280-wide grid its tolerances are set for."""
    k = 1280.0 / width

    def scaled(lanes: list[list[float]]) -> list[list[float]]:
        return [[x * k if x >= 0 else x for x in lane] for lane in lanes]

    return score_image(scaled(pred.lanes), scaled(gt.lanes), [h * k for h in gt.h_samples], 0.0).accuracy


def _kept(aspect: float, detector: LearnedDetector, keep: float) -> View:
    in_w, in_h = detector.spec.input_size
    width = (aspect / (in_h / in_w)) ** keep
    return View((0.5 - width / 2, 0.0, 0.5 + width / 2, 1.0))


def _read_through(detector: LearnedDetector, rgb: np.ndarray, view: View) -> list:
    saved = detector.view
    detector.view = view
    try:
        return detector.lines(rgb)
    finally:
        detector.view = saved


if __name__ == "__main__":
    main()
