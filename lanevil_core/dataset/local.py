"""Run render tasks on local processes: a process pool over frame chunks (or in this process for one worker).

``LocalPool`` is the executor a dataset run uses: ``generate_dataset`` starts it before planning, so the workers'
start-up (spawn, imports, loading the cached kernels) overlaps the planner's renders instead of following them.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from typing import Any

from .plan import RenderTask, threads_map
from .worker import TaskDone, render_chunk, warm_up


def run_local(tasks: Sequence[RenderTask], on_done: TaskDone, workers: int) -> None:
    """Render ``tasks`` on ``workers`` processes, calling ``on_done(task, results)`` here as each one finishes.

    Processes are spawned, not forked, so every worker starts clean (numba loads its cached kernels once per
    process). With one worker, or one task, the work runs in this process.
    """
    LocalPool(workers)(tasks, on_done)


def _spawn_pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))


class LocalPool:
    """An executor on ``workers`` spawned processes; ``start()`` spawns them early and warms each one up."""

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self._pool: ProcessPoolExecutor | None = None

    def start(self) -> None:
        """Spawn the workers now (with one worker: nothing to spawn); each renders a tiny frame to load kernels."""
        if self.workers > 1 and self._pool is None:
            self._pool = _spawn_pool(self.workers)
            for _ in range(self.workers):
                self._pool.submit(warm_up)

    def map(self, fn: Callable[[Any], Any], items: list[Any]) -> Iterable[Any]:
        """``fn`` over ``items`` on the started workers (the planner's in-view search, while they have nothing
        else to do); on threads here when no worker was started."""
        if self._pool is None:
            return threads_map(fn, items)
        return self._pool.map(fn, items)  # in order, each result as soon as it and those before it are done

    def close(self) -> None:
        """Stop workers that ``start()`` spawned and no call used (a run that failed while planning)."""
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)  # a warm-up takes a second or two

    def __call__(self, tasks: Sequence[RenderTask], on_done: TaskDone) -> None:
        pool, self._pool = self._pool, None
        if pool is None:
            if self.workers <= 1 or len(tasks) <= 1:
                for task in tasks:
                    on_done(task, render_chunk(task))
                return
            pool = _spawn_pool(min(self.workers, len(tasks)))
        _run_on(pool, tasks, on_done)


def _run_on(pool: Executor, tasks: Sequence[RenderTask], on_done: TaskDone,
            work: Callable[[RenderTask], Any] = render_chunk) -> None:
    """Run ``work`` (rendering) over ``tasks`` on ``pool``, calling ``on_done`` here as each one finishes; the pool
    is shut down after."""
    try:
        futures: dict[Future, RenderTask] = {pool.submit(work, task): task for task in tasks}
        for future in as_completed(futures):
            # Dropped as it is handled: a finished future holds its frames' encoded bytes (0.3-0.6 MB each at
            # 1280x720), which a 58,800-frame run would otherwise keep to the end.
            task = futures.pop(future)
            on_done(task, future.result())
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
