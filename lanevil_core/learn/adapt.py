"""``lanevil adapt``: adapt a trained detector to a user's own unlabelled footage (a folder of their frames).

Three methods that change the weights (``--method``), combined as named, and one that does not (``view``,
``learn/view.py``: the window of the user's camera that shows the model the view it was trained on; a model
adapted so keeps its window through a later adaptation, which then reads the frames through it):

- **AdaBN** (Li et al., "Revisiting Batch Normalization For Practical Domain Adaptation"): every batch-norm layer's
  running mean and variance are estimated again, as a cumulative average over the user's frames, with the weights
  unchanged. The statistics of our renders give way to those of the user's camera and roads.
- **Self-training** with confidence-filtered pseudo-labels: the (AdaBN-adapted) model reads every frame and its
  horizontal mirror; a lane is kept as a pseudo-label only where both readings agree (mean horizontal distance
  under ``agreement`` of the image width over the rows both cover) and a frame only with at least ``min_lanes``
  such lanes. The model is then fine-tuned on those frames and labels with strong photometric augmentation
  (``learn.randomise.photometric``) at a small learning rate, which keeps it near what it learned from renders.
  With ``rounds`` above 1 the frames are read again by the fine-tuned model and it is fine-tuned on its new
  readings, round after round (each round's lanes must again agree with their mirror).
- **DANN** (``learn.dann``, Ganin & Lempitsky's domain-adversarial training): fine-tuned on labelled renders
  (``source``, a ``lanevil dataset`` split) while a domain classifier behind gradient reversal pushes its backbone
  features of renders and of the user's frames together. With ``adabn+dann`` the batch-norm statistics are estimated
  on the user's frames *after* it (training moves them); ``dann+self-train`` self-trains the model it leaves.

The result is a model folder like ``lanevil train``'s (``config.json``, ``weights.pt``, ``model.onnx``,
``training.json`` with what was adapted on), usable wherever a detector is chosen (``--weights``).
No label of the user's frames is read: scoring the adapted model on labelled frames of *other* clips of the same
camera is the user's check (``lanevil detect`` + ``lanevil eval --metric ego``).
"""

from __future__ import annotations

import io
import json
import math
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn
from torch.utils.data import DataLoader

from ..detect.lane_slots import LaneLine, mirror_slots, tusimple_lanes
from ..detect.learned import decode_outputs
from ..detect.model_spec import CONFIG_FILE, ONNX_FILE, TRAINING_FILE, WEIGHTS_FILE, ModelSpec
from ..detect.split import read_rgb
from ..detect.view import View, view_input
from ..files import write_atomic
from ..images import frame_files
from ..labels.lanes import TUSIMPLE_H_SAMPLES
from . import ADAPT_METHODS
from .dann import adversarial_training
from .data import LabelledFrames, _Frames, read_splits, resized
from .export import export_onnx, load_weights
from .losses import detector_loss
from .models import Deployed, LaneNet

METHODS = tuple(method for method in ADAPT_METHODS if method != "view")  # view: learn.view.adapt_view, no torch


class AdaptError(ValueError):
    """Adaptation that cannot start (no frames, no model)."""


@dataclass(frozen=True)
class AdaptSettings:
    model: Path  # a model folder with config.json and weights.pt (lanevil train's, or a shipped family's)
    frames: tuple[Path, ...]  # folders of the user's unlabelled frames (png/jpg, searched recursively)
    out: Path
    method: str = "adabn+self-train"
    source: tuple[Path, ...] = ()  # labelled split folders of renders (lanevil dataset), read by the dann methods
    epochs: int = 3  # self-training epochs, and passes over the source with dann
    domain_weight: float = 1.0  # scales dann's reversed gradient (0: a fine-tune on the source alone, a control)
    rounds: int = 1  # self-training rounds: each reads the frames again with the model the last round left
    batch: int = 16
    lr: float = 2e-4
    agreement: float = 0.015  # mean |x - x_mirrored| as a share of the width for a lane to be kept
    min_lanes: int = 2
    max_frames: int = 2000  # frames read at most (evenly over the folders' sorted files), of the source too
    device: str = "auto"
    seed: int = 0
    threads: int = 0

    def __post_init__(self) -> None:
        """The rules between settings, each broken one named as the command line names it (``AdaptError``)."""
        if self.method not in METHODS:
            raise AdaptError(f"--method {self.method}: choose from {', '.join(METHODS)}")
        if "dann" in self.method and not self.source:
            raise AdaptError(f"--source: --method {self.method} needs a labelled split of renders (--source DIR)")
        if self.source and "dann" not in self.method:
            raise AdaptError(f"--source: only with a dann method (not {self.method})")
        if self.domain_weight < 0:
            raise AdaptError(f"--domain-weight {self.domain_weight:g}: must be at least 0")


