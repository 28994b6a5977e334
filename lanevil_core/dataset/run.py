"""A dataset run: plan, keep what is already on disk and verified, render the rest, then write labels and manifest.

Resume: a frame is kept when its sidecar carries the frame's key (``manifest.frame_key``) and the image file still
has the sha256 the sidecar recorded; anything else (missing, truncated, corrupt, from other settings or from
other code: the key holds the digest of the render-path sources) is rendered again. Label files and the manifest
are rebuilt from the sidecars at the end of every run.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .manifest import build_manifest, frame_key, software_versions
from .plan import (
    SPLIT_LABELS,
    DatasetPlan,
    Mapper,
    PlannedCase,
    RenderTask,
    Settings,
    build_plan,
    discover_cases,
    render_tasks,
    split_sources,
    threads_map,
)
from .progress import planning_bar, progress_bar
from .worker import FrameResult, TaskDone
from .writer import DatasetFolder

Executor = Callable[[Sequence[RenderTask], TaskDone], None]
# An executor may also have ``start()`` (called before planning, e.g. to spawn workers), ``map(fn, items)`` (the
# planner's in-view search runs on it) and ``close()`` (called after the run, also when it fails): see
# ``local.LocalPool``.


@dataclass(frozen=True)
class RunSummary:
    """What a run did: frames in the plan, frames rendered now, frames kept from disk, the wall time (s) of the
    whole run (worker start-up, planning, resume checks, label files and manifest included) and of its rendering
    alone (from the first task handed out to the last one written)."""

    out_dir: Path
    total: int
    rendered: int
    kept: int
    seconds: float
    render_seconds: float

    @property
    def frames_per_second(self) -> float:
        """Rendered frames per second of rendering wall time (0 when nothing was rendered): the progress bar's
        rate, averaged over the whole rendering."""
        return self.rendered / self.render_seconds if self.rendered and self.render_seconds > 0 else 0.0


class _Sidecars:
    """The sidecars of every planned frame, gathered from disk and from finished tasks."""

    def __init__(self, plan: DatasetPlan, folder: DatasetFolder, versions: dict[str, str]) -> None:
        self.plan = plan
        self.folder = folder
        self.cases = {case.key: case for case in plan.cases}
        self.keys = {(*case.key, index): frame_key(case, index, plan, versions)
                     for case in plan.cases for index in case.frames}
        self.found: dict[tuple[str, str, int], dict[str, Any]] = {}

    def scan(self) -> dict[tuple[str, str], list[int]]:
        """Collect verified frames; return the frames still to render per (split, folder)."""
        pending: dict[tuple[str, str], list[int]] = {}
        for case in self.plan.cases:
            self.folder.remove_partial(case)
            for index in case.frames:
                sidecar = self.folder.verified(case, index, self.keys[(*case.key, index)])
                if sidecar is None:
                    pending.setdefault(case.key, []).append(index)
                else:
                    self.found[(*case.key, index)] = sidecar
        return pending

    def store(self, task: RenderTask, results: list[FrameResult]) -> None:
        """Write a finished task's frames and sidecars."""
        case = self.cases[(task.split, task.folder)]
        for result in results:
            key = self.keys[(task.split, task.folder, result.frame)]
            self.found[(task.split, task.folder, result.frame)] = self.folder.write_frame(case, result, key)

    def records(self, case: PlannedCase) -> list[dict[str, Any]]:
        """The case's TuSimple records in frame order."""
        return [self.found[(*case.key, index)]["record"] for index in case.frames]

    def hashes(self, case: PlannedCase) -> dict[int, str]:
        """Frame -> sha256 of its file."""
        return {index: self.found[(*case.key, index)]["sha256"] for index in case.frames}


def _finish(plan: DatasetPlan, folder: DatasetFolder, sidecars: _Sidecars, versions: dict[str, str]) -> None:
    """Per-case ``case.json`` and ``labels.json``, the split label files, then the manifest."""
    for split in SPLIT_LABELS:
        cases = plan.split_cases(split)
        if not cases:
            continue
        split_records = []
        for case in cases:
            records = sidecars.records(case)
            folder.write_case_files(case, records)
            split_records += records
        folder.write_split_labels(split, split_records)
    hashes = {case.key: sidecars.hashes(case) for case in plan.cases}
    folder.write_manifest(build_manifest(plan, versions, hashes))


def counted(mapper: Mapper, enabled: bool) -> Mapper:
    """``mapper`` with the planning bar: one step per case folder whose in-view frames are found."""

    def mapped(fn: Callable[[Any], Any], items: list[Any]) -> list[Any]:
        results = []
        with planning_bar(len(items), enabled) as bar:
            for result in mapper(fn, items):
                results.append(result)
                bar.update(1)
        return results

    return mapped


def generate_dataset(cases_dir: Path, out_dir: Path, settings: Settings, executor: Executor,
                     show_progress: bool = True) -> RunSummary:
    """Render the dataset of the cases under ``cases_dir`` into ``out_dir``; frames verified on disk are kept."""
    start = time.perf_counter()
    sources = discover_cases(cases_dir)
    split_sources(sources, settings)  # a run that cannot be planned fails before any worker starts
    getattr(executor, "start", lambda: None)()  # e.g. LocalPool: workers start up while the plan is made
    try:
        mapper = counted(getattr(executor, "map", threads_map), show_progress)
        plan = build_plan(sources, settings, mapper)
        versions = software_versions()  # the render-path sources are hashed before any frame is rendered
        folder = DatasetFolder(out_dir, settings.suffix)
        sidecars = _Sidecars(plan, folder, versions)
        pending = sidecars.scan()
        tasks = render_tasks(plan, pending)
        kept = len(sidecars.found)
        with progress_bar(plan.total_frames, kept, show_progress) as bar:

            def on_done(task: RenderTask, results: list[FrameResult]) -> None:
                sidecars.store(task, results)
                bar.update(len(results))

            render_start = time.perf_counter()
            executor(tasks, on_done)
            render_seconds = time.perf_counter() - render_start
    finally:
        getattr(executor, "close", lambda: None)()
    _finish(plan, folder, sidecars, versions)
    return RunSummary(out_dir, plan.total_frames, plan.total_frames - kept, kept, time.perf_counter() - start,
                      render_seconds)
