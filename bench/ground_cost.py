"""Ground cost: the renderer on the clean stock cases with the land's patchwork (verges, fields, lawns:
``render/ground.py``) and with the grass shaded as one plain material, side by side.

The plain render is the renderer with every piece's land set to ``NO_LAND`` (the grass then takes the path it took
before the patchwork: its material colour, grain, stains and clumps). Every timed frame is rendered through both,
interleaved, ``--rounds`` times, through the case's own camera and each ``--cameras`` preset; prints per camera the
median ms/frame of each and their ratio.

    .venv/bin/python bench/ground_cost.py [--frames-per-case 2] [--rounds 2] [--cameras carla] [--json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

from lanevil_core.case import load_case
from lanevil_core.pipeline.bench import CASE_CAMERA, frames_to_time, with_camera
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.presets import CAMERA_PRESET_NAMES
from lanevil_core.render import render_frame, renderer
from lanevil_core.render.ground import LAND, NO_LAND, ground_table

ROOT = Path(__file__).resolve().parents[1]
SIZE = (1280, 720)


def plain_table(pieces: list) -> np.ndarray:
    """``ground_table`` with no land anywhere: the grass as one material."""
    table = ground_table(pieces)
    table[:, LAND] = NO_LAND
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames-per-case", type=int, default=2)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--cameras", nargs="*", choices=CAMERA_PRESET_NAMES, default=[])
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    views = [CASE_CAMERA, *args.cameras]
    tables = {"plain": plain_table, "patchwork": ground_table}
    times: dict[tuple[str, str], list[float]] = {}
    for path in sorted((ROOT / "scenes" / "00_clean").glob("*.json")):
        case = load_case(path)
        scenes = {view: compile_scene(with_camera(case, view)) for view in views}
        for scene in scenes.values():
            for table in tables.values():
                renderer.ground_table = table
                render_frame(scene, 0, SIZE)  # warm: packing, shadow caches, numba
        for frame in frames_to_time(case, args.frames_per_case):
            for view, scene in scenes.items():
                for _ in range(args.rounds):
                    for name, table in tables.items():
                        renderer.ground_table = table
                        scene.cache.pop("shadow_cascades", None)  # as ``lanevil bench`` times a frame
                        start = time.perf_counter()
                        render_frame(scene, frame, SIZE)
                        times.setdefault((view, name), []).append((time.perf_counter() - start) * 1e3)
    result = {}
    for view in views:
        plain, patchwork = (statistics.median(times[(view, name)]) for name in tables)
        result[view] = {"frames": len(times[(view, "plain")]), "plain_ms": round(plain, 1),
                        "patchwork_ms": round(patchwork, 1), "ratio": round(patchwork / plain, 3)}
    if args.json:
        print(json.dumps(result, indent=2))
        return
    for view, row in result.items():
        print(f"1280x720 {view}: {row['frames']} frames, median {row['plain_ms']} ms plain grass, "
              f"{row['patchwork_ms']} ms with the patchwork, ratio {row['ratio']}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
