"""Two browser tabs (two headless websocket clients) on one editor: each keeps its own case edits and view settings,
a tab opened later starts from the stored case and the panel's defaults, and the tabs meet only in the store."""

from __future__ import annotations

import json
import operator

import numpy as np

from app.editor import Editor, EditorTab, HeadlessTab
from app.state import AppState
from lanevil_core.drive.outputs import SUMMARY_FILE

SHADOW = "fence_shadow-00_uphill_rural_noon-03_level3"
WAIT_S = 120.0


def settle(tab: EditorTab) -> np.ndarray:
    assert tab.preview.wait_idle(WAIT_S)
    return np.asarray(tab.last_result.rgb)


def opened(tab: EditorTab, case_id: str) -> EditorTab:
    tab.cases.case_id.value = case_id
    settle(tab)
    return tab


VIEW = ("illusions.severity", "sun.azimuth", "sun.altitude", "sun.intensity", "display.detector", "display.quality",
        "display.overlay", "display.frame", "camera.fov", "cases.title")


def shown(tab: EditorTab) -> dict[str, object]:
    """What the tab's panel shows for the settings a user scrubs."""
    return {name: operator.attrgetter(name)(tab).value for name in VIEW}


def test_a_new_tab_inherits_nothing_from_an_open_tab(editor_server: Editor, state: AppState) -> None:
    with HeadlessTab(editor_server, timeout=WAIT_S) as first:
        opened(first, SHADOW)
        fresh = shown(first)
        first.illusions.severity.value = 5
        first.sun.altitude.value = 12.0
        first.sun.azimuth.value = -100.0
        first.display.detector.value = "hough"
        first.display.quality.value = "full"
        first.display.overlay.value = False
        first.display.frame.value = 7
        first.camera.fov.value = 70.0
        settle(first)
        edited = shown(first)
        assert [name for name in VIEW if edited[name] == fresh[name]] == ["sun.intensity", "cases.title"]
        with HeadlessTab(editor_server, timeout=WAIT_S) as second:
            assert second is not first and second.client_id != first.client_id
            assert second.display is not first.display and second.preview is not first.preview
            opened(second, SHADOW)
            assert shown(second) == fresh  # the stored case and the panel's defaults, not the first tab's state
            assert second.case == state.store.get(SHADOW).case and not second.session.dirty
            request = second.last_result.request
            assert (request.detector, request.overlay, request.frame, request.draft) == (None, True, 0, False)

            second.sun.altitude.value = 70.0  # and back: the second tab's edits stay in the second tab
            second.display.detector.value = "birdseye"
            settle(second)
            assert shown(first) == edited and first.case.sun.altitude == 12.0
            assert first.display.detector.value == "hough" and first.case.illusions[0].severity == 5
        assert first.session.dirty and first.case.sun.altitude == 12.0


def test_a_save_in_one_tab_reaches_a_clean_tab_and_warns_an_edited_one(editor_server: Editor,
                                                                         state: AppState) -> None:
    with HeadlessTab(editor_server, timeout=WAIT_S) as first, HeadlessTab(editor_server, timeout=WAIT_S) as second:
        opened(first, SHADOW)
        opened(second, SHADOW)
        first.illusions.severity.value = 1
        assert second.case.illusions[0].severity == 3  # unsaved edits are the first tab's own
        first.cases.save_button.value = True
        assert state.store.get(SHADOW).version == 2
        assert second.case.illusions[0].severity == 1 and second.session.version == 2  # clean: takes it at once
        assert "arrived from the store" in second.status.content
        assert "stored elsewhere" not in first.status.content

        second.sun.altitude.value = 30.0
        first.cases.title.value = "Saved from the first tab"
        first.cases.save_button.value = True
        assert second.case.sun.altitude == 30.0 and second.case.title != "Saved from the first tab"
        assert "Version 3 was stored elsewhere" in second.status.content
        settle(first)
        settle(second)


def test_the_editor_link_opens_its_case_in_the_next_tab_only(editor_server: Editor) -> None:
    with HeadlessTab(editor_server, timeout=WAIT_S) as first:
        first_case = first.session.case_id
        editor_server.open_case(SHADOW)
        assert first.session.case_id == first_case  # an open tab keeps its case
        with HeadlessTab(editor_server, timeout=WAIT_S) as linked:
            assert linked.session.case_id == SHADOW
            settle(linked)
        with HeadlessTab(editor_server, timeout=WAIT_S) as later:
            assert later.session.case_id == first_case
            settle(later)
        settle(first)


def test_each_tab_drives_its_own_edited_case(editor_server: Editor, state: AppState) -> None:
    """The Drive folder's plot is titled (``summary.title``) after the case as edited in that tab."""
    with HeadlessTab(editor_server, timeout=WAIT_S) as first, HeadlessTab(editor_server, timeout=WAIT_S) as second:
        opened(first, SHADOW)
        opened(second, SHADOW)
        first.cases.title.value = "Edited in the first tab"
        jobs = []
        for tab in (first, second):
            tab.drive.seconds.value = 1.0
            jobs.append(tab.drive.start())
        titles = []
        for job in jobs:
            assert job is not None and job.finished.wait(WAIT_S) and job.status == "done", job.error
            assert job.result is not None
            titles.append(json.loads((job.result / SUMMARY_FILE).read_text())["title"])
        assert titles == ["Edited in the first tab", state.store.get(SHADOW).case.title]
