"""Which frames of a case's drive: evenly spaced indices, and frame ranges as users type them.

``parse_frame_range`` reads ``A:B`` (half-open, either end optional) or, where allowed, one frame ``N``: one parser
for the command line (``--frames``) and the web API (``?frames=``); each front end adds its own field name to the
``ValueError`` message.
"""

from __future__ import annotations


def parse_frame_range(text: str, frames: int, single: bool = False) -> range:
    """``"10:20"`` -> range(10, 20) of a case with ``frames`` frames (``":"`` = all, ``"90:"``, ``":10"``; with
    ``single``, ``"5"`` -> range(5, 6)). Raises ValueError with a one-line message quoting ``text``."""
    parts = text.split(":")
    try:
        if single and len(parts) == 1:
            start = int(parts[0])
            stop = start + 1
        elif len(parts) == 2:
            start = int(parts[0]) if parts[0].strip() else 0
            stop = int(parts[1]) if parts[1].strip() else frames
        else:
            raise ValueError
    except ValueError:
        forms = "START:STOP or N" if single else "START:STOP"
        raise ValueError(f"{text!r} is not {forms} (e.g. 0:20)") from None
    if not 0 <= start < stop <= frames:
        raise ValueError(f"{text!r} must satisfy 0 <= START < STOP <= {frames} (the case has {frames} frames)")
    return range(start, stop)


def evenly_spaced(total: int, count: int | None) -> tuple[int, ...]:
    """``count`` indices spread evenly over ``0..total-1`` including both ends (all of them when ``count`` is None
    or at least ``total``); one index is frame 0."""
    if count is None or count >= total:
        return tuple(range(total))
    if count == 1:
        return (0,)
    return tuple(i * (total - 1) // (count - 1) for i in range(count))