def adapt_batch_norm(model: LaneNet, images: np.ndarray, device: torch.device, batch: int = 32) -> int:
    """AdaBN: the running statistics of every batch-norm layer re-estimated on ``images`` ((N, H, W, 3) uint8 at the
    input size) as a cumulative average, weights unchanged; returns the layers reset."""
    layers = [m for m in model.modules() if isinstance(m, nn.modules.batchnorm._BatchNorm)]
    for layer in layers:
        layer.reset_running_stats()
        layer.momentum = None  # cumulative moving average over every batch
    model.eval()
    for layer in layers:
        layer.train()
    with torch.no_grad():
        for start in range(0, len(images), batch):
            model(_tensor(images[start:start + batch]).to(device))
    model.eval()
    for layer in layers:
        layer.momentum = 0.1
    return len(layers)


def _tensor(images: np.ndarray) -> torch.Tensor:
    return torch.from_numpy(np.ascontiguousarray(images.transpose(0, 3, 1, 2)).astype(np.float32) / 255.0)


def _read(model: LaneNet, images: np.ndarray, device: torch.device, batch: int = 32) -> list[list[LaneLine | None]]:
    deployed = Deployed(model).to(device).eval()
    slots = []
    with torch.no_grad():
        for start in range(0, len(images), batch):
            values = deployed(_tensor(images[start:start + batch]).to(device))
            outputs = {name: v.float().cpu().numpy() for name, v in zip(deployed.output_names(), values, strict=True)}
            slots += [decode_outputs(model.spec, outputs, k) for k in range(len(values[0]))]
    return slots


def agreeing_lanes(direct: list[LaneLine | None], flipped: list[LaneLine | None], agreement: float) -> list[LaneLine]:
    """The lanes read alike in a frame and in its mirror (``flipped``: the lanes read on the mirrored image): each
    lane of ``direct`` that some mirrored-back lane follows. Families with fixed slots read a lane in the mirrored
    slot; anchor and curve families read however many lanes they find, in their own order, so lanes are matched
    by position, not by slot."""
    back = [b for b in mirror_slots(flipped) if b is not None]
    return [a for a in direct if a is not None and any(_follows(a, b, agreement) for b in back)]


def _follows(a: LaneLine, b: LaneLine, agreement: float) -> bool:
    """Whether ``b`` lies within ``agreement`` (mean |dx|, a share of the width) of ``a`` on at least 3 of a's rows."""
    xb = b.x_at(a.points[:, 1])
    both = ~np.isnan(xb)
    return bool(both.sum() >= 3 and float(np.mean(np.abs(a.points[both, 0] - xb[both]))) < agreement)


def pseudo_labels(model: LaneNet, images: np.ndarray, device: torch.device, agreement: float,
                  min_lanes: int) -> list[list[LaneLine] | None]:
    """Per image, its confident lanes (``agreeing_lanes``), or None where fewer than ``min_lanes`` agree."""
    direct = _read(model, images, device)
    flipped = _read(model, np.ascontiguousarray(images[:, :, ::-1]), device)
    out: list[list[LaneLine] | None] = []
    for a, b in zip(direct, flipped, strict=True):
        lanes = agreeing_lanes(a, b, agreement)
        out.append(lanes if len(lanes) >= min_lanes else None)
    return out


class PseudoLabelledFrames(_Frames):
    """The user's frames (at the input size) with their pseudo-labels as TuSimple records at the input size."""

    def __init__(self, images: np.ndarray, lanes: list[list[LaneLine]], spec: ModelSpec, seed: int) -> None:
        super().__init__(spec, train=True, augment=None, seed=seed, photometric=True)
        self.images = images
        size = spec.input_size
        rows = [h * size[1] / 720.0 for h in TUSIMPLE_H_SAMPLES]
        self.records = [{"lanes": tusimple_lanes(frame_lanes, rows, size), "h_samples": rows,
                         "raw_file": f"pseudo/{index}"} for index, frame_lanes in enumerate(lanes)]
        self.frame_sizes = [size] * len(lanes)


def _save(obj: Any, path: Path) -> None:
    buffer = io.BytesIO()
    torch.save(obj, buffer)
    write_atomic(path, buffer.getvalue())


