"""PNG encoding of real 1280x720 frames: ms per frame and size for each zlib level and filter choice, in one run.

Frames are rendered once (not timed) from a few stock cases, a clean road, traffic, shadows and a wet reflection.
Every setting then encodes every frame, in a rotating order so that the machine's load falls on all alike; the
table gives the median ms per frame, the mean size, and both relative to ``lanevil_core.images.png_bytes`` (the
project's choice, marked ``*``). Each setting's output is decoded once to check it is lossless, and encoded twice
to check it is byte-stable.

Settings: Pillow at zlib levels 0..9 with its adaptive per-row filter, and with zlib's RLE strategy; OpenCV's
``imencode`` at a few levels, and with RLE, with one fixed row filter (sub, up, paeth) or its adaptive choice.

Usage: ``python bench/png_levels.py [--repeat 5] [--json]``
"""

from __future__ import annotations

import argparse
import functools
import io
import json
import statistics
import time
import zlib
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from lanevil_core.case import load_case
from lanevil_core.images import png_bytes
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.typed import UInt8Array

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SIZE = (1280, 720)
FRAMES: tuple[tuple[str, int], ...] = (
    ("00_clean/00_straight_urban.json", 0),
    ("00_clean/02_s_curve_rural.json", 40),
    ("20_traffic/vehicle/00_straight_highway_noon/03_level3.json", 20),
    ("30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json", 0),
    ("40_reflection/streetlight_reflection/00_t_junction_suburban_night/03_level3.json", 10),
    ("10_road_damage/road_crack/00_straight_suburban_cloudy/05_level5.json", 60),
)
Encoder = Callable[[UInt8Array], bytes]
PROJECT = "project"
CV2_FILTERS = {"sub": cv2.IMWRITE_PNG_FILTER_SUB, "up": cv2.IMWRITE_PNG_FILTER_UP,
               "paeth": cv2.IMWRITE_PNG_FILTER_PAETH, "adaptive": cv2.IMWRITE_PNG_ALL_FILTERS}


def pillow_png(rgb: UInt8Array, level: int, strategy: int = -1) -> bytes:
    """Pillow's PNG at zlib ``level`` (adaptive row filters) and zlib ``strategy`` (-1: the default)."""
    buffer = io.BytesIO()
    Image.fromarray(rgb, "RGB").save(buffer, format="PNG", compress_level=level, compress_type=strategy)
    return buffer.getvalue()


def cv2_png(rgb: UInt8Array, level: int, row_filter: int, strategy: int = cv2.IMWRITE_PNG_STRATEGY_DEFAULT) -> bytes:
    """OpenCV's PNG at zlib ``level`` and ``strategy`` with one row filter (or its adaptive choice); channels
    swapped to BGR."""
    params = [cv2.IMWRITE_PNG_COMPRESSION, level, cv2.IMWRITE_PNG_FILTER, row_filter, cv2.IMWRITE_PNG_STRATEGY,
              strategy]
    ok, data = cv2.imencode(".png", np.ascontiguousarray(rgb[..., ::-1]), params)
    if not ok:
        raise RuntimeError("cv2.imencode failed")
    return data.tobytes()


def encoders() -> dict[str, Encoder]:
    """Every setting by name; ``PROJECT`` is ``png_bytes`` itself."""
    table: dict[str, Encoder] = {PROJECT: png_bytes}
    table |= {f"pillow level {level}": functools.partial(pillow_png, level=level) for level in range(10)}
    # zlib's RLE strategy only looks for runs of one byte, so the level makes no difference to it.
    table["pillow rle"] = functools.partial(pillow_png, level=1, strategy=zlib.Z_RLE)
    for level in (1, 3, 6):
        table |= {f"cv2 level {level} {name}": functools.partial(cv2_png, level=level, row_filter=code)
                  for name, code in CV2_FILTERS.items()}
    table |= {f"cv2 rle {name}": functools.partial(cv2_png, level=1, row_filter=code,
                                                   strategy=cv2.IMWRITE_PNG_STRATEGY_RLE)
              for name, code in CV2_FILTERS.items()}
    return table


def render_frames() -> list[UInt8Array]:
    """The (720, 1280, 3) uint8 frames of FRAMES."""
    return [render_frame(compile_scene(load_case(SCENES / path)), frame, SIZE).rgb for path, frame in FRAMES]


def decodes_to(data: bytes, rgb: UInt8Array) -> bool:
    return bool(np.array_equal(np.asarray(Image.open(io.BytesIO(data)).convert("RGB")), rgb))


def measure(frames: list[UInt8Array], table: dict[str, Encoder], repeat: int) -> dict[str, dict[str, float]]:
    """Per setting: median ms per frame, mean bytes, whether it is lossless and byte-stable, and whether its bytes
    are the project's (``is_project``; 1.0 or 0.0 like the checks, so the result stays one JSON-able table)."""
    names = list(table)
    times: dict[str, list[float]] = {name: [] for name in names}
    for turn in range(repeat * len(frames)):
        rgb = frames[turn % len(frames)]
        shift = turn % len(names)
        for name in names[shift:] + names[:shift]:
            start = time.perf_counter()
            table[name](rgb)
            times[name].append((time.perf_counter() - start) * 1000.0)
    results = {}
    project_outputs = [table[PROJECT](rgb) for rgb in frames]
    for name, encode in table.items():
        outputs = [encode(rgb) for rgb in frames]
        results[name] = {
            "is_project": float(outputs == project_outputs),
            "ms": statistics.median(times[name]),
            "bytes": statistics.mean(len(data) for data in outputs),
            "lossless": float(all(decodes_to(data, rgb) for data, rgb in zip(outputs, frames))),
            "stable": float(all(encode(rgb) == data for data, rgb in zip(outputs, frames))),
        }
    return results


def project_setting(results: dict[str, dict[str, float]]) -> str:
    """The name of the setting whose bytes are the project's on every frame."""
    same = [name for name, row in results.items() if name != PROJECT and row["is_project"]]
    return same[0] if same else PROJECT


def report(results: dict[str, dict[str, float]], frames: int, repeat: int) -> str:
    base = results[PROJECT]
    chosen = project_setting(results)
    lines = [f"{frames} frames at {SIZE[0]}x{SIZE[1]}, each encoded {repeat} times per setting; "
             f"* = png_bytes ({chosen})",
             f"  {'setting':<24} {'ms/frame':>9} {'KiB':>7} {'time':>6} {'size':>6}  checks"]
    for name, row in results.items():
        if name == PROJECT and chosen != PROJECT:  # the project's bytes are another setting's: shown there
            continue
        checks = ("lossless" if row["lossless"] else "LOSSY") + (" stable" if row["stable"] else " UNSTABLE")
        lines.append(f"{'*' if name == chosen else ' '} {name:<24} {row['ms']:>9.1f} {row['bytes'] / 1024:>7.0f} "
                     f"{row['ms'] / base['ms']:>5.2f}x {row['bytes'] / base['bytes']:>5.2f}x  {checks}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="encodings of each frame per setting (default 5)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    frames = render_frames()
    results = measure(frames, encoders(), args.repeat)
    if args.json:
        print(json.dumps({"size": list(SIZE), "frames": len(frames), "repeat": args.repeat, "settings": results}))
    else:
        print(report(results, len(frames), args.repeat))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
