"""The lane-detector networks: row-anchor classification (``ufld``) and lane-slot segmentation (``seg``) here;
``laneatt``, ``bezier``, ``ganet`` and ``scnn`` in ``learn.families``, all on the same backbone.

Both take ``(N, 3, H, W)`` float RGB in 0..1 (normalised inside the network) at the spec's input size.

- ``UFLDNet`` (Ultra Fast Lane Detection): the last stage squeezed to 8 channels, flattened, and a two-layer
  classifier giving per lane slot and row anchor the logits of ``grid`` column cells plus "no lane". While
  training, an auxiliary lane-mask head on the three last stages (as in UFLD) adds a segmentation loss.
- ``SegNet`` (SCNN/ERFNet-like): the three last stages merged at stride 8 (a small feature pyramid), two 3x3
  convolutions, logits of background + one channel per slot at stride ``mask_stride``; an existence head on the
  pooled last stage says which slots hold a lane.

``Deployed`` wraps any of them for export: each network's ``OUTPUTS`` (probabilities and regressions under
fixed names, see ``detect.learned``) from its ``deploy``.
"""

from __future__ import annotations

import abc
from collections.abc import Iterator
from contextlib import contextmanager

import torch
import torch.nn.functional as F
from torch import nn

from ..detect.model_spec import ModelSpec
from .backbone import ResNet

MEAN = (0.485, 0.456, 0.406)
STD = (0.229, 0.224, 0.225)


