"""Backdrop cost: the renderer on the clean stock cases with and without the backdrop, side by side.

Compiles every clean stock case once, and a copy of its compiled scene without the backdrop's meshes
(``world/backdrop.py``: hills, tree lines, hedgerows, houses behind houses, a tunnel's ridge; drawn after every prop,
so the copy is the scene as it was before the backdrop), then renders each timed frame through both, interleaved,
``--rounds`` times, and prints per size the median ms/frame of each, their ratio and the triangles added.

    .venv/bin/python bench/backdrop_cost.py [--frames-per-case 2] [--rounds 2] [--sizes 1280x720 640x360] [--json]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import time
from pathlib import Path

import numpy as np

from lanevil_core.case import load_case
from lanevil_core.pipeline.bench import frames_to_time
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.world.backdrop import is_backdrop

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames-per-case", type=int, default=2)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--sizes", nargs="+", default=["1280x720"])
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    sizes = [(int(size.split("x")[0]), int(size.split("x")[1])) for size in args.sizes]
    times: dict[tuple[str, str], list[float]] = {}
    faces = {"without": 0, "with": 0}
    for path in sorted((ROOT / "scenes" / "00_clean").glob("*.json")):
        case = load_case(path)
        scenes = {"with": compile_scene(case)}
        scenes["without"] = dataclasses.replace(scenes["with"], meshes=[
            mesh for mesh in scenes["with"].meshes if not is_backdrop(mesh)])
        for name, scene in scenes.items():
            faces[name] += sum(len(mesh.faces) for mesh in scene.meshes)
            for size in sizes:
                render_frame(scene, 0, size)  # warm: packing, shadow caches, numba
        for frame in frames_to_time(case, args.frames_per_case):
            for size in sizes:
                for _ in range(args.rounds):
                    for name in ("without", "with"):
                        start = time.perf_counter()
                        render_frame(scenes[name], frame, size)
                        times.setdefault((f"{size[0]}x{size[1]}", name), []).append(
                            (time.perf_counter() - start) * 1e3)
    table: dict[str, dict[str, float]] = {}
    for size in args.sizes:
        before, after = (statistics.median(times[(size, name)]) for name in ("without", "with"))
        table[size] = {"frames": len(times[(size, "with")]), "without_ms": round(before, 1),
                       "with_ms": round(after, 1), "ratio": round(after / before, 3)}
    if args.json:
        print(json.dumps({**table, "triangles": faces}, indent=2))
        return
    for size in args.sizes:
        row = table[size]
        print(f"{size}: {row['frames']} frames, median {row['without_ms']} ms without the backdrop, "
              f"{row['with_ms']} ms with it, ratio {row['ratio']}")
    print(f"triangles of the 9 clean cases: {faces['without']} without, {faces['with']} with")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
