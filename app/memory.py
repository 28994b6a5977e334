"""Keep the server's resident memory near what it uses: fewer glibc malloc arenas.

glibc gives each thread that allocates concurrently its own arena (up to 8 per core) and rarely returns their
freed pages; with the API's thread pool rendering frames (tens of MB of buffers each) the server measured 2.1 GB
peak under 8 concurrent frame clients, against 1.06 GB with two arenas (``bench/server_memory.py``). ``mallopt``
must run before the threads start, so ``lanevil serve`` calls ``limit_malloc_arenas`` first.
"""

from __future__ import annotations

import ctypes
import ctypes.util

M_ARENA_MAX = -8  # glibc's mallopt parameter


def limit_malloc_arenas(arenas: int) -> bool:
    """Cap glibc's malloc arenas at ``arenas`` (0: leave glibc's default); False where there is no glibc."""
    if arenas <= 0:
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        return bool(libc.mallopt(M_ARENA_MAX, arenas))
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to tune
        return False
