"""Which lane detectors this installation can run: kind, availability and, for learned ones, the shipped model.

The names are ``detect.registry.detector_names()``: the built-in ``detect.split.METHODS`` and the plug-ins (HTTP
servers, ONNX models with a sidecar, installed Python plug-ins). A learned detector is available when its shipped
model folder (``lanevil_core/detect/models/<family>/``) holds ``config.json`` and ``model.onnx`` and onnxruntime is
installed; availability is read from the files on every call, so a model added while a server runs is picked up. A
detector's ``version`` changes with its model file, so caches keyed by it never serve a retrained model's
stale lanes.
"""

from __future__ import annotations

import importlib.util
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ..metrics.formats import LaneFileError
from .learned import SHIPPED_MODELS
from .model_spec import CONFIG_FILE, ONNX_FILE, TRAINING_FILE
from .registry import (
    ONNX_PREFIX,
    PluginSpec,
    bundled_specs,
    detector_names,
    plugin_real_trained,
    plugin_spec,
)
from .split import DETECTORS, LEARNED_METHODS

DetectorKind = Literal["learned", "classical", "http", "onnx", "plugin"]
# training.json keys shown as a learned model's summary
SUMMARY_KEYS = ("val_accuracy", "epochs", "train_frames", "val_frames", "data", "augment")


@dataclass(frozen=True)
class DetectorInfo:
    """A detector as a product lists it.

    Attributes:
        name: the method name ``detect.registry.detector_for`` takes.
        kind: ``learned`` (a shipped ONNX network), ``classical`` (OpenCV), or a plug-in: ``http`` (a server),
            ``onnx`` (a model with a sidecar) or ``plugin`` (an installed Python entry point).
        available: whether it can run here; ``reason`` says why not (an HTTP server is only reached when used).
        version: cache token: the name, plus the model file's size and time for a learned or ONNX detector, the
            URL of an HTTP one, the package version of a Python plug-in.
        model: a learned detector's training summary (``val_accuracy``, ``input_size``, ``backbone``, ...).
        source: a plug-in's URL, ``onnx:PATH`` or entry point.
        real_trained: whether the detector was trained on real roads (the Real -> LanEvil table).
    """

    name: str
    kind: DetectorKind
    available: bool
    version: str
    reason: str | None = None
    model: dict[str, Any] | None = None
    source: str | None = None
    real_trained: bool = False

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "kind": self.kind, "available": self.available, "reason": self.reason,
                "model": self.model, "source": self.source, "real_trained": self.real_trained}


def _kind(name: str) -> DetectorKind:
    if name in DETECTORS:
        return "classical"
    if name in LEARNED_METHODS:
        return "learned"
    spec = plugin_spec(name)
    assert spec is not None
    return spec.kind


def _missing(name: str) -> str | None:
    """Why the learned detector ``name`` cannot run here, or None."""
    folder = SHIPPED_MODELS / name
    for file in (CONFIG_FILE, ONNX_FILE):
        if not (folder / file).is_file():
            return f"no {name} model is installed (detect/models/{name}/{file} is missing; `lanevil train` makes one)"
    if importlib.util.find_spec("onnxruntime") is None:
        return "onnxruntime is not installed (pip install onnxruntime)"
    return None


def _plugin_version(spec: PluginSpec) -> str:
    if spec.kind == "http":
        return f"{spec.name}@{spec.source}"
    if spec.kind == "onnx":
        from .onnx_detector import onnx_version

        return f"{spec.name}@{onnx_version(Path(spec.source.removeprefix(ONNX_PREFIX)))}"
    from .plugin import entry_point_version, entry_points

    point = entry_points().get(spec.name)
    return f"{spec.name}@{entry_point_version(point) if point is not None else 'none'}"


def detector_version(name: str) -> str:
    """The cache token of detector ``name`` (raises ``LaneFileError`` for an unknown name)."""
    kind = _kind(name)
    if kind == "classical":
        return name
    if kind != "learned":
        spec = plugin_spec(name)
        assert spec is not None
        return _plugin_version(spec)
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


def _plugin_info(spec: PluginSpec) -> DetectorInfo:
    """A plug-in's entry; an ONNX model or Python plug-in is opened to tell whether it can run and whether it is
    marked real-trained (an HTTP server is only reached when it detects)."""
    version = _plugin_version(spec)
    bundled = bundled_specs().get(spec.name) == spec  # shipped: its folder in the package, not this disk's path
    source = f"{ONNX_PREFIX}detect/models/{spec.name}" if bundled else spec.source
    model = model_summary(spec.name) if bundled else None
    try:
        real_trained = spec.real_trained if spec.kind == "http" else plugin_real_trained(spec)
    except LaneFileError as error:
        return DetectorInfo(spec.name, spec.kind, False, version, str(error).removeprefix("detector: "),
                            model=model, source=source, real_trained=spec.real_trained)
    return DetectorInfo(spec.name, spec.kind, True, version, model=model, source=source, real_trained=real_trained)


def detector_info(name: str) -> DetectorInfo:
    """What ``name`` is and whether it can run (raises ``LaneFileError`` for an unknown name)."""
    kind = _kind(name)
    if kind == "classical":
        return DetectorInfo(name, "classical", True, name)
    if kind != "learned":
        spec = plugin_spec(name)
        assert spec is not None
        return _plugin_info(spec)
    reason = _missing(name)
    return DetectorInfo(name, "learned", reason is None, detector_version(name), reason, model_summary(name))


def detector_infos() -> list[DetectorInfo]:
    """Every detector of ``detect.registry.detector_names()``, in that order."""
    return [detector_info(name) for name in detector_names()]


def available_detector(name: str) -> DetectorInfo:
    """``detector_info(name)``, raising ``LaneFileError`` (message starting ``detector:``) when it cannot run."""
    info = detector_info(name)
    if not info.available:
        raise LaneFileError(f"detector: {name} is not available here: {info.reason}")
    return info
