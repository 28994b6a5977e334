"""Frame ranges as users type them: ``A:B`` (half-open, either end optional) or, where allowed, one frame ``N``.

One parser for the command line (``--frames``) and the web API (``?frames=``); each front end adds its own
field name to the ``ValueError`` message.
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
