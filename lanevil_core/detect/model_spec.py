"""What a learned lane detector is: its family, backbone, input size and output encoding (``config.json``).

The spec is plain data shared by training (``lanevil_core.learn``, torch) and inference (``detect.learned``,
onnxruntime), so a model folder describes itself and inference needs no torch.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..typed import FloatArray
from .lane_slots import anchor_rows

Family = Literal["ufld", "seg", "laneatt", "bezier", "ganet", "scnn"]
Backbone = Literal["resnet18", "resnet34"]
# The one list of learned detector families: training, `lanevil detect`, the drive loop, the web app and the
# editor all take their choices from it (through ``detect.split.METHODS``).
FAMILIES: tuple[Family, ...] = ("ufld", "seg", "laneatt", "bezier", "ganet", "scnn")
BACKBONES: tuple[Backbone, ...] = ("resnet18", "resnet34")
CONFIG_FILE = "config.json"
ONNX_FILE = "model.onnx"
WEIGHTS_FILE = "weights.pt"
TRAINING_FILE = "training.json"


class ModelSpecError(ValueError):
    """A model folder or config that cannot be used (missing files, unknown family, bad numbers)."""


@dataclass(frozen=True)
class ModelSpec:
    """A learned detector's architecture and output encoding.

    Attributes:
        family: ``ufld`` (row-anchor classification), ``seg`` (lane-slot segmentation + existence), ``laneatt``
            (line anchors with attention), ``bezier`` (Bézier curves, Hungarian matching), ``ganet`` (keypoints
            grouped by their start points) or ``scnn`` (segmentation with slice-by-slice message passing).
        backbone: residual network depth, trained from scratch unless initialised from a file.
        width: channel multiplier of the backbone (1.0 = the published ResNet widths 64 ... 512).
        input_size: network input (width, height) in pixels; frames are resized to it.
        slots: lane slots, half left and half right of the camera (see ``lane_slots``).
        anchors: row anchors (``ufld``; ``laneatt``'s offset rows), evenly over TuSimple rows 160 ... 710 of a
            720-row frame.
        grid: column cells per row anchor (``ufld``); class ``grid`` means no lane.
        hidden: units of the row-anchor head's hidden layer (``ufld``).
        mask_stride: output stride of the lane masks (``seg``, ``scnn``, and the auxiliary head of the others).
    """

    family: Family = "ufld"
    backbone: Backbone = "resnet18"
    width: float = 0.25
    input_size: tuple[int, int] = (320, 180)
    slots: int = 6
    anchors: int = 28
    grid: int = 56
    hidden: int = 128
    mask_stride: int = 2
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise ModelSpecError(f"family: {self.family!r} is not one of {', '.join(FAMILIES)}")
        if self.backbone not in BACKBONES:
            raise ModelSpecError(f"backbone: {self.backbone!r} is not one of {', '.join(BACKBONES)}")
        if self.slots < 2 or self.slots % 2:
            raise ModelSpecError(f"slots: {self.slots} must be an even number of at least 2")
        if not 0.0 < self.width <= 2.0:
            raise ModelSpecError(f"width: {self.width} must be in (0, 2]")
        w, h = self.input_size
        if w < 64 or h < 64:
            raise ModelSpecError(f"input_size: {w}x{h} is below 64x64")

    @property
    def anchor_rows(self) -> FloatArray:
        """(anchors,) normalised rows of the row anchors."""
        return anchor_rows(self.anchors)

    @property
    def mask_size(self) -> tuple[int, int]:
        """(width, height) of the lane-mask output."""
        w, h = self.input_size
        return -(-w // self.mask_stride), -(-h // self.mask_stride)

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2, sort_keys=True) + "\n"

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ModelSpec:
        known = {name: data[name] for name in cls.__dataclass_fields__ if name in data}
        if "input_size" in known:
            known["input_size"] = tuple(int(v) for v in known["input_size"])
        try:
            return cls(**known)
        except TypeError as error:
            raise ModelSpecError(str(error)) from None

    @classmethod
    def load(cls, model_dir: str | Path) -> ModelSpec:
        path = Path(model_dir) / CONFIG_FILE
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise ModelSpecError(f"{model_dir}: not a model folder (no {CONFIG_FILE})") from None
        except json.JSONDecodeError as error:
            raise ModelSpecError(f"{path}: not JSON ({error.msg}, line {error.lineno})") from None
        return cls.from_dict(data)
