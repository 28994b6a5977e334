"""The one numba decorator of the renderer's hot loops, and a guard for numba's on-disk cache.

Fast-math lets LLVM fuse and vectorise arithmetic; ``nnan``/``ninf`` stay off because depth buffers use inf
for "nothing here". numpy's error model drops the zero check numba puts before every division (Python would
raise ZeroDivisionError; the kernels guard their divisors themselves): 25 % off ``shade`` at 1280x720. Results are
deterministic for a given machine and build.

Array arguments of inlined helpers: numba takes a reference to each on entry (an atomic increment) and releases it
where each path through the helper last uses the array. LLVM drops such a pair when the release is in one block
after the take, but gives up on the large row kernels when the releases are spread over several branches (its
pruner stops at 1000 blocks), and the atomics then run for every pixel. So a helper on the per-pixel path reads
its small arrays before any branch, or ends every path on a use of its arrays: in the sun's shadow lookup and
the sky, that alone took 22 % off ``shade`` at 1280x720, same bytes.

Numba keys a cached kernel on its own source file only, so a kernel that inlines helpers from another module
would keep running stale machine code after that module changes. The guard below drops the package's cache
whenever any renderer source changes.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba as nb

FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}
_PACKAGE = Path(__file__).resolve().parent


def _sources_digest() -> str:
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _drop_stale_cache() -> None:
    cache_dir = _PACKAGE / "__pycache__"
    if os.environ.get("NUMBA_CACHE_DIR"):
        return  # a user-chosen cache location is the user's to manage
    stamp = cache_dir / "lanevil-kernels.sha256"
    digest = _sources_digest()
    try:
        if stamp.read_text() == digest:
            return
    except OSError:
        pass
    try:
        cache_dir.mkdir(exist_ok=True)
        for path in list(cache_dir.glob("*.nbi")) + list(cache_dir.glob("*.nbc")):
            path.unlink(missing_ok=True)
        stamp.write_text(digest)
    except OSError:  # a read-only install: numba then compiles in memory
        pass


_drop_stale_cache()


def kernel(fn: Callable[..., Any] | None = None, *, inline: str = "never") -> Any:
    """``numba.njit`` with on-disk caching, the renderer's fast-math flags, numpy's error model and the GIL
    released (so row bands of one frame run on several threads, see ``bands``)."""
    decorator = nb.njit(  # type: ignore[call-overload]  # a set is a valid fastmath
        cache=True, fastmath=FASTMATH, inline=inline, nogil=True, error_model="numpy")
    return decorator if fn is None else decorator(fn)
