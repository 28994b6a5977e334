"""A user's ONNX lane model with a standard head, described by a sidecar JSON: ``--method onnx:PATH``.

``PATH`` is the ``.onnx`` file; its sidecar is the file of the same name with ``.json`` (``lanes.onnx`` ->
``lanes.json``)::

    {
      "head": "mask",                   // row_anchors | mask | polynomial (detect.standard_heads)
      "input_size": [640, 360],         // network input (width, height)
      "mean": [0.485, 0.456, 0.406],    // per channel, on 0..1 values, in the network's colour order
      "std": [0.229, 0.224, 0.225],
      "color_order": "rgb",             // rgb | bgr
      "crop": [0.0, 0.33, 1.0, 1.0],    // left, top, right, bottom: the part of the frame the network sees
      "real_trained": true,             // trained on real roads (the Real -> LanEvil table)
      "logits": true,                   // row_anchors and mask: scores before softmax / sigmoid
      "threshold": 0.5,                 // mask: lane-line probability
      "row_anchors": [64, 68, ...],     // row_anchors: the anchor rows, network-input pixels
      "lane_class": 1,                  // polynomial: the class index of "lane"
      "outputs": ["pred_logits", "pred_curves"]  // output names in the head's order (default: the model's order)
    }

Only ``head`` and ``input_size`` are required (and ``row_anchors`` for that head). The network gets one
``(1, 3, H, W)`` float32 input: the crop of the frame resized (area filter) to ``input_size``, scaled to 0..1,
then ``(value - mean) / std``.
"""

from __future__ import annotations

import functools
import importlib.util
import json
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import cv2
import numpy as np

from ..metrics.formats import LaneFileError
from ..typed import BoolArray, FloatArray, UInt8Array
from .model_spec import CONFIG_FILE, ONNX_FILE
from .standard_heads import (
    HEADS,
    decode_mask_head,
    decode_polynomial_head,
    decode_row_anchor_head,
    lane_probability,
)

ONNX_PREFIX = "onnx:"
FULL_FRAME = (0.0, 0.0, 1.0, 1.0)


@dataclass(frozen=True)
class Sidecar:
    """How to feed an ONNX lane model and read its outputs (the fields of the module docstring)."""

    head: Literal["row_anchors", "mask", "polynomial"]
    input_size: tuple[int, int]
    mean: tuple[float, float, float] = (0.0, 0.0, 0.0)
    std: tuple[float, float, float] = (1.0, 1.0, 1.0)
    color_order: Literal["rgb", "bgr"] = "rgb"
    crop: tuple[float, float, float, float] = FULL_FRAME
    real_trained: bool = False
    logits: bool = True
    threshold: float = 0.5
    row_anchors: tuple[float, ...] = ()
    lane_class: int = 1
    outputs: tuple[str, ...] = ()

    @classmethod
    def from_dict(cls, data: Any, where: str) -> Sidecar:
        if not isinstance(data, dict):
            raise LaneFileError(f"{where}: not a JSON object")
        unknown = sorted(set(data) - set(cls.__dataclass_fields__))
        if unknown:
            raise LaneFileError(f"{where}: unknown field {unknown[0]!r}")
        for required in ("head", "input_size"):
            if required not in data:
                raise LaneFileError(f"{where}: {required} is missing")
        if data["head"] not in HEADS:
            raise LaneFileError(f"{where}: head {data['head']!r} is not one of {', '.join(HEADS)}")
        fields = {"input_size": 2, "mean": 3, "std": 3, "crop": 4}
        values = dict(data)
        for name, length in fields.items():
            if name in values:
                values[name] = _numbers(values[name], length, f"{where}: {name}")
        if "row_anchors" in values:
            values["row_anchors"] = _numbers(values["row_anchors"], None, f"{where}: row_anchors")
        if "outputs" in values:
            values["outputs"] = tuple(str(name) for name in values["outputs"])
        sidecar = cls(**values)
        sidecar.check(where)
        return sidecar

    def check(self, where: str) -> None:
        width, height = self.input_size
        if width < 8 or height < 8 or width != int(width) or height != int(height):
            raise LaneFileError(f"{where}: input_size {width}x{height} must be whole pixels, at least 8x8")
        left, top, right, bottom = self.crop
        if not (0.0 <= left < right <= 1.0 and 0.0 <= top < bottom <= 1.0):
            raise LaneFileError(f"{where}: crop {list(self.crop)} must be fractions left < right, top < bottom")
        if any(s <= 0 for s in self.std):
            raise LaneFileError(f"{where}: std must be positive")
        if self.color_order not in ("rgb", "bgr"):
            raise LaneFileError(f"{where}: color_order {self.color_order!r} is not rgb or bgr")
        if self.head == "row_anchors" and len(self.row_anchors) < 2:
            raise LaneFileError(f"{where}: the row_anchors head needs row_anchors (network-input rows)")

    @classmethod
    def load(cls, path: Path) -> Sidecar:
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise LaneFileError(f"{path}: no sidecar (the ONNX model's input size, normalisation and head)") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
            raise LaneFileError(f"{path}: not a JSON sidecar ({error})") from None
        return cls.from_dict(data, str(path))


