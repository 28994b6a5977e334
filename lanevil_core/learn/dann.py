"""Domain-adversarial training (DANN: Ganin & Lempitsky, "Unsupervised Domain Adaptation by Backpropagation", 2015),
the adversarial feature alignment of ``lanevil adapt --method dann``.

A small domain classifier reads the detector's backbone features (the last stage, global-average-pooled:
``models.pooled_features``) through a gradient-reversal layer and learns to tell our labelled renders (source) from
the user's unlabelled frames (target). Trained jointly with the detector's own loss on the source frames, the
reversed gradient pushes the backbone towards features the classifier cannot tell apart, while the lanes stay
learned from labels. As in the paper, the reversal weight ramps from 0 to 1 over training
(``lambda = 2 / (1 + exp(-10 p)) - 1``, ``p`` the share of steps done) and the learning rate anneals
(``lr / (1 + 10 p) ** 0.75``); the classifier, new, learns at ten times the detector's rate.

Source and target batches go through the network apart, so batch norm normalises each domain by its own batch
while training (its running statistics then mix both): ``adabn+dann`` re-estimates them on the target afterwards.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn
from torch.utils.data import DataLoader

from ..detect.learned import network_input
from .data import LabelledFrames
from .losses import detector_loss
from .models import LaneNet, pooled_features

HEAD_LR_FACTOR = 10.0  # the new domain classifier's learning rate over the detector's


class _ReverseGradient(torch.autograd.Function):
    """Identity forward; the gradient times ``-weight`` backward."""

    @staticmethod
    def forward(ctx: Any, features: torch.Tensor, weight: float) -> torch.Tensor:
        ctx.weight = weight
        return features.view_as(features)

    @staticmethod
    def backward(ctx: Any, grad: torch.Tensor) -> tuple[torch.Tensor, None]:
        return -ctx.weight * grad, None


def reverse_gradient(features: torch.Tensor, weight: float) -> torch.Tensor:
    """The gradient-reversal layer: ``features`` unchanged, their gradient multiplied by ``-weight``."""
    return _ReverseGradient.apply(features, weight)


def reversal_weight(progress: float) -> float:
    """The paper's ramp of the reversal weight: 0 at the start (``progress`` 0), 0.46 a tenth of the way, 0.9999
    at the end (1)."""
    return 2.0 / (1.0 + math.exp(-10.0 * progress)) - 1.0


def annealed_lr(base: float, progress: float) -> float:
    """The paper's learning-rate schedule ``base / (1 + 10 p) ** 0.75``."""
    return base / (1.0 + 10.0 * progress) ** 0.75


class DomainClassifier(nn.Module):
    """Pooled backbone features ``(N, C)`` -> the logit of "the user's frame" (target), behind gradient reversal."""

    def __init__(self, channels: int, hidden: int = 64) -> None:
        super().__init__()
        self.net = nn.Sequential(nn.Linear(channels, hidden), nn.ReLU(inplace=True), nn.Linear(hidden, hidden),
                                 nn.ReLU(inplace=True), nn.Linear(hidden, 1))

    def forward(self, features: torch.Tensor, weight: float) -> torch.Tensor:
        return self.net(reverse_gradient(features, weight)).squeeze(1)


def target_batches(count: int, batch: int, steps: int, rng: np.random.Generator) -> list[np.ndarray]:
    """``steps`` batches of indices into ``count`` target frames: shuffled passes, one after another."""
    passes = math.ceil(steps * batch / count)
    order = np.concatenate([rng.permutation(count) for _ in range(passes)])
    return [order[k * batch:(k + 1) * batch] for k in range(steps)]


def _target_tensor(images: np.ndarray, flips: np.ndarray, input_size: tuple[int, int]) -> torch.Tensor:
    """Target images ((N, H, W, 3) uint8 at the input size) as a network batch, those of ``flips`` mirrored."""
    return torch.from_numpy(np.stack([network_input(np.ascontiguousarray(image[:, ::-1]) if flip else image,
                                                    input_size) for image, flip in zip(images, flips, strict=True)]))


def adversarial_training(model: LaneNet, source: LabelledFrames, target: np.ndarray, epochs: int, batch: int,
                         lr: float, seed: int, device: torch.device, domain_weight: float = 1.0,
                         show_progress: bool = False) -> dict[str, Any]:
    """Train ``model`` on the labelled ``source`` frames and, adversarially, on the unlabelled ``target`` images
    ((N, H, W, 3) uint8 at the input size) for ``epochs`` passes over the source; per epoch the mean detector and
    domain losses and the classifier's accuracy (0.5: it can no longer tell the domains apart). ``domain_weight``
    scales the reversed gradient (0: the classifier still learns, the backbone never hears of it, which leaves a
    fine-tune on the source alone, the control of a measurement)."""
    spec = model.spec
    domain = DomainClassifier(model.backbone.channels[-1]).to(device)
    optimizer = torch.optim.AdamW([{"params": model.parameters(), "base_lr": lr},
                                   {"params": domain.parameters(), "base_lr": lr * HEAD_LR_FACTOR}],
                                  lr=lr, weight_decay=1e-4)
    batch = min(batch, len(source), len(target))
    steps = max(1, len(source) // batch)
    total = epochs * steps
    report: dict[str, Any] = {"source_frames": len(source), "target_frames": len(target), "steps": total,
                              "detector_loss": [], "domain_loss": [], "domain_accuracy": []}
    model.train()
    domain.train()
    step = 0
    for epoch in range(epochs):
        source.epoch = epoch
        loader = DataLoader(source, batch_size=batch, shuffle=True, drop_last=True,
                            generator=torch.Generator().manual_seed(seed * 1000 + epoch))
        rng = np.random.default_rng([seed, epoch, 23])
        chosen = target_batches(len(target), batch, steps, rng)
        sums = np.zeros(3)
        for indices, sample in zip(chosen, loader, strict=True):
            progress = step / total
            weight = domain_weight * reversal_weight(progress)
            for group in optimizer.param_groups:
                group["lr"] = annealed_lr(group["base_lr"], progress)
            sample = {k: v.to(device) for k, v in sample.items()}
            target_images = _target_tensor(target[indices], rng.random(len(indices)) < 0.5, spec.input_size)
            with pooled_features(model) as features:
                detection, _ = detector_loss(spec.family, model(sample["image"]), sample)
                model(target_images.to(device))  # the detector's outputs on the target are not read
            logits = domain(torch.cat(features), weight)
            labels = torch.cat([torch.zeros(len(sample["image"])), torch.ones(len(indices))]).to(device)
            domain_loss = F.binary_cross_entropy_with_logits(logits, labels)
            optimizer.zero_grad(set_to_none=True)
            (detection + domain_loss).backward()
            optimizer.step()
            sums += (float(detection.detach()), float(domain_loss.detach()),
                     float(((logits.detach() > 0).float() == labels).float().mean()))
            step += 1
        means = sums / steps
        for key, value in zip(("detector_loss", "domain_loss", "domain_accuracy"), means, strict=True):
            report[key].append(round(float(value), 4))
        if show_progress:
            print(f"adversarial epoch {epoch + 1}/{epochs}: detector loss {means[0]:.4f}, domain loss {means[1]:.4f}, "
                  f"domain accuracy {means[2]:.3f} (reversal weight {weight:.3f})", flush=True)
    return report
