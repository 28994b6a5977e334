"""Attention Area Mixing (AAM) with hard examples: the defence of the LanEvil paper, built on the renderer.

1. **Bank.** Training variations of the clean cases (``dataset.plan.train_variation`` under a seed of their own,
   so never a test case; checked by case hash) each get one illusion of a type taken in turn, at severity 3-5 with
   a fresh seed. Each is rendered with and without the illusion; the *patch* is the perturbed frame restricted to
   the illusion's own pixels: the pixels of its meshes (object ids) and every pixel whose luminance it changes by
   more than ``illusion_effect.CHANGED_LEVEL`` (its shadows, streaks, surface layers), softened by a small blur.
2. **Hard examples.** Before every epoch after the first, the current model scores the bank (TuSimple accuracy of
   each frame against its labels); the ``hard_share`` lowest-scoring patches of each illusion type are the ones
   mixed in that epoch.
3. **Mixing.** For a training image ``x`` (a share ``probability`` of each batch) the model's own attention ``A``
   (its lane probability, 1 - background, of the lane-mask head: the segmentation output of ``seg``, the
   auxiliary head of ``ufld``; widened to the area around the lanes by ``attention_spread_px`` and normalised to
   0..1 per image) is computed on ``x``, and a random hard patch
   ``(h, M)`` is blended where the model looks: ``x' = x * (1 - A * M) + h * A * M``. Labels stay those of ``x``:
   illusions never move the lanes, and only masked pixels change.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import torch
import torch.nn.functional as F

from ..case import Case, case_json, load_case
from ..compile import compile_scene
from ..dataset.plan import train_variation
from ..illusion_effect import CHANGED_LEVEL, luminance, with_illusion
from ..illusions import REGISTRY
from ..labels import h_samples_for, tusimple_record
from ..render import render_frame
from ..scene import FIRST_OBJECT_ID
from .data import resized, targets_for

BANK_SEED_OFFSET = 1_000_003  # bank variations draw from a seed space of their own
BANK_RENDER_SIZE = (640, 360)
BANK_FRAMES = (0, 8)  # the illusion stands 15-22 m ahead: in view and near


@dataclass(frozen=True)
class AamSettings:
    """Parameters of AAM (see the module docstring)."""

    bank_cases: int = 84  # bank variations (six per illusion type)
    hard_share: float = 0.35  # share of the bank kept as hard examples each epoch
    probability: float = 0.5  # share of training images mixed
    mask_blur_px: float = 1.0  # softening of the patch mask at the network's input size
    attention_spread_px: int = 0  # widen the lanes' attention to the area around them (box radius px, 2 passes)


@dataclass
class HardPatch:
    """One bank frame at the network's input size: image (H, W, 3) uint8, mask (H, W) float32 0..1, its TuSimple
    record (labels), the source case's sha256, the illusion type and the current model's accuracy on it."""

    image: np.ndarray
    mask: np.ndarray
    record: dict[str, Any]
    frame_size: tuple[int, int]
    case_sha256: str
    illusion_type: str
    accuracy: float = 1.0


def bank_case(clean: list[Case], seed: int, index: int) -> Case:
    """Bank variation ``index``: a train variation of a clean case with one illusion of the ``index``-th type."""
    base = clean[index % len(clean)]
    case, _ = train_variation(base, seed + BANK_SEED_OFFSET, index)
    rng = np.random.default_rng([seed, BANK_SEED_OFFSET, index])
    types = sorted(REGISTRY)
    illusion = {"type": types[index % len(types)], "severity": int(rng.integers(3, 6)),
                "seed": int(rng.integers(0, 2**31))}
    return with_illusion(case, illusion)


def illusion_mask(clean_rgb: np.ndarray, perturbed_rgb: np.ndarray, object_id: np.ndarray,
                  illusion_ids: np.ndarray) -> np.ndarray:
    """(H, W) bool: the illusion's meshes plus every pixel whose luminance it changes visibly."""
    changed = np.abs(luminance(perturbed_rgb) - luminance(clean_rgb)) > CHANGED_LEVEL
    return changed | np.isin(object_id, illusion_ids)


