"""PGD adversarial training (``--augment pgd``): the paper's adversarial-training baseline.

A share of every batch is replaced by its projected-gradient-descent adversary (Madry et al.): starting from a
random point of the L-infinity ball of radius ``epsilon`` around the image (pixel values in 0..1), ``steps``
signed-gradient ascents of ``step_size`` on the detector's own training loss, each projected back into the ball
and onto valid pixels. The adversary keeps the image's labels. Batch norm layers use their running statistics
while the adversary is searched, so the attack's forward passes do not move them; the rest of the model stays in
training mode (the loss includes the auxiliary heads as in training).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from .losses import detector_loss
from .models import running_statistics


@dataclass(frozen=True)
class PgdSettings:
    """Radius and steps of the attack, in pixel units of 0..1 (4/255: a change of 4 grey levels at most)."""

    epsilon: float = 4.0 / 255.0
    steps: int = 2
    step_size: float = 2.5 / 255.0
    probability: float = 0.5  # share of a batch's images replaced by their adversary


def adversary(model: nn.Module, family: str, batch: dict[str, torch.Tensor], settings: PgdSettings,
              generator: torch.Generator) -> torch.Tensor:
    """The PGD adversary of ``batch["image"]`` ((N, 3, H, W) in 0..1) against ``model``'s loss on the batch's
    targets (same device as the model)."""
    images = batch["image"]
    delta = (torch.rand(images.shape, generator=generator) * 2.0 - 1.0).to(images.device) * settings.epsilon
    with running_statistics(model):
        for _ in range(settings.steps):
            delta.requires_grad_(True)
            loss, _ = detector_loss(family, model((images + delta).clamp(0.0, 1.0)), batch)
            (grad,) = torch.autograd.grad(loss, delta)
            delta = (delta.detach() + settings.step_size * grad.sign()).clamp(-settings.epsilon, settings.epsilon)
    model.zero_grad(set_to_none=True)
    return (images + delta).clamp(0.0, 1.0).detach()


def pgd_batch(model: nn.Module, family: str, batch: dict[str, torch.Tensor], settings: PgdSettings, seed: int,
              epoch: int, step: int) -> torch.Tensor:
    """The batch's images with a share (chosen by seed, epoch and step) replaced by their PGD adversaries."""
    rng = np.random.default_rng([seed, epoch, step, 11])
    chosen = torch.from_numpy(np.flatnonzero(rng.random(len(batch["image"])) < settings.probability))
    if not len(chosen):
        return batch["image"]
    device = next(model.parameters()).device
    subset = {name: value[chosen].to(device) for name, value in batch.items()}
    generator = torch.Generator().manual_seed(int(rng.integers(2**62)))
    images = batch["image"].clone()
    images[chosen] = adversary(model, family, subset, settings, generator).to(images.device)
    return images
