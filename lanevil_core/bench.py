"""Renderer benchmark: median milliseconds per frame and per stage over the stock cases.

One warm-up frame per size runs first so numba's compilation is not timed. Each case is compiled once (which packs
its triangles; not timed) and a few frames spread over its drive are timed at every size.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .case import Case, load_case

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


def run_benchmark(
    cases: Sequence[Case], sizes: Sequence[tuple[int, int]] = BENCH_SIZES, frames_per_case: int = 2,
) -> dict[str, dict[str, Any]]:
    """``{"WxH": {"median_ms": float, "stages": {stage: median ms}}}`` for every size.

    Cases are compiled one at a time (and dropped after timing) so memory stays that of one scene.
    """
    from .compile import compile_scene
    from .render import render_frame
    from .render.packed import pack_scene

    warm = compile_scene(cases[0])
    for size in sizes:  # warm-up: numba compilation
        render_frame(warm, 0, size)
    totals: dict[tuple[int, int], list[float]] = {size: [] for size in sizes}
    stages: dict[tuple[int, int], dict[str, list[float]]] = {size: {} for size in sizes}
    for case in cases:
        scene = compile_scene(case)
        pack_scene(scene)  # once per scene, cached on it: not a per-frame cost
        for size in sizes:
            for frame_index in frames_to_time(case, frames_per_case):
                start = time.perf_counter()
                frame = render_frame(scene, frame_index, size)
                totals[size].append((time.perf_counter() - start) * 1000.0)
                for stage, ms in frame.timings.items():
                    stages[size].setdefault(stage, []).append(float(ms))
    return {
        f"{width}x{height}": {
            "median_ms": _median(totals[(width, height)]),
            "stages": {stage: _median(values) for stage, values in stages[(width, height)].items()},
        }
        for width, height in sizes
    }


def format_table(result: dict[str, dict[str, Any]]) -> str:
    """A plain-text table: one row per size, total then every stage (median ms)."""
    stages = sorted({stage for row in result.values() for stage in row["stages"]})
    header = ["size", "ms/frame", *stages]
    rows = [[size, f"{row['median_ms']:.1f}", *(f"{row['stages'].get(stage, 0.0):.1f}" for stage in stages)]
            for size, row in result.items()]
    widths = [max(len(line[i]) for line in [header, *rows]) for i in range(len(header))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(line, widths)) for line in [header, *rows])


def illusion_benchmark(size: tuple[int, int] = (1280, 720), frames: int = 3, level: int = 5) -> list[dict[str, Any]]:
    """Per illusion type: median ms/frame of its stock original and of its ``level`` case, and their ratio."""
    from .compile import compile_scene
    from .illusions import REGISTRY
    from .render import render_frame
    from .render.packed import pack_scene
    from .stock import original_case, perturbed_case

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