def _numbers(value: Any, length: int | None, where: str) -> tuple[float, ...]:
    ok = isinstance(value, list) and (length is None or len(value) == length) and all(
        isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v) for v in value)
    if not ok:
        raise LaneFileError(f"{where}: expected a list of {length or 'some'} numbers")
    if length == 2:
        return tuple(int(v) for v in value)
    return tuple(float(v) for v in value)


def sidecar_path(onnx_path: Path) -> Path:
    """The sidecar JSON of an ONNX file: same name, ``.json``."""
    return onnx_path.with_suffix(".json")


def crop_box(crop: Sequence[float], size: tuple[int, int]) -> tuple[int, int, int, int]:
    """Pixel box (left, top, right, bottom) of the crop fractions in a frame of ``size``, rounded to whole pixels."""
    width, height = size
    left, top, right, bottom = crop
    return round(left * width), round(top * height), max(round(right * width), round(left * width) + 1), \
        max(round(bottom * height), round(top * height) + 1)


def network_input(rgb: UInt8Array, sidecar: Sidecar) -> FloatArray:
    """(1, 3, H, W) float32: the frame's crop resized to the input size, normalised, in the sidecar's colour order."""
    left, top, right, bottom = crop_box(sidecar.crop, (rgb.shape[1], rgb.shape[0]))
    image = np.ascontiguousarray(rgb[top:bottom, left:right])
    if image.shape[1::-1] != sidecar.input_size:
        image = np.asarray(cv2.resize(image, sidecar.input_size, interpolation=cv2.INTER_AREA), np.uint8)
    if sidecar.color_order == "bgr":
        image = image[..., ::-1]
    scaled = np.multiply(image, np.float32(1.0 / 255.0), dtype=np.float32)
    normalised = np.divide(scaled - np.asarray(sidecar.mean, np.float32), np.asarray(sidecar.std, np.float32),
                           dtype=np.float32)
    return np.ascontiguousarray(normalised.transpose(2, 0, 1)[None], dtype=np.float32)


def decode_head(sidecar: Sidecar, outputs: list[FloatArray]) -> list[FloatArray]:
    """Normalised polylines of one image's outputs (batch axis removed), in the sidecar's head order."""
    if sidecar.head == "row_anchors":
        rows_norm = np.asarray(sidecar.row_anchors, np.float64) / sidecar.input_size[1]
        return decode_row_anchor_head(outputs[0], rows_norm, sidecar.logits)
    if sidecar.head == "mask":
        return decode_mask_head(outputs[0], sidecar.logits, sidecar.threshold)
    if len(outputs) < 2:
        raise ValueError("polynomial: the model needs two outputs (class scores, curves)")
    return decode_polynomial_head(outputs[0], outputs[1], sidecar.lane_class)


