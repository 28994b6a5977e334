"""Training losses of the detector families.

``ufld`` (as in Ultra Fast Lane Detection): cross-entropy over the ``grid + 1`` classes of every (slot, anchor); a
similarity loss (L1 between the cell distributions of adjacent anchors: lanes are continuous); a shape loss (L1 of
the second difference of the expected column along three adjacent anchors: lanes are smooth); and the auxiliary
lane-mask cross-entropy. ``seg`` and ``scnn``: lane-mask cross-entropy (background down-weighted, as in SCNN) and
binary cross-entropy of slot existence. ``laneatt``: focal loss of the anchor scores (weighted 10x, as LaneATT
does), smooth L1 of the positive anchors' x offsets, bottom row and length. ``bezier``: query slots matched to the
lanes by the Hungarian method on sampled curve points (``scipy.optimize.linear_sum_assignment``), L1 of the matched
curves' sampled points and existence cross-entropy (matched queries weighted as the unmatched together). ``ganet``:
CenterNet's focal loss on the keypoint heatmap and L1 of the offsets at the keypoints. The last three add the
auxiliary lane-mask cross-entropy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F

from ..detect.bezier_curves import bernstein

BACKGROUND_WEIGHT = 0.4


@dataclass(frozen=True)
class LossWeights:
    similarity: float = 0.5
    shape: float = 0.1
    aux_mask: float = 1.0
    existence: float = 0.1
    anchor_score: float = 10.0  # laneatt's focal loss of the anchor scores (LaneATT's cls_loss_weight)
    regression: float = 10.0  # laneatt's smooth L1 of normalised x offsets, bottom row and length
    curve: float = 5.0  # bezier's L1 of normalised sampled curve points
    keypoint_offset: float = 1.0  # ganet's L1 of sub-cell column and start offsets


CURVE_SAMPLES = 24  # points per curve compared by bezier's matching and loss
MATCH_EXIST_COST = 0.1  # weight of the (negative) existence probability in bezier's matching cost


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


def focal_loss(logits: torch.Tensor, labels: torch.Tensor, gamma: float = 2.0, alpha: float = 0.25) -> torch.Tensor:
    """Sigmoid focal loss of (N, A) ``logits`` against ``labels`` 1 / 0 / -1 (ignored), per positive."""
    used = (labels >= 0).float()
    target = labels.clamp(min=0).float()
    prob = torch.sigmoid(logits)
    ce = F.binary_cross_entropy_with_logits(logits, target, reduction="none")
    p_t = prob * target + (1 - prob) * (1 - target)
    weight = (alpha * target + (1 - alpha) * (1 - target)) * (1 - p_t) ** gamma
    return (weight * ce * used).sum() / (labels == 1).sum().clamp(min=1)


def anchor_losses(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """LaneATT: focal loss of the anchor scores; smooth L1 of the positives' bottom row, length and row offsets."""
    labels, target, rows = batch["anchor_labels"], batch["anchor_regs"], batch["anchor_rows"]
    positive = (labels == 1).float()
    count = positive.sum().clamp(min=1)
    error = F.smooth_l1_loss(out["anchor_regs"], target, reduction="none", beta=0.02)
    extent = (error[..., :2].sum(-1) * positive).sum() / count
    offsets = (error[..., 2:] * rows).sum() / rows.sum().clamp(min=1)
    return {"cls": focal_loss(out["anchor_logits"], labels), "reg": extent + offsets}


