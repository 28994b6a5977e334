"""Keep the server's resident memory near what it uses: fewer glibc malloc arenas, large blocks always mapped.

glibc gives each thread that allocates concurrently its own arena (up to 8 per core) and rarely returns their
freed pages, and after a large block is freed it raises its mmap threshold (up to 32 MB), so later frame buffers
come from the heap and fragment it. With the API's thread pool rendering frames (tens of MB of buffers each), two
arenas and a fixed 1 MB threshold (blocks above it are mapped and unmapped whole) keep the resident memory near the
live data (``bench/server_memory.py``, docs/performance.md). ``mallopt`` must run before the threads start, so
``lanevil serve`` calls ``limit_malloc_arenas`` first.
"""

from __future__ import annotations

import ctypes
import ctypes.util

M_ARENA_MAX = -8  # glibc's mallopt parameters
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_BYTES = 1 << 20


def limit_malloc_arenas(arenas: int) -> bool:
    """Cap glibc's malloc arenas at ``arenas`` and map every block over ``MMAP_THRESHOLD_BYTES`` (0: leave glibc's
    defaults); False where there is no glibc."""
    if arenas <= 0:
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        return bool(libc.mallopt(M_ARENA_MAX, arenas)) and bool(libc.mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES))
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to tune
        return False
