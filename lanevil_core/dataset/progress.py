"""The progress bars of a dataset run: tqdm on stderr, first the planning's case folders, then the frames with
frames/s and the remaining time."""

from __future__ import annotations

import sys
from typing import Any

from tqdm import tqdm


def _bar(enabled: bool, **settings: Any) -> tqdm:
    """How every bar of a run looks: on stderr, as wide as the terminal, redrawn at most twice a second."""
    return tqdm(file=sys.stderr, dynamic_ncols=True, mininterval=0.5, disable=not enabled, **settings)


def progress_bar(total: int, done: int, enabled: bool = True) -> tqdm:
    """A bar over ``total`` frames of which ``done`` were already on disk (the rate counts new frames only)."""
    return _bar(enabled, total=total, initial=done, unit="frame", desc="frames", smoothing=0.1)


def planning_bar(total: int, enabled: bool = True) -> tqdm:
    """A bar over the ``total`` case folders whose in-view frames the planner looks for (a few small renders each;
    minutes for the whole library before the first frame is rendered)."""
    return _bar(enabled, total=total, unit="folder", desc="planning")
