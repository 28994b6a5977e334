"""``lanevil train``: fit a lane detector on a dataset's clean train split and write a model folder.

The model folder holds ``config.json`` (the ``ModelSpec``), ``checkpoint.pt`` (written after every epoch, read by
``--resume``), ``weights.pt`` (the final state dict in half precision), ``model.onnx`` and ``training.json`` (data
hash, settings, time, per-epoch loss and validation accuracy). A ``val_fraction`` of the train split's case folders
is held out by seed; validation accuracy is TuSimple Accuracy on the 1280x720 grid.
"""

from __future__ import annotations

import io
import json
import math
import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader

from ..detect.learned import decode_outputs, lanes_of
from ..detect.model_spec import CONFIG_FILE, ONNX_FILE, TRAINING_FILE, WEIGHTS_FILE, ModelSpec
from ..files import write_atomic
from ..labels.lanes import on_tusimple_grid
from ..metrics.tusimple import score_image
from .aam import (
    AamSettings,
    build_bank,
    hard_patches,
    hard_summary,
    lane_attention,
    mix,
    paint_area,
    patch_tensors,
    update_attention_areas,
)
from .augment import AUGMENTS
from .backbone import BackboneWeightsError, load_backbone_weights, load_init
from .data import LabelledFrames, read_splits, split_indices
from .export import export_onnx
from .losses import detector_loss
from .models import Deployed, LaneNet, build_model
from .pgd import PgdSettings, pgd_batch

CHECKPOINT_FILE = "checkpoint.pt"
AUGMENT_NAMES = (*AUGMENTS, "aam", "pgd")
AAM_BANK_FILE = "aam_bank.pt"
WARMUP_STEPS = 100


class TrainError(ValueError):
    """Training that cannot start (no data, a resume that does not match)."""


@dataclass(frozen=True)
class TrainSettings:
    data: tuple[Path, ...]  # dataset (or split) folders, trained on together (--data, repeated)
    out: Path
    spec: ModelSpec = field(default_factory=ModelSpec)
    epochs: int = 12
    batch: int = 16
    lr: float = 2e-3
    weight_decay: float = 1e-4
    augment: str = "none"
    affine: bool = False  # UFLD's rotation and shifts of every training sample (learn.affine)
    device: str = "auto"
    seed: int = 0
    val_fraction: float = 0.1
    resume: bool = False
    init: Path | None = None
    max_steps: int | None = None  # stop each epoch after this many batches (tests and smoke runs)
    # stop once validation accuracy has not improved for this many epochs, and keep the best epoch's weights
    # (``epochs`` is then the most there can be; the learning-rate schedule still spans it)
    patience: int | None = None
    # with ``patience``: no stop before this many epochs (a plateau early in training is not the end of it)
    min_epochs: int = 0
    aam: AamSettings = field(default_factory=AamSettings)
    pgd: PgdSettings = field(default_factory=PgdSettings)
    threads: int = 0  # CPU threads of torch (0 = every core); 1 on a machine busy with other work
    randomise: bool = False  # image-space domain randomisation of everything but the paint (learn.randomise)
    photometric: bool = False  # strong photometric augmentation (learn.randomise.photometric)
    backbone_weights: Path | None = None  # an ImageNet checkpoint in torchvision's ResNet layout (--backbone-weights)
    # held-out synthetic splits (other cameras, roads, materials) to validate on instead of held-out case folders:
    # the epoch kept with --patience is chosen on them, never on real frames
    val_data: tuple[Path, ...] = ()
    loader_workers: int = 0  # DataLoader processes (a GPU waits on one process's augmentation)
    time_limit: float | None = None  # seconds of training after which no new epoch starts (--time-limit)

    def __post_init__(self) -> None:
        """The rules between settings, each broken one named as the command line names it (``TrainError``)."""
        if self.augment not in AUGMENT_NAMES:
            raise TrainError(f"--augment {self.augment}: choose from {', '.join(AUGMENT_NAMES)}")
        if self.aam.keep_paint and self.augment != "aam":
            raise TrainError(f"--aam-keep-paint: only with --augment aam (not {self.augment})")
        if self.min_epochs and self.patience is None:
            raise TrainError("--min-epochs: only with --patience")
        if self.min_epochs > self.epochs:
            raise TrainError(f"--min-epochs {self.min_epochs}: more than --epochs {self.epochs}")
        if not 0.0 <= self.val_fraction < 1.0:
            raise TrainError(f"--val {self.val_fraction}: must lie in [0, 1)")
        if self.backbone_weights is not None and self.spec.width != 1.0:
            raise TrainError(f"--backbone-weights: ImageNet ResNet weights need --width 1.0 (not {self.spec.width})")
        if self.time_limit is not None and self.time_limit <= 0:
            raise TrainError(f"--time-limit {self.time_limit:g}: must be positive")


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if name == "cuda" and not torch.cuda.is_available():
        raise TrainError("--device cuda: no CUDA device is available to this torch")
    return torch.device(name)


