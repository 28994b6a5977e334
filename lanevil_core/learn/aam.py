"""Attention Area Mixing (AAM) with hard examples: the defence of the LanEvil paper, built on the renderer.

1. **Bank.** Training variations of the clean cases (``dataset.plan.train_variation`` under a seed of their own,
   so never a test case; checked by case hash) each get one illusion of a type taken in turn, at severity 3-5 with
   a fresh seed. Each is rendered with and without the illusion; the *patch* is the perturbed frame restricted to
   the illusion's own pixels: the pixels of its meshes (object ids) and every pixel whose luminance it changes by
   more than ``illusion_effect.CHANGED_LEVEL`` (its shadows, streaks, surface layers), less the bank frame's own
   lane markings (found by a third render with the paint removed from the world): a mixed patch never carries
   another frame's lanes into an image whose labels do not have them. The mask is softened by a small blur.
2. **Hard examples.** Before every epoch after the first, the current model scores the bank (TuSimple accuracy of
   each frame against its labels); the ``hard_share`` lowest-scoring patches of each illusion type are the ones
   mixed in that epoch.
3. **High-attention areas.** In the same pass the model's attention on each bank frame is compared with the
   frame's ground truth, as the paper's HAA extraction does (blur ``mismatch_blur_px``, threshold
   ``mismatch_threshold``): the *mismatches* are where the model looks but no lane is (a seam, a streak or a
   shadow edge it follows) and the lanes it no longer sees. Grown by ``mismatch_grow_px`` and restricted to the
   illusion's pixels, they are the patch's high-attention area ``H``: exactly the part of the illusion that still
   misleads the current model.
4. **Mixing.** For a training image ``x`` (a share ``probability`` of each batch) the model's own attention ``A``
   (its lane probability, 1 - background, of the lane-mask head: the segmentation output of ``seg``, the
   auxiliary head of ``ufld``; widened to the area around the lanes by ``attention_spread_px`` and normalised to
   0..1 per image) is computed on ``x``, and a random hard patch ``(h, M, H)`` is blended where the model looks
   and where it was misled: ``W = max(A * M, H)``, ``x' = x * (1 - W) + h * W``. Labels stay those of ``x``:
   illusions never move the lanes, and only masked pixels change (``H`` lies inside ``M``). With
   ``mismatch_threshold = None`` the high-attention areas are left out (``W = A * M``). With ``relight`` the
   mixed-in pixels are ``h`` only where the illusion's meshes are and elsewhere ``x`` relit by the illusion,
   ``x * g`` with ``g`` the perturbed over the clean bank render, so the illusion falls on this image's own road.
   With ``keep_paint`` the image's own lane markings (its lane-mask target, grown by a pixel) are left out of ``W``:
   the illusion lies around the lines but never erases the paint the labels describe.

Attention maps are taken with batch norm on its running statistics (``models.running_statistics``), so these
extra forward passes do not count as training data.
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
from ..dataset.plan import train_variation
from ..illusions import REGISTRY
from ..labels.lanes import h_samples_for, tusimple_record
from ..pipeline.compile import compile_scene
from ..pipeline.illusion_effect import CHANGED_LEVEL, lane_band, luminance, with_illusion
from ..render import render_frame
from ..world.scene import FIRST_OBJECT_ID, ID_ROAD
from .data import resized, targets_for
from .models import LaneNet, running_statistics

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
    mismatch_threshold: float | None = 0.3  # T: blurred attention above it is the model's focus; None = no HAA
    mismatch_blur_px: float = 1.5  # sigma of the Gaussian blur of the attention before the threshold
    mismatch_grow_px: int = 3  # the mismatch regions grown by this radius (input pixels)
    lane_band_px: int = 2  # half width of a ground-truth lane at the input size
    relight: bool = False  # mix the illusion's light change into the image's own road instead of its pixels
    keep_paint: bool = False  # leave the image's own lane markings (its lane-mask target) unmixed


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
    haa: np.ndarray | None = None  # (H, W) float32 0..1: the high-attention area of the last scoring, inside mask
    gain: np.ndarray | None = None  # (H, W, 3) float32: perturbed / clean radiance, the illusion's light change
    objects: np.ndarray | None = None  # (H, W) float32 0..1: the illusion's own meshes (pasted, not relit)


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
                  illusion_ids: np.ndarray, unpainted_rgb: np.ndarray | None = None,
                  road_only: bool = False) -> np.ndarray:
    """(H, W) bool: the illusion's meshes plus every pixel whose luminance it changes visibly (with ``road_only``,
    only on the carriageway: not the sky, roadside or buildings a moved sun relights); with the frame rendered
    without lane paint (``unpainted_rgb``), those changed pixels less the frame's own markings and a pixel around
    them."""
    changed = np.abs(luminance(perturbed_rgb) - luminance(clean_rgb)) > CHANGED_LEVEL
    if road_only:
        changed &= object_id == ID_ROAD
    if unpainted_rgb is not None:
        paint = (np.abs(luminance(clean_rgb) - luminance(unpainted_rgb)) > CHANGED_LEVEL).astype(np.uint8)
        changed &= ~cv2.dilate(paint, np.ones((3, 3), np.uint8)).astype(bool)
    return changed | np.isin(object_id, illusion_ids)


GAIN_OFFSET = 8.0  # grey levels added to both renders before their ratio (keeps dark pixels' gains bounded)
MAX_GAIN = 6.0


def light_gain(clean_rgb: np.ndarray, perturbed_rgb: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32: how the illusion scales each pixel's colour (perturbed over clean, per channel): a
    shadow's darkening, a reflection's glare, a crack's or a seam's albedo, transferable to another image's road
    without carrying that frame's own content."""
    ratio = (perturbed_rgb.astype(np.float32) + GAIN_OFFSET) / (clean_rgb.astype(np.float32) + GAIN_OFFSET)
    return np.clip(ratio, 0.0, MAX_GAIN).astype(np.float32)


