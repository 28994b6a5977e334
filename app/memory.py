"""Keep the server's resident memory near what it uses: fewer glibc malloc arenas, large blocks always mapped.

glibc gives each thread that allocates concurrently its own arena (up to 8 per core) and rarely returns their
freed pages, and after a large block is freed it raises its mmap threshold (up to 32 MB), so later frame buffers
come from the heap and fragment it. With the API's thread pool rendering frames (tens of MB of buffers each), two
arenas and a fixed 1 MB threshold (blocks above it are mapped and unmapped whole) keep the resident memory near the
live data (``bench/server_memory.py``, docs/performance.md). ``mallopt`` must run before the threads start, so
``lanevil serve`` calls ``limit_malloc_arenas`` first.

Freed small blocks (a compile's meshes, pydantic models, numpy arrays under the threshold) stay in the arenas'
heaps, where glibc returns only the top of each heap to the system; after many distinct scenes the server held
several times its live data. ``release_free_memory`` (glibc's ``malloc_trim``) gives every free page back; the
frame service calls it whenever a render slot is released (a few milliseconds against a render's 0.1-3 s).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

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


@functools.cache
def _libc() -> ctypes.CDLL | None:
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name) if name is not None else None
    except OSError:
        return None


def release_free_memory() -> bool:
    """Return the malloc heaps' free pages to the system (glibc's ``malloc_trim(0)``); False where there is no
    glibc."""
    libc = _libc()
    try:
        return libc is not None and bool(libc.malloc_trim(0))
    except AttributeError:  # not glibc
        return False
