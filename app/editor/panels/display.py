"""The camera preview and the Frame folder: which frame, playing, the lane overlay, a detector, the quality.

``publish`` shows a finished preview: the image first (latency), its timing line and, for an exact frame, the
detector's score line; the tab then brings the 3D view up to the same state.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

import numpy as np
import viser

from lanevil_core.case import Case
from lanevil_core.metrics.formats import LaneFileError

from ..detection import NO_DETECTOR, chosen_detector, detection_text, detector_choices, unavailable_text
from ..page import BrowserWebGL
from ..preview import PREVIEW_SIZE, QUALITIES, PreviewRequest, PreviewResult
from ..scene_view import VIEW_MODES, ViewMode
from ..session import CaseSession
from ..text import escape_markdown
from .base import EditError, set_value

if TYPE_CHECKING:
    from ..tab import EditorTab

# Where the page reports software WebGL, the tab starts with this 3D view: each frame of the road scene costs the
# browser about two CPU seconds in software, and viser redraws about once a second even when nothing moves.
SOFTWARE_VIEW_MODE: ViewMode = "off"


def software_note(renderer: str) -> str:
    """The line under the preview when the browser draws 3D in software."""
    return (f"⚙ This browser draws 3D in software (*{escape_markdown(renderer)}*): the 3D view starts "
            f"*{SOFTWARE_VIEW_MODE}* and the camera preview is the main view. **3D view** turns it back on.")


class DisplayPanel:
    """What the preview shows, and the frame player."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi, webgl: BrowserWebGL) -> None:
        self.tab = tab
        guarded = tab.guarded
        self.image = gui.add_image(np.full((PREVIEW_SIZE[1], PREVIEW_SIZE[0], 3), 200, np.uint8),
                                   label="Camera preview", format="jpeg", jpeg_quality=90)
        self.info = gui.add_markdown("")
        self.detection = gui.add_markdown("")
        mode: ViewMode = SOFTWARE_VIEW_MODE if webgl.software else "full"
        self.view_mode = gui.add_dropdown("3D view", list(VIEW_MODES), initial_value=mode,
                                          hint="full: shadows and an environment map; light: neither (for a "
                                               "browser without a graphics card); off: the camera preview alone")
        self.view_mode.on_update(guarded(lambda e: self.set_view_mode(str(e.target.value))))
        self.gl_note = gui.add_markdown(software_note(webgl.renderer) if webgl.software else "")
        if mode != "full":
            tab.view.set_mode(mode)
        with gui.add_folder("Frame"):
            self.frame = gui.add_slider("Frame", 0, 99, 1, 0, hint="frame of the ego drive shown in the preview")
            self.frame.on_update(guarded(lambda e: self.set_frame(int(e.target.value))))
            self.play = gui.add_checkbox("Play", False, hint="step through the frames (loops)")
            self.play.on_update(guarded(lambda e: self.set_playing(bool(e.target.value))))
            self.overlay = gui.add_checkbox("Lane overlay", True, hint="draw the ground-truth lanes on the preview")
            self.overlay.on_update(guarded(lambda e: self.set_overlay(bool(e.target.value))))
            self.detector = gui.add_dropdown("Detector", list(detector_choices()), initial_value=NO_DETECTOR,
                                             hint="run a lane detector on the preview: its lanes in magenta, its "
                                                  "TuSimple accuracy / FP / FN under the picture")
            self.detector.on_update(guarded(lambda e: self.set_detector(str(e.target.value))))
            self.quality = gui.add_dropdown("Quality", list(QUALITIES), initial_value="draft",
                                            hint="draft: while a slider moves, a quick half-size preview without the "
                                                 "camera's sensor stage, then the exact frame once it rests; full: "
                                                 "only exact frames")
            self.quality.on_update(guarded(lambda e: self.set_quality(str(e.target.value))))
        self._playing = threading.Event()
        self._stopped = threading.Event()
        self._player = threading.Thread(target=self._play_loop, name="lanevil-editor-play", daemon=True)
        self._player.start()

    def stop(self) -> None:
        """Stop the player."""
        self._stopped.set()
        self._playing.clear()

    # ------------------------------------------------------------------------------------------ actions

    def set_frame(self, frame: int) -> None:
        self.tab.frame = int(np.clip(frame, 0, self.tab.case.ego.frames - 1))
        self.request_preview()

    def set_overlay(self, on: bool) -> None:
        with self.tab.syncing():
            set_value(self.overlay, on)
        self.request_preview()

    def set_detector(self, name: str) -> None:
        """Show ``name``'s lanes and score on the preview (``none``: no detector)."""
        with self.tab.syncing():
            set_value(self.detector, name)
        self.request_preview()

    def set_quality(self, quality: str) -> None:
        """``draft``: quick previews while a slider moves, the exact frame once it rests; ``full``: exact only."""
        if quality not in QUALITIES:
            raise EditError(f"quality: choose one of {', '.join(QUALITIES)}, not {quality!r}")
        with self.tab.syncing():
            set_value(self.quality, quality)
        self.request_preview()

    def set_view_mode(self, mode: str) -> None:
        """Draw the 3D view ``full``, ``light`` or ``off`` (the preview image stays either way)."""
        chosen = next((m for m in VIEW_MODES if m == mode), None)
        if chosen is None:
            raise EditError(f"3D view: choose one of {', '.join(VIEW_MODES)}, not {mode!r}")
        was_off = self.tab.view.mode == "off"
        self.tab.view.set_mode(chosen)
        with self.tab.syncing():
            set_value(self.view_mode, chosen)
        result = self.tab.last_result
        if was_off and chosen != "off" and result is not None and not result.request.draft:
            self.tab.show_3d(result)  # the view skipped every state while it was off

    def set_playing(self, on: bool) -> None:
        (self._playing.set if on else self._playing.clear)()

    def _play_loop(self) -> None:
        tab = self.tab
        while not self._stopped.is_set():
            if not self._playing.wait(0.2) or tab.session is None:
                continue
            started = time.monotonic()
            nxt = (tab.frame + 1) % tab.case.ego.frames
            with tab.syncing():
                set_value(self.frame, nxt)
            self.set_frame(nxt)
            self._stopped.wait(max(0.0, 1.0 / tab.case.ego.fps - (time.monotonic() - started)))

    # ------------------------------------------------------------------------------------------ preview

    def request_preview(self) -> int:
        """Ask the preview worker for the open case at the tab's frame as the inputs say; returns the request's
        sequence number."""
        tab = self.tab
        quality = next(q for q in QUALITIES if q == self.quality.value)
        return tab.preview.request(tab.case, tab.frame, bool(self.overlay.value), detector=self.chosen_detector(),
                                   quality=quality)

    def chosen_detector(self) -> str | None:
        """The detector the preview shows (None: none)."""
        return chosen_detector(str(self.detector.value))

    def publish(self, result: PreviewResult) -> None:
        """Under a pushed preview image: its timing line and (exact frames) the detector's score."""
        timing = f"rendered in {result.render_ms:.0f} ms" if result.render_ms >= 1.0 else "from the frame cache"
        kind = "draft " if result.request.draft else ""
        self.info.content = (f"Frame {result.request.frame} · {kind}{result.rgb.shape[1]}×{result.rgb.shape[0]} · "
                             f"{timing}")
        if not result.request.draft:  # a draft has no detector: the score waits for the exact frame
            self.detection.content = self._detection_text(result.request)

    def _detection_text(self, request: PreviewRequest) -> str:
        """The score line of the preview's detector (from the frame service's cache: the render ran it)."""
        if request.detector is None:
            return ""
        try:
            found = self.tab.state.frames.detection(request.case, request.frame, request.size, request.detector)
        except LaneFileError as error:
            return unavailable_text(request.detector, str(error))
        return detection_text(found)

    def sync(self, case: Case, session: CaseSession) -> None:
        """The frame slider's range and value."""
        self.frame.max = case.ego.frames - 1
        set_value(self.frame, self.tab.frame)
