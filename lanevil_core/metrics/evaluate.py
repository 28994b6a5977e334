"""Score a prediction file (or folder) against ground truth with the TuSimple, the CULane or the ego line metric.

Inputs are recognised by what they are: a file is TuSimple JSON lines, a folder is a tree of CULane
``.lines.txt`` files. Both sides must have the same format (their pixel frames differ).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

from ..labels.lanes import CULANE_SIZE, IMAGE_SIZE_FIELD, TUSIMPLE_SIZE, on_tusimple_grid
from . import culane, ego, pixel, tusimple
from .formats import (
    CULANE_SUFFIX,
    LaneFileError,
    LaneRecord,
    Points,
    culane_files,
    pair_records,
    read_culane_file,
    read_tusimple,
    split_labels,
    tusimple_points,
)

Metric = Literal["tusimple", "culane", "ego", "pixel"]
METRICS: tuple[Metric, ...] = ("tusimple", "culane", "ego", "pixel")


@dataclass(frozen=True)
class ScoredImage:
    """One GT image with its per-image TuSimple score and the extra GT fields (category, type, severity...)."""

    raw_file: str
    score: tusimple.ImageScore
    extra: dict[str, Any]


def score_tusimple_files(gt_path: Path, pred_path: Path) -> list[ScoredImage]:
    """Per-image official TuSimple scores, in GT order.

    A GT record of a 16:9 image rendered at another size than 1280x720 (it carries ``image_size``) is scored with
    both its lanes and the prediction's moved to the 1280x720 grid (``labels.on_tusimple_grid``), so the metric's
    20 px tolerance means what it means at 1280x720 whatever size was rendered. Other cameras (a CULane-shaped
    1640x590, say) are scored in their own pixels.
    """
    gt = read_tusimple(gt_path, "gt")
    pairs = [(_on_grid(g), _on_grid(p, g)) for g, p in
             pair_records(gt, read_tusimple(pred_path, "pred"), str(gt_path), str(pred_path))]
    scores = tusimple.score_pairs(pairs)
    return [ScoredImage(g.raw_file, score, g.extra) for (g, _), score in zip(pairs, scores)]


def _tusimple_shaped(size: list[int]) -> bool:
    """Whether an image of ``size`` (w, h) is a scaled 1280x720 frame (16:9 within a pixel)."""
    return abs(size[0] * TUSIMPLE_SIZE[1] / TUSIMPLE_SIZE[0] - size[1]) <= 1.0


def _on_grid(record: LaneRecord, gt: LaneRecord | None = None) -> LaneRecord:
    """``record`` on the 1280x720 grid when its GT (``gt``, else itself) names another ``image_size``."""
    gt = gt if gt is not None else record
    size = gt.extra.get(IMAGE_SIZE_FIELD)
    if not size or tuple(size) == TUSIMPLE_SIZE or not _tusimple_shaped(size):
        return record
    lanes, rows = on_tusimple_grid(record.lanes, gt.h_samples, (int(size[0]), int(size[1])))
    return replace(record, lanes=[[float(x) for x in lane] for lane in lanes],
                   h_samples=rows if record is gt else record.h_samples)


def _frame_width(gt: LaneRecord) -> float:
    """Width of ``gt``'s own frame: its ``image_size`` when it names one, else 1280."""
    size = gt.extra.get(IMAGE_SIZE_FIELD)
    return float(size[0]) if size else float(TUSIMPLE_SIZE[0])


def score_ego_files(gt_path: Path, pred_path: Path) -> ego.EgoSummary:
    """The ego line match over a TuSimple GT and prediction file (no ``run_time`` needed), in each frame's own
    pixels: the 20 px are pixels of the labelled frame whatever its size (``image_size``, default 1280x720)."""
    pairs = pair_records(read_tusimple(gt_path, "gt"), read_tusimple(pred_path, "pred"), str(gt_path),
                         str(pred_path), require_run_time=False)
    return ego.summarize_ego(ego.ego_line_match(g, p, _frame_width(g)) for g, p in pairs)


def _interpolated(lanes: list[Points], where: str) -> list[Points]:
    for lane in lanes:
        try:
            culane.interpolate_lane(lane)
        except culane.LaneInterpolationError as error:
            raise LaneFileError(f"{where}: {error}") from None
    return lanes


