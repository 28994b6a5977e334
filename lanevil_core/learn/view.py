"""``lanevil adapt --method view``: the window of a user's camera that shows a model the view it was trained on.

No weight changes and no torch: the reference detector (``VIEW_REFERENCE``, the shipped model that reads other
cameras best) reads the user's unlabelled frames; their road's vanishing point is measured from its lines
(``detect.view.measure_view``); the ego lane's opening (the *wedge*) comes from the camera's height and the lane
width when the user gives them (``--camera-height``, ``--lane-width``: exact on a flat road), and otherwise the
window keeps the frame's proportions (the wedge read off the reference's lines is too unsure to follow, see
docs/learning.md). The model folder is copied with a ``view.json``; every detector run of it is shown that window.
``view.png`` beside it shows the window on one of the frames, to check by eye: the window's outline (where it
reaches past the frame, the part inside), the measured vanishing point and the ego lane as the window expects it.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path
from typing import Any, Final

from PIL import Image, ImageDraw

from ..detect.learned import LearnedDetector, shipped_model_dir
from ..detect.model_spec import CONFIG_FILE, TRAINING_FILE
from ..detect.view import STOCK_VANISHING, STOCK_WEDGE, VIEW_FILE, View, ViewError, measure_view, window_for
from ..files import write_atomic
from ..images import frame_files, read_rgb
from ..typed import UInt8Array

VIEW_REFERENCE: Final = "seg-transfer"
DEFAULT_LANE_M: Final = 3.5
VIEW_PICTURE: Final = "view.png"
OUTLINE = (255, 200, 0)  # the window
MARK = (0, 220, 255)  # the vanishing point and the ego lane the window expects


def camera_view(files: list[Path], camera_height: float | None, lane_width: float = DEFAULT_LANE_M) -> View:
    """The view of the camera that took ``files``: its vanishing point from the reference's readings, its wedge
    from ``camera_height`` and ``lane_width`` (metres) when the height is given."""
    reference = LearnedDetector(shipped_model_dir(VIEW_REFERENCE))
    readings = []
    aspect = 0.0
    for path in files:
        rgb = read_rgb(path)
        aspect = rgb.shape[0] / rgb.shape[1]
        readings.append([line for line in reference.lines(rgb) if line is not None])
    measured = measure_view(readings, aspect)
    assert measured.vanishing is not None
    wedge = None if camera_height is None else aspect * lane_width / camera_height
    return View(window_for(measured.vanishing, wedge), measured.vanishing, wedge, measured.frames)


def adapt_view(model: Path, frames: tuple[Path, ...], out: Path, camera_height: float | None,
               lane_width: float = DEFAULT_LANE_M, max_frames: int = 2000) -> dict[str, Any]:
    """Copy the model folder ``model`` to ``out`` with the view of the camera of ``frames``; returns the summary
    written to ``out``'s ``training.json``. Raises ``ViewError`` when the frames do not show the road's lines."""
    files = frame_files(frames, max_frames)
    if not files:
        raise ViewError("--frames: no png or jpg images under " + ", ".join(str(f) for f in frames))
    if not (model / CONFIG_FILE).is_file():
        raise ViewError(f"--weights {model}: no {CONFIG_FILE}")
    started = time.perf_counter()
    view = camera_view(files, camera_height, lane_width)
    out.mkdir(parents=True, exist_ok=True)
    for path in sorted(model.iterdir()):
        if path.is_file() and path.name not in (VIEW_FILE, TRAINING_FILE):
            shutil.copyfile(path, out / path.name)
    view.save(out)
    view_picture(read_rgb(files[len(files) // 2]), view).save(out / VIEW_PICTURE)
    summary = {"adapted_from": model.name, "method": "view", "frames": len(files), "reference": VIEW_REFERENCE,
               "camera_height": camera_height, "lane_width": lane_width if camera_height is not None else None,
               "view": view.as_dict(), "seconds": round(time.perf_counter() - started, 1)}
    trained = model / TRAINING_FILE
    if trained.is_file():
        summary["model_training"] = json.loads(trained.read_text())
    write_atomic(out / TRAINING_FILE, (json.dumps(summary, indent=2) + "\n").encode("utf-8"))
    return summary


def view_picture(rgb: UInt8Array, view: View) -> Image.Image:
    """``rgb`` with the window's outline, the vanishing point and the stock camera's ego lane as the window places
    it (its two lines from the vanishing point to the window's bottom corners' share of the lane)."""
    image = Image.fromarray(rgb)
    draw = ImageDraw.Draw(image)
    height, width = rgb.shape[:2]
    thick = max(2, width // 320)
    left, top, right, bottom = view.window
    box = [max(left, 0.0) * width, max(top, 0.0) * height, min(right, 1.0) * width - 1, min(bottom, 1.0) * height - 1]
    draw.rectangle(box, outline=OUTLINE, width=thick)
    if view.vanishing is not None:
        u, v = view.vanishing[0] * width, view.vanishing[1] * height
        draw.line([u - 4 * thick, v, u + 4 * thick, v], fill=MARK, width=thick)
        draw.line([u, v - 4 * thick, u, v + 4 * thick], fill=MARK, width=thick)
        # the stock ego lane in window coordinates: half the wedge either side of the vanishing point, per unit of
        # window height below it; mapped back to the frame
        drop = (1.0 - STOCK_VANISHING[1]) * (bottom - top) * height
        spread = 0.5 * STOCK_WEDGE * (1.0 - STOCK_VANISHING[1]) * (right - left) * width
        for side in (-1.0, 1.0):
            draw.line([u, v, u + side * spread, v + drop], fill=MARK, width=thick)
    return image
