"""The editor's "Drive" folder: the closed loop (``lanevil_core.drive``) for the open case, played back in the panel.

**Drive** queues a backend drive job (the same job as ``POST /api/drives``) with the detector chosen in the
preview's Detector dropdown (none chosen: the ground truth, the reference) and the controller chosen here. While it
runs the folder shows its progress; when it is done it plays the drive's video (ground truth and detected lanes
drawn) frame by frame, shows the deviation plot and the verdict of the paper's criterion. **Replay** plays it again.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import viser

from lanevil_core.case import Case
from lanevil_core.drive.controllers import CONTROLLERS
from lanevil_core.drive.detectors import GROUND_TRUTH
from lanevil_core.drive.loop import DEFAULT_SIZE, DriveSettings
from lanevil_core.drive.outputs import SUMMARY_FILE, TRACE_PLOT_FILE
from lanevil_core.drive.summary import verdict

from ..jobs import Job, drive_job
from ..state import AppState
from .detection import detector_choices
from .text import escape_markdown

POLL_S = 0.5
MAX_FRAMES = 600
BLANK = np.full((DEFAULT_SIZE[1], DEFAULT_SIZE[0], 3), 200, np.uint8)

CurrentCase = Callable[[], tuple[str, Case]]  # (case id, the case as edited)
ChosenDetector = Callable[[], str | None]  # the preview's detector (None = none chosen)


def video_frames(folder: Path, limit: int = MAX_FRAMES) -> list[np.ndarray]:
    """(H, W, 3) uint8 RGB frames of a drive's ``drive.mp4`` (or ``drive.gif``)."""
    mp4, gif = folder / "drive.mp4", folder / "drive.gif"
    frames: list[np.ndarray] = []
    if mp4.is_file():
        capture = cv2.VideoCapture(str(mp4))
        while len(frames) < limit:
            ok, bgr = capture.read()
            if not ok:
                break
            frames.append(np.ascontiguousarray(bgr[..., ::-1]))
        capture.release()
    elif gif.is_file():
        from PIL import Image, ImageSequence

        with Image.open(gif) as image:
            frames = [np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(image)][:limit]
    return frames


def verdict_text(summary: dict) -> str:
    """Markdown: the paper's criterion on the drive, max deviation, departures."""
    exceed = f"at {summary['t_exceed']:.1f} s" if summary.get("t_exceed") is not None else "never"
    phrase = verdict(summary["success"], summary.get("illusion_span") is not None, summary["max_abs_deviation"])
    return (f"**{phrase}** (attack: |deviation| > 0.285 m within 2.5 s of coming into view) · > 0.285 m {exceed} · "
            f"max {summary['max_abs_deviation']:.3f} m · lane departure {'yes' if summary['lane_departure'] else 'no'}"
            f" · off road {'yes' if summary['off_road'] else 'no'} · {escape_markdown(summary['detector'])} + "
            f"{escape_markdown(summary['controller'])}")


class DrivePanel:
    """The Drive folder's inputs, the running job and the playback thread."""

    def __init__(self, gui: viser.GuiApi, state: AppState, current: CurrentCase,
                 chosen_detector: ChosenDetector | None = None) -> None:
        self.state = state
        self.current = current
        self.chosen_detector = chosen_detector
        self.job: Job | None = None
        self.frames: list[np.ndarray] = []
        self.fps = 10.0
        self._play_token = 0
        self._stopped = threading.Event()
        with gui.add_folder("Drive (closed loop)", expand_by_default=False):
            self.own_detector = None if chosen_detector is not None else gui.add_dropdown(
                "Detector", [GROUND_TRUTH, *detector_choices()[1:]], initial_value=GROUND_TRUTH,
                hint="gt = the projected ground truth")
            self.controller = gui.add_dropdown("Controller", list(CONTROLLERS), initial_value=CONTROLLERS[0],
                                               hint="lateral controller steering the kinematic bicycle model")
            self.seconds = gui.add_slider("Seconds", 1.0, 30.0, 1.0, 10.0, hint="how long to drive")
            self.button = gui.add_button("Drive", icon=viser.Icon.STEERING_WHEEL,
                                         hint="drive the open case with the preview's detector in the loop "
                                              "(none chosen: the ground truth)")
            self.status = gui.add_markdown("")
            self.video = gui.add_image(BLANK, label="Drive", format="jpeg", jpeg_quality=85)
            self.plot = gui.add_image(BLANK, label="Deviation over time", format="png")
            self.replay = gui.add_button("Replay", icon=viser.Icon.PLAYER_PLAY, disabled=True)
        self.button.on_click(lambda event: self._start_clicked())
        self.replay.on_click(lambda event: self.play())

    def _start_clicked(self) -> None:
        self.start()

    def detector(self) -> str:
        if self.own_detector is not None:
            return str(self.own_detector.value)
        return (self.chosen_detector() if self.chosen_detector is not None else None) or GROUND_TRUTH

    def start(self) -> Job | None:
        """Queue a drive of the open case; returns the job (None when no case is open)."""
        try:
            case_id, case = self.current()
        except Exception as error:  # noqa: BLE001 - no case open: say why in the folder
            self.status.content = f"⚠ {escape_markdown(error)}"
            return None
        controller = next(name for name in CONTROLLERS if name == self.controller.value)
        settings = DriveSettings(detector=self.detector(), controller=controller,
                                 seconds=float(self.seconds.value), size=DEFAULT_SIZE)
        self.fps = case.ego.fps
        self.job = drive_job(self.state.jobs, case, settings,
                             {"case_id": case_id, "detector": settings.detector, "controller": settings.controller},
                             meshes_dir=self.state.meshes_dir)
        self.status.content = f"driving {escape_markdown(case_id)} with **{escape_markdown(settings.detector)}** …"
        threading.Thread(target=self._follow, args=(self.job,), name="lanevil-editor-drive", daemon=True).start()
        return self.job

    def _follow(self, job: Job) -> None:
        while not job.finished.wait(POLL_S):
            if self._stopped.is_set():
                return
            detector = escape_markdown(job.meta["detector"])
            self.status.content = f"driving with **{detector}**: step {job.done} of {job.total}"
        if self._stopped.is_set():
            return
        if job.status != "done" or job.result is None:
            self.status.content = f"⚠ the drive {job.status}: {escape_markdown(job.error or '')}"
            return
        summary = json.loads((job.result / SUMMARY_FILE).read_text(encoding="utf-8"))
        self.status.content = verdict_text(summary)
        plot = cv2.imread(str(job.result / TRACE_PLOT_FILE))
        if plot is not None:
            self.plot.image = np.ascontiguousarray(plot[..., ::-1])
        frames = video_frames(job.result)
        if self._stopped.is_set():
            return
        self.frames = frames
        self.replay.disabled = not frames
        self.play()

    def stop(self) -> None:
        """Stop following the drive and playing it (the editor is closing)."""
        self._stopped.set()
        self._play_token += 1

    def play(self) -> None:
        """Play the last drive's frames once (a new call restarts it)."""
        self._play_token += 1
        threading.Thread(target=self._play, args=(self._play_token,), name="lanevil-editor-drive-play",
                         daemon=True).start()

    def _play(self, token: int) -> None:
        for frame in self.frames:
            if token != self._play_token or self._stopped.is_set():
                return
            self.video.image = frame
            self._stopped.wait(1.0 / self.fps)
