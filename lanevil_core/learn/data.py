"""Training data: frames with TuSimple labels as network inputs and targets (``torch.utils.data.Dataset``).

Two sources give the same samples:
- ``LabelledFrames``: a split folder written by ``lanevil dataset`` (its ``*_label.json`` and images), read once
  and kept in memory at the network's input size.
- ``RenderedFrames``: case files rendered on the fly (no images on disk) through the renderer and the very
  labels code the dataset writer uses (``labels.tusimple_record``).

A sample's targets come from ``detect.lane_slots``: lanes placed in slots, row-anchor classes and a lane mask.
A horizontal flip (half the training samples) mirrors image and slots; ``--augment`` adds one of ``augment``;
``--affine`` rotates and shifts every training sample (``affine``); ``--randomise`` and ``--photometric`` add the
domain randomisation of ``randomise`` (from their own draws, so a run without them draws as before).
"""

from __future__ import annotations

import hashlib
import json
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import torch
from torch.utils.data import Dataset

from ..detect.bezier_curves import encode_curves
from ..detect.lane_keypoints import encode_keypoints, keypoint_map_size
from ..detect.lane_slots import (
    LaneLine,
    assign_slots,
    encode_lane_mask,
    encode_row_anchors,
    lane_lines,
    mirror_slots,
)
from ..detect.learned import network_input
from ..detect.line_anchors import encode_anchors, line_anchors
from ..detect.model_spec import ModelSpec
from ..detect.split import read_rgb
from ..metrics.formats import split_labels
from ..typed import UInt8Array
from .affine import draw_affine, ego_column, warp_image, warp_lines
from .augment import AUGMENT_PROBABILITY, Augment
from .randomise import paint_mask, photometric, randomise


@dataclass(frozen=True)
class Targets:
    """What a network learns from one frame: row-anchor classes ``(slots, anchors)``, lane mask ``(h, w)`` uint8, slot
    existence ``(slots,)`` and the family's own targets by batch key (``FAMILY_TARGETS``)."""

    rows: np.ndarray
    mask: np.ndarray
    exist: np.ndarray
    extra: dict[str, np.ndarray] = field(default_factory=dict)


def _anchor_targets(placed: list[LaneLine | None], spec: ModelSpec) -> dict[str, np.ndarray]:
    width, height = spec.input_size
    targets = encode_anchors(placed, line_anchors(), spec.anchor_rows, width / height)
    return {"anchor_labels": targets.labels, "anchor_regs": targets.regression, "anchor_rows": targets.row_mask}


def _curve_targets(placed: list[LaneLine | None], spec: ModelSpec) -> dict[str, np.ndarray]:
    control, valid = encode_curves(placed)
    return {"curves": control, "curve_valid": valid}


def _keypoint_targets(placed: list[LaneLine | None], spec: ModelSpec) -> dict[str, np.ndarray]:
    heat, offsets = encode_keypoints(placed, keypoint_map_size(spec.input_size))
    return {"heat": heat, "keypoint_offsets": offsets}


FAMILY_TARGETS = {"laneatt": _anchor_targets, "bezier": _curve_targets, "ganet": _keypoint_targets}


def targets_for(record: dict[str, Any], frame_size: tuple[int, int], spec: ModelSpec, flip: bool,
                M_out_in: np.ndarray | None = None) -> Targets:
    """The targets of a TuSimple record of a frame of ``frame_size`` (width, height); ``M_out_in`` is the
    ``affine.draw_affine`` map the image went through (before the flip), in pixels of the input size."""
    lines = lane_lines(record["lanes"], record["h_samples"], frame_size)
    camera_x = 0.5
    if M_out_in is not None:  # the lanes keep their places beside the ego, which moved with the image
        lines = warp_lines(lines, M_out_in, spec.input_size)
        camera_x = ego_column(M_out_in, spec.input_size)
    placed = assign_slots(lines, spec.slots, camera_x)
    if flip:
        placed = mirror_slots(placed)
    extra = FAMILY_TARGETS[spec.family](placed, spec) if spec.family in FAMILY_TARGETS else {}
    # the mask kept as uint8 (slot + 1 <= 255): the targets of a 40,000-frame split are cached per frame and side,
    # and at int64 its 160x90 masks alone would take 8 GB
    return Targets(encode_row_anchors(placed, spec.anchor_rows, spec.grid),
                   encode_lane_mask(placed, spec.mask_size).astype(np.uint8),
                   np.array([line is not None for line in placed], np.float32), extra)