class Normalize(nn.Module):
    mean: torch.Tensor
    std: torch.Tensor

    def __init__(self) -> None:
        super().__init__()
        self.register_buffer("mean", torch.tensor(MEAN).view(1, 3, 1, 1))
        self.register_buffer("std", torch.tensor(STD).view(1, 3, 1, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return (x - self.mean) / self.std


def conv_bn_relu(c_in: int, c_out: int, kernel: int = 3) -> nn.Sequential:
    return nn.Sequential(nn.Conv2d(c_in, c_out, kernel, 1, kernel // 2, bias=False), nn.BatchNorm2d(c_out),
                         nn.ReLU(inplace=True))


class MaskHead(nn.Module):
    """Stages at strides 8, 16, 32 -> ``classes`` logits at the input size divided by ``stride``."""

    def __init__(self, channels: tuple[int, ...], mid: int, classes: int, out_size: tuple[int, int]) -> None:
        super().__init__()
        c2, c3, c4 = channels[1:]
        self.lateral = nn.ModuleList([nn.Conv2d(c, mid, 1) for c in (c2, c3, c4)])
        self.fuse = nn.Sequential(conv_bn_relu(mid, mid), conv_bn_relu(mid, mid))
        self.classify = nn.Conv2d(mid, classes, 1)
        self.out_size = out_size  # (width, height)

    def features(self, c2: torch.Tensor, c3: torch.Tensor, c4: torch.Tensor) -> torch.Tensor:
        """(N, mid, H/8, W/8): the stages merged at stride 8 and fused (what ``classify`` reads)."""
        size = c2.shape[-2:]
        x = self.lateral[0](c2)
        x = x + F.interpolate(self.lateral[1](c3), size=size, mode="bilinear", align_corners=False)
        x = x + F.interpolate(self.lateral[2](c4), size=size, mode="bilinear", align_corners=False)
        return self.fuse(x)

    def logits(self, features: torch.Tensor) -> torch.Tensor:
        """Class logits at ``out_size`` from ``features``."""
        width, height = self.out_size
        return F.interpolate(self.classify(features), size=(height, width), mode="bilinear", align_corners=False)

    def forward(self, c2: torch.Tensor, c3: torch.Tensor, c4: torch.Tensor) -> torch.Tensor:
        return self.logits(self.features(c2, c3, c4))


def _stage_sizes(backbone: ResNet, input_size: tuple[int, int], stage: int = -1) -> tuple[int, int]:
    """(height, width) of a stage (default the last) for an input of ``input_size`` (width, height)."""
    with torch.no_grad():
        backbone.eval()
        stages = backbone(torch.zeros(1, 3, input_size[1], input_size[0]))
        backbone.train()
    return int(stages[stage].shape[-2]), int(stages[stage].shape[-1])


class LaneNet(nn.Module, abc.ABC):
    """What every family shares: its spec, input normalisation, the backbone and the lane-mask head's shape.

    ``OUTPUTS`` names what ``deploy`` returns (the exported model's outputs, in order)."""

    OUTPUTS: tuple[str, ...] = ()

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__()
        self.spec = spec
        self.normalize = Normalize()
        self.backbone = ResNet(spec.backbone, spec.width)

    def stages(self, image: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """The backbone's stages at strides 8, 16 and 32 for images in 0..1."""
        return self.backbone(self.normalize(image))

    def mask_head(self) -> MaskHead:
        """A lane-mask head (background + one class per slot) on this backbone."""
        channels = self.backbone.channels
        return MaskHead(channels, max(16, channels[1]), self.spec.slots + 1, self.spec.mask_size)

    @abc.abstractmethod
    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        """The exported outputs ``OUTPUTS`` from the training outputs ``out``; every family defines them."""


class UFLDNet(LaneNet):
    OUTPUTS = ("row_probs",)

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        h, w = _stage_sizes(self.backbone, spec.input_size)
        self.squeeze = nn.Conv2d(self.backbone.channels[-1], 8, 1)
        self.classifier = nn.Sequential(
            nn.Linear(8 * h * w, spec.hidden), nn.ReLU(inplace=True),
            nn.Linear(spec.hidden, spec.slots * spec.anchors * (spec.grid + 1)),
        )
        self.aux = self.mask_head()

    def forward(self, image: torch.Tensor) -> dict[str, torch.Tensor]:
        c2, c3, c4 = self.stages(image)
        flat = torch.flatten(self.squeeze(c4), 1)
        logits = self.classifier(flat).view(-1, self.spec.slots, self.spec.anchors, self.spec.grid + 1)
        out = {"row_logits": logits}
        if self.training:
            out["mask_logits"] = self.aux(c2, c3, c4)
        return out

    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        return (torch.softmax(out["row_logits"], dim=-1),)


class SegNet(LaneNet):
    OUTPUTS = ("mask_probs", "exist_probs")

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        self.head = self.mask_head()
        self.exist = nn.Sequential(nn.Linear(self.backbone.channels[-1], 64), nn.ReLU(inplace=True),
                                   nn.Linear(64, spec.slots))

    def forward(self, image: torch.Tensor) -> dict[str, torch.Tensor]:
        c2, c3, c4 = self.stages(image)
        pooled = torch.flatten(F.adaptive_avg_pool2d(c4, 1), 1)
        return {"mask_logits": self.head(c2, c3, c4), "exist_logits": self.exist(pooled)}

    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        return torch.softmax(out["mask_logits"], dim=1), torch.sigmoid(out["exist_logits"])


def build_model(spec: ModelSpec) -> LaneNet:
    """The network of a spec, freshly initialised."""
    from .families import FAMILY_NETS

    nets: dict[str, type[LaneNet]] = {"ufld": UFLDNet, "seg": SegNet, **FAMILY_NETS}
    return nets[spec.family](spec)


class Deployed(nn.Module):
    """A trained network in eval mode returning its ``OUTPUTS`` under the names ``detect.learned`` reads."""

    def __init__(self, model: LaneNet) -> None:
        super().__init__()
        self.model = model.eval()
        self.family = model.spec.family

    def output_names(self) -> list[str]:
        return list(self.model.OUTPUTS)

    def forward(self, image: torch.Tensor) -> tuple[torch.Tensor, ...]:
        return self.model.deploy(self.model(image))


@contextmanager
def running_statistics(model: nn.Module) -> Iterator[None]:
    """Batch norm layers normalise with their running statistics (and leave them unchanged) inside the block, while
    the rest of ``model`` stays in training mode (auxiliary heads included): for extra forward passes of a
    training step, an attack's or an attention map's, that must not count as training data."""
    norms = [m for m in model.modules() if isinstance(m, nn.modules.batchnorm._BatchNorm) and m.training]
    for m in norms:
        m.eval()
    try:
        yield
    finally:
        for m in norms:
            m.train()


@contextmanager
def pooled_features(model: LaneNet) -> Iterator[list[torch.Tensor]]:
    """Inside the block, every forward pass of ``model`` appends its last backbone stage, global-average-pooled to
    ``(N, C)``, to the yielded list (gradients flow through it): the features a domain classifier reads, alike for
    every family, since each reads its image through ``LaneNet.stages``."""
    captured: list[torch.Tensor] = []

    def keep(_module: nn.Module, _inputs: object, stages: tuple[torch.Tensor, ...]) -> None:
        captured.append(torch.flatten(F.adaptive_avg_pool2d(stages[-1], 1), 1))

    handle = model.backbone.register_forward_hook(keep)
    try:
        yield captured
    finally:
        handle.remove()