def predict_on(model: LaneNet, images: np.ndarray, records: list[dict[str, Any]],
               frame_sizes: list[tuple[int, int]], device: torch.device,
               batch: int = 32) -> list[tuple[list[list[int]], list[list[int]], list[float]]]:
    """(predicted lanes, GT lanes, rows) for ``images`` ((N, H, W, 3) uint8 at the input size) with their TuSimple
    ``records`` of frames of ``frame_sizes``; both sides on the 1280x720 grid."""
    deployed = Deployed(model).to(device).eval()
    results = []
    with torch.no_grad():
        for start in range(0, len(images), batch):
            chunk = torch.from_numpy(images[start:start + batch].transpose(0, 3, 1, 2).astype(np.float32) / 255.0)
            values = deployed(chunk.to(device))
            outputs = {name: v.float().cpu().numpy() for name, v in zip(deployed.output_names(), values, strict=True)}
            for k in range(len(chunk)):
                record, size = records[start + k], frame_sizes[start + k]
                gt, rows = on_tusimple_grid(record["lanes"], record["h_samples"], size)
                # rows are continuous 720-grid rows; lanes_of adds the half pixel of a TuSimple row
                pred = lanes_of(model.spec, decode_outputs(model.spec, outputs, k), rows, (1280, 720))
                results.append((pred, gt, rows))
    model.train()
    return results


def predict_lanes(model: LaneNet, dataset: LabelledFrames, device: torch.device,
                  batch: int = 32) -> list[tuple[list[list[int]], list[list[int]], list[float]]]:
    """(predicted lanes, GT lanes, rows) of every frame of ``dataset``, both on the 1280x720 grid."""
    return predict_on(model, dataset.images, dataset.records, dataset.frame_sizes, device, batch)


def tusimple_accuracy(results: list[tuple[list[list[int]], list[list[int]], list[float]]]) -> float:
    """Mean official per-image accuracy over the frames with labelled lanes (the metric scores a frame with no
    lanes 0 whatever is predicted, so unpainted training variations are left out)."""
    scores = [score_image(pred, gt, rows, 0.0).accuracy for pred, gt, rows in results if gt]
    return float(np.mean(scores)) if scores else float("nan")


def _save(obj: Any, path: Path) -> None:
    buffer = io.BytesIO()
    torch.save(obj, buffer)
    write_atomic(path, buffer.getvalue())


def _lr_at(step: int, total: int, base: float) -> float:
    if step < WARMUP_STEPS:
        return base * (step + 1) / WARMUP_STEPS
    progress = (step - WARMUP_STEPS) / max(1, total - WARMUP_STEPS)
    return base * 0.5 * (1.0 + math.cos(math.pi * min(1.0, progress)))


Progress = Callable[[str], None]


def _patience_spent(best: dict[str, Any] | None, epochs_done: int, patience: int | None,
                    min_epochs: int = 0) -> bool:
    """Whether ``patience`` epochs have passed without gain since the best one (``--patience``), once at least
    ``min_epochs`` have run (``--min-epochs``)."""
    return (best is not None and patience is not None and epochs_done >= min_epochs
            and epochs_done - best["epoch"] >= patience)


def aam_bank(settings: TrainSettings, frames: list[tuple[Path, dict[str, Any]]], data_sha: str) -> list:
    """The AAM bank of this run (rendered once, kept in the model folder for ``--resume``)."""
    path = settings.out / AAM_BANK_FILE
    key = {"data_sha256": data_sha, "seed": settings.seed, "input_size": list(settings.spec.input_size),
           "settings": asdict(settings.aam)}
    if path.is_file():
        cached = torch.load(path, weights_only=False)
        if cached.get("key") == key:
            return cached["patches"]
    folders = sorted({split_dir / Path(record["raw_file"]).parent for split_dir, record in frames})
    bases = [folder / "case.json" for folder in folders if (folder / "case.json").is_file()]
    if not bases:
        raise TrainError("--augment aam: no case.json beside the frames of "
                         + ", ".join(str(data) for data in settings.data))
    patches = build_bank(bases, settings.spec.input_size, settings.seed, settings.aam)
    settings.out.mkdir(parents=True, exist_ok=True)
    _save({"key": key, "patches": patches}, path)
    return patches