def resized(rgb: UInt8Array, input_size: tuple[int, int]) -> UInt8Array:
    """(H, W, 3) uint8 at the network's input size (area filter, as at inference)."""
    width, height = input_size
    if rgb.shape[:2] == (height, width):
        return rgb
    return np.asarray(cv2.resize(rgb, (width, height), interpolation=cv2.INTER_AREA), np.uint8)


class _Frames(Dataset):
    """Shared sample assembly over ``images`` ((N, H, W, 3) uint8 at the input size), their TuSimple ``records``
    and the ``frame_sizes`` the records refer to, which the subclasses fill."""

    def __init__(self, spec: ModelSpec, train: bool, augment: Augment | None, seed: int,
                 affine: bool = False, randomised: bool = False, photometric: bool = False) -> None:
        self.spec = spec
        self.train = train
        self.augment = augment
        self.affine = affine
        self.randomised = randomised
        self.photometric = photometric
        self.seed = seed
        self.epoch = 0
        self.records: list[dict[str, Any]] = []
        self.frame_sizes: list[tuple[int, int]] = []
        width, height = spec.input_size
        self.images: UInt8Array = np.zeros((0, height, width, 3), np.uint8)
        # (index, flipped) -> targets: without --affine a frame's targets are one of two, so each is encoded once
        self._targets: dict[tuple[int, bool], Targets] = {}

    def targets(self, index: int, flip: bool, M_out_in: np.ndarray | None) -> Targets:
        """The targets of frame ``index`` as drawn (encoding them is most of a sample's time)."""
        if M_out_in is not None:
            return targets_for(self.records[index], self.frame_sizes[index], self.spec, flip, M_out_in)
        key = (index, flip)
        if key not in self._targets:
            self._targets[key] = targets_for(self.records[index], self.frame_sizes[index], self.spec, flip)
        return self._targets[key]

    def image(self, index: int) -> UInt8Array:
        return self.images[index]

    def __len__(self) -> int:
        return len(self.records)

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        image = self.image(index)
        flip = False
        M_out_in = None
        if self.train:  # per (seed, epoch, index): the same run draws the same augmentations, also on resume
            rng = np.random.default_rng([self.seed, self.epoch, index])
            flip = bool(rng.random() < 0.5)
            domain_rng = np.random.default_rng([self.seed, self.epoch, index, 11])
            if self.randomised:
                record = self.records[index]
                lines = lane_lines(record["lanes"], record["h_samples"], self.frame_sizes[index])
                image = randomise(image, paint_mask(lines, self.spec.input_size), domain_rng)
            if self.augment is not None and rng.random() < AUGMENT_PROBABILITY:
                other = self.image(int(rng.integers(len(self))))
                image = self.augment(image, rng, other)
            if self.affine:  # drawn last, so the draws above are those of a run without it
                M_out_in = draw_affine(rng, self.spec.input_size)
                image = warp_image(image, M_out_in)
            if self.photometric:
                image = photometric(image, domain_rng)
            if flip:
                image = np.ascontiguousarray(image[:, ::-1])
        targets = self.targets(index, flip, M_out_in)
        return {"image": torch.from_numpy(network_input(image, self.spec.input_size)),
                "rows": torch.from_numpy(targets.rows), "mask": torch.from_numpy(targets.mask).long(),
                "exist": torch.from_numpy(targets.exist), "index": torch.tensor(index),
                **{key: torch.from_numpy(value) for key, value in targets.extra.items()}}


def read_records(label_file: Path) -> list[dict[str, Any]]:
    """The JSON records of a TuSimple label file."""
    return [json.loads(line) for line in label_file.read_text(encoding="utf-8").splitlines() if line.strip()]


