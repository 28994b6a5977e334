"""Editor preview latency per Quality (draft, full), side by side in one run, while severity and sun are scrubbed.

Runs the editor in process on a temporary copy of a few stock cases (one seen through the dashcam camera preset,
``{"preset": "dashcam"}``), opens one tab (a headless websocket client) and drags its Severity and Sun altitude
sliders as a browser does (an update every 20 ms, 50 per second). The latency of a change is the time from the
slider update to the first preview image pushed for that state or a later one (a draft in draft quality). Qualities
alternate within every run on the same warm editor, each scrub starts from a state not seen before (the sun's
azimuth moves a little first), and the median over runs of each run's p50 and p95 is printed, in milliseconds.

    python bench/editor_quality.py [--runs 3] [--steps 10] [--json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from app.editor import EditorTab, HeadlessTab, launch_editor
from app.editor.preview import QUALITIES
from app.settings import Settings
from app.state import AppState

REPO = Path(__file__).resolve().parents[1]

SHADOW = "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json"
# (case id in the store, stock file, camera override)
CASES = [("fence_shadow-03_level3", SHADOW, None),
         ("vehicle-03_level3", "20_traffic/vehicle/00_straight_highway_noon/03_level3.json", None),
         ("fence_shadow-dashcam", SHADOW, {"preset": "dashcam"})]
UPDATE_GAP_S = 0.02  # a slider dragged at 50 updates per second
WAIT_S = 300.0


def copy_cases(scenes: Path) -> None:
    for case_id, relative, camera in CASES:
        data = json.loads((REPO / "scenes" / relative).read_text(encoding="utf-8"))
        if camera is not None:
            data["camera"] = camera
        target = scenes / f"{case_id}.json"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(json.dumps(data), encoding="utf-8")


def first_push_ms(tab: EditorTab, seq: int, changed_at: float) -> float:
    """Milliseconds from a change to the first image pushed from its state or a later one."""
    for pushed_seq, pushed_at in tab.push_log:
        if pushed_seq >= seq and pushed_at >= changed_at:
            return (pushed_at - changed_at) * 1000.0
    raise RuntimeError(f"request {seq} was never pushed")


def drag(tab: EditorTab, handle, values) -> list[float]:
    """Set ``handle`` to each value 20 ms apart (a drag); the latency of every update."""
    marks = []
    for value in values:
        changed_at = time.perf_counter()
        handle.value = value
        marks.append((tab.preview.latest_seq, changed_at))
        time.sleep(UPDATE_GAP_S)
    assert tab.preview.wait_idle(WAIT_S)
    return [first_push_ms(tab, seq, at) for seq, at in marks]


def scrubs(tab: EditorTab, steps: int, fresh: float) -> dict[str, list[float]]:
    """Severity dragged up and down through its levels, then the sun's altitude, from a new sun azimuth."""
    tab.sun.azimuth.value = fresh  # a state no cache has seen
    assert tab.preview.wait_idle(WAIT_S)
    severities = [1 + (i % 8 if i % 8 < 5 else 8 - i % 8) for i in range(steps)]  # 1 2 3 4 5 4 3 2 1 ...
    altitudes = [20.0 + fresh / 10.0 + 2.0 * i for i in range(steps)]
    return {"severity": drag(tab, tab.illusions.severity, severities),
            "sun": drag(tab, tab.sun.altitude, altitudes)}


def stats(values: list[float]) -> tuple[float, float]:
    return float(np.percentile(values, 50)), float(np.percentile(values, 95))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs; the median of their p50 and p95 is printed")
    parser.add_argument("--steps", type=int, default=10, help="slider updates per drag")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    # per (quality, case, slider): each run's (p50, p95)
    per_run: dict[tuple[str, str, str], list[tuple[float, float]]] = {}
    pooled: dict[str, list[list[float]]] = {quality: [[] for _ in range(args.runs)] for quality in QUALITIES}
    with tempfile.TemporaryDirectory(prefix="lanevil-bench-") as tmp:
        scenes = Path(tmp) / "scenes"
        copy_cases(scenes)
        state = AppState.open(Settings(data_dir=Path(tmp) / "data", scenes_dir=scenes, port=0, editor_port=0))
        editor = launch_editor(state, host="127.0.0.1", port=0)
        try:
            with HeadlessTab(editor, timeout=WAIT_S) as tab:
                for case_id, _relative, _camera in CASES:  # warm: kernels, roadside, first compile of each case
                    tab.cases.case_id.value = case_id
                    assert tab.preview.wait_idle(WAIT_S)
                    scrubs(tab, 3, fresh=-170.0)
                fresh = -160.0
                for run in range(args.runs):
                    for quality in QUALITIES if run % 2 == 0 else QUALITIES[::-1]:
                        tab.display.quality.value = quality
                        for case_id, _relative, _camera in CASES:
                            tab.cases.case_id.value = case_id
                            assert tab.preview.wait_idle(WAIT_S)
                            fresh += 7.0
                            for slider, latencies in scrubs(tab, args.steps, fresh).items():
                                per_run.setdefault((quality, case_id, slider), []).append(stats(latencies))
                                pooled[quality][run].extend(latencies)
        finally:
            editor.stop()
            state.jobs.shutdown()
    rows = [{"quality": quality, "case": case_id, "slider": slider,
             "p50_ms": round(float(np.median([p50 for p50, _ in runs])), 1),
             "p95_ms": round(float(np.median([p95 for _, p95 in runs])), 1)}
            for (quality, case_id, slider), runs in per_run.items()]
    overall = {quality: {"p50_ms": round(float(np.median([stats(run)[0] for run in runs])), 1),
                         "p95_ms": round(float(np.median([stats(run)[1] for run in runs])), 1)}
               for quality, runs in pooled.items()}
    if args.json:
        print(json.dumps({"rows": rows, "overall": overall, "runs": args.runs, "steps": args.steps}, indent=2))
        return 0
    print(f"preview latency while dragging (ms; median over {args.runs} runs of each run's p50 / p95)")
    print(f"{'case':<24}{'slider':<10}" + "".join(f"{q + ' p50':>12}{q + ' p95':>12}" for q in QUALITIES))
    for case_id, _relative, _camera in CASES:
        for slider in ("severity", "sun"):
            cells = {row["quality"]: row for row in rows if row["case"] == case_id and row["slider"] == slider}
            print(f"{case_id:<24}{slider:<10}"
                  + "".join(f"{cells[q]['p50_ms']:>12.1f}{cells[q]['p95_ms']:>12.1f}" for q in QUALITIES))
    print(f"{'all':<34}" + "".join(f"{overall[q]['p50_ms']:>12.1f}{overall[q]['p95_ms']:>12.1f}" for q in QUALITIES))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
