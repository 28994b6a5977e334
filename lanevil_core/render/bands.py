"""Splitting one frame's kernels across threads with output byte-identical to one thread.

Every per-pixel kernel takes ``(band, bands)`` and touches only the rows of its band: rows are grouped in runs
of BAND_ROWS and the runs are dealt round-robin to the bands, so the cheap sky rows at the
top and the busy road rows at the bottom are shared evenly. A pixel's value never depends on which band computed
it (each band walks all of its inputs in the same order and loops over whole rows), hence the same bytes for any
thread count. The kernels release the GIL, so a plain thread pool runs them in parallel.
"""

from __future__ import annotations

import itertools
import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ._jit import kernel

BAND_ROWS = 8
# More bands per thread balance a loaded machine better but repeat per-band work: a 2-thread 640x360 frame took
# 13 % more CPU than one thread with three bands per thread, 6-7 % with one.
BANDS_PER_THREAD = 1


@kernel(inline="always")
def in_band(row: int, band: int, bands: int) -> bool:
    """Whether ``row`` belongs to band ``band`` of ``bands``."""
    return (row // BAND_ROWS) % bands == band


@kernel(inline="always")
def overlaps_band(first: int, last: int, band: int, bands: int) -> bool:
    """Whether any of the rows ``first`` .. ``last`` belongs to band ``band`` of ``bands``."""
    if first > last:
        return False
    if last - first + 1 >= BAND_ROWS * bands:
        return True
    for run in range(first // BAND_ROWS, last // BAND_ROWS + 1):
        if run % bands == band:
            return True
    return False


@kernel(inline="always")
def band_rows(count: int, band: int, bands: int) -> np.ndarray:
    """(k,) int64 the rows (or columns) among ``count`` that belong to band ``band`` of ``bands``, in order."""
    rows = np.empty(count, np.int64)
    k = 0
    for row in range(count):
        if in_band(row, band, bands):
            rows[k] = row
            k += 1
    return rows[:k]


def all_cores() -> int:
    """Threads that use every core this process may run on."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


_POOL_LOCK = threading.Lock()
_pool: ThreadPoolExecutor | None = None
_pool_size = 0


def _workers(count: int) -> ThreadPoolExecutor:
    """The shared pool, grown to at least ``count`` threads."""
    global _pool, _pool_size
    with _POOL_LOCK:
        if _pool is None or _pool_size < count:
            if _pool is not None:
                _pool.shutdown(wait=False)  # its queued bands still run
            _pool = ThreadPoolExecutor(max_workers=count, thread_name_prefix="lanevil-band")
            _pool_size = count
        return _pool


def run_bands(work: Callable[[int, int], None], threads: int) -> None:
    """Call ``work(band, bands)`` for every one of BANDS_PER_THREAD * ``threads`` bands on ``threads`` threads
    (the caller is one of them), each thread taking the next band not yet taken.

    Taking bands as they come lets the caller draw a band whose thread has not started yet; which thread draws a
    band does not change its bytes. Bands never wait on each other, so renders on several threads
    at once share the pool without deadlock.
    """
    if threads <= 1:
        work(0, 1)
        return
    bands = BANDS_PER_THREAD * threads
    taken = itertools.count()  # next() on it is atomic under the GIL

    def take_bands() -> None:
        for band in iter(taken.__next__, None):
            if band >= bands:
                return
            work(band, bands)

    pool = _workers(threads - 1)
    futures = [pool.submit(take_bands) for _ in range(threads - 1)]
    try:
        take_bands()
    finally:
        for future in futures:
            future.result()
