"""One detector on one rendered frame: its TuSimple lanes and their score against the frame's ground truth.

Lanes and rows are in the frame's own pixels (``labels.h_samples_for(height)``). The score is the official
per-image TuSimple accuracy, FP and FN, computed after moving both sides to the 1280x720 grid
(``labels.on_tusimple_grid``), where the metric's 20 px tolerance is defined. The metric's 200 ms
run-time rule is left out: ``run_time_ms`` is wall-clock time on whatever machine ran it, and a busy machine must
not turn a correct detection into a miss.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..labels.lanes import on_tusimple_grid
from ..metrics.tusimple import ImageScore, score_image
from ..typed import UInt8Array
from .registry import detector_for


@dataclass(frozen=True)
class FrameDetection:
    """A detector's lanes on one frame and their TuSimple score.

    Attributes:
        detector: the method name.
        lanes: detected lanes, x per row of ``h_samples`` (-2 = none), frame pixels.
        h_samples: the rows, frame pixels.
        gt_lanes: ground-truth lanes at the same rows.
        size: (width, height) of the frame.
        accuracy, fp, fn: official per-image TuSimple scores (accuracy in [0, 1]).
        run_time_ms: wall-clock milliseconds of the detection alone.
    """

    detector: str
    lanes: list[list[int]]
    h_samples: list[int]
    gt_lanes: list[list[int]]
    size: tuple[int, int]
    accuracy: float
    fp: float
    fn: float
    run_time_ms: float

    def as_dict(self) -> dict[str, Any]:
        return {"detector": self.detector, "width": self.size[0], "height": self.size[1],
                "h_samples": self.h_samples, "lanes": self.lanes, "gt_lanes": self.gt_lanes,
                "accuracy": self.accuracy, "fp": self.fp, "fn": self.fn, "run_time_ms": self.run_time_ms}


def score_frame_lanes(lanes: Sequence[Sequence[int]], gt_lanes: Sequence[Sequence[int]], h_samples: Sequence[int],
                      size: tuple[int, int]) -> ImageScore:
    """TuSimple accuracy, FP and FN of ``lanes`` against ``gt_lanes`` of a frame of ``size`` (scored at 1280x720)."""
    pred, rows = on_tusimple_grid(lanes, h_samples, size)
    gt, _ = on_tusimple_grid(gt_lanes, h_samples, size)
    return score_image(pred, gt, rows, 0.0)


def detect_frame(method: str, rgb: UInt8Array, record: dict[str, Any]) -> FrameDetection:
    """Run detector ``method`` on ``rgb`` (H, W, 3) uint8 and score it against ``record`` (the frame's TuSimple
    label: ``lanes``, ``h_samples``). Raises ``LaneFileError`` for an unknown or unusable detector."""
    detector = detector_for(method)
    h_samples = [int(h) for h in record["h_samples"]]
    gt_lanes = [[int(x) for x in lane] for lane in record["lanes"]]
    height, width = rgb.shape[:2]
    started = time.perf_counter()
    lanes = detector(rgb, h_samples)
    run_time_ms = (time.perf_counter() - started) * 1000.0
    lanes = [[int(x) for x in lane] for lane in lanes]
    score = score_frame_lanes(lanes, gt_lanes, h_samples, (width, height))
    return FrameDetection(method, lanes, h_samples, gt_lanes, (width, height), float(score.accuracy),
                          float(score.fp), float(score.fn), round(run_time_ms, 2))