def adapt(settings: AdaptSettings, show_progress: bool = True) -> dict[str, Any]:
    """Adapt ``settings.model`` to the frames and write the model folder ``settings.out``; returns its
    ``training.json`` content."""
    from .train import pick_device

    torch.manual_seed(settings.seed)
    torch.set_num_threads(settings.threads or os.cpu_count() or 1)
    device = pick_device(settings.device)
    weights = settings.model / WEIGHTS_FILE
    if not weights.is_file():
        raise AdaptError(f"--weights {settings.model}: no {WEIGHTS_FILE} (adaptation needs the PyTorch weights)")
    spec = ModelSpec.load(settings.model)
    files = frame_files(settings.frames, settings.max_frames)
    if not files:
        raise AdaptError("--frames: no png or jpg images under " + ", ".join(str(f) for f in settings.frames))
    started = time.perf_counter()
    view = View.load(settings.model)  # a model adapted with --method view keeps its window, and learns through it
    images = np.stack([resized(read_rgb(path), spec.input_size) if view is None else
                       view_input(read_rgb(path), view, spec.input_size) for path in files])
    model = load_weights(settings.model).to(device)
    recorded = {k: (str(v) if isinstance(v, Path) else v)
                for k, v in asdict(settings).items() if k not in ("frames", "out", "source")}
    summary: dict[str, Any] = {"adapted_from": settings.model.name, "frames": len(files), "settings": recorded}
    if settings.source:
        summary["source"] = [folder.name for folder in settings.source]
    if "dann" in settings.method:
        source = source_frames(settings, spec)
        summary["dann"] = adversarial_training(model, source, images, settings.epochs, settings.batch, settings.lr,
                                               settings.seed, device, settings.domain_weight, show_progress)
    if "adabn" in settings.method:  # after dann, whose training moves the statistics
        summary["adabn_layers"] = adapt_batch_norm(model, images, device)
    if "self-train" in settings.method:
        rounds = [_self_train(model, images, settings, device, show_progress) for _ in range(settings.rounds)]
        summary["self_training"] = rounds[-1] if len(rounds) == 1 else {**rounds[-1], "rounds": rounds}
    model = model.cpu().eval()
    out = settings.out
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / CONFIG_FILE, spec.to_json().encode("utf-8"))
    _save({k: (v.half() if v.is_floating_point() else v) for k, v in model.state_dict().items()}, out / WEIGHTS_FILE)
    export_onnx(model, out / ONNX_FILE)
    if view is not None:
        view.save(out)
    summary.update(spec=asdict(spec), seconds=round(time.perf_counter() - started, 1), torch=torch.__version__)
    write_atomic(out / TRAINING_FILE, (json.dumps(summary, indent=2) + "\n").encode("utf-8"))
    return summary


def source_frames(settings: AdaptSettings, spec: ModelSpec) -> LabelledFrames:
    """The labelled source frames of ``settings.source`` at the model's input size (flipped half the time while
    training), thinned evenly to ``settings.max_frames``."""
    try:
        frames, _ = read_splits(settings.source)
    except ValueError as error:
        raise AdaptError(str(error).replace("--data", "--source")) from None
    indices = None
    if len(frames) > settings.max_frames:
        indices = [int(i) for i in np.linspace(0, len(frames) - 1, settings.max_frames).round()]
    return LabelledFrames(frames, spec, indices, train=True, seed=settings.seed)


def _self_train(model: LaneNet, images: np.ndarray, settings: AdaptSettings, device: torch.device,
                show_progress: bool) -> dict[str, Any]:
    """Fine-tune ``model`` on its own confident readings of ``images``; what it kept and the loss per epoch."""
    labels = pseudo_labels(model, images, device, settings.agreement, settings.min_lanes)
    chosen = [i for i, lanes in enumerate(labels) if lanes is not None]
    report: dict[str, Any] = {"pseudo_labelled": len(chosen), "lanes": int(sum(len(labels[i] or []) for i in chosen))}
    if not chosen:
        report["skipped"] = "no frame had enough confident lanes"
        return report
    dataset = PseudoLabelledFrames(images[chosen], [labels[i] or [] for i in chosen], model.spec, settings.seed)
    optimizer = torch.optim.AdamW(model.parameters(), lr=settings.lr, weight_decay=1e-4)
    batch = min(settings.batch, len(dataset))
    steps = settings.epochs * max(1, len(dataset) // batch)
    losses = []
    model.train()
    step = 0
    for epoch in range(settings.epochs):
        dataset.epoch = epoch
        loader = DataLoader(dataset, batch_size=batch, shuffle=True, drop_last=True,
                            generator=torch.Generator().manual_seed(settings.seed * 1000 + epoch))
        epoch_losses = []
        for sample in loader:
            for group in optimizer.param_groups:  # cosine from lr to 0
                group["lr"] = settings.lr * 0.5 * (1.0 + math.cos(math.pi * step / max(1, steps)))
            sample = {k: v.to(device) for k, v in sample.items()}
            loss, _ = detector_loss(model.spec.family, model(sample["image"]), sample)
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            optimizer.step()
            epoch_losses.append(float(loss.detach()))
            step += 1
        losses.append(round(float(np.mean(epoch_losses)), 4) if epoch_losses else None)
        if show_progress:
            print(f"self-training epoch {epoch + 1}/{settings.epochs}: loss {losses[-1]}", flush=True)
    report["loss"] = losses
    return report
