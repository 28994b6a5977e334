"""How much an illusion changes what a lane detector looks at: the *lane band*.

The lane band of a frame is every pixel within ``radius`` of a ground-truth lane (the lanes of the clean
original, which illusions never move). What a lane detector follows there are edges: the paint against the
asphalt, and whatever an illusion lays beside or across it (a shadow's edge, a seam, a light streak, an occluder's
outline). So an illusion's *effect* on a frame is the mean absolute change of the band's *local contrast*, the
luminance minus its Gaussian blur over the band's width (0..255), between the original and the perturbed render of
the same frame. A change of the light over the whole scene (a lower sun) scales the local contrast a little but
does not add edges, so it does not swamp the illusion's own marks. Its *share* is the fraction of band pixels whose
luminance it changes by more than ``CHANGED_LEVEL``. Severity ladders are checked with the
effect (it must rise with the level); the dataset writer records the share per frame and picks test frames where
the illusion is in view.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from ..case import Case, parse_case
from ..labels.lanes import h_samples_for, tusimple_record
from ..render import render_frame
from ..typed import BoolArray, UInt8Array
from ..world.scene import CompiledScene
from .compile import compile_scene
from .frames import evenly_spaced

BAND_RADIUS_FRACTION = 1.0 / 64.0  # band half width as a share of the image width (20 px at 1280)
CHANGED_LEVEL = 12.0  # a band pixel changed by more than this (of 255) counts towards the share


@dataclass(frozen=True)
class BandChange:
    """Mean absolute change of the band (0..255) and the share of band pixels changed, for one frame."""

    effect: float
    share: float


def lane_band(lanes: Sequence[Sequence[int]], h_samples: Sequence[int], size: tuple[int, int],
              radius: int | None = None) -> BoolArray:
    """(H, W) bool: pixels within ``radius`` px of a lane (TuSimple lanes of an image of ``size``)."""
    width, height = size
    radius = radius if radius is not None else max(1, round(width * BAND_RADIUS_FRACTION))
    mask = np.zeros((height, width), np.uint8)
    for lane in lanes:
        points = [(x, y) for x, y in zip(lane, h_samples) if x >= 0]
        if len(points) >= 2:
            cv2.polylines(mask, [np.array(points, np.int32).reshape(-1, 1, 2)], False, 1, 2 * radius + 1)
    return mask.astype(bool)


def luminance(rgb: UInt8Array) -> np.ndarray:
    """(H, W) float32 Rec. 601 luma of sRGB bytes (0..255)."""
    return rgb.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)


def local_contrast(rgb: UInt8Array, sigma: float) -> np.ndarray:
    """(H, W) float32 luminance minus its Gaussian blur of ``sigma`` px: the image's edges and fine marks."""
    y = luminance(rgb)
    return y - cv2.GaussianBlur(y, (0, 0), sigma)


def band_change(original: UInt8Array, perturbed: UInt8Array, band: BoolArray) -> BandChange:
    """Effect and share of one frame pair on a band."""
    if not band.any():
        return BandChange(0.0, 0.0)
    sigma = max(1.0, original.shape[1] * BAND_RADIUS_FRACTION)
    edges = np.abs(local_contrast(perturbed, sigma) - local_contrast(original, sigma))[band]
    light = np.abs(luminance(perturbed) - luminance(original))[band]
    return BandChange(float(edges.mean()), float((light > CHANGED_LEVEL).mean()))


def with_illusion(case: Case, illusion: dict[str, Any]) -> Case:
    """The case with ``illusion`` (a case-file illusion dict) as its only illusion."""
    data = case.model_dump()
    data["illusions"] = [illusion]
    return parse_case(data)


def clean_of(case: Case) -> Case:
    """The case without its illusions (what an illusion's change is measured against), untitled: every level of a
    type folder has the same clean case, down to its text."""
    return case.model_copy(update={"illusions": [], "title": "", "description": ""})


