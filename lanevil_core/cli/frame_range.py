"""Frame ranges as users type them (``A:B``, or one frame ``N``): the parser lives in ``pipeline.frames``."""

from ..pipeline.frames import parse_frame_range

__all__ = ["parse_frame_range"]