def aam_batch(model: LaneNet, images: torch.Tensor, hard: list, settings: TrainSettings, epoch: int,
              step: int, lane_masks: torch.Tensor | None = None) -> torch.Tensor:
    """The batch with AAM applied to a share of its images (chosen by seed, epoch and step); ``lane_masks``, the
    batch's lane-mask targets, are kept unmixed with ``settings.aam.keep_paint``."""
    rng = np.random.default_rng([settings.seed, epoch, step, 7])
    chosen = np.flatnonzero(rng.random(len(images)) < settings.aam.probability)
    if not len(chosen):
        return images
    device = next(model.parameters()).device
    attention_map = lane_attention(model, images[chosen].to(device), settings.aam.attention_spread_px).cpu()
    bank = patch_tensors([hard[int(i)] for i in rng.integers(0, len(hard), len(chosen))])
    keep = None
    if settings.aam.keep_paint and lane_masks is not None:
        keep = paint_area(lane_masks[chosen], model.spec.input_size)
    images = images.clone()
    images[chosen] = mix(images[chosen], attention_map, bank.images, bank.masks, bank.areas, bank.gains,
                         bank.objects, keep)
    return images


def _validation_set(settings: TrainSettings, frames: list[tuple[Path, dict[str, Any]]],
                    val_idx: list[int]) -> LabelledFrames | None:
    """The frames validated on: every frame of ``settings.val_data`` where given, else the held-out case folders
    ``val_idx`` of the train data (None when there are none)."""
    if settings.val_data:
        try:
            held_out, _ = read_splits(settings.val_data)
        except ValueError as error:
            raise TrainError(str(error).replace("--data", "--val-data")) from None
        return LabelledFrames(held_out, settings.spec, train=False)
    return LabelledFrames(frames, settings.spec, val_idx, train=False) if val_idx else None


@dataclass
class _TrainData:
    """What one run reads: the train frames and their identity, the training and validation sets."""

    frames: list[tuple[Path, dict[str, Any]]]
    sha256: str
    train_set: LabelledFrames
    val_set: LabelledFrames | None


@dataclass
class _Run:
    """The state of a run between epochs (what ``checkpoint.pt`` holds)."""

    model: LaneNet
    optimizer: torch.optim.Optimizer
    steps_per_epoch: int
    total_steps: int
    history: list[dict[str, Any]] = field(default_factory=list)
    start_epoch: int = 0
    best: dict[str, Any] | None = None  # {"epoch", "model"} of the best validation accuracy (with --patience)


def _read_data(settings: TrainSettings) -> _TrainData:
    """The train splits, read once, split into training and validation frames (case folders held out whole)."""
    try:
        frames, data_sha = read_splits(settings.data)
    except ValueError as error:
        raise TrainError(str(error)) from None
    # a case folder is held out whole; folders of the same name in two splits are different cases
    groups = [f"{split_dir}:{Path(record['raw_file']).parent}" for split_dir, record in frames]
    val_fraction = 0.0 if settings.val_data else settings.val_fraction
    train_idx, val_idx = split_indices(len(frames), groups, val_fraction, settings.seed)
    train_set = LabelledFrames(frames, settings.spec, train_idx, train=True, augment=AUGMENTS.get(settings.augment),
                               seed=settings.seed, affine=settings.affine, randomised=settings.randomise,
                               photometric=settings.photometric)
    val_set = _validation_set(settings, frames, val_idx)
    if settings.patience is not None and val_set is None:
        raise TrainError("--patience: no validation frames to watch (--val is 0 or the split has one case folder)")
    return _TrainData(frames, data_sha, train_set, val_set)