def render_patches(case: Case, input_size: tuple[int, int], relight: bool = False) -> list[HardPatch]:
    """The bank frames of one bank case (its ``BANK_FRAMES``), at the network's input size; with ``relight``
    their light change and meshes too, and masks on the carriageway only."""
    clean_case = with_illusion(case, {"type": case.illusions[0].type, "severity": 1}).model_copy(
        update={"illusions": []})
    unpainted_case = clean_case.model_copy(update={"road": clean_case.road.model_copy(update={"paint": False})})
    scene, clean_scene, unpainted_scene = compile_scene(case), compile_scene(clean_case), compile_scene(unpainted_case)
    illusion_ids = np.array([FIRST_OBJECT_ID + i for i, mesh in enumerate(scene.meshes) if mesh.source >= 0])
    rows = h_samples_for(BANK_RENDER_SIZE[1])
    sha = hashlib.sha256(case_json(case).encode("utf-8")).hexdigest()
    patches = []
    for frame_index in BANK_FRAMES:
        frame = render_frame(scene, frame_index, BANK_RENDER_SIZE)
        clean = render_frame(clean_scene, frame_index, BANK_RENDER_SIZE)
        unpainted = render_frame(unpainted_scene, frame_index, BANK_RENDER_SIZE).rgb
        mask = illusion_mask(clean.rgb, frame.rgb, frame.object_id, illusion_ids, unpainted,
                             road_only=relight).astype(np.float32)
        if mask.mean() < 0.002:  # the illusion is not in this frame
            continue
        record = tusimple_record(clean_scene, frame_index, clean, "", rows)
        small_mask = cv2.resize(mask, input_size, interpolation=cv2.INTER_AREA)
        image = resized(frame.rgb, input_size)
        patch = HardPatch(image, np.clip(small_mask, 0.0, 1.0), record, BANK_RENDER_SIZE, sha, case.illusions[0].type)
        if relight:
            objects = np.isin(frame.object_id, illusion_ids).astype(np.float32)
            patch.gain = light_gain(resized(clean.rgb, input_size), image)
            patch.objects = np.clip(cv2.resize(objects, input_size, interpolation=cv2.INTER_AREA), 0.0, 1.0)
        patches.append(patch)
    return patches


