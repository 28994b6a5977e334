"""Training losses of the two detector families.

``ufld`` (as in Ultra Fast Lane Detection): cross-entropy over the ``grid + 1`` classes of every (slot, anchor);
a similarity loss (L1 between the cell distributions of adjacent anchors: lanes are continuous); a shape loss
(L1 of the second difference of the expected column along three adjacent anchors: lanes are smooth); and the
auxiliary lane-mask cross-entropy. ``seg``: lane-mask cross-entropy (background down-weighted, as in SCNN) and
binary cross-entropy of slot existence.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
import torch.nn.functional as F

BACKGROUND_WEIGHT = 0.4


@dataclass(frozen=True)
class LossWeights:
    similarity: float = 0.5
    shape: float = 0.1
    aux_mask: float = 1.0
    existence: float = 0.1


def mask_loss(logits: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    weight = torch.ones(logits.shape[1], device=logits.device)
    weight[0] = BACKGROUND_WEIGHT
    return F.cross_entropy(logits, target, weight=weight)


def row_anchor_losses(logits: torch.Tensor, target: torch.Tensor) -> dict[str, torch.Tensor]:
    """``logits`` (N, slots, anchors, grid + 1), ``target`` (N, slots, anchors) -> named loss terms."""
    grid = logits.shape[-1] - 1
    classification = F.cross_entropy(logits.reshape(-1, grid + 1), target.reshape(-1))
    cells = torch.softmax(logits[..., :grid], dim=-1)
    present = (target < grid).float()
    both = present[:, :, 1:] * present[:, :, :-1]
    similarity = ((cells[:, :, 1:] - cells[:, :, :-1]).abs().sum(-1) * both).sum() / both.sum().clamp(min=1)
    position = cells @ torch.arange(grid, dtype=cells.dtype, device=cells.device)  # expected cell per anchor
    three = present[:, :, 2:] * both[:, :, :-1]
    curvature = (position[:, :, 2:] - 2 * position[:, :, 1:-1] + position[:, :, :-2]).abs()
    shape = (curvature * three).sum() / three.sum().clamp(min=1) / grid
    return {"cls": classification, "sim": similarity, "shape": shape}


def detector_loss(family: str, out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
                  weights: LossWeights = LossWeights()) -> tuple[torch.Tensor, dict[str, float]]:
    """The total loss and its named terms (as floats, for the progress bar)."""
    if family == "ufld":
        terms = row_anchor_losses(out["row_logits"], batch["rows"])
        total = terms["cls"] + weights.similarity * terms["sim"] + weights.shape * terms["shape"]
        if "mask_logits" in out:
            terms["aux"] = mask_loss(out["mask_logits"], batch["mask"])
            total = total + weights.aux_mask * terms["aux"]
    else:
        terms = {"mask": mask_loss(out["mask_logits"], batch["mask"]),
                 "exist": F.binary_cross_entropy_with_logits(out["exist_logits"], batch["exist"])}
        total = terms["mask"] + weights.existence * terms["exist"]
    return total, {name: float(value.detach()) for name, value in terms.items()}
