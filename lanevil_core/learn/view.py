"""``lanevil adapt --method view``: the window of a user's camera that shows a model the view it was trained on.

No weight changes and no torch: the reference detector (``VIEW_REFERENCE``, the shipped model that reads other
cameras best) reads the user's unlabelled frames; their road's vanishing point is measured from its lines
(``detect.view.measure_view``); the ego lane's opening (the *wedge*) comes from the camera's height and the lane
width when the user gives them (``--camera-height``, ``--lane-width``: exact on a flat road), and otherwise the
window keeps the frame's proportions (the wedge read off the reference's lines is too unsure to follow, see
docs/learning.md). The model folder is copied with a ``view.json``; every detector run of it is shown that window.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path
from typing import Any, Final

import numpy as np

from ..detect.learned import LearnedDetector, shipped_model_dir
from ..detect.model_spec import CONFIG_FILE, TRAINING_FILE
from ..detect.view import VIEW_FILE, View, ViewError, measure_view, window_for
from ..files import write_atomic
from ..images import IMAGE_SUFFIXES, read_rgb

VIEW_REFERENCE: Final = "seg-transfer"
DEFAULT_LANE_M: Final = 3.5


def frame_files(folders: tuple[Path, ...], max_frames: int) -> list[Path]:
    """The image files under ``folders`` (sorted), thinned evenly to ``max_frames``."""
    files = sorted(path for folder in folders for path in folder.rglob("*")
                   if path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES)
    if len(files) > max_frames:
        files = [files[int(i)] for i in np.linspace(0, len(files) - 1, max_frames).round()]
    return files


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
    summary = {"adapted_from": model.name, "method": "view", "frames": len(files), "reference": VIEW_REFERENCE,
               "camera_height": camera_height, "lane_width": lane_width if camera_height is not None else None,
               "view": view.as_dict(), "seconds": round(time.perf_counter() - started, 1)}
    trained = model / TRAINING_FILE
    if trained.is_file():
        summary["model_training"] = json.loads(trained.read_text())
    write_atomic(out / TRAINING_FILE, (json.dumps(summary, indent=2) + "\n").encode("utf-8"))
    return summary
