"""Run render tasks on local processes: a process pool over frame chunks (or in this process for one worker)."""

from __future__ import annotations

import multiprocessing
from collections.abc import Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed

from .plan import RenderTask
from .worker import TaskDone, render_chunk


def run_local(tasks: Sequence[RenderTask], on_done: TaskDone, workers: int) -> None:
    """Render ``tasks`` on ``workers`` processes, calling ``on_done(task, results)`` here as each one finishes.

    Processes are spawned, not forked, so every worker starts clean (numba loads its cached kernels once per
    process). With one worker, or one task, the work runs in this process.
    """
    if workers <= 1 or len(tasks) <= 1:
        for task in tasks:
            on_done(task, render_chunk(task))
        return
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(max_workers=min(workers, len(tasks)), mp_context=context)
    try:
        futures: dict[Future, RenderTask] = {pool.submit(render_chunk, task): task for task in tasks}
        for future in as_completed(futures):
            on_done(futures[future], future.result())
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
