"""The progress bar of a dataset run: tqdm on stderr with frames/s and the remaining time."""

from __future__ import annotations

import sys

from tqdm import tqdm


def progress_bar(total: int, done: int, enabled: bool = True) -> tqdm:
    """A bar over ``total`` frames of which ``done`` were already on disk (the rate counts new frames only)."""
    return tqdm(total=total, initial=done, unit="frame", desc="frames", file=sys.stderr, dynamic_ncols=True,
                smoothing=0.1, mininterval=0.5, disable=not enabled)


def planning_bar(total: int, enabled: bool = True) -> tqdm:
    """A bar over the ``total`` case folders whose in-view frames the planner looks for (a few small renders each;
    minutes for the whole library before the first frame is rendered)."""
    return tqdm(total=total, unit="folder", desc="planning", file=sys.stderr, dynamic_ncols=True, mininterval=0.5,
                disable=not enabled)
