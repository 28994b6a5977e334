"""The preview's detector: the Detector dropdown's choices and the line that scores the shown frame.

The preview worker draws the chosen detector's lanes (magenta bands under the ground-truth dots) and the panel
shows the frame's TuSimple accuracy, FP and FN against its labels, so an author sees at once whether the illusion
being placed fools the detector. Lanes and scores come from the frame service (``FrameService.detection``).
"""

from __future__ import annotations

from lanevil_core.detect.frame_detection import FrameDetection
from lanevil_core.detect.registry import detector_names
from lanevil_core.metrics.formats import LaneFileError

from .text import escape_markdown

NO_DETECTOR = "none"


def detector_choices() -> tuple[str, ...]:
    """The dropdown's choices: none, the built-in methods and the configured or installed plug-ins (built-ins only
    when the plug-in configuration is malformed; choosing a plug-in then says why)."""
    try:
        return (NO_DETECTOR, *detector_names())
    except LaneFileError:
        from lanevil_core.detect.split import METHODS

        return (NO_DETECTOR, *METHODS)


def chosen_detector(value: str) -> str | None:
    """The method name of a dropdown value (None for no detector)."""
    return None if value == NO_DETECTOR else value


def rate_text(value: float) -> str:
    """A TuSimple rate for reading: two decimals without trailing zeros (``0``, ``0.2``, ``0.25``)."""
    return f"{value:.2f}".rstrip("0").rstrip(".")


def detection_text(found: FrameDetection) -> str:
    """Markdown, two lines: the detector's verdict on the frame, then its score."""
    fooled = found.fp > 0 or found.fn > 0
    verdict = "✗ **fooled**" if fooled else "✓ not fooled"
    return (f"**{escape_markdown(found.detector)}** (magenta): {verdict} · {len(found.lanes)} lanes found, "
            f"{len(found.gt_lanes)} labelled  \n"
            f"accuracy **{100 * found.accuracy:.1f}%** · FP {rate_text(found.fp)} · FN {rate_text(found.fn)}")


def unavailable_text(detector: str, reason: str) -> str:
    """Markdown: why the chosen detector shows nothing."""
    return f"⚠ **{escape_markdown(detector)}**: {escape_markdown(reason.removeprefix('detector: '))}"