def _culane_pairs_from_json(gt_path: Path, pred_path: Path) -> list[tuple[list[Points], list[Points]]]:
    def points(record: LaneRecord, h_samples: list[float], name: Path) -> list[Points]:
        lanes = [tusimple_points(lane, h_samples) for lane in record.lanes]
        return _interpolated([lane for lane in lanes if len(lane) >= 2], f"{name}:{record.line}")

    pairs = pair_records(read_tusimple(gt_path, "gt"), read_tusimple(pred_path, "pred"), str(gt_path),
                         str(pred_path), require_run_time=False)
    return [(points(p, g.h_samples, pred_path), points(g, g.h_samples, gt_path)) for g, p in pairs]


def _culane_pairs_from_folders(gt_root: Path, pred_root: Path) -> list[tuple[list[Points], list[Points]]]:
    gt_names = culane_files(gt_root)
    if not gt_names:
        raise LaneFileError(f"{gt_root}: no {CULANE_SUFFIX} files")
    extra = sorted(set(culane_files(pred_root)) - set(gt_names))
    if extra:
        raise LaneFileError(f"{pred_root / extra[0]}: prediction for an image not in the ground truth {gt_root}")
    pairs = []
    for name in gt_names:
        pred_file = pred_root / name
        # The official evaluator reads a missing prediction file as an image with no lanes.
        pred = read_culane_file(pred_file) if pred_file.exists() else []
        pairs.append((_interpolated(pred, str(pred_file)), _interpolated(read_culane_file(gt_root / name),
                                                                         str(gt_root / name))))
    return pairs


def evaluate(gt_path: str | Path, pred_path: str | Path, metric: Metric = "tusimple",
             f1_variant: str = "ganet", line_width: float = pixel.LINE_WIDTH_720) -> dict[str, Any]:
    """The metric's summary as a JSON-ready dict (``metric`` names it; TuSimple adds ``f1_variant``; ``ego`` is
    ``metrics.ego``'s ego line match; ``pixel`` is ``metrics.pixel``'s lane-line IoU and F1 with lines
    ``line_width`` pixels wide at 720 rows).

    ``gt_path`` may also be a split folder (its ``*_label.json`` is read) when ``pred_path`` is a file (or, for
    ``pixel``, a folder of mask PNGs).
    """
    gt_path, pred_path = Path(gt_path), Path(pred_path)
    for path in (gt_path, pred_path):
        if not path.exists():
            raise LaneFileError(f"{path}: no such file or folder")
    if metric == "pixel":
        if gt_path.is_dir():
            gt_path = split_labels(gt_path)
        return {"metric": "pixel", **pixel.score_pixel_files(gt_path, pred_path, line_width).as_dict()}
    if gt_path.is_dir() and not pred_path.is_dir() and not culane_files(gt_path):
        gt_path = split_labels(gt_path)  # a split folder: its *_label.json
    if gt_path.is_dir() != pred_path.is_dir():
        raise LaneFileError(f"{gt_path} and {pred_path}: give two TuSimple JSON files or two CULane folders")
    if metric == "tusimple":
        if gt_path.is_dir():
            raise LaneFileError(f"{gt_path}: the TuSimple metric reads TuSimple JSON-lines files, not folders")
        scores = [image.score for image in score_tusimple_files(gt_path, pred_path)]
        return {"metric": "tusimple", **tusimple.summarize(scores, f1_variant).as_dict()}
    if metric == "ego":
        if gt_path.is_dir():
            raise LaneFileError(f"{gt_path}: the ego line metric reads TuSimple JSON-lines files, not folders")
        return {"metric": "ego", **score_ego_files(gt_path, pred_path).as_dict()}
    if gt_path.is_dir():
        pairs, size = _culane_pairs_from_folders(gt_path, pred_path), CULANE_SIZE
    else:
        pairs, size = _culane_pairs_from_json(gt_path, pred_path), TUSIMPLE_SIZE
    counts = (culane.match_image(pred, gt, size) for pred, gt in pairs)
    return {"metric": "culane", "iou_threshold": culane.IOU_THRESHOLD, "lane_width": culane.LANE_WIDTH_PX,
            **culane.summarize(counts).as_dict()}
