"""Four more detector families on the shared backbone, each with its published method's essentials.

- ``LaneATTNet`` (LaneATT): line anchors from the left, right and bottom borders (``detect.line_anchors``);
  features pooled along each anchor from the stride-8 map the auxiliary lane-mask head also classifies (so the
  anchors read features trained to find paint), attention over anchors (each anchor's features attend to all
  others'), per anchor a lane score and ``2 + anchors`` regressions (bottom row, length, x offset per row).
- ``BezierNet`` (BezierLaneNet): a stride-16 map fused with its horizontally flipped self (feature flip fusion),
  pooled over rows; each column is a query slot giving an existence logit and 4 control points
  (``detect.bezier_curves``); Hungarian matching in ``losses``.
- ``GANet``: a keypoint heatmap and per keypoint (sub-cell column, offset to its lane's start point) at stride 4
  (``detect.lane_keypoints``); a dilated 3x3 block aggregates each keypoint's neighbourhood (local feature
  aggregation).
- ``SCNNNet`` (SCNN): ``seg``'s lane-slot masks and existence with slice-by-slice convolutions passing messages
  downward, upward, rightward and leftward over the stride-8 feature map before the classifier.

While training, ``laneatt``, ``bezier`` and ``ganet`` also carry ``ufld``'s auxiliary lane-mask head (a
segmentation loss that helps from-scratch training and gives AAM its attention map); its classifier is not
exported (``laneatt``'s anchors read its fused stride-8 features).
"""

from __future__ import annotations

import math

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ..detect.bezier_curves import CONTROL_POINTS
from ..detect.lane_keypoints import OFFSET_CHANNELS, keypoint_map_size
from ..detect.line_anchors import anchor_xs, line_anchors
from ..detect.model_spec import ModelSpec
from .models import LaneNet, MaskHead, SegNet, _stage_sizes, conv_bn_relu

ANCHOR_CHANNELS = 16
CURVE_CHANNELS = 32
MESSAGE_KERNEL = 9
NEGATIVE = -1e4  # attention logit of an anchor to itself (softmax weight 0)


class _AuxNet(LaneNet):
    """A family trained with the auxiliary lane-mask head (``mask_logits`` while training)."""

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        self.aux = self.mask_head()

    def with_aux(self, out: dict[str, torch.Tensor], c2: torch.Tensor, c3: torch.Tensor,
                 c4: torch.Tensor) -> dict[str, torch.Tensor]:
        if self.training:
            out["mask_logits"] = self.aux(c2, c3, c4)
        return out


class StrideSixteen(nn.Module):
    """The stride-16 stage with the stride-32 stage added (1x1 projections, bilinear upsampling)."""

    def __init__(self, channels: tuple[int, ...], out: int) -> None:
        super().__init__()
        self.c3 = nn.Conv2d(channels[2], out, 1)
        self.c4 = nn.Conv2d(channels[3], out, 1)

    def forward(self, c3: torch.Tensor, c4: torch.Tensor) -> torch.Tensor:
        up = F.interpolate(self.c4(c4), size=c3.shape[-2:], mode="bilinear", align_corners=False)
        return F.relu(self.c3(c3) + up)


class LaneATTNet(_AuxNet):
    OUTPUTS = ("anchor_scores", "anchor_regs")
    pool_index: torch.Tensor
    pool_valid: torch.Tensor
    self_mask: torch.Tensor

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        self.reduce = nn.Conv2d(self.aux.classify.in_channels, ANCHOR_CHANNELS, 1)
        height, width = _stage_sizes(self.backbone, spec.input_size, stage=0)
        anchors = line_anchors()
        count = len(anchors)
        # Anchor feature pooling (LaneATT): per anchor and feature-map row, the cell the anchor line crosses.
        rows = (np.arange(height) + 0.5) / height
        columns = np.floor(anchor_xs(anchors, rows, spec.input_size[0] / spec.input_size[1]) * width)
        valid = (columns >= 0) & (columns < width) & (rows[None] <= anchors[:, 1:2] + 0.5 / height)
        index = np.where(valid, np.arange(height)[None] * width + columns, 0).astype(np.int64)
        self.register_buffer("pool_index", torch.from_numpy(index.reshape(-1)), persistent=False)
        self.register_buffer("pool_valid", torch.from_numpy(valid.astype(np.float32))[None, None], persistent=False)
        self.register_buffer("self_mask", torch.eye(count) * NEGATIVE, persistent=False)
        self.feature_size = ANCHOR_CHANNELS * height
        self.attention = nn.Linear(self.feature_size, count)
        self.classify = nn.Linear(2 * self.feature_size, 1)
        self.regress = nn.Linear(2 * self.feature_size, 2 + spec.anchors)

    def anchor_features(self, feature_map: torch.Tensor) -> torch.Tensor:
        """(N, A, C * H) the feature map's cells along each anchor (zero outside the image)."""
        n, channels, height, _ = feature_map.shape
        pooled = feature_map.flatten(2).index_select(2, self.pool_index)
        pooled = pooled.view(n, channels, -1, height) * self.pool_valid
        return pooled.permute(0, 2, 1, 3).reshape(n, -1, channels * height)

    def forward(self, image: torch.Tensor) -> dict[str, torch.Tensor]:
        c2, c3, c4 = self.stages(image)
        fused = self.aux.features(c2, c3, c4)
        features = self.anchor_features(F.relu(self.reduce(fused)))
        weights = torch.softmax(self.attention(features) + self.self_mask, dim=-1)  # (N, A, A), none to itself
        joined = torch.cat([features, torch.bmm(weights, features)], dim=-1)
        out = {"anchor_logits": self.classify(joined)[..., 0], "anchor_regs": self.regress(joined)}
        if self.training:
            out["mask_logits"] = self.aux.logits(fused)
        return out

    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        return torch.sigmoid(out["anchor_logits"]), out["anchor_regs"]


