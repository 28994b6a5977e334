"""Which lane detectors this installation can run: kind, availability and, for learned ones, the shipped model.

The names are ``detect.split.METHODS``. A learned detector is available when its shipped model folder
(``lanevil_core/detect/models/<family>/``) holds ``config.json`` and ``model.onnx`` and onnxruntime is installed;
availability is read from the files on every call, so a model added while a server runs is picked up. A
detector's ``version`` changes with its model file, so caches keyed by it never serve a retrained model's
stale lanes.
"""

from __future__ import annotations

import importlib.util
import json
from dataclasses import dataclass
from typing import Any, Literal

from ..metrics.formats import LaneFileError
from .learned import SHIPPED_MODELS
from .model_spec import CONFIG_FILE, ONNX_FILE, TRAINING_FILE
from .split import DETECTORS, LEARNED_METHODS, METHODS

DetectorKind = Literal["learned", "classical"]
# training.json keys shown as a learned model's summary
SUMMARY_KEYS = ("val_accuracy", "epochs", "train_frames", "val_frames", "data", "augment")


@dataclass(frozen=True)
class DetectorInfo:
    """A detector as a product lists it.

    Attributes:
        name: the method name ``detect.split.detector_for`` takes.
        kind: ``learned`` (an ONNX network) or ``classical`` (OpenCV).
        available: whether it can run here; ``reason`` says why not.
        version: cache token: the name, plus the model file's size and time for a learned detector.
        model: a learned detector's training summary (``val_accuracy``, ``input_size``, ``backbone``, ...).
    """

    name: str
    kind: DetectorKind
    available: bool
    version: str
    reason: str | None = None
    model: dict[str, Any] | None = None

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "kind": self.kind, "available": self.available, "reason": self.reason,
                "model": self.model}


def _kind(name: str) -> DetectorKind:
    if name in DETECTORS:
        return "classical"
    if name in LEARNED_METHODS:
        return "learned"
    raise LaneFileError(f"detector: unknown detector {name!r} (choose from {', '.join(METHODS)})")


def _missing(name: str) -> str | None:
    """Why the learned detector ``name`` cannot run here, or None."""
    folder = SHIPPED_MODELS / name
    for file in (CONFIG_FILE, ONNX_FILE):
        if not (folder / file).is_file():
            return f"no {name} model is installed (detect/models/{name}/{file} is missing; `lanevil train` makes one)"
    if importlib.util.find_spec("onnxruntime") is None:
        return "onnxruntime is not installed (pip install onnxruntime)"
    return None


def detector_version(name: str) -> str:
    """The cache token of detector ``name`` (raises ``LaneFileError`` for an unknown name)."""
    if _kind(name) == "classical":
        return name
    try:
        stat = (SHIPPED_MODELS / name / ONNX_FILE).stat()
    except FileNotFoundError:
        return f"{name}@none"
    return f"{name}@{stat.st_size}-{stat.st_mtime_ns}"


def model_summary(name: str) -> dict[str, Any] | None:
    """Architecture and training results of the shipped ``name`` model (None when it has no readable files)."""
    folder = SHIPPED_MODELS / name
    try:
        spec = json.loads((folder / CONFIG_FILE).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None
    summary: dict[str, Any] = {"input_size": spec.get("input_size"), "backbone": spec.get("backbone"),
                               "width": spec.get("width")}
    try:
        training = json.loads((folder / TRAINING_FILE).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        training = {}
    summary.update({key: training.get(key) for key in SUMMARY_KEYS})
    return summary


def detector_info(name: str) -> DetectorInfo:
    """What ``name`` is and whether it can run (raises ``LaneFileError`` for an unknown name)."""
    if _kind(name) == "classical":
        return DetectorInfo(name, "classical", True, name)
    reason = _missing(name)
    return DetectorInfo(name, "learned", reason is None, detector_version(name), reason, model_summary(name))


def detector_infos() -> list[DetectorInfo]:
    """Every detector of ``METHODS``, in that order."""
    return [detector_info(name) for name in METHODS]


def available_detector(name: str) -> DetectorInfo:
    """``detector_info(name)``, raising ``LaneFileError`` (message starting ``detector:``) when it cannot run."""
    info = detector_info(name)
    if not info.available:
        raise LaneFileError(f"detector: {name} is not available here: {info.reason}")
    return info