def _start(settings: TrainSettings, train_frames: int, data_sha: str, device: torch.device) -> _Run:
    """The network (ImageNet backbone, ``--init`` tensors), its optimiser and schedule, resumed from the checkpoint
    where asked."""
    spec = settings.spec
    model = build_model(spec)
    if settings.backbone_weights is not None:
        try:
            load_backbone_weights(model.backbone, settings.backbone_weights)
        except BackboneWeightsError as error:
            raise TrainError(f"--backbone-weights {error}") from None
    model = model.to(device)
    if settings.init is not None:
        copied, skipped = load_init(model, settings.init)
        if copied == 0:
            raise TrainError(f"--init {settings.init}: no tensor matches the {spec.family} network")
    optimizer = torch.optim.AdamW(model.parameters(), lr=settings.lr, weight_decay=settings.weight_decay)
    steps_per_epoch = math.ceil(train_frames / settings.batch)
    if settings.max_steps is not None:
        steps_per_epoch = min(steps_per_epoch, settings.max_steps)
    run = _Run(model, optimizer, steps_per_epoch, steps_per_epoch * settings.epochs)
    checkpoint_path = settings.out / CHECKPOINT_FILE
    if settings.resume and checkpoint_path.is_file():
        checkpoint = torch.load(checkpoint_path, map_location=device, weights_only=False)
        if checkpoint["data_sha256"] != data_sha or checkpoint["spec"] != asdict(spec):
            raise TrainError(f"--resume: {checkpoint_path} was trained on other data or another model; "
                             "use a new --out folder")
        model.load_state_dict(checkpoint["model"])
        optimizer.load_state_dict(checkpoint["optimizer"])
        run.history = checkpoint["history"]
        run.start_epoch = checkpoint["epoch"] + 1
        run.best = checkpoint.get("best")
    return run


def _hard_examples(run: _Run, bank: list, settings: TrainSettings, device: torch.device) -> list:
    """AAM's hard examples for the next epoch: the bank scored by the model as it is now."""
    scores = predict_on(run.model, np.stack([p.image for p in bank]), [p.record for p in bank],
                        [p.frame_size for p in bank], device)
    for patch, (pred, gt, rows) in zip(bank, scores, strict=True):
        patch.accuracy = score_image(pred, gt, rows, 0.0).accuracy
    update_attention_areas(run.model, bank, settings.aam)
    return hard_patches(bank, settings.aam.hard_share)


def _train_epoch(run: _Run, train_set: LabelledFrames, hard: list, settings: TrainSettings, epoch: int,
                 device: torch.device, show_progress: bool) -> list[float]:
    """One epoch of optimiser steps; the batches' losses."""
    from tqdm import tqdm

    model, spec = run.model, settings.spec
    train_set.epoch = epoch
    generator = torch.Generator().manual_seed(settings.seed * 1000 + epoch)
    loader = DataLoader(train_set, batch_size=settings.batch, shuffle=True, generator=generator, drop_last=True,
                        num_workers=settings.loader_workers, persistent_workers=False)
    bar = tqdm(total=run.steps_per_epoch, desc=f"epoch {epoch + 1}/{settings.epochs}", disable=not show_progress,
               unit="batch", dynamic_ncols=True)
    losses: list[float] = []
    for step, batch in enumerate(loader):
        if step >= run.steps_per_epoch:
            break
        for group in run.optimizer.param_groups:
            group["lr"] = _lr_at(epoch * run.steps_per_epoch + step, run.total_steps, settings.lr)
        if hard:
            batch["image"] = aam_batch(model, batch["image"], hard, settings, epoch, step, batch["mask"])
        if settings.augment == "pgd":
            batch["image"] = pgd_batch(model, spec.family, batch, settings.pgd, settings.seed, epoch, step)
        batch = {k: v.to(device) for k, v in batch.items()}
        loss, terms = detector_loss(spec.family, model(batch["image"]), batch)
        run.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        run.optimizer.step()
        losses.append(float(loss.detach()))
        bar.set_postfix(loss=f"{np.mean(losses[-20:]):.3f}", **{k: f"{v:.3f}" for k, v in terms.items()})
        bar.update()
    bar.close()
    return losses


def _end_epoch(run: _Run, data: _TrainData, settings: TrainSettings, epoch: int, losses: list[float], hard: list,
               seconds: float, device: torch.device, show_progress: bool) -> None:
    """Validate, record the epoch, keep the best weights (``--patience``) and write the checkpoint."""
    val_set = data.val_set
    val_accuracy = tusimple_accuracy(predict_lanes(run.model, val_set, device)) if val_set is not None else None
    run.history.append({"epoch": epoch + 1, "loss": float(np.mean(losses)) if losses else None,
                        "val_accuracy": val_accuracy, "seconds": round(seconds, 2),
                        **({"aam": hard_summary(hard)} if hard else {})})
    if show_progress:
        shown = "n/a" if val_accuracy is None else f"{100 * val_accuracy:.2f} %"
        print(f"epoch {epoch + 1}: loss {run.history[-1]['loss']:.4f}  val accuracy {shown}", flush=True)
    best = run.best
    if settings.patience is not None and val_accuracy is not None and (
            best is None or val_accuracy > run.history[best["epoch"] - 1]["val_accuracy"]):
        run.best = {"epoch": epoch + 1,
                    "model": {k: v.detach().cpu().clone() for k, v in run.model.state_dict().items()}}
    _save({"model": run.model.state_dict(), "optimizer": run.optimizer.state_dict(), "epoch": epoch,
           "history": run.history, "data_sha256": data.sha256, "spec": asdict(settings.spec), "best": run.best},
          settings.out / CHECKPOINT_FILE)