class BezierNet(_AuxNet):
    OUTPUTS = ("curve_exist", "curve_points")
    flip_index: torch.Tensor
    column_x: torch.Tensor

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        channels = CURVE_CHANNELS
        self.features = StrideSixteen(self.backbone.channels, channels)
        _, width = _stage_sizes(self.backbone, spec.input_size, stage=1)
        self.register_buffer("flip_index", torch.arange(width - 1, -1, -1), persistent=False)
        self.flip_fusion = nn.Sequential(nn.Conv2d(channels, channels, 3, 1, 1, bias=False), nn.BatchNorm2d(channels))
        self.queries = nn.Sequential(
            nn.Conv1d(channels, channels, 3, 1, 1, bias=False), nn.BatchNorm1d(channels), nn.ReLU(inplace=True),
            nn.Conv1d(channels, channels, 3, 1, 1, bias=False), nn.BatchNorm1d(channels), nn.ReLU(inplace=True),
            nn.Conv1d(channels, 1 + 2 * CONTROL_POINTS, 1),
        )
        # each query column starts from a vertical curve through its own column
        self.register_buffer("column_x", ((torch.arange(width) + 0.5) / width).view(1, width, 1), persistent=False)

    def forward(self, image: torch.Tensor) -> dict[str, torch.Tensor]:
        c2, c3, c4 = self.stages(image)
        f = self.features(c3, c4)
        f = F.relu(f + self.flip_fusion(f.index_select(3, self.flip_index)))  # feature flip fusion
        q = self.queries(f.mean(dim=2)).permute(0, 2, 1)  # (N, Q, 1 + 8)
        points = q[..., 1:].reshape(q.shape[0], q.shape[1], CONTROL_POINTS, 2)
        points = torch.stack([points[..., 0] + self.column_x, points[..., 1] + 0.5], dim=-1)
        return self.with_aux({"curve_logits": q[..., 0], "curve_points": points}, c2, c3, c4)

    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        return torch.sigmoid(out["curve_logits"]), out["curve_points"]


class GANet(_AuxNet):
    OUTPUTS = ("heat_probs", "keypoint_offsets")

    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        channels = self.backbone.channels
        mid = max(16, channels[1])
        self.keypoints = MaskHead(channels, mid, 1 + OFFSET_CHANNELS, keypoint_map_size(spec.input_size))
        # local feature aggregation: a dilated block widens what each keypoint cell sees along its lane
        self.keypoints.fuse.append(nn.Sequential(nn.Conv2d(mid, mid, 3, 1, 2, dilation=2, bias=False),
                                                 nn.BatchNorm2d(mid), nn.ReLU(inplace=True)))
        with torch.no_grad():  # heat starts near 0.1 (CenterNet's prior for its focal loss)
            self.keypoints.classify.bias[:1] = -2.2  # type: ignore[index]

    def forward(self, image: torch.Tensor) -> dict[str, torch.Tensor]:
        c2, c3, c4 = self.stages(image)
        maps = self.keypoints(c2, c3, c4)
        return self.with_aux({"heat_logits": maps[:, :1], "keypoint_offsets": maps[:, 1:]}, c2, c3, c4)

    def deploy(self, out: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
        return torch.sigmoid(out["heat_logits"]), out["keypoint_offsets"]


def directional_pass(x: torch.Tensor, conv: nn.Module, dim: int, reverse: bool) -> torch.Tensor:
    """SCNN's message passing along ``dim``: slice by slice, each slice adds ReLU(conv(previous slice))."""
    slices = list(torch.split(x, 1, dim))
    order = list(range(len(slices)))[::-1] if reverse else list(range(len(slices)))
    done = {order[0]: slices[order[0]]}
    for previous, current in zip(order, order[1:], strict=False):
        done[current] = slices[current] + F.relu(conv(done[previous]))
    return torch.cat([done[k] for k in range(len(slices))], dim)


class MessagePassing(nn.Module):
    """The four directional passes of SCNN: downward, upward (row slices), rightward, leftward (column slices)."""

    def __init__(self, channels: int, kernel: int = MESSAGE_KERNEL) -> None:
        super().__init__()
        row = {"kernel_size": (1, kernel), "padding": (0, kernel // 2), "bias": False}
        column = {"kernel_size": (kernel, 1), "padding": (kernel // 2, 0), "bias": False}
        self.down = nn.Conv2d(channels, channels, **row)  # type: ignore[arg-type]
        self.up = nn.Conv2d(channels, channels, **row)  # type: ignore[arg-type]
        self.right = nn.Conv2d(channels, channels, **column)  # type: ignore[arg-type]
        self.left = nn.Conv2d(channels, channels, **column)  # type: ignore[arg-type]
        for conv in (self.down, self.up, self.right, self.left):  # SCNN's small init keeps long passes stable
            nn.init.normal_(conv.weight, 0.0, math.sqrt(2.0 / (channels * kernel * 5)))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = directional_pass(x, self.down, 2, reverse=False)
        x = directional_pass(x, self.up, 2, reverse=True)
        x = directional_pass(x, self.right, 3, reverse=False)
        return directional_pass(x, self.left, 3, reverse=True)


class SCNNNet(SegNet):
    def __init__(self, spec: ModelSpec) -> None:
        super().__init__(spec)
        mid = self.head.classify.in_channels
        self.head.fuse = nn.Sequential(conv_bn_relu(mid, mid), MessagePassing(mid), conv_bn_relu(mid, mid))


FAMILY_NETS: dict[str, type[LaneNet]] = {"laneatt": LaneATTNet, "bezier": BezierNet, "ganet": GANet,
                                         "scnn": SCNNNet}
