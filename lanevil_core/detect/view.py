"""The view a learned detector was trained on, and the window of another camera's frames that shows it so.

A detector trained on renders of the stock camera (90° across, 3 m up, level) reads lanes where that camera puts
them: the road's vanishing point in the middle of the frame, the ego lane's two lines opening from it at a set
angle. Another camera puts them elsewhere. A pitched camera moves the vanishing point up or down; a lower one
(TuSimple's ~1.5 m, a dash cam's ~1.3 m) opens the ego lane twice as wide. The row- and line-anchor families have
learned where lanes sit in the image, and on such frames they read little (docs/learning.md).

A ``View`` is the window of the frame the network is shown instead of the whole frame: a rectangle in fractions of
the frame's width and height that may reach past its edges (the outside filled with the nearest edge pixel),
stretched to the network's input. It is chosen so that the road's vanishing point lands where the stock camera has
it and the ego lane opens as it does there; the lanes read are mapped back to the frame's own pixels.

Geometry (flat road, pinhole camera at height ``z`` above it, lane ``w`` wide): a row ``dv`` pixels below the
horizon sees the road at depth ``f z / dv``, where a lane is ``f w / depth = w dv / z`` pixels wide. The ego lane's
width grows linearly below the vanishing point at ``w / z`` pixels per row whatever the focal length, so only a
stretch of the window's width against its height changes it. In fractions of the frame (``x = u / W``,
``y = v / H``) the slope is ``(H / W) w / z``: the *wedge*.

A camera's view is measured without labels (``lanevil adapt --method view``): a reference detector that reads
other cameras (``seg-transfer``) reads the user's frames; each frame's lines give a vanishing point (where their
lower parts meet, ``camera.vanishing.meeting_point``) and a wedge (the slope of the ego lane's width); the camera's
are the medians over its frames.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import cv2
import numpy as np

from ..camera.vanishing import meeting_point
from ..files import write_atomic
from ..typed import FloatArray, UInt8Array
from .lane_slots import LaneLine

VIEW_FILE: Final = "view.json"

STOCK_ASPECT: Final = 720.0 / 1280.0  # the stock camera's frame, H / W
STOCK_HEIGHT_M: Final = 3.0  # the stock camera's height over the road (docs/cameras.md, `carla`)
STOCK_LANE_M: Final = 3.5  # the stock cases' usual lane width
STOCK_VANISHING: Final = (0.5, 0.5)  # a level camera looking along the road: the frame's centre
STOCK_WEDGE: Final = STOCK_ASPECT * STOCK_LANE_M / STOCK_HEIGHT_M  # ≈ 0.656

LOWER_SHARE: Final = 0.6  # the part of a read line, nearest the camera, fitted by a straight line
MIN_LINE_POINTS: Final = 4
MIN_FRAMES: Final = 2  # frames with a vanishing point and an ego lane needed to measure a camera
WINDOW_HEIGHT: Final = (0.6, 2.0)  # the window's height and width, in frames, are kept in these ranges
WINDOW_WIDTH: Final = (0.6, 3.0)


class ViewError(ValueError):
    """A view that cannot be read or measured."""


@dataclass(frozen=True)
class View:
    """The window (left, top, right, bottom) of a frame, in fractions of its width and height, that a network sees.

    ``vanishing`` and ``wedge`` record what it was measured from (``None`` for a window given directly).
    """

    window: tuple[float, float, float, float]
    vanishing: tuple[float, float] | None = None
    wedge: float | None = None
    frames: int = 0

    def __post_init__(self) -> None:
        left, top, right, bottom = self.window
        if not all(np.isfinite(self.window)) or right <= left or bottom <= top:
            raise ViewError(f"window: {list(self.window)} is not a rectangle (left < right, top < bottom)")

    def to_frame(self, line: LaneLine) -> LaneLine:
        """A line read in the network's normalised input mapped to the frame's normalised coordinates."""
        left, top, right, bottom = self.window
        scale = np.array([right - left, bottom - top])
        return LaneLine(line.points * scale + np.array([left, top]))

    def as_dict(self) -> dict[str, object]:
        return {"window": [round(value, 6) for value in self.window],
                "vanishing": None if self.vanishing is None else [round(value, 6) for value in self.vanishing],
                "wedge": None if self.wedge is None else round(self.wedge, 6), "frames": self.frames}

    def save(self, model_dir: Path) -> None:
        write_atomic(model_dir / VIEW_FILE, (json.dumps(self.as_dict(), indent=2) + "\n").encode())

    @classmethod
    def load(cls, model_dir: Path) -> View | None:
        """The view of a model folder, or None when it has none."""
        path = model_dir / VIEW_FILE
        if not path.is_file():
            return None
        try:
            data = json.loads(path.read_text())
            window = tuple(float(value) for value in data["window"])
            vanishing = data.get("vanishing")
            wedge = data.get("wedge")
            return cls((window[0], window[1], window[2], window[3]),
                       None if vanishing is None else (float(vanishing[0]), float(vanishing[1])),
                       None if wedge is None else float(wedge), int(data.get("frames", 0)))
        except (OSError, ValueError, KeyError, TypeError, IndexError) as error:
            raise ViewError(f"{path}: window: not a view file ({error})") from None


def window_for(vanishing: tuple[float, float], wedge: float | None) -> tuple[float, float, float, float]:
    """The window that puts a camera's vanishing point where the stock camera has it and opens its ego lane as the
    stock camera does. The frame's bottom row stays the window's bottom; height and width are kept within
    ``WINDOW_HEIGHT`` and ``WINDOW_WIDTH`` (a far-off measurement is not followed all the way)."""
    vanish_x, vanish_y = vanishing
    target_x, target_y = STOCK_VANISHING
    top = (vanish_y - target_y) / (1.0 - target_y)  # the vanishing point lands target_y down the window
    height = float(np.clip(1.0 - top, *WINDOW_HEIGHT))
    width = height if wedge is None else float(np.clip(wedge * height / STOCK_WEDGE, *WINDOW_WIDTH))
    left = vanish_x - target_x * width
    return left, 1.0 - height, left + width, 1.0


def view_input(rgb: UInt8Array, view: View, input_size: tuple[int, int]) -> UInt8Array:
    """The window of ``rgb`` at the network's input size: the frame shrunk (area filter) so that the window has the
    input's size, then the window cut out, the outside filled with the nearest edge pixel."""
    height, width = rgb.shape[:2]
    left, top, right, bottom = view.window
    in_w, in_h = input_size
    scale_x = in_w / ((right - left) * width)
    scale_y = in_h / ((bottom - top) * height)
    small_w, small_h = max(1, round(width * scale_x)), max(1, round(height * scale_y))
    small = rgb if (small_w, small_h) == (width, height) else \
        np.asarray(cv2.resize(rgb, (small_w, small_h), interpolation=cv2.INTER_AREA), np.uint8)
    # input pixel (i, j) centre -> small-image coordinates: a shift by the window's corner, rescaled for rounding
    sx, sy = small_w / width, small_h / height
    T_small_input = np.array([[(right - left) * width * sx / in_w, 0.0, left * width * sx],
                              [0.0, (bottom - top) * height * sy / in_h, top * height * sy]])
    T_small_input[:, 2] += 0.5 * T_small_input[:, :2].sum(axis=1) - 0.5  # pixel centres on both sides
    return np.asarray(cv2.warpAffine(small, T_small_input, (in_w, in_h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                                     borderMode=cv2.BORDER_REPLICATE), np.uint8)


def _lower_line(line: LaneLine) -> FloatArray | None:
    """(a, b) of ``x = a y + b`` fitted to the lower ``LOWER_SHARE`` of a read line, or None when too short."""
    points = line.points[np.isfinite(line.points).all(axis=1)]
    if len(points) < MIN_LINE_POINTS:
        return None
    lower = points[int(len(points) * (1.0 - LOWER_SHARE)):]
    if len(lower) < 2 or np.ptp(lower[:, 1]) < 1e-6:
        return None
    return np.polyfit(lower[:, 1], lower[:, 0], 1)


def frame_geometry(lines: Sequence[LaneLine], aspect: float) -> tuple[float, float, float] | None:
    """(vanishing x, vanishing y, wedge) of one frame's read lines in normalised coordinates, or None without two
    lines that meet and an ego lane (a line either side of the frame's centre at its bottom row). ``aspect``: the
    frame's H / W, so that lines meet where they do in pixels."""
    fits = [fit for line in lines if (fit := _lower_line(line)) is not None]
    pixel_lines = [np.array([a, b]) / aspect for a, b in fits]  # x in units of the frame's height, as pixels
    point = meeting_point(pixel_lines)
    if point is None:
        return None
    vanish_x, vanish_y = point[0] * aspect, point[1]
    if not 0.0 < vanish_y < 0.95:
        return None
    bottoms = [(a + b, a) for a, b in fits]
    left = [(x, a) for x, a in bottoms if x < 0.5]
    right = [(x, a) for x, a in bottoms if x >= 0.5]
    if not left or not right:
        return None
    wedge = min(right)[1] - max(left)[1]  # the slopes of the nearest line either side
    if wedge <= 0.0:
        return None
    return vanish_x, vanish_y, wedge


def measure_view(frames: Sequence[Sequence[LaneLine]], aspect: float) -> View:
    """The view of a camera from the lines read in its frames (the medians over frames); raises ``ViewError`` when
    fewer than ``MIN_FRAMES`` frames show a vanishing point and an ego lane."""
    found = [geometry for lines in frames if (geometry := frame_geometry(lines, aspect)) is not None]
    if len(found) < MIN_FRAMES:
        raise ViewError(f"frames: only {len(found)} of {len(frames)} frames show two lines that meet and the ego "
                        f"lane (at least {MIN_FRAMES} are needed to measure the camera's view)")
    vanish_x, vanish_y, wedge = (float(value) for value in np.median(np.asarray(found), axis=0))
    return View(window_for((vanish_x, vanish_y), wedge), (vanish_x, vanish_y), wedge, len(found))