def build_bank(clean_cases: list[Path], input_size: tuple[int, int], seed: int,
               settings: AamSettings = AamSettings()) -> list[HardPatch]:
    """Every bank patch for the clean case files ``clean_cases`` (the bases of the train split)."""
    clean = [load_case(path) for path in clean_cases]
    patches = []
    for index in range(settings.bank_cases):
        patches += render_patches(bank_case(clean, seed, index), input_size, settings.relight)
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


def hard_summary(hard: list[HardPatch]) -> dict[str, float]:
    """What an epoch mixed: the hard patches' count, mean accuracy and the share of their illusion pixels that is
    high-attention area (``training.json`` records it per epoch)."""
    mask = sum(float(p.mask.sum()) for p in hard)
    area = sum(float(p.haa.sum()) for p in hard if p.haa is not None)
    return {"hard_patches": len(hard), "hard_accuracy": round(float(np.mean([p.accuracy for p in hard])), 4),
            "attention_area_share": round(area / mask, 4) if mask > 0 else 0.0}


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


def paint_area(lane_masks: torch.Tensor, size: tuple[int, int], grow_px: int = 1) -> torch.Tensor:
    """(N, H, W) float 0/1 at the input ``size``: the images' lanes from their lane-mask targets ((N, h, w) slot
    ids, 0 = background, at the mask stride), grown by ``grow_px`` input pixels: where an image's paint is."""
    lanes = (lane_masks > 0).float()[:, None]
    lanes = F.interpolate(lanes, size=(size[1], size[0]), mode="nearest")
    if grow_px > 0:
        lanes = F.max_pool2d(lanes, 2 * grow_px + 1, stride=1, padding=grow_px)
    return lanes[:, 0]


def mix(images: torch.Tensor, attention_map: torch.Tensor, patches: torch.Tensor,
        masks: torch.Tensor, areas: torch.Tensor | None = None, gains: torch.Tensor | None = None,
        objects: torch.Tensor | None = None, keep: torch.Tensor | None = None) -> torch.Tensor:
    """``x * (1 - W) + t * W`` with ``W = max(A * M, H)`` for images (N, 3, H, W), attention (N, H, W), patches
    (N, 3, H, W), masks (N, H, W) and high-attention areas (N, H, W; none: ``W = A * M``), all in 0..1.

    The mixed-in ``t`` is the patch itself, or with ``gains`` (N, 3, H, W) and ``objects`` (N, H, W) the patch
    where the illusion's meshes are and elsewhere the image relit by the illusion (``x * gain``): a shadow or a
    streak then falls on this image's own paint instead of replacing it with another frame's road. ``keep``
    (N, H, W) 0..1 is left unmixed (``W * (1 - keep)``: the image's own paint, ``paint_area``)."""
    weight = attention_map * masks
    if areas is not None:
        weight = torch.maximum(weight, areas)
    if keep is not None:
        weight = weight * (1.0 - keep)
    weight = weight[:, None]
    target = patches
    if gains is not None and objects is not None:
        occluded = objects[:, None]
        target = patches * occluded + (images * gains).clamp(0.0, 1.0) * (1.0 - occluded)
    return images * (1.0 - weight) + target * weight


@dataclass(frozen=True)
class PatchBatch:
    """Bank patches as tensors: images (N, 3, H, W) 0..1, masks, areas, objects (N, H, W), gains (N, 3, H, W)."""

    images: torch.Tensor
    masks: torch.Tensor
    areas: torch.Tensor
    gains: torch.Tensor
    objects: torch.Tensor


