"""The one numba decorator of the renderer's hot loops.

Fast-math lets LLVM fuse and vectorise arithmetic; ``nnan``/``ninf`` stay off because depth buffers use inf
for "nothing here". Results are deterministic for a given machine and build.
"""

from __future__ import annotations

from typing import Any, Callable

import numba as nb

FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}


def kernel(fn: Callable[..., Any] | None = None, *, inline: str = "never") -> Any:
    """``numba.njit`` with on-disk caching and the renderer's fast-math flags."""
    decorator = nb.njit(cache=True, fastmath=FASTMATH, inline=inline)
    return decorator if fn is None else decorator(fn)