def train(settings: TrainSettings, show_progress: bool = True) -> dict[str, Any]:
    """Train, export and describe a model in ``settings.out``; returns the ``training.json`` content."""
    torch.manual_seed(settings.seed)
    torch.set_num_threads(settings.threads or os.cpu_count() or 1)
    device = pick_device(settings.device)
    data = _read_data(settings)
    settings.out.mkdir(parents=True, exist_ok=True)
    run = _start(settings, len(data.train_set), data.sha256, device)
    write_atomic(settings.out / CONFIG_FILE, settings.spec.to_json().encode("utf-8"))
    bank = aam_bank(settings, data.frames, data.sha256) if settings.augment == "aam" else []
    hard: list = []
    run.model.train()
    training_started = time.perf_counter()
    for epoch in range(run.start_epoch, settings.epochs):
        if _patience_spent(run.best, epoch, settings.patience, settings.min_epochs):
            break  # a resumed run that had already stopped
        if settings.time_limit is not None and time.perf_counter() - training_started > settings.time_limit:
            if show_progress:
                print(f"--time-limit {settings.time_limit:g} s reached: no epoch {epoch + 1}", flush=True)
            break
        if bank and epoch >= 1:  # the model's attention means something after one epoch
            hard = _hard_examples(run, bank, settings, device)
        started = time.perf_counter()
        losses = _train_epoch(run, data.train_set, hard, settings, epoch, device, show_progress)
        _end_epoch(run, data, settings, epoch, losses, hard, time.perf_counter() - started, device, show_progress)
        if _patience_spent(run.best, epoch + 1, settings.patience, settings.min_epochs):
            if show_progress:
                print(f"no gain for {settings.patience} epochs: keeping the best epoch", flush=True)
            break
    return _finish(run, data, settings, device)


def _finish(run: _Run, data: _TrainData, settings: TrainSettings, device: torch.device) -> dict[str, Any]:
    """The kept weights (the best epoch's with ``--patience``) written in half precision and as ONNX, and
    ``training.json``; returns its content."""
    if run.best is not None:
        run.model.load_state_dict(run.best["model"])
    model = run.model.cpu().eval()
    _save({k: (v.half() if v.is_floating_point() else v) for k, v in model.state_dict().items()},
          settings.out / WEIGHTS_FILE)
    export_onnx(model, settings.out / ONNX_FILE)
    summary = _summary(run, data, settings, device)
    write_atomic(settings.out / TRAINING_FILE, (json.dumps(summary, indent=2) + "\n").encode("utf-8"))
    return summary


def _summary(run: _Run, data: _TrainData, settings: TrainSettings, device: torch.device) -> dict[str, Any]:
    """The content of ``training.json``: the data, the settings, the time and every epoch."""
    history, best = run.history, run.best
    seconds = [h["seconds"] for h in history]
    return {
        "spec": asdict(settings.spec),
        "data": "+".join(folder.name for folder in settings.data),
        "data_sha256": data.sha256,
        "train_frames": len(data.train_set),
        "val_frames": 0 if data.val_set is None else len(data.val_set),
        "epochs": settings.epochs,
        "batch": settings.batch,
        "lr": settings.lr,
        "augment": settings.augment,
        **({"aam_settings": asdict(settings.aam)} if settings.augment == "aam" else {}),
        "affine": settings.affine,
        "randomise": settings.randomise,
        "photometric": settings.photometric,
        "backbone_weights": None if settings.backbone_weights is None else settings.backbone_weights.name,
        "val_data": [folder.name for folder in settings.val_data],
        "time_limit": settings.time_limit,
        "seed": settings.seed,
        "device": device.type,
        "threads": torch.get_num_threads(),
        "init": None if settings.init is None else settings.init.name,
        "seconds": round(float(sum(seconds)), 1),
        "seconds_per_epoch": round(float(np.median(seconds)), 1) if seconds else None,
        "val_accuracy": (history[best["epoch"] - 1]["val_accuracy"] if best is not None
                         else history[-1]["val_accuracy"] if history else None),
        "patience": settings.patience,
        "min_epochs": settings.min_epochs,
        "epochs_run": len(history),
        "kept_epoch": best["epoch"] if best is not None else len(history),
        "history": history,
        "torch": torch.__version__,
    }
