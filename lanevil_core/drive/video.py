"""The drive as a video: each frame with its ground-truth lanes, the detector's lanes and a status line.

Written as MPEG-4 (``drive.mp4``, OpenCV's ``mp4v``) where OpenCV can encode it, else as an animated GIF.
Ground-truth lanes are drawn thin in the lane colours of ``overlay``; detected lanes as wider magenta bands.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from ..labels.overlay import lane_color
from ..typed import UInt8Array
from .loop import StepView
from .summary import DEVIATION_THRESHOLD_M

DETECTED_RGB = (255, 0, 255)
GIF_FRAME_LIMIT = 300


def _polyline(image: UInt8Array, xs: Sequence[int], h_samples: Sequence[int], rgb: tuple[int, int, int],
              thickness: int) -> None:
    points = np.array([(x + 0.5, h + 0.5) for x, h in zip(xs, h_samples) if x >= 0], np.float64)
    if len(points) >= 2:
        cv2.polylines(image, [np.round(points * 4).astype(np.int32)], False, rgb, thickness, cv2.LINE_AA, shift=2)


def _status(image: UInt8Array, view: StepView) -> None:
    step = view.step
    height, width = image.shape[:2]
    scale = width / 1280
    text = (f"t {step.time:5.1f} s   dev {step.deviation:+.3f} m   steer {np.degrees(step.steer):+5.1f} deg   "
            f"{step.source}")
    color = (255, 80, 80) if abs(step.deviation) > DEVIATION_THRESHOLD_M else (255, 255, 255)
    cv2.rectangle(image, (0, 0), (width, int(44 * scale)), (0, 0, 0), -1)
    cv2.putText(image, text, (int(12 * scale), int(30 * scale)), cv2.FONT_HERSHEY_SIMPLEX, 0.8 * scale, color,
                max(1, int(2 * scale)), cv2.LINE_AA)
    # A deviation gauge: the centre tick, the +-0.285 m marks and the vehicle's offset.
    centre, half = width // 2, int(200 * scale)
    y = height - int(18 * scale)
    cv2.line(image, (centre - half, y), (centre + half, y), (255, 255, 255), 1)
    for mark in (-DEVIATION_THRESHOLD_M, DEVIATION_THRESHOLD_M):
        x = centre - int(mark / 1.0 * half)
        cv2.line(image, (x, y - 8), (x, y + 8), (255, 80, 80), 2)
    x = centre - int(np.clip(step.deviation, -1.0, 1.0) * half)  # left deviation drawn left
    cv2.circle(image, (x, y), max(3, int(7 * scale)), color, -1)


def drive_frame(view: StepView) -> UInt8Array:
    """(H, W, 3) uint8 RGB: the frame with detected (magenta bands) and ground-truth lanes and the status."""
    image = np.ascontiguousarray(view.rgb.copy())
    width = image.shape[1]
    for xs in view.lanes:
        _polyline(image, xs, view.h_samples, DETECTED_RGB, max(3, width // 120))
    for index, xs in enumerate(view.gt_lanes):
        _polyline(image, xs, view.h_samples, lane_color(index), max(2, width // 400))
    _status(image, view)
    return image


class DriveVideo:
    """Collects frames during a drive (use as ``on_step``) and writes them at ``fps`` on ``close``."""

    def __init__(self, path: Path, fps: float) -> None:
        self.path = Path(path)
        self.fps = fps
        self._writer: cv2.VideoWriter | None = None
        self._gif: list[UInt8Array] = []

    def __call__(self, view: StepView) -> None:
        image = drive_frame(view)
        if self._writer is None and not self._gif and self.path.suffix == ".mp4":
            height, width = image.shape[:2]
            writer = cv2.VideoWriter(str(self.path), cv2.VideoWriter.fourcc(*"mp4v"), self.fps, (width, height))
            if writer.isOpened():
                self._writer = writer
            else:
                self.path = self.path.with_suffix(".gif")
        if self._writer is not None:
            self._writer.write(np.ascontiguousarray(image[..., ::-1]))
        elif len(self._gif) < GIF_FRAME_LIMIT:
            self._gif.append(image)

    def close(self) -> Path:
        """Finish the file; returns its path (``.gif`` when MPEG-4 could not be written)."""
        if self._writer is not None:
            self._writer.release()
            self._writer = None
        elif self._gif:
            from PIL import Image

            frames = [Image.fromarray(image) for image in self._gif]
            frames[0].save(self.path.with_suffix(".gif"), save_all=True, append_images=frames[1:],
                           duration=int(round(1000 / self.fps)), loop=0)
            self.path = self.path.with_suffix(".gif")
        return self.path
