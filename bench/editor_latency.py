"""Editor latency: from a GUI change (a panel handle set, as a browser message would) to the pushed preview image.

Runs the editor in process on a temporary copy of a few stock cases, opens one tab (a headless websocket client,
in full quality: exact frames only) and drives its handles: severity, sun
altitude and frame changes, one at a time (each waits for its image) and in bursts (a dragged slider: the
worker coalesces, and the latency of every change is measured to the first push that covers it). Prints median
and p95 per kind of change, in milliseconds, and the compile/render split.

    python bench/editor_latency.py [--repeats 12] [--json]
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path, PurePosixPath

import numpy as np

from app.editor import EditorTab, HeadlessTab, launch_editor
from app.settings import Settings
from app.state import AppState
from app.store import stock_id

REPO = Path(__file__).resolve().parents[1]

CASES = ["00_clean/00_straight_urban.json", "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json",
         "20_traffic/vehicle/00_straight_highway_noon/03_level3.json"]
SHADOW_CASE = 1  # the case of CASES whose severity and sun are changed
BURST_GAP_S = 0.02  # a slider dragged at 50 updates per second


def push_latency_ms(editor: EditorTab, seq: int, changed_at: float) -> float:
    """Milliseconds from a change to the first pushed image rendered from it or a later state."""
    for pushed_seq, pushed_at in editor.push_log:
        if pushed_seq >= seq:
            return (pushed_at - changed_at) * 1000.0
    raise RuntimeError(f"request {seq} was never pushed")


def change(editor: EditorTab, handle, value) -> tuple[int, float]:
    changed_at = time.perf_counter()
    handle.value = value
    return editor.preview.latest_seq, changed_at


def single(editor: EditorTab, handle, values) -> list[float]:
    latencies = []
    for value in values:
        seq, at = change(editor, handle, value)
        editor.preview.wait_idle(120)
        latencies.append(push_latency_ms(editor, seq, at))
    return latencies


def burst(editor: EditorTab, handle, values) -> list[float]:
    marks = []
    for value in values:
        marks.append(change(editor, handle, value))
        time.sleep(BURST_GAP_S)
    editor.preview.wait_idle(120)
    return [push_latency_ms(editor, seq, at) for seq, at in marks]


def stats(values: list[float]) -> dict[str, float]:
    return {"median_ms": round(float(np.median(values)), 1), "p95_ms": round(float(np.percentile(values, 95)), 1),
            "n": len(values)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=12, help="changes per kind")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="lanevil-bench-") as tmp:
        scenes = Path(tmp) / "scenes"
        for relative in CASES:
            (scenes / relative).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(REPO / "scenes" / relative, scenes / relative)
        state = AppState.open(Settings(data_dir=Path(tmp) / "data", scenes_dir=scenes, port=0, editor_port=0))
        case_id = stock_id(PurePosixPath(CASES[SHADOW_CASE]))  # the store's id of that file, as seeding names it
        if case_id not in state.store:
            raise SystemExit(f"{CASES[SHADOW_CASE]} was not seeded as {case_id!r}; the store holds "
                             f"{', '.join(record.id for record in state.store.list())}")
        server = launch_editor(state, host="127.0.0.1", port=0)
        try:
            with HeadlessTab(server, timeout=300) as editor:
                editor.display.quality.value = "full"
                editor.cases.case_id.value = case_id
                editor.preview.wait_idle(300)
                editor.illusions.selected.value = editor.illusions.selected.options[1]
                editor.preview.wait_idle(300)
                n = args.repeats
                frames = [(i * 7) % 90 + 1 for i in range(n)]
                severities = [(i % 5) + 1 for i in range(n)]
                altitudes = [10.0 + 5 * (i % 12) for i in range(n)]
                single(editor, editor.display.frame, [0, 1])  # warm the kernels and caches
                results = {
                    "frame": stats(single(editor, editor.display.frame, frames)),
                    "severity": stats(single(editor, editor.illusions.severity, severities)),
                    "sun_altitude": stats(single(editor, editor.sun.altitude, altitudes)),
                    "frame_drag": stats(burst(editor, editor.display.frame, list(range(10, 10 + 2 * n)))),
                    "sun_drag": stats(burst(editor, editor.sun.altitude, [20.0 + i for i in range(2 * n)])),
                    "renders_dropped_by_coalescing": editor.preview.dropped,
                    "compiles": {"full": state.frames.full_compiles, "partial": state.frames.partial_compiles},
                }
        finally:
            server.stop()
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for name, value in results.items():
            print(f"{name:>30}: {value}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
