"""Renderer benchmark: median milliseconds per frame and per stage over the stock cases.

One warm-up frame per size runs first so numba's compilation is not timed. Each case is compiled once (which packs
its triangles; not timed) and a few frames spread over its drive are timed at every size.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..case import Case, load_case, seen_through

if TYPE_CHECKING:
    from ..render import Frame

BENCH_SIZES: tuple[tuple[int, int], ...] = ((1280, 720), (640, 360))


def bench_cases(paths: Sequence[Path]) -> list[Case]:
    """The cases to time: the given files, or the default case when there are none."""
    return [load_case(path) for path in paths] or [Case()]


def frames_to_time(case: Case, count: int) -> list[int]:
    """``count`` frames spread evenly over the drive (first and last included)."""
    last = case.ego.frames - 1
    if count == 1:
        return [0]
    return sorted({round(i * last / (count - 1)) for i in range(count)})


def _median(values: list[float]) -> float:
    return round(float(statistics.median(values)), 3) if values else 0.0


def _same_bytes(a: Frame, b: Frame) -> bool:
    return (np.array_equal(a.rgb, b.rgb) and np.array_equal(a.depth, b.depth)
            and np.array_equal(a.object_id, b.object_id))


CASE_CAMERA = "case"  # the row name of each case's own camera when presets are timed beside it


def _row_key(size: tuple[int, int], threads: int, thread_counts: Sequence[int], camera: str,
             cameras: Sequence[str]) -> str:
    width, height = size
    key = f"{width}x{height}" if len(thread_counts) == 1 else f"{width}x{height} t{threads}"
    return key if len(cameras) == 1 else f"{key} {camera}"


def with_camera(case: Case, preset: str) -> Case:
    """``case`` seen through camera preset ``preset`` (its lens, mount and sensor; ``CASE_CAMERA``: unchanged)."""
    return case if preset == CASE_CAMERA else seen_through(case, preset)


def run_benchmark(
    cases: Sequence[Case], sizes: Sequence[tuple[int, int]] = BENCH_SIZES, frames_per_case: int = 2,
    threads: Sequence[int] = (1,), cameras: Sequence[str] = (),
) -> dict[str, dict[str, Any]]:
    """``{"WxH": {"median_ms": float, "stages": {stage: median ms}}}`` for every size.

    With several thread counts every frame is rendered with each count in turn (so load on the machine hits
    them alike), rows are keyed ``"WxH tN"`` and each row after the first count's also holds ``speedup`` (the
    first count's median over its own) and ``identical`` (every frame's bytes equal the first count's).
    With camera presets (``presets.CAMERA_PRESETS`` names) every frame is also rendered through each of them,
    in turn after the case's own camera, rows are keyed ``"WxH case"`` and ``"WxH <preset>"`` and a preset's
    row holds ``ratio`` (its median over the case camera's at the same size and thread count).
    Cases are compiled one at a time (and dropped after timing) so memory stays that of one scene.
    """
    from ..render import render_frame
    from ..render.packed import pack_scene
    from .compile import compile_scene

    views = [CASE_CAMERA, *cameras]
    for size in sizes:  # warm-up: numba compilation, of every camera's path
        for view in views:
            render_frame(compile_scene(with_camera(cases[0], view)), 0, size)
    runs = [(size, n, view) for size in sizes for n in threads for view in views]
    totals: dict[tuple[tuple[int, int], int, str], list[float]] = {run: [] for run in runs}
    stages: dict[tuple[tuple[int, int], int, str], dict[str, list[float]]] = {run: {} for run in runs}
    identical = {run: True for run in runs}
    for case in cases:
        scenes = {view: compile_scene(with_camera(case, view)) for view in views}
        for scene in scenes.values():
            pack_scene(scene)  # once per scene, cached on it: not a per-frame cost
        for size in sizes:
            for frame_index in frames_to_time(case, frames_per_case):
                for view, scene in scenes.items():
                    first: Frame | None = None
                    for n in threads:
                        scene.cache.pop("shadow_cascades", None)  # frames spread over a drive share no cascade
                        start = time.perf_counter()
                        frame = render_frame(scene, frame_index, size, threads=n)
                        totals[(size, n, view)].append((time.perf_counter() - start) * 1000.0)
                        for stage, ms in frame.timings.items():
                            stages[(size, n, view)].setdefault(stage, []).append(float(ms))
                        if first is None:
                            first = frame
                        identical[(size, n, view)] &= _same_bytes(first, frame)
    result: dict[str, dict[str, Any]] = {}
    for size, n, view in runs:
        row: dict[str, Any] = {
            "median_ms": _median(totals[(size, n, view)]),
            "stages": {stage: _median(values) for stage, values in stages[(size, n, view)].items()},
        }
        if len(threads) > 1:
            base = _median(totals[(size, threads[0], view)])
            row.update(threads=n, speedup=round(base / max(row["median_ms"], 1e-9), 2),
                       identical=identical[(size, n, view)])
        if view != CASE_CAMERA:
            row.update(camera=view, ratio=round(row["median_ms"] / max(_median(totals[(size, n, CASE_CAMERA)]),
                                                                        1e-9), 2))
        result[_row_key(size, n, threads, view, views)] = row
    return result


def format_table(result: dict[str, dict[str, Any]]) -> str:
    """A plain-text table: one row per size (and thread count, and camera), total then every stage (median ms),
    then the speed-up over the first thread count and whether the bytes matched it, when several were timed, and
    a preset camera's ratio to the case camera, when presets were timed."""
    stages = sorted({stage for row in result.values() for stage in row["stages"]})
    extra = ["speedup", "identical"] if any("speedup" in row for row in result.values()) else []
    extra += ["ratio"] if any("ratio" in row for row in result.values()) else []
    header = ["size", "ms/frame", *stages, *extra]
    rows = [[size, f"{row['median_ms']:.1f}", *(f"{row['stages'].get(stage, 0.0):.1f}" for stage in stages),
             *(str(row.get(key, "")) for key in extra)]
            for size, row in result.items()]
    widths = [max(len(line[i]) for line in [header, *rows]) for i in range(len(header))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(line, widths)) for line in [header, *rows])


def illusion_benchmark(size: tuple[int, int] = (1280, 720), frames: int = 3, level: int = 5) -> list[dict[str, Any]]:
    """Per illusion type: median ms/frame of its stock original and of its ``level`` case, and their ratio."""
    from ..illusions import REGISTRY
    from ..library.stock import original_case, perturbed_case
    from ..render import render_frame
    from ..render.packed import pack_scene
    from .compile import compile_scene

    def median_ms(case: Case) -> float:
        scene = compile_scene(case)
        pack_scene(scene)
        times = []
        for frame_index in frames_to_time(case, frames):
            start = time.perf_counter()
            render_frame(scene, frame_index, size)
            times.append((time.perf_counter() - start) * 1000.0)
        return _median(times)

    render_frame(compile_scene(Case()), 0, size)  # warm-up: numba compilation
    rows = []
    for name in REGISTRY:
        base, perturbed = median_ms(original_case(name)), median_ms(perturbed_case(name, level))
        rows.append({"type": name, "original_ms": base, f"level{level}_ms": perturbed,
                     "ratio": round(perturbed / base, 2) if base else 0.0})
    return rows


def format_rows(rows: list[dict[str, Any]]) -> str:
    """A plain-text table of a list of flat dicts (same keys)."""
    header = list(rows[0])
    cells = [[str(row[key]) for key in header] for row in rows]
    widths = [max(len(line[i]) for line in [header, *cells]) for i in range(len(header))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(line, widths)) for line in [header, *cells])