def image_tensor(chosen: list[HardPatch]) -> torch.Tensor:
    """(N, 3, H, W) float 0..1 of the bank patches' images."""
    return torch.from_numpy(np.stack([p.image for p in chosen]).transpose(0, 3, 1, 2).astype(np.float32) / 255.0)


def patch_tensors(chosen: list[HardPatch]) -> PatchBatch:
    """The tensors of bank patches (zero areas where a patch has none; a patch without gains is pasted whole)."""
    def stacked(arrays: list[np.ndarray]) -> torch.Tensor:
        return torch.from_numpy(np.ascontiguousarray(np.stack(arrays), dtype=np.float32))

    return PatchBatch(
        images=image_tensor(chosen),
        masks=stacked([p.mask for p in chosen]),
        areas=stacked([p.haa if p.haa is not None else np.zeros_like(p.mask) for p in chosen]),
        gains=stacked([p.gain if p.gain is not None else np.ones_like(p.image, np.float32)
                       for p in chosen]).permute(0, 3, 1, 2),
        objects=stacked([p.objects if p.objects is not None else np.ones_like(p.mask) for p in chosen]),
    )


def lane_attention(model: LaneNet, images: torch.Tensor, spread_px: int = 0) -> torch.Tensor:
    """(N, H, W) ``attention`` of ``model`` on ``images`` ((N, 3, H, W) 0..1, the model's device), on the model's
    lane-mask head (training mode keeps ``ufld``'s auxiliary head) with batch norm on its running statistics."""
    with torch.no_grad(), running_statistics(model):
        out = model(images)
    return attention(out, model.spec.input_size, spread_px)


def mismatch_area(attention_map: np.ndarray, lanes: np.ndarray, settings: AamSettings) -> np.ndarray:
    """(H, W) bool: where the model's focus (``attention_map`` (H, W) 0..1, blurred, above the threshold) and the
    ground-truth lanes (``lanes`` (H, W) bool) disagree: focus away from every lane, or a lane without focus;
    grown by ``mismatch_grow_px``."""
    assert settings.mismatch_threshold is not None
    blurred = cv2.GaussianBlur(attention_map.astype(np.float32), (0, 0), settings.mismatch_blur_px)
    focus: np.ndarray = blurred > settings.mismatch_threshold
    grow = 2 * settings.mismatch_grow_px + 1
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (grow, grow))
    near_lanes: np.ndarray = cv2.dilate(lanes.astype(np.uint8), kernel).astype(bool)
    wrong = (focus & ~near_lanes) | (lanes & ~focus)
    return cv2.dilate(wrong.astype(np.uint8), kernel).astype(bool)


def patch_lanes(patch: HardPatch, size: tuple[int, int], radius: int) -> np.ndarray:
    """(H, W) bool at ``size``: the ground-truth lanes of a bank frame, ``radius`` px each side."""
    sx, sy = size[0] / patch.frame_size[0], size[1] / patch.frame_size[1]
    lanes = [[round(x * sx) if x >= 0 else -2 for x in lane] for lane in patch.record["lanes"]]
    return lane_band(lanes, [round(h * sy) for h in patch.record["h_samples"]], size, radius)


def update_attention_areas(model: LaneNet, bank: list[HardPatch], settings: AamSettings, batch: int = 32) -> None:
    """Set every bank patch's high-attention area ``haa`` from the current model's attention on it."""
    if settings.mismatch_threshold is None:
        return
    device = next(model.parameters()).device
    size = model.spec.input_size
    for start in range(0, len(bank), batch):
        chunk = bank[start:start + batch]
        maps = lane_attention(model, image_tensor(chunk).to(device)).cpu().numpy()
        for patch, attention_map in zip(chunk, maps, strict=True):
            area = mismatch_area(attention_map, patch_lanes(patch, size, settings.lane_band_px), settings)
            patch.haa = (patch.mask * area).astype(np.float32)


def patch_targets(patch: HardPatch, spec: Any) -> Any:
    """Training targets of a bank frame (to score it)."""
    return targets_for(patch.record, patch.frame_size, spec, flip=False)