def file_sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_splits(data_dirs: Sequence[Path]) -> tuple[list[tuple[Path, dict[str, Any]]], str]:
    """Every frame of the train splits of ``data_dirs`` (each a dataset folder with ``train/`` or a split folder)
    as (split folder, record) pairs in order, and the data's identity: the label file's sha256 for one split, the
    sha256 of the label files' hashes in order for several. ``ValueError`` names the folder without a usable split."""
    frames: list[tuple[Path, dict[str, Any]]] = []
    hashes = []
    for data in data_dirs:
        split_dir = data / "train" if (data / "train").is_dir() else data
        try:
            label_file = split_labels(split_dir)
        except ValueError as error:
            raise ValueError(f"--data {data}: {error}") from None
        records = read_records(label_file)
        if not records:
            raise ValueError(f"--data {data}: {label_file.name} has no frames")
        frames += [(split_dir, record) for record in records]
        hashes.append(file_sha256(label_file))
    identity = hashes[0] if len(hashes) == 1 else hashlib.sha256("\n".join(hashes).encode()).hexdigest()
    return frames, identity


class LabelledFrames(_Frames):
    """Frames of one or more split folders, held in memory: ``frames`` are (split folder, TuSimple record) pairs,
    as ``read_splits`` returns them, and ``indices`` the chosen ones (default all)."""

    def __init__(self, frames: Sequence[tuple[Path, dict[str, Any]]], spec: ModelSpec,
                 indices: list[int] | None = None, train: bool = True, augment: Augment | None = None,
                 seed: int = 0, affine: bool = False, randomised: bool = False, photometric: bool = False) -> None:
        super().__init__(spec, train, augment, seed, affine, randomised, photometric)
        chosen = [frames[i] for i in (range(len(frames)) if indices is None else indices)]
        self.records = [record for _, record in chosen]
        width, height = spec.input_size
        # filled in place: a 40,000-frame split at 320x180 is 6.9 GB, and a list stacked afterwards holds it twice
        self.images = np.empty((len(chosen), height, width, 3), np.uint8)
        for slot, (split_dir, record) in enumerate(chosen):
            rgb = read_rgb(split_dir / record["raw_file"])
            self.frame_sizes.append((rgb.shape[1], rgb.shape[0]))
            self.images[slot] = resized(rgb, spec.input_size)


class RenderedFrames(_Frames):
    """Frames rendered on the fly from case files: ``items`` are (case file, frame index) pairs, rendered at
    ``render_size`` and labelled by ``labels.tusimple_record``; the last few compiled scenes are kept."""

    def __init__(self, items: list[tuple[str | Path, int]], spec: ModelSpec, render_size: tuple[int, int] = (640, 360),
                 train: bool = True, augment: Augment | None = None, seed: int = 0, affine: bool = False) -> None:
        super().__init__(spec, train, augment, seed, affine)
        self.items = [(Path(path), int(frame)) for path, frame in items]
        self.render_size = render_size
        self._scenes: OrderedDict[Path, Any] = OrderedDict()
        rendered = [self._render(path, frame) for path, frame in self.items]
        self.records = [record for _, record in rendered]
        self.frame_sizes = [render_size] * len(self.items)
        if rendered:
            self.images = np.stack([image for image, _ in rendered])

    def _render(self, path: Path, frame_index: int) -> tuple[UInt8Array, dict[str, Any]]:
        from ..case import load_case
        from ..labels.lanes import tusimple_record
        from ..pipeline.compile import compile_scene
        from ..render import render_frame

        scene = self._scenes.pop(path, None) or compile_scene(load_case(path))
        self._scenes[path] = scene
        while len(self._scenes) > 2:
            self._scenes.popitem(last=False)
        frame = render_frame(scene, frame_index, self.render_size)
        record = tusimple_record(scene, frame_index, frame, raw_file=f"{path.name}#{frame_index}")
        return resized(frame.rgb, self.spec.input_size), record


def split_indices(count: int, groups: list[str], val_fraction: float, seed: int) -> tuple[list[int], list[int]]:
    """(train, val) record indices; whole groups (case folders) go to one side, drawn by ``seed``."""
    unique = sorted(set(groups))
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(unique))
    n_val = int(round(len(unique) * val_fraction)) if val_fraction > 0 else 0
    if val_fraction > 0 and len(unique) > 1:
        n_val = min(max(n_val, 1), len(unique) - 1)
    val_groups = {unique[i] for i in order[:n_val]}
    train = [i for i in range(count) if groups[i] not in val_groups]
    val = [i for i in range(count) if groups[i] in val_groups]
    return train, val
