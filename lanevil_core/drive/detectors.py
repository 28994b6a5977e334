"""The lane detectors a drive can use: the projected ground truth (``gt``, the reference) or any detector of
``detect.registry`` (built-in methods and plug-ins), all as ``detect(rgb, h_samples, gt_lanes) -> lanes`` in the
frame's pixels."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from ..detect.registry import detector_for, detector_names
from ..detect.split import METHODS
from ..labels.lanes import on_tusimple_grid
from ..metrics.tusimple import score_image
from ..typed import UInt8Array

DriveDetector = Callable[[UInt8Array, list[int], list[list[int]]], list[list[int]]]
GROUND_TRUTH = "gt"
DRIVE_DETECTORS: tuple[str, ...] = (GROUND_TRUTH, *METHODS)  # the built-in choices


def drive_detector_names() -> tuple[str, ...]:
    """Every detector a drive can use: ``gt``, the built-in methods and the configured or installed plug-ins."""
    return (GROUND_TRUTH, *detector_names())


def drive_detector(name: str, weights: str | Path | None = None, sources: bool = True) -> DriveDetector:
    """The detector ``name`` (with ``sources``, also a SOURCE such as ``http://HOST:PORT/PATH``); raises
    ``metrics.formats.LaneFileError`` for an unknown or unusable one."""
    if name == GROUND_TRUTH:
        return lambda rgb, h_samples, gt_lanes: [list(lane) for lane in gt_lanes]
    detector = detector_for(name, weights, sources)
    return lambda rgb, h_samples, gt_lanes: [[int(x) for x in lane] for lane in detector(rgb, h_samples)]


def frame_accuracy(lanes: Sequence[Sequence[int]], gt_lanes: Sequence[Sequence[int]], h_samples: Sequence[int],
                   size: tuple[int, int]) -> float:
    """Official TuSimple accuracy of one frame's lanes (both sides moved to the 1280x720 grid of the metric)."""
    pred, rows = on_tusimple_grid(lanes, h_samples, size)
    gt, _ = on_tusimple_grid(gt_lanes, h_samples, size)
    return float(score_image(pred, gt, rows, 0.0).accuracy)
