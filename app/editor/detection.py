"""The preview's detector: the Detector dropdown's choices and the line that scores the shown frame.

The preview worker draws the chosen detector's lanes (magenta bands under the ground-truth dots) and the panel
shows the frame's TuSimple accuracy, FP and FN against its labels, so an author sees at once whether the illusion
being placed fools the detector. Lanes and scores come from the frame service (``FrameService.detection``).
"""

from __future__ import annotations

from lanevil_core.detect.split import METHODS
from lanevil_core.frame_detection import FrameDetection

NO_DETECTOR = "none"
DETECTOR_CHOICES: tuple[str, ...] = (NO_DETECTOR, *METHODS)


def chosen_detector(value: str) -> str | None:
    """The method name of a dropdown value (None for no detector)."""
    return None if value == NO_DETECTOR else value


def detection_text(found: FrameDetection) -> str:
    """Markdown: the detector's verdict on the frame and its score."""
    fooled = found.fp > 0 or found.fn > 0
    verdict = "**fooled**" if fooled else "not fooled"
    return (f"**{found.detector}** (magenta) {verdict} · accuracy **{found.accuracy:.2f}** · FP {found.fp:.2f} · "
            f"FN {found.fn:.2f} · {len(found.lanes)} lanes found, {len(found.gt_lanes)} labelled")


def unavailable_text(detector: str, reason: str) -> str:
    """Markdown: why the chosen detector shows nothing."""
    return f"⚠ **{detector}**: {reason.removeprefix('detector: ')}"