def render_patches(case: Case, input_size: tuple[int, int]) -> list[HardPatch]:
    """The bank frames of one bank case (its ``BANK_FRAMES``), at the network's input size."""
    clean_case = with_illusion(case, {"type": case.illusions[0].type, "severity": 1}).model_copy(
        update={"illusions": []})
    scene, clean_scene = compile_scene(case), compile_scene(clean_case)
    illusion_ids = np.array([FIRST_OBJECT_ID + i for i, mesh in enumerate(scene.meshes) if mesh.source >= 0])
    rows = h_samples_for(BANK_RENDER_SIZE[1])
    sha = hashlib.sha256(case_json(case).encode("utf-8")).hexdigest()
    patches = []
    for frame_index in BANK_FRAMES:
        frame = render_frame(scene, frame_index, BANK_RENDER_SIZE)
        clean = render_frame(clean_scene, frame_index, BANK_RENDER_SIZE)
        mask = illusion_mask(clean.rgb, frame.rgb, frame.object_id, illusion_ids).astype(np.float32)
        if mask.mean() < 0.002:  # the illusion is not in this frame
            continue
        record = tusimple_record(clean_scene, frame_index, clean, "", rows)
        small_mask = cv2.resize(mask, input_size, interpolation=cv2.INTER_AREA)
        patches.append(HardPatch(resized(frame.rgb, input_size), np.clip(small_mask, 0.0, 1.0), record,
                                 BANK_RENDER_SIZE, sha, case.illusions[0].type))
    return patches


def build_bank(clean_cases: list[Path], input_size: tuple[int, int], seed: int,
               settings: AamSettings = AamSettings()) -> list[HardPatch]:
    """Every bank patch for the clean case files ``clean_cases`` (the bases of the train split)."""
    clean = [load_case(path) for path in clean_cases]
    patches = []
    for index in range(settings.bank_cases):
        patches += render_patches(bank_case(clean, seed, index), input_size)
    blur = settings.mask_blur_px
    for patch in patches:
        if blur > 0:
            patch.mask = cv2.GaussianBlur(patch.mask, (0, 0), blur)
    return patches


def hard_patches(patches: list[HardPatch], share: float) -> list[HardPatch]:
    """The ``share`` of each illusion type's bank patches with the lowest accuracy (at least one per type; ties in
    bank order), in bank order.

    Taken per type, not over the whole bank: a bank-wide cut keeps every patch of the types that fool the model
    most (all the night-time street-light reflections) and almost none of the others, so the model would train
    against a few illusions only.
    """
    chosen: set[int] = set()
    for illusion_type in sorted({p.illusion_type for p in patches}):
        members = [i for i, p in enumerate(patches) if p.illusion_type == illusion_type]
        keep = max(1, int(round(len(members) * share)))
        chosen.update(sorted(members, key=lambda i: (patches[i].accuracy, i))[:keep])
    return [patches[i] for i in sorted(chosen)]


def attention(out: dict[str, torch.Tensor], size: tuple[int, int], spread_px: int = 0) -> torch.Tensor:
    """(N, H, W) the model's lane attention at the input size: 1 - background probability of its lane-mask
    head, widened by two box blurs of radius ``spread_px`` (the *area* the model attends to: the lines and the
    road beside them, where a distractor competes with them), normalised to 0..1 per image."""
    lanes = 1.0 - torch.softmax(out["mask_logits"].detach(), dim=1)[:, 0]
    lanes = F.interpolate(lanes[:, None], size=(size[1], size[0]), mode="bilinear", align_corners=False)
    for _ in range(2 if spread_px > 0 else 0):
        lanes = F.avg_pool2d(lanes, 2 * spread_px + 1, stride=1, padding=spread_px, count_include_pad=False)
    lanes = lanes[:, 0]
    peak = lanes.flatten(1).max(dim=1).values.clamp(min=1e-6)
    return lanes / peak[:, None, None]


def mix(images: torch.Tensor, attention_map: torch.Tensor, patches: torch.Tensor,
        masks: torch.Tensor) -> torch.Tensor:
    """``x * (1 - A * M) + h * A * M`` for images (N, 3, H, W), attention (N, H, W), patches (N, 3, H, W) and
    masks (N, H, W), all in 0..1."""
    weight = (attention_map * masks)[:, None]
    return images * (1.0 - weight) + patches * weight


def patch_tensors(chosen: list[HardPatch]) -> tuple[torch.Tensor, torch.Tensor]:
    """(N, 3, H, W) float 0..1 images and (N, H, W) masks of bank patches."""
    images = torch.from_numpy(np.stack([p.image for p in chosen]).transpose(0, 3, 1, 2).astype(np.float32) / 255.0)
    return images, torch.from_numpy(np.stack([p.mask for p in chosen]))


def patch_targets(patch: HardPatch, spec: Any) -> Any:
    """Training targets of a bank frame (to score it)."""
    return targets_for(patch.record, patch.frame_size, spec, flip=False)
