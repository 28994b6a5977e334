"""End-to-end dataset throughput: frames/s of ``generate_dataset`` at 1280x720 PNG with labels.

Runs the same small plan (a few stock cases, a few frames each) with 1 and 2 local worker processes and on a Dask
LocalCluster of 1 and 2 single-threaded worker processes, each into a fresh folder, and prints the median
frames/s of every setup and its ratio to one local worker.

What a timed run includes: planning, rendering, labelling, PNG encoding, hashing and the atomic writes of every
frame, label file and manifest. Local runs with two workers also pay for spawning their processes and loading
the cached numba kernels in them (a real run pays it once); the Dask cluster is started, and warmed by one
untimed run, before its timed runs, as a long-lived cluster would be.

Wall-clock rates depend on what else runs on the machine, so the CPU time per frame of the local runs (all
their processes) is printed too: ``cores / cpu_per_frame`` bounds the rate an idle machine could reach.

Usage: ``python bench/dataset_throughput.py [--cases 8] [--frames-per-case 4] [--repeats 3] [--json]``
"""

from __future__ import annotations

import argparse
import functools
import json
import resource
import shutil
import statistics
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from lanevil_core.dataset import Settings, generate_dataset
from lanevil_core.dataset.distributed import run_dask
from lanevil_core.dataset.local import LocalPool
from lanevil_core.dataset.run import Executor

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SIZE = (1280, 720)
TARGET_FPS = 33.0  # the goal on two cores
# One original and one perturbed case per category (plus more in this order when --cases asks for them).
CASES = (
    "10_road_damage/road_crack/00_straight_suburban_cloudy/00_original.json",
    "10_road_damage/road_crack/00_straight_suburban_cloudy/03_level3.json",
    "20_traffic/vehicle/00_straight_highway_noon/00_original.json",
    "20_traffic/vehicle/00_straight_highway_noon/03_level3.json",
    "30_shadow/fence_shadow/00_uphill_rural_noon/00_original.json",
    "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json",
    "40_reflection/sunlight_reflection/00_straight_suburban_noon/00_original.json",
    "40_reflection/sunlight_reflection/00_straight_suburban_noon/03_level3.json",
    "10_road_damage/road_repair/00_bend_urban_noon/05_level5.json",
    "20_traffic/pedestrian/00_crossroad_urban_noon/05_level5.json",
    "30_shadow/rail_shadow/00_straight_urban_noon/05_level5.json",
    "40_reflection/streetlight_reflection/00_t_junction_suburban_night/05_level5.json",
)


def copy_cases(root: Path, count: int) -> Path:
    """A cases folder with the first ``count`` benchmark cases."""
    for relative in CASES[:count]:
        target = root / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(SCENES / relative, target)
    return root


def cpu_seconds() -> float:
    """CPU time (user + system) of this process and of its finished child processes."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


RENDERED: list[int] = []  # frames rendered per run (in-view sampling may find fewer than asked for per case)


def timed_runs(cases: Path, work: Path, settings: Settings, executor: Executor, repeats: int,
               cpu: list[float] | None = None) -> list[float]:
    """frames/s of ``repeats`` runs, each into an empty folder; CPU s per frame of each run appended to ``cpu``."""
    rates = []
    for repeat in range(repeats):
        out = work / f"run{repeat}"
        cpu_start = cpu_seconds()
        summary = generate_dataset(cases, out, settings, executor, show_progress=False)
        RENDERED.append(summary.rendered)
        rates.append(summary.rendered / summary.seconds)
        if cpu is not None:
            cpu.append((cpu_seconds() - cpu_start) / summary.rendered)
        shutil.rmtree(out)
    return rates


@contextmanager
def dask_executor(workers: int) -> Iterator[Executor]:
    """An executor on a fresh LocalCluster of ``workers`` single-threaded worker processes."""
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        yield functools.partial(run_dask, address=cluster.scheduler_address)


def measure(cases: Path, work: Path, settings: Settings, repeats: int) -> dict[str, list[float]]:
    """frames/s per setup (local-1, local-2, dask-1, dask-2) and CPU s per frame of the local setups
    (``cpu-local-1``, ``cpu-local-2``: every process of the run, pool start-up included)."""
    results: dict[str, list[float]] = {}
    for workers in (1, 2):
        if workers == 1:  # load the kernels in this process once, as a spawned worker does per run
            timed_runs(cases, work, settings, LocalPool(workers), 1)
        cpu: list[float] = []
        results[f"local-{workers}"] = timed_runs(cases, work, settings, LocalPool(workers), repeats, cpu)
        results[f"cpu-local-{workers}"] = cpu
    for workers in (1, 2):
        with dask_executor(workers) as executor:
            timed_runs(cases, work, settings, executor, 1)  # warm-up: workers import and load kernels
            results[f"dask-{workers}"] = timed_runs(cases, work, settings, executor, repeats)
    return results


def report(results: dict[str, list[float]], frames: int) -> str:
    """A table of median frames/s, ms/frame, and ratios to one local worker and to the target."""
    base = statistics.median(results["local-1"])
    lines = [f"{frames} frames per run at {SIZE[0]}x{SIZE[1]} PNG with labels; median of "
             f"{len(results['local-1'])} runs",
             f"{'setup':<9} {'frames/s':>9} {'ms/frame':>9} {'vs local-1':>11} {'vs target':>10}  runs"]
    for name, rates in results.items():
        if name.startswith("cpu-"):
            continue
        median = statistics.median(rates)
        runs = " ".join(f"{rate:.2f}" for rate in rates)
        lines.append(f"{name:<9} {median:>9.2f} {1000 / median:>9.0f} {median / base:>10.2f}x "
                     f"{median / TARGET_FPS:>9.3f}x  {runs}")
    cpu_per_frame = statistics.median(results["cpu-local-1"])
    lines.append(f"CPU per frame: {cpu_per_frame * 1000:.0f} ms with 1 worker, "
                 f"{statistics.median(results['cpu-local-2']) * 1000:.0f} ms with 2 (pool start-up included); "
                 f"2 idle cores could give at most {2 / cpu_per_frame:.2f} frames/s")
    lines.append(f"target: {TARGET_FPS:.0f} frames/s on 2 cores")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=8, help=f"stock cases per run (1..{len(CASES)}, default 8)")
    parser.add_argument("--frames-per-case", type=int, default=4, help="frames per case (default 4)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per setup (default 3)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if not 1 <= args.cases <= len(CASES) or args.frames_per_case < 1 or args.repeats < 1:
        parser.error(f"--cases must lie in 1..{len(CASES)}; --frames-per-case and --repeats at least 1")
    settings = Settings(size=SIZE, image_format="png", frames_per_case=args.frames_per_case)
    with tempfile.TemporaryDirectory(prefix="lanevil-bench-") as tmp:
        cases = copy_cases(Path(tmp) / "cases", args.cases)
        results = measure(cases, Path(tmp) / "out", settings, args.repeats)
    frames = max(RENDERED)
    if args.json:
        medians = {name: statistics.median(rates) for name, rates in results.items()}
        print(json.dumps({"frames_per_run": frames, "size": list(SIZE), "runs": results, "median": medians}))
    else:
        print(report(results, frames))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
