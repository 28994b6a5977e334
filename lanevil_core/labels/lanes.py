"""Lane ground truth: the main road's lane boundaries projected through the camera that rendered the frame.

Every boundary is sampled densely along the road (``ReferenceLine.to_world`` at its ``t``, on the road surface),
projected with the frame's own ``PinholeCamera``, and cut with horizontal image lines. For each line the label is
the crossing nearest to the camera (the first one walking out along the road), so crests and bends give the
visible branch. Points are dropped when they fall outside the image, are hidden behind the road itself (a
crest) or by the ego's own bonnet, or lie where an edge line breaks for a junction arm; dashed lines are labelled
through their gaps. The camera's lens distortion is part of ``project``, so labels bend with the image. Points
hidden by an object (a vehicle, a pedestrian) are kept, as TuSimple and CULane annotate lanes through occluders,
and flagged in a ``visibility`` extension.

Row conventions (see docs/conventions.md):
- TuSimple: ``h_samples`` are pixel rows; the crossing is taken at the row centre ``y + 0.5`` and written as the
  index of the pixel column that contains it, ``floor(x)`` (the nearest pixel centre); ``-2`` = no point.
- CULane: ``y`` values 590, 580, ... are continuous image coordinates (590 = the bottom edge of a 590-row image)
  and ``x`` is the continuous crossing, both with the origin at the top-left corner of the image.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..typed import BoolArray, FloatArray
from ..world.road_layout import RoadPiece
from ..world.scene import FIRST_OBJECT_ID, ID_EGO, ID_ROAD, ID_ROADSIDE, CompiledScene

if TYPE_CHECKING:
    from ..camera import PinholeCamera
    from ..render import Frame

TUSIMPLE_SIZE = (1280, 720)
TUSIMPLE_H_SAMPLES: tuple[int, ...] = tuple(range(160, 720, 10))  # 160 ... 710, 56 rows
CULANE_SIZE = (1640, 590)
CULANE_Y: tuple[int, ...] = tuple(range(590, 260, -10))  # 590 ... 270, bottom to top
MAX_LANES = 5
NO_POINT = -2

SAMPLE_STEP_M = 0.1  # spacing of boundary samples along the road
BEHIND_M = 2.0  # boundaries are sampled from this far behind the camera ...
RANGE_M = 200.0  # ... to this far ahead
NEAR_M = 0.5  # samples closer than this (camera z) are not projected
# A label point is hidden when the rendered surface at its pixel is closer by this margin (relative, absolute m).
ROAD_HIDE_MARGIN = (0.05, 0.5)
OBJECT_HIDE_MARGIN = (0.01, 0.05)


@dataclass(frozen=True)
class BoundaryInView:
    """One lane boundary of the main road, sampled along the road and projected.

    Attributes:
        index: boundary index in ``network.main.boundaries_t`` (0 = leftmost).
        t_road: lateral position of the boundary (m, left positive).
        line_type: paint type of the boundary's marking (``scene.paint``).
        s_road: (n,) float64 arc length of the samples, increasing away from the camera.
        uv_image: (n, 2) float64 continuous image coordinates (NaN closer than ``NEAR_M`` or where an edge line
            breaks for a junction arm).
        depth: (n,) float64 camera z of the samples (m).
    """

    index: int
    t_road: float
    line_type: str
    s_road: FloatArray
    uv_image: FloatArray
    depth: FloatArray


@dataclass(frozen=True)
class LaneLabel:
    """A boundary cut with horizontal image lines ``v_image`` (continuous image y).

    Attributes:
        boundary: the projected boundary.
        v_image: (r,) float64 the image lines.
        x_image: (r,) float64 continuous x of the nearest crossing, NaN where there is no valid point.
        s_road: (r,) float64 arc length of that crossing (NaN where none).
        depth: (r,) float64 camera z of that crossing (NaN where none).
        visible: (r,) bool True where the point exists and no object hides it.
    """

    boundary: BoundaryInView
    v_image: FloatArray
    x_image: FloatArray
    s_road: FloatArray
    depth: FloatArray
    visible: BoolArray

    @property
    def valid(self) -> BoolArray:
        """(r,) bool: rows with a label point."""
        return np.isfinite(self.x_image)


def camera_station(scene: CompiledScene, camera: PinholeCamera) -> tuple[float, float]:
    """Road-frame (s, t) of the camera centre on the main road (nearest reference-line sample)."""
    line = scene.network.main.line
    p_world = camera.p_world_camera
    nearest = int(np.argmin(np.sum((line.xy - p_world[:2]) ** 2, axis=1)))
    s_road = float(line.s[nearest])
    p_line, _, left = line.frame(s_road)
    return s_road, float(np.dot(p_world - p_line, left))


def _painted(main: RoadPiece, index: int, s_road: FloatArray) -> BoolArray:
    """(n,) bool: False where an edge line breaks for a junction arm (no paint, no label)."""
    side = 1 if index == 0 else (-1 if index == len(main.boundaries_t) - 1 else 0)
    painted = np.ones(s_road.shape, bool)
    for s0, s1, gap_side in main.gaps:
        if side and gap_side == side:
            painted &= ~((s_road > s0) & (s_road < s1))
    return painted


def lane_boundaries_in_view(scene: CompiledScene, camera: PinholeCamera) -> list[BoundaryInView]:
    """Every marked boundary of the main road, left to right, sampled from just behind the camera to ``RANGE_M``
    ahead. A boundary whose marking is ``none`` has no paint and so no label."""
    main = scene.network.main
    s_camera, _ = camera_station(scene, camera)
    s0 = max(main.s_start, s_camera - BEHIND_M)
    s1 = min(main.line.length, s_camera + RANGE_M)
    s_road = np.arange(s0, s1, SAMPLE_STEP_M)
    line_types = scene.paint.line_types
    views = []
    for index, t_road in enumerate(main.boundaries_t):
        if line_types[index] == "none":
            continue
        p_world = main.line.to_world(s_road, float(t_road))
        uv_image, depth = camera.project(p_world)
        uv_image[(depth <= NEAR_M) | ~_painted(main, index, s_road)] = np.nan
        views.append(BoundaryInView(index, float(t_road), line_types[index], s_road, uv_image, depth))
    return views


def nearest_crossings(view: BoundaryInView, v_image: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """For each image line ``v_image`` (r,), the first crossing of the projected polyline walking out from the camera.

    Returns:
        x_image, s_road, depth: (r,) float64 each, NaN where the polyline never reaches the line.
    """
    v_image = np.asarray(v_image, np.float64)
    u, v = view.uv_image[:, 0], view.uv_image[:, 1]
    v0, v1 = v[:-1], v[1:]  # segment end points, (n - 1,)
    lo, hi = np.fmin(v0, v1), np.fmax(v0, v1)
    ok = np.isfinite(v0) & np.isfinite(v1)
    crosses = ok[None, :] & (lo[None, :] <= v_image[:, None]) & (v_image[:, None] <= hi[None, :])  # (r, n - 1)
    found = crosses.any(axis=1)
    first = np.argmax(crosses, axis=1)
    dv = v1[first] - v0[first]
    a = np.where(np.abs(dv) > 1e-12, (v_image - v0[first]) / np.where(dv == 0, 1.0, dv), 0.0)
    a = np.clip(a, 0.0, 1.0)

    def lerp(values: FloatArray) -> FloatArray:
        out = values[first] + a * (values[first + 1] - values[first])
        return np.where(found, out, np.nan)

    return lerp(u), lerp(view.s_road), lerp(view.depth)


def _closer(surface_depth: FloatArray, point_depth: FloatArray, margin: tuple[float, float]) -> BoolArray:
    relative, absolute = margin
    return surface_depth < point_depth * (1.0 - relative) - absolute


def label_boundary(
    view: BoundaryInView, v_image: FloatArray, size: tuple[int, int], frame: Frame | None = None,
) -> LaneLabel:
    """Cut one boundary with the image lines ``v_image``; drop points outside the image or behind a crest.

    ``frame`` (the rendered frame of the same camera) supplies depth and object ids for the crest and occlusion
    tests; without it every in-image point counts as visible.
    """
    width, height = size
    v_image = np.asarray(v_image, np.float64)
    x_image, s_road, depth = nearest_crossings(view, v_image)
    inside = np.isfinite(x_image) & (x_image >= 0) & (x_image < width) & (v_image >= 0) & (v_image <= height)
    occluded = np.zeros(v_image.shape, bool)
    if frame is not None:
        col = np.clip(np.floor(np.nan_to_num(x_image)), 0, width - 1).astype(np.intp)
        row = np.clip(np.floor(v_image), 0, height - 1).astype(np.intp)
        surface_depth = frame.depth[row, col].astype(np.float64)
        ids = frame.object_id[row, col]
        on_ground = (ids == ID_ROAD) | (ids == ID_ROADSIDE)
        inside &= ~(on_ground & _closer(surface_depth, depth, ROAD_HIDE_MARGIN))
        inside &= ids != ID_EGO  # the ego's bonnet hides the road: the label stops at its edge
        occluded = (ids >= FIRST_OBJECT_ID) & _closer(surface_depth, depth, OBJECT_HIDE_MARGIN)
    nan = np.full(v_image.shape, np.nan)
    return LaneLabel(view, v_image, np.where(inside, x_image, nan), np.where(inside, s_road, nan),
                     np.where(inside, depth, nan), inside & ~occluded)


def select_lanes(labels: list[LaneLabel], t_camera: float, max_lanes: int = MAX_LANES) -> list[LaneLabel]:
    """At most ``max_lanes`` labels with two or more points: nearest the camera first, returned left to right."""
    usable = [label for label in labels if int(label.valid.sum()) >= 2]
    # Nearest in t first; on a tie the left boundary wins (a stable, documented order).
    usable.sort(key=lambda label: (abs(label.boundary.t_road - t_camera), -label.boundary.t_road))
    chosen = usable[:max_lanes]
    return sorted(chosen, key=lambda label: label.boundary.index)


def lane_labels(
    scene: CompiledScene, camera: PinholeCamera, v_image: FloatArray, frame: Frame | None = None,
    max_lanes: int = MAX_LANES,
) -> list[LaneLabel]:
    """The chosen lanes (left to right) cut with the image lines ``v_image`` (r,) (continuous image y)."""
    size = (camera.intrinsics.width, camera.intrinsics.height)
    views = lane_boundaries_in_view(scene, camera)
    labels = [label_boundary(view, v_image, size, frame) for view in views]
    return select_lanes(labels, camera_station(scene, camera)[1], max_lanes)


def h_samples_for(height: int) -> list[int]:
    """TuSimple rows for an image of ``height`` rows: the standard grid at 720, scaled for other heights."""
    if height == TUSIMPLE_SIZE[1]:
        return list(TUSIMPLE_H_SAMPLES)
    return sorted({min(height - 1, int(round(y * height / TUSIMPLE_SIZE[1]))) for y in TUSIMPLE_H_SAMPLES})


def on_tusimple_grid(lanes: Sequence[Sequence[float]], h_samples: Sequence[float],
                     size: tuple[int, int]) -> tuple[list[list[int]], list[float]]:
    """Lanes and rows of an image of ``size`` moved to the 1280x720 TuSimple grid, where the metric's 20 px
    tolerance is defined: columns scaled (``floor``), rows as continuous 720-grid rows (``h + 0.5`` scaled, minus
    0.5), so labels rendered at any size are scored as at 1280x720."""
    width, height = size
    sx, sy = TUSIMPLE_SIZE[0] / width, TUSIMPLE_SIZE[1] / height
    rows = [(h + 0.5) * sy - 0.5 for h in h_samples]
    scaled = [[int(np.floor((x + 0.5) * sx)) if x >= 0 else NO_POINT for x in lane] for lane in lanes]
    return scaled, rows


def tusimple_columns(label: LaneLabel) -> list[int]:
    """Pixel column of each point (``floor(x)``, the pixel whose centre is nearest), ``-2`` where none."""
    return [int(np.floor(x)) if np.isfinite(x) else NO_POINT for x in label.x_image]


def tusimple_record(
    scene: CompiledScene, frame_index: int, frame: Frame, raw_file: str, h_samples: list[int] | None = None,
) -> dict[str, Any]:
    """One TuSimple JSON record for a rendered frame, with ``visibility``, ``line_types`` and ``frame`` extensions."""
    camera = frame.camera
    rows = h_samples if h_samples is not None else h_samples_for(camera.intrinsics.height)
    labels = lane_labels(scene, camera, np.asarray(rows, np.float64) + 0.5, frame)
    return {
        "raw_file": raw_file,
        "lanes": [tusimple_columns(label) for label in labels],
        "h_samples": list(rows),
        "visibility": [[bool(flag) for flag in label.visible] for label in labels],
        "line_types": [label.boundary.line_type for label in labels],
        "frame": int(frame_index),
        **image_size_field((camera.intrinsics.width, camera.intrinsics.height)),
    }


IMAGE_SIZE_FIELD = "image_size"


def image_size_field(size: tuple[int, int]) -> dict[str, list[int]]:
    """``{"image_size": [w, h]}`` for a record of an image that is not 1280x720 (scorers move a 16:9 one to the
    TuSimple grid, ``on_tusimple_grid``), else nothing: standard records stay standard."""
    return {} if tuple(size) == TUSIMPLE_SIZE else {IMAGE_SIZE_FIELD: [int(size[0]), int(size[1])]}


def culane_lines(scene: CompiledScene, frame: Frame, y_values: tuple[int, ...] = CULANE_Y) -> str:
    """CULane ``.lines.txt`` text: one lane per line, ``x1 y1 x2 y2 ...`` bottom to top, valid points only."""
    labels = lane_labels(scene, frame.camera, np.asarray(y_values, np.float64), frame, max_lanes=4)
    lines = []
    for label in labels:
        points = [f"{x:.2f} {y}" for x, y in zip(label.x_image, y_values) if np.isfinite(x)]
        lines.append(" ".join(points))
    return "".join(line + "\n" for line in lines)
