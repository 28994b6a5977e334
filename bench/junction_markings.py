"""Junction markings: render time, labels and frames of the junction cases, for a side-by-side before/after.

Renders frames 0, 15, 30, 45 of the two clean junction cases at 1280x720 (one thread) through the case's own camera
and through the ``carla`` preset, and prints per case and camera the median ms/frame and a digest of the TuSimple
lane labels of those frames (labels must not change with the road's paint). Each frame is rendered ``--repeat``
times and its fastest kept (the machine may be shared), total and the ``shade`` stage that paints the road.
Run it once on each checkout to compare (``PYTHONPATH`` naming the checkout); with ``--save DIR`` the frames are
written as
``DIR/<camera>/<case>_<frame>.png``.

    PYTHONPATH=. .venv/bin/python bench/junction_markings.py [--frames 0 15 30 45] [--save DIR] [--json]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import time
from pathlib import Path

import numpy as np
from PIL import Image

from lanevil_core.case import load_case
from lanevil_core.labels import lanes
from lanevil_core.pipeline.bench import with_camera
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame

ROOT = Path(__file__).resolve().parents[1]
CASES = ("05_t_junction_urban", "06_crossroad_suburban")
CAMERAS = ("own", "carla")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", nargs="+", type=int, default=[0, 15, 30, 45])
    parser.add_argument("--save", type=Path, default=None)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    table = {}
    for stem in CASES:
        base = load_case(ROOT / "scenes" / "00_clean" / f"{stem}.json")
        for camera in CAMERAS:
            scene = compile_scene(base if camera == "own" else with_camera(base, camera))
            render_frame(scene, args.frames[0], (1280, 720))  # warm the scene's caches
            times, shade, records = [], [], []
            for frame in args.frames:
                runs = []
                for _ in range(args.repeat):
                    start = time.perf_counter()
                    rendered = render_frame(scene, frame, (1280, 720))
                    runs.append(((time.perf_counter() - start) * 1e3, rendered.timings["shade"]))
                times.append(min(run[0] for run in runs))
                shade.append(min(run[1] for run in runs))
                records.append(lanes.tusimple_record(scene, frame, rendered, f"{frame}.png")["lanes"])
                if args.save is not None:
                    folder = args.save / camera
                    folder.mkdir(parents=True, exist_ok=True)
                    Image.fromarray(rendered.rgb).save(folder / f"{stem}_{frame:03d}.png")
            digest = hashlib.sha256(json.dumps(records).encode()).hexdigest()[:12]
            table[f"{stem} {camera}"] = {"median_ms": round(statistics.median(times), 1),
                                         "shade_ms": round(statistics.median(shade), 1), "labels": digest}
    if args.json:
        print(json.dumps(table, indent=2))
        return
    for name, row in table.items():
        print(f"{name:<32}{row['median_ms']:>10} ms  shade {row['shade_ms']:>8} ms  labels {row['labels']}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