class OnnxLaneDetector:
    """An ONNX model with a standard head: ``detect(rgb)`` -> polylines in ``rgb``'s pixels."""

    input_size = None  # the crop and resize are the sidecar's

    def __init__(self, name: str, onnx_path: Path) -> None:
        if importlib.util.find_spec("onnxruntime") is None:
            raise LaneFileError("detector: onnxruntime is not installed (pip install onnxruntime)")
        from .learned import inference_session

        self.name = name
        self.path = onnx_path
        self.sidecar = Sidecar.load(sidecar_path(onnx_path))
        self.real_trained = self.sidecar.real_trained
        try:
            self._session = inference_session(onnx_path)
        except Exception as error:  # noqa: BLE001 - onnxruntime raises its own error types
            raise LaneFileError(f"{onnx_path}: not a usable ONNX model ({str(error).splitlines()[0]})") from None
        names = [output.name for output in self._session.get_outputs()]
        missing = [name for name in self.sidecar.outputs if name not in names]
        if missing:
            raise LaneFileError(f"{sidecar_path(onnx_path)}: outputs: the model has no output {missing[0]!r} "
                                f"(it has {', '.join(names)})")
        self._outputs = list(self.sidecar.outputs) or names
        self._input = self._session.get_inputs()[0].name
        self._lock = threading.Lock()

    def outputs(self, rgb: UInt8Array) -> list[FloatArray]:
        """The network's outputs for one frame, batch axis removed, in the head's order."""
        batch = network_input(rgb, self.sidecar)
        with self._lock:
            try:
                values = self._session.run(self._outputs, {self._input: batch})
            except Exception as error:  # noqa: BLE001
                raise LaneFileError(f"detector: {self.name}: the model failed ({str(error).splitlines()[0]})") \
                    from None
        return [np.asarray(value, np.float64)[0] for value in values]

    def lane_mask(self, rgb: UInt8Array) -> BoolArray:
        """(H, W) bool lane-line mask of a ``mask`` head in ``rgb``'s pixels: the probability map resized
        (bilinear) over the crop, above ``threshold``; nothing outside the crop."""
        if self.sidecar.head != "mask":
            raise LaneFileError(f"detector: {self.name}: a {self.sidecar.head} head has no lane-line mask")
        height, width = rgb.shape[:2]
        try:
            probability = lane_probability(self.outputs(rgb)[0], self.sidecar.logits)
        except ValueError as error:
            raise LaneFileError(f"detector: {self.name}: {error}") from None
        left, top, right, bottom = crop_box(self.sidecar.crop, (width, height))
        resized = cv2.resize(probability.astype(np.float32), (right - left, bottom - top),
                             interpolation=cv2.INTER_LINEAR)
        mask = np.zeros((height, width), bool)
        mask[top:bottom, left:right] = resized > self.sidecar.threshold
        return mask

    def detect(self, rgb: UInt8Array) -> list[FloatArray]:
        height, width = rgb.shape[:2]
        try:
            lines = decode_head(self.sidecar, self.outputs(rgb))
        except ValueError as error:
            raise LaneFileError(f"detector: {self.name}: {error}") from None
        left, top, right, bottom = crop_box(self.sidecar.crop, (width, height))
        scale = np.array([right - left, bottom - top], np.float64)
        return [line * scale + np.array([left, top]) - 0.5 for line in lines]


@functools.lru_cache(maxsize=8)
def _load(name: str, path: str, version: str) -> OnnxLaneDetector:
    return OnnxLaneDetector(name, Path(path))


def onnx_version(onnx_path: Path) -> str:
    """Size and time of the model and its sidecar (of a model folder: its ONNX file and config): a new model or
    sidecar is a new detector version."""
    parts = []
    files = (onnx_path / ONNX_FILE, onnx_path / CONFIG_FILE) if onnx_path.is_dir() else (onnx_path,
                                                                                          sidecar_path(onnx_path))
    for path in files:
        try:
            stat = path.stat()
        except OSError:
            return "none"
        parts.append(f"{stat.st_size}-{stat.st_mtime_ns}")
    return "-".join(parts)


def onnx_detector(name: str, onnx_path: Path) -> OnnxLaneDetector:
    """The ONNX detector at ``onnx_path`` (opened once per version of its files)."""
    if not onnx_path.is_file():
        raise LaneFileError(f"detector: {name}: no ONNX model at {onnx_path}")
    return _load(name, str(onnx_path.resolve()), onnx_version(onnx_path))
