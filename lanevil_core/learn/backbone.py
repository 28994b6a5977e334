"""Residual backbones (ResNet-18/34) in plain PyTorch, with a channel-width multiplier.

Layer names follow the common ResNet layout (``conv1``, ``bn1``, ``layer1`` ... ``layer4``, blocks with ``conv1``,
``bn1``, ``conv2``, ``bn2``, ``downsample.0/1``), so a state dict of ImageNet weights at width 1.0 loads by name
(``load_init``). Trained from scratch otherwise: no weights can be downloaded.
"""

from __future__ import annotations

from pathlib import Path

import torch
from torch import nn

BLOCKS = {"resnet18": (2, 2, 2, 2), "resnet34": (3, 4, 6, 3)}
BASE_CHANNELS = (64, 128, 256, 512)


class BasicBlock(nn.Module):
    def __init__(self, c_in: int, c_out: int, stride: int) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(c_in, c_out, 3, stride, 1, bias=False)
        self.bn1 = nn.BatchNorm2d(c_out)
        self.conv2 = nn.Conv2d(c_out, c_out, 3, 1, 1, bias=False)
        self.bn2 = nn.BatchNorm2d(c_out)
        self.relu = nn.ReLU(inplace=True)
        self.downsample: nn.Module | None = None
        if stride != 1 or c_in != c_out:
            self.downsample = nn.Sequential(nn.Conv2d(c_in, c_out, 1, stride, bias=False), nn.BatchNorm2d(c_out))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        identity = x if self.downsample is None else self.downsample(x)
        out = self.relu(self.bn1(self.conv1(x)))
        out = self.bn2(self.conv2(out))
        return self.relu(out + identity)


class ResNet(nn.Module):
    """Stem (stride 4) and four stages (strides 4, 8, 16, 32); ``forward`` returns the last three stages."""

    def __init__(self, depth: str = "resnet18", width: float = 1.0) -> None:
        super().__init__()
        self.channels = tuple(max(8, int(round(c * width))) for c in BASE_CHANNELS)
        c0 = self.channels[0]
        self.conv1 = nn.Conv2d(3, c0, 7, 2, 3, bias=False)
        self.bn1 = nn.BatchNorm2d(c0)
        self.relu = nn.ReLU(inplace=True)
        self.maxpool = nn.MaxPool2d(3, 2, 1)
        stages = []
        c_in = c0
        for index, (count, c_out) in enumerate(zip(BLOCKS[depth], self.channels, strict=True)):
            stride = 1 if index == 0 else 2
            blocks = [BasicBlock(c_in, c_out, stride)] + [BasicBlock(c_out, c_out, 1) for _ in range(count - 1)]
            stages.append(nn.Sequential(*blocks))
            c_in = c_out
        self.layer1, self.layer2, self.layer3, self.layer4 = stages
        for module in self.modules():
            if isinstance(module, nn.Conv2d):
                nn.init.kaiming_normal_(module.weight, mode="fan_out", nonlinearity="relu")
        for module in self.modules():  # residual branches start as identity (zero-init last BN), easier from scratch
            if isinstance(module, BasicBlock):
                nn.init.zeros_(module.bn2.weight)

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        x = self.maxpool(self.relu(self.bn1(self.conv1(x))))
        c2 = self.layer2(self.layer1(x))
        c3 = self.layer3(c2)
        return c2, c3, self.layer4(c3)


def load_init(model: nn.Module, path: str | Path) -> tuple[int, int]:
    """Copy into ``model`` (a detector) the tensors of a state dict file whose names and shapes match: a trained
    detector's ``weights.pt`` (its heads too, for fine-tuning) or a backbone's (e.g. ImageNet ResNet weights,
    matched under ``backbone.``); returns (copied, skipped). A ``fc.*`` classifier matches nothing."""
    state = torch.load(Path(path), map_location="cpu", weights_only=True)
    if isinstance(state, dict) and "state_dict" in state:
        state = state["state_dict"]
    own = model.state_dict()
    copied = 0
    for name, tensor in state.items():
        name = name.removeprefix("module.")
        for candidate in (name, "backbone." + name.removeprefix("backbone.")):
            if candidate in own and own[candidate].shape == tensor.shape:
                own[candidate] = tensor.to(own[candidate].dtype)
                copied += 1
                break
    model.load_state_dict(own)
    return copied, len(state) - copied


class BackboneWeightsError(ValueError):
    """A ``--backbone-weights`` file that does not fit the network's backbone (named tensor and shapes)."""


# The keys of torchvision's ``resnet18()`` / ``resnet34()`` state dicts that are not the backbone: its classifier.
CLASSIFIER_PREFIX = "fc."


def torchvision_keys(state: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """A state dict in torchvision's ResNet layout (optionally under ``module.`` or ``backbone.``, or wrapped in
    ``{"state_dict": ...}``) as the backbone's own names: the layouts are the same, the classifier is dropped."""
    if "state_dict" in state and isinstance(state["state_dict"], dict):
        state = state["state_dict"]
    mapped = {}
    for name, tensor in state.items():
        name = name.removeprefix("module.").removeprefix("backbone.")
        if not name.startswith(CLASSIFIER_PREFIX):
            mapped[name] = tensor
    return mapped


def load_backbone_weights(backbone: ResNet, path: str | Path) -> int:
    """Load an ImageNet checkpoint the user supplies (torchvision's ResNet key layout) into ``backbone``; every
    backbone tensor must be there with its shape, else ``BackboneWeightsError`` names the first that is not (a
    ResNet-34 file on a ResNet-18, or a network narrower than ``--width 1.0``). Returns the tensors copied."""
    try:
        loaded = torch.load(Path(path), map_location="cpu", weights_only=True)
    except Exception as error:  # a file torch cannot read: say so in one line
        raise BackboneWeightsError(f"{Path(path).name}: not a PyTorch state dict ({type(error).__name__})") from None
    if not isinstance(loaded, dict):
        raise BackboneWeightsError(f"{Path(path).name}: not a state dict")
    state = torchvision_keys(loaded)
    own = backbone.state_dict()
    for name, tensor in own.items():
        if name not in state:
            raise BackboneWeightsError(f"{Path(path).name}: no tensor {name} (not a torchvision ResNet of this depth)")
        if tuple(state[name].shape) != tuple(tensor.shape):
            raise BackboneWeightsError(
                f"{Path(path).name}: {name} is {tuple(state[name].shape)}, the network's {tuple(tensor.shape)} "
                "(ImageNet weights need --width 1.0 and the same --backbone)")
    extra = sorted(set(state) - set(own))
    if extra:
        raise BackboneWeightsError(f"{Path(path).name}: {extra[0]} is not a tensor of a {len(own)}-tensor backbone "
                                   "(not a torchvision ResNet of this depth)")
    backbone.load_state_dict({name: state[name].to(own[name].dtype) for name in own})
    return len(own)
