"""GANet's lane keypoints: a keypoint heatmap and, per keypoint, the offset to its lane's start point, in numpy.

On a map at ``KEYPOINT_STRIDE`` of the input, each lane has one keypoint per map row (its crossing of the row's
centre), drawn as a horizontal Gaussian whose peak cell is exactly 1. Per keypoint cell the targets are the
sub-cell column offset of the crossing and the offset (dx, dy, normalised) to the lane's start point, its lowest
labelled point. Decoding takes the heatmap's row-wise peaks, groups them globally by their predicted start points
(keypoints pointing within ``GROUP_RADIUS`` of a group's start join it) and samples each group's keypoints, ended
by the group's mean start point, as a lane line: lanes need no slot order, and a lane ends where its keypoints say
it starts, not at the map row before.
"""

from __future__ import annotations

import numpy as np

from ..typed import FloatArray
from .lane_slots import LaneLine

KEYPOINT_STRIDE = 4
SIGMA_CELLS = 1.0
HEAT_THRESHOLD = 0.3
GROUP_RADIUS = 0.04  # normalised distance between start points of one lane
MIN_KEYPOINTS = 3
OFFSET_CHANNELS = 3  # sub-cell column, start dx, start dy


def keypoint_map_size(input_size: tuple[int, int]) -> tuple[int, int]:
    """(width, height) of the keypoint maps for a network input of ``input_size``."""
    width, height = input_size
    return -(-width // KEYPOINT_STRIDE), -(-height // KEYPOINT_STRIDE)


def encode_keypoints(placed: list[LaneLine | None], size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) float32 heatmap and (3, H, W) float32 offsets (sub-cell column, start dx, start dy; zero away from
    keypoints) of the lanes ``placed`` on a map of ``size`` (width, height)."""
    width, height = size
    heat = np.zeros((height, width), np.float32)
    offsets = np.zeros((OFFSET_CHANNELS, height, width), np.float32)
    y_norm = (np.arange(height) + 0.5) / height
    columns = np.arange(width)
    for line in placed:
        if line is None:
            continue
        x_norm = line.x_at(y_norm)
        rows = np.flatnonzero(np.isfinite(x_norm) & (x_norm >= 0.0) & (x_norm < 1.0))
        if not len(rows):
            continue
        start_x, start_y = line.points[-1]  # the lane's lowest labelled point
        for row in rows:
            u_map = x_norm[row] * width - 0.5  # continuous column, cell centres at integers
            cell = int(np.clip(np.rint(u_map), 0, width - 1))
            heat[row] = np.maximum(heat[row], np.exp(-0.5 * ((columns - u_map) / SIGMA_CELLS) ** 2))
            heat[row, cell] = 1.0
            offsets[:, row, cell] = (u_map - cell, start_x - x_norm[row], start_y - y_norm[row])
    return heat, offsets


def keypoint_peaks(heat: FloatArray, threshold: float = HEAT_THRESHOLD) -> tuple[np.ndarray, np.ndarray]:
    """(rows, columns) of the cells above ``threshold`` that are the maximum of their row neighbourhood."""
    left = np.pad(heat[:, :-1], ((0, 0), (1, 0)), constant_values=-1.0)
    right = np.pad(heat[:, 1:], ((0, 0), (0, 1)), constant_values=-1.0)
    peak = (heat > threshold) & (heat >= left) & (heat > right)
    rows, columns = np.nonzero(peak)
    return rows, columns


def decode_keypoints(heat: FloatArray, offsets: FloatArray, max_lanes: int, threshold: float = HEAT_THRESHOLD,
                     radius: float = GROUP_RADIUS, min_points: int = MIN_KEYPOINTS) -> list[LaneLine | None]:
    """Lane lines from ``heat`` (H, W) keypoint probabilities and ``offsets`` (3, H, W): peaks grouped by their
    predicted start points (strongest first), a group's strongest keypoint per row kept, at most ``max_lanes``
    groups (by total score)."""
    height, width = heat.shape
    rows, columns = keypoint_peaks(heat, threshold)
    scores = heat[rows, columns]
    x_norm = (columns + 0.5 + offsets[0, rows, columns]) / width
    y_norm = (rows + 0.5) / height
    starts = np.stack([x_norm + offsets[1, rows, columns], y_norm + offsets[2, rows, columns]], axis=1)
    centres: list[np.ndarray] = []
    members: list[list[int]] = []
    for k in np.argsort(-scores, kind="stable"):
        gaps = [float(np.linalg.norm(starts[k] - c)) for c in centres]
        if gaps and min(gaps) < radius:
            nearest = int(np.argmin(gaps))
            members[nearest].append(int(k))
            centres[nearest] = starts[members[nearest]].mean(axis=0)
        else:
            centres.append(starts[k].copy())
            members.append([int(k)])
    lanes = []
    for group in members:
        best: dict[int, int] = {}
        for keypoint in group:  # one keypoint per row: the strongest
            row = int(rows[keypoint])
            if row not in best or scores[keypoint] > scores[best[row]]:
                best[row] = keypoint
        chosen = [best[r] for r in sorted(best)]
        if len(chosen) < min_points:
            continue
        points = np.stack([x_norm[chosen], y_norm[chosen]], axis=1)
        start = starts[chosen].mean(axis=0)
        if start[1] > points[-1, 1]:
            points = np.vstack([points, start])
        lanes.append((float(scores[chosen].sum()), points))
    lanes.sort(key=lambda item: -item[0])
    return [LaneLine(points) for _, points in lanes[:max_lanes]]
