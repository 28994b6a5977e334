"""Lane-line masks of a split: what a segmenter saw, written beside its lanes for the pixel metric.

``lanevil detect SPLIT --method onnx:MODEL.onnx --out PRED.json --masks DIR`` writes, for every image of the
split, ``DIR/<raw_file>.png`` (``metrics.pixel.mask_file``): the model's lane-line mask in the image's pixels, 255
on lane line, 0 elsewhere (``onnx_detector.OnnxLaneDetector.lane_mask``). ``lanevil eval --metric pixel --pred
DIR`` then scores the mask itself rather than the lanes cut out of it.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ..metrics.formats import LaneFileError, split_folder
from ..metrics.pixel import mask_file
from .onnx_detector import OnnxLaneDetector, onnx_detector
from .registry import ONNX_PREFIX, plugin_spec
from .split import Progress, read_rgb, split_images


def mask_detector(method: str) -> OnnxLaneDetector:
    """The ONNX model with a ``mask`` head that ``method`` names (a name or ``onnx:PATH``); raises
    ``LaneFileError`` for any other kind of method."""
    spec = plugin_spec(method, sources=True)
    if spec is None or spec.kind != "onnx":
        raise LaneFileError(f"--masks: {method} is not an ONNX model with a mask head (onnx:PATH)")
    detector = onnx_detector(spec.name, Path(spec.source.removeprefix(ONNX_PREFIX)))
    if detector.sidecar.head != "mask":
        raise LaneFileError(f"--masks: {method} has a {detector.sidecar.head} head, not a mask head")
    return detector


def write_split_masks(split_dir: str | Path, detector: OnnxLaneDetector, out_dir: str | Path,
                      progress: Progress | None = None) -> int:
    """Write every image's lane-line mask of ``detector`` (``mask_detector``) under ``out_dir``; the number of
    masks."""
    split_dir = split_folder(split_dir)
    items = split_images(split_dir)
    out_dir = Path(out_dir)
    for done, (raw_file, _) in enumerate(items, start=1):
        mask = detector.lane_mask(read_rgb(split_dir / raw_file))
        path = mask_file(out_dir, raw_file)
        path.parent.mkdir(parents=True, exist_ok=True)
        if not cv2.imwrite(str(path), np.where(mask, 255, 0).astype(np.uint8)):
            raise LaneFileError(f"{path}: cannot write the mask")
        if progress is not None:
            progress(done, len(items))
    return len(items)
