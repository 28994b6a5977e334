"""The tab's Drive folder: a drive job of the open case with the preview's detector, played back in the panel."""

from __future__ import annotations

import json
import time

from app.editor import EditorTab
from lanevil_core.drive.outputs import SUMMARY_FILE

WAIT_S = 120.0


def test_drive_button_runs_the_open_case_and_plays_it(tab: EditorTab) -> None:
    tab.drive.seconds.value = 1.0
    job = tab.drive.start()
    assert job is not None and job.kind == "drive"
    assert job.meta["detector"] == "gt"  # the preview shows no detector: the ground truth drives
    assert job.finished.wait(WAIT_S) and job.status == "done", job.error
    _wait_for_playback(tab)
    assert len(tab.drive.frames) == 10 and tab.drive.frames[0].shape == (360, 640, 3)
    assert "**LANE KEPT**" in tab.drive.status.content and not tab.drive.replay.disabled


def test_drive_uses_the_preview_detector(tab: EditorTab) -> None:
    tab.display.set_detector("hough")
    tab.drive.seconds.value = 1.0
    job = tab.drive.start()
    assert job is not None and job.meta["detector"] == "hough"
    assert job.finished.wait(WAIT_S) and job.status == "done", job.error
    _wait_for_playback(tab)


def _wait_for_playback(tab: EditorTab) -> None:
    """Until the finished drive's frames are loaded (no video decoding left running when the tab stops)."""
    deadline = time.monotonic() + 10
    while not tab.drive.frames and time.monotonic() < deadline:
        time.sleep(0.1)


def test_the_drive_plot_is_titled_after_the_edited_case(tab: EditorTab) -> None:
    tab.cases.title.value = "Edited, not saved"
    assert tab.session.dirty and tab.state.store.get(tab.session.case_id).case.title != "Edited, not saved"
    tab.drive.seconds.value = 1.0
    job = tab.drive.start()
    assert job is not None and job.finished.wait(WAIT_S) and job.status == "done", job.error
    assert job.result is not None
    summary = json.loads((job.result / SUMMARY_FILE).read_text())
    assert summary["title"] == "Edited, not saved"  # what the deviation plot's title starts with
    _wait_for_playback(tab)