SHARE_SIZE = (160, 90)  # renders that only locate an illusion are this small
IN_VIEW_SHARE = 0.05  # a frame shows the illusion when it changes at least this share of the lane band


def drive_changes(case: Case, step: int) -> tuple[list[int], list[BandChange]]:
    """Every ``step``-th frame of the drive and the illusion's band change on it (renders at ``SHARE_SIZE``)."""
    candidates = list(range(0, case.ego.frames, step))
    return candidates, frame_changes(clean_of(case), case, candidates, SHARE_SIZE)


def shown_share(case: Case, step: int = 5) -> float:
    """Share of the drive's frames (every ``step``-th tried) on which the illusion is in view: it changes at least
    ``IN_VIEW_SHARE`` of the lane band. A test case should show its illusion on most of its frames, since the
    benchmark scores every one."""
    _, changes = drive_changes(case, step)
    return sum(change.share >= IN_VIEW_SHARE for change in changes) / max(len(changes), 1)


def in_view_frames(case: Case, count: int, step: int = 2) -> tuple[int, ...]:
    """``count`` frames of the drive, evenly over those where the illusion changes at least ``IN_VIEW_SHARE``
    of the lane band (every ``step``-th frame tried at ``SHARE_SIZE``); the frames where it changes most when
    fewer show it; the evenly spaced frames of the whole drive when it never does."""
    candidates, changes = drive_changes(case, step)
    shown = [frame for frame, change in zip(candidates, changes, strict=True) if change.share >= IN_VIEW_SHARE]
    if not shown:
        return evenly_spaced(case.ego.frames, count)
    if len(shown) < count:  # a short sighting: the frames where it shows most
        ranked = sorted(zip(candidates, changes, strict=True), key=lambda fc: (-fc[1].share, fc[0]))
        return tuple(sorted(frame for frame, _ in ranked[:count]))
    return tuple(shown[i] for i in evenly_spaced(len(shown), count))


def frame_changes(original: Case, perturbed: Case, frames: Sequence[int],
                  size: tuple[int, int] = (320, 180)) -> list[BandChange]:
    """Band change of each frame between two renders of the same drive (the original's lanes as the band)."""
    return scene_changes(compile_scene(original), compile_scene(perturbed), frames, size)


CleanView = Callable[[CompiledScene, int, tuple[int, int]], tuple[UInt8Array, BoolArray]]


def clean_view(scene_original: CompiledScene, frame_index: int, size: tuple[int, int]) -> tuple[UInt8Array, BoolArray]:
    """The original's render of a frame and its lane band: what every perturbed version is compared with."""
    rows = h_samples_for(size[1])
    clean = render_frame(scene_original, frame_index, size)
    record = tusimple_record(scene_original, frame_index, clean, "", rows)
    return clean.rgb, lane_band(record["lanes"], rows, size)


def scene_changes(scene_original: CompiledScene, scene_perturbed: CompiledScene, frames: Sequence[int],
                  size: tuple[int, int] = (320, 180), original_view: CleanView = clean_view) -> list[BandChange]:
    """``frame_changes`` of two compiled scenes (a caller that has the perturbed scene compiled already; one that
    compares several perturbed scenes with the same original can pass a cached ``original_view``)."""
    changes = []
    for frame_index in frames:
        original, band = original_view(scene_original, frame_index, size)
        changes.append(band_change(original, render_frame(scene_perturbed, frame_index, size).rgb, band))
    return changes


def ladder(case: Case, illusion_type: str, frames: Sequence[int], size: tuple[int, int] = (320, 180),
           **fields: Any) -> list[float]:
    """Mean band effect of levels 1..5 of ``illusion_type`` added to a clean ``case`` over ``frames``."""
    effects = []
    for level in range(1, 6):
        perturbed = with_illusion(case, {"type": illusion_type, "severity": level, **fields})
        effects.append(float(np.mean([c.effect for c in frame_changes(case, perturbed, frames, size)])))
    return effects