def match_curves(points: torch.Tensor, exist_prob: torch.Tensor, target: torch.Tensor,
                 valid: torch.Tensor) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per image, (query, lane) index pairs of the Hungarian matching of sampled curve points ``points``
    (N, Q, T, 2) to the lanes' ``target`` (N, S, T, 2) where ``valid`` (N, S): cost = mean L1 distance of the
    points - ``MATCH_EXIST_COST`` x existence probability."""
    from scipy.optimize import linear_sum_assignment

    pairs = []
    with torch.no_grad():
        for k in range(points.shape[0]):
            lanes = torch.nonzero(valid[k] > 0)[:, 0]
            if not len(lanes):
                pairs.append((np.zeros(0, np.int64), np.zeros(0, np.int64)))
                continue
            distance = (points[k][:, None] - target[k, lanes][None]).abs().mean(dim=(-1, -2))  # (Q, S')
            cost = distance - MATCH_EXIST_COST * exist_prob[k][:, None]
            queries, chosen = linear_sum_assignment(cost.cpu().numpy())
            pairs.append((queries, lanes.cpu().numpy()[chosen]))
    return pairs


def curve_losses(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """BezierLaneNet: Hungarian matching on sampled curve points, L1 of the matched points, existence BCE."""
    weights = torch.as_tensor(bernstein(np.linspace(0.0, 1.0, CURVE_SAMPLES)), dtype=out["curve_points"].dtype,
                              device=out["curve_points"].device)
    points = torch.einsum("tk,nqkd->nqtd", weights, out["curve_points"])
    target = torch.einsum("tk,nqkd->nqtd", weights, batch["curves"])
    logits = out["curve_logits"]
    pairs = match_curves(points, torch.sigmoid(logits), target, batch["curve_valid"])
    exist = torch.zeros_like(logits)
    matched_points, matched_target = [], []
    for k, (queries, lanes) in enumerate(pairs):
        exist[k, queries] = 1.0
        matched_points.append(points[k, queries])
        matched_target.append(target[k, lanes])
    l1 = F.l1_loss(torch.cat(matched_points), torch.cat(matched_target)) if sum(map(len, matched_points)) else \
        points.sum() * 0.0
    # a handful of lanes among the query slots: positives weighted as all negatives together, so a matched
    # query's existence passes 0.5 (unweighted, 6 epochs left every query below 0.4 and nothing was decoded)
    balance = ((exist.numel() - exist.sum()) / exist.sum().clamp(min=1)).detach()
    return {"curve": l1, "exist": F.binary_cross_entropy_with_logits(logits, exist, pos_weight=balance)}


def keypoint_losses(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """GANet: CenterNet focal loss on the heatmap (peaks exactly 1); L1 of the offsets at the keypoints."""
    heat = batch["heat"][:, None]
    prob = torch.sigmoid(out["heat_logits"]).clamp(1e-4, 1 - 1e-4)
    peak = (heat >= 1.0).float()
    count = peak.sum().clamp(min=1)
    positive = -torch.log(prob) * (1 - prob) ** 2 * peak
    negative = -torch.log(1 - prob) * prob ** 2 * (1 - heat) ** 4 * (1 - peak)
    offsets = ((out["keypoint_offsets"] - batch["keypoint_offsets"]).abs() * peak).sum() / count
    return {"heat": (positive.sum() + negative.sum()) / count, "offset": offsets}


def _ufld_loss(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
               weights: LossWeights) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    terms = row_anchor_losses(out["row_logits"], batch["rows"])
    return terms["cls"] + weights.similarity * terms["sim"] + weights.shape * terms["shape"], terms


def _seg_loss(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
              weights: LossWeights) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    terms = {"mask": mask_loss(out["mask_logits"], batch["mask"]),
             "exist": F.binary_cross_entropy_with_logits(out["exist_logits"], batch["exist"])}
    return terms["mask"] + weights.existence * terms["exist"], terms


def _laneatt_loss(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
                  weights: LossWeights) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    terms = anchor_losses(out, batch)
    return weights.anchor_score * terms["cls"] + weights.regression * terms["reg"], terms


def _bezier_loss(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
                 weights: LossWeights) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    terms = curve_losses(out, batch)
    return weights.curve * terms["curve"] + terms["exist"], terms


def _ganet_loss(out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
                weights: LossWeights) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    terms = keypoint_losses(out, batch)
    return terms["heat"] + weights.keypoint_offset * terms["offset"], terms


FamilyLoss = Callable[[dict[str, torch.Tensor], dict[str, torch.Tensor], LossWeights],
                      tuple[torch.Tensor, dict[str, torch.Tensor]]]
FAMILY_LOSSES: dict[str, FamilyLoss] = {"ufld": _ufld_loss, "seg": _seg_loss, "scnn": _seg_loss,
                                        "laneatt": _laneatt_loss, "bezier": _bezier_loss, "ganet": _ganet_loss}


def detector_loss(family: str, out: dict[str, torch.Tensor], batch: dict[str, torch.Tensor],
                  weights: LossWeights = LossWeights()) -> tuple[torch.Tensor, dict[str, float]]:
    """The total loss and its named terms (as floats, for the progress bar). A training-mode auxiliary lane-mask
    head (``mask_logits`` of a family without its own masks) adds its cross-entropy."""
    total, terms = FAMILY_LOSSES[family](out, batch, weights)
    if "mask_logits" in out and "mask" not in terms:
        terms["aux"] = mask_loss(out["mask_logits"], batch["mask"])
        total = total + weights.aux_mask * terms["aux"]
    return total, {name: float(value.detach()) for name, value in terms.items()}
