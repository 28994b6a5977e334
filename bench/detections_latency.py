"""Detections endpoint latency: ``GET /api/cases/{id}/frames/{n}/detections`` cold and cached, per size and detector.

Runs the API in process (TestClient) on a temporary copy of one stock case. For each size and detector, every
frame asked for is new to the frame service (cold: render + detection + score); the same requests again are
answered from its detection cache (cached). A third pass asks for frames already rendered but not yet detected
(detect only: the detector and the score alone). Prints median and p95 in milliseconds, and the detector's own
``run_time_ms``.

    python bench/detections_latency.py [--frames 8] [--detectors ufld hough] [--json]
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore", category=DeprecationWarning)
from fastapi.testclient import TestClient  # noqa: E402

from app.main import create_app  # noqa: E402
from app.settings import Settings  # noqa: E402
from app.state import AppState  # noqa: E402

REPO = Path(__file__).resolve().parents[1]

CASE = "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json"
CASE_ID = "fence_shadow-03_level3"
SIZES = [(640, 360), (1280, 720)]


def stats(values: list[float]) -> dict[str, float]:
    return {"median_ms": round(float(np.median(values)), 1), "p95_ms": round(float(np.percentile(values, 95)), 1),
            "n": len(values)}


def timed_get(client: TestClient, url: str) -> tuple[float, dict]:
    started = time.perf_counter()
    response = client.get(url)
    elapsed = (time.perf_counter() - started) * 1000.0
    response.raise_for_status()
    return elapsed, response.json()


def measure(client: TestClient, state: AppState, size: tuple[int, int], detector: str, frames: list[int],
            spare: list[int]) -> dict[str, object]:
    query = f"detector={detector}&width={size[0]}&height={size[1]}"
    urls = [f"/api/cases/{CASE_ID}/frames/{n}/detections?{query}" for n in frames]
    cold = [timed_get(client, url) for url in urls]
    cached = [timed_get(client, url)[0] for url in urls]
    case = state.store.get(CASE_ID).case
    for n in spare:  # rendered, not detected
        state.frames.frame(case, n, size)
    detect_only = [timed_get(client, f"/api/cases/{CASE_ID}/frames/{n}/detections?{query}")[0] for n in spare]
    return {"cold": stats([ms for ms, _ in cold]), "cached": stats(cached), "detect_only": stats(detect_only),
            "run_time_ms": stats([body["run_time_ms"] for _, body in cold]),
            "accuracy_mean": round(float(np.mean([body["accuracy"] for _, body in cold])), 3)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=8, help="frames per size and detector")
    parser.add_argument("--detectors", nargs="+", default=["ufld", "hough"])
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results: dict[str, object] = {}
    with tempfile.TemporaryDirectory(prefix="lanevil-bench-") as tmp:
        scenes = Path(tmp) / "scenes"
        (scenes / CASE).parent.mkdir(parents=True)
        shutil.copyfile(REPO / "scenes" / CASE, scenes / CASE)
        settings = Settings(data_dir=Path(tmp) / "data", scenes_dir=scenes, port=0, editor_port=0)
        state = AppState.open(settings)
        try:
            with TestClient(create_app(settings, state)) as client:
                timed_get(client, f"/api/cases/{CASE_ID}/frames/99/detections?detector=ufld&width=320&height=180")
                step = 2 * args.frames
                for d, detector in enumerate(args.detectors):
                    for s, size in enumerate(SIZES):
                        base = (d * len(SIZES) + s) * step % 90
                        frames = list(range(base, base + args.frames))
                        spare = list(range(base + args.frames, base + step))
                        key = f"{detector} {size[0]}x{size[1]}"
                        results[key] = measure(client, state, size, detector, frames, spare)
        finally:
            state.jobs.shutdown()
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for name, value in results.items():
            print(f"{name:>16}: {value}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
