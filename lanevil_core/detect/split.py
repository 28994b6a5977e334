"""Run a detector over a split folder and write its predictions as TuSimple JSON lines; the built-in methods."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from .. import images
from ..images import IMAGE_SUFFIXES
from ..labels.lanes import h_samples_for
from ..metrics.formats import LaneFileError, read_tusimple, split_folder, split_labels
from ..typed import UInt8Array
from .birdseye import detect_birdseye
from .hough import detect_hough
from .model_spec import FAMILIES

Detector = Callable[[UInt8Array, list[int]], list[list[int]]]
Progress = Callable[[int, int], None]

DETECTORS: dict[str, Detector] = {"hough": detect_hough, "birdseye": detect_birdseye}
LEARNED_METHODS: tuple[str, ...] = FAMILIES
METHODS = (*LEARNED_METHODS, *DETECTORS)


def builtin_detector(method: str, weights: str | Path | None = None) -> Detector:
    """The built-in detector called ``method``: a classical baseline, or a learned model (``weights``: its model
    folder, default the model shipped for that family) run through onnxruntime. Plug-ins resolve through
    ``detect.registry.detector_for``."""
    if method in DETECTORS:
        if weights is not None:
            raise LaneFileError(f"--weights: the {method} baseline has no weights")
        return DETECTORS[method]
    if method not in LEARNED_METHODS:
        raise LaneFileError(f"--method {method!r}: choose from {', '.join(METHODS)}")
    from .learned import load_detector, shipped_model_dir
    from .model_spec import ModelSpecError

    model_dir = Path(weights) if weights is not None else shipped_model_dir(method)
    try:
        detector = load_detector(str(model_dir.resolve()))
    except ModelSpecError as error:
        raise LaneFileError(str(error)) from None
    if detector.spec.family != method:
        raise LaneFileError(f"--weights {weights}: a {detector.spec.family} model, not {method}")
    return detector


def read_rgb(path: Path) -> UInt8Array:
    """(H, W, 3) uint8 RGB pixels of an image file (``images.read_rgb``); a ``LaneFileError`` if unreadable."""
    return images.read_rgb(path, error=LaneFileError)


def split_images(split_dir: Path) -> list[tuple[str, list[int] | None]]:
    """(raw_file, h_samples) of every image: from the split's label file, else every image file (rows by height)."""
    try:
        labels = split_labels(split_dir)
    except LaneFileError:
        if not split_dir.is_dir():
            raise
        images = sorted(path.relative_to(split_dir).as_posix() for path in split_dir.rglob("*")
                        if path.suffix.lower() in IMAGE_SUFFIXES)
        if not images:
            raise LaneFileError(f"{split_dir}: no label file and no images") from None
        return [(name, None) for name in images]
    return [(record.raw_file, [int(h) for h in record.h_samples]) for record in read_tusimple(labels, "gt")]


def detect_split(split_dir: str | Path, method: str, progress: Progress | None = None,
                 fixed_run_time_ms: float | None = None, weights: str | Path | None = None) -> list[dict[str, Any]]:
    """One prediction record per image: ``raw_file``, ``lanes``, ``h_samples``, ``run_time``.

    ``run_time`` is the CPU time (ms) of the detection alone, not wall-clock time, so that a busy machine does
    not push frames over the metric's 200 ms limit (for a learned model: resize, network and decoding).

    ``fixed_run_time_ms`` replaces the measured time (for byte-reproducible files); everything else is
    deterministic.
    """
    return detect_split_methods(split_dir, [method], progress, fixed_run_time_ms, weights)[method]


def detect_split_methods(split_dir: str | Path, methods: Sequence[str], progress: Progress | None = None,
                         fixed_run_time_ms: float | None = None,
                         weights: str | Path | None = None) -> dict[str, list[dict[str, Any]]]:
    """:func:`detect_split` for several detectors at once, by method: each image is read once and handed to every
    detector in turn (reading a 1280x720 PNG costs about as much as one small network). ``weights`` only with
    one method."""
    if not methods:
        raise LaneFileError("--method: name at least one detector")
    if len(set(methods)) != len(methods):
        raise LaneFileError(f"--method: a method is named twice ({', '.join(methods)})")
    if weights is not None and len(methods) > 1:
        raise LaneFileError("--weights: only with a single --method")
    from .registry import detector_for

    split_dir = split_folder(split_dir)  # a dataset folder: its test split, whose label file names the images
    detectors = {method: detector_for(method, weights) for method in methods}
    items = split_images(split_dir)
    records: dict[str, list[dict[str, Any]]] = {method: [] for method in methods}
    for done, (raw_file, h_samples) in enumerate(items, start=1):
        rgb = read_rgb(split_dir / raw_file)
        rows = h_samples if h_samples is not None else h_samples_for(rgb.shape[0])
        for method, detector in detectors.items():
            start = time.process_time()
            lanes = detector(rgb, rows)
            elapsed_ms = (time.process_time() - start) * 1000.0
            run_time = fixed_run_time_ms if fixed_run_time_ms is not None else round(elapsed_ms, 2)
            records[method].append({"raw_file": raw_file, "lanes": lanes, "h_samples": rows, "run_time": run_time})
        if progress is not None:
            progress(done, len(items))
    return records
