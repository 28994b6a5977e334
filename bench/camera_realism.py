"""Camera realism: image statistics of the clean stock drives through each camera, and render time side by side.

Renders frames 0, 15, ..., 90 of every clean stock case (9 cases x 7 frames = 63 frames at 1280x720) through the
ideal camera (the paper's, no sensor) and through each named preset, interleaved per frame, and prints per camera
the mean of every ``lanevil realism`` statistic and the median ms/frame with its ratio to the ideal camera. With
``--save DIR`` the frames are written as ``DIR/<camera>/<case>_<frame>.png`` for ``lanevil realism --ours``.

    .venv/bin/python bench/camera_realism.py [--cameras carla dashcam] [--frames 0 15 30 45 60 75 90] [--save DIR]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np
from PIL import Image

from lanevil_core.case import load_case
from lanevil_core.metrics.realism import frame_statistics, summary
from lanevil_core.pipeline.bench import with_camera
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.presets import CAMERA_PRESET_NAMES
from lanevil_core.render import render_frame

ROOT = Path(__file__).resolve().parents[1]
IDEAL = "ideal"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cameras", nargs="+", choices=CAMERA_PRESET_NAMES, default=["carla"])
    parser.add_argument("--frames", nargs="+", type=int, default=[0, 15, 30, 45, 60, 75, 90])
    parser.add_argument("--save", type=Path, default=None)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    cameras = [IDEAL, *args.cameras]
    stats: dict[str, list] = {name: [] for name in cameras}
    times: dict[str, list[float]] = {name: [] for name in cameras}
    for path in sorted((ROOT / "scenes" / "00_clean").glob("*.json")):
        base = load_case(path)
        scenes = {IDEAL: compile_scene(base)}
        for name in args.cameras:
            scenes[name] = compile_scene(with_camera(base, name))
        for name in cameras:
            render_frame(scenes[name], args.frames[0], (1280, 720))  # warm the scene's caches
        for frame in args.frames:
            for name in cameras:
                start = time.perf_counter()
                rgb = render_frame(scenes[name], frame, (1280, 720)).rgb
                times[name].append((time.perf_counter() - start) * 1e3)
                stats[name].append(frame_statistics(rgb))
                if args.save is not None:
                    folder = args.save / name
                    folder.mkdir(parents=True, exist_ok=True)
                    Image.fromarray(rgb).save(folder / f"{path.stem}_{frame:03d}.png")
    ideal_ms = statistics.median(times[IDEAL])
    table = {}
    for name in cameras:
        means = {key: round(value.mean, 4) for key, value in summary(stats[name]).items()}
        ms = statistics.median(times[name])
        table[name] = {"frames": len(stats[name]), "median_ms": round(ms, 1), "ratio": round(ms / ideal_ms, 2),
                       **means}
    if args.json:
        print(json.dumps(table, indent=2))
        return
    keys = list(next(iter(table.values())))
    print("camera".ljust(10) + "".join(key.rjust(15) for key in keys))
    for name, row in table.items():
        print(name.ljust(10) + "".join(f"{row[key]:>15}" for key in keys))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
