"""Two browser tabs on the editor: Save in one tab shows no "stored elsewhere" warning in either, and a real write
from elsewhere (REST) over unsaved edits still does. Screenshot: tests/web/_screenshots/editor_two_tabs_*.png."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from app.editor import Editor, launch_editor
from app.state import AppState

pytestmark = [pytest.mark.browser, pytest.mark.slow]

WAIT_S = 90.0
FOREIGN = "was stored elsewhere"
TOAST = ".mantine-Notification-root"  # viser's notifications (the status line in the panel says it too)


@pytest.fixture
def editor(state: AppState) -> Iterator[Editor]:
    editor = launch_editor(state, host="127.0.0.1", port=0)
    yield editor
    editor.stop()


def wait_for(condition: Callable[[], bool], what: str, timeout: float = WAIT_S) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


def test_save_in_one_of_two_tabs_warns_no_tab(browser, editor: Editor, state: AppState, screenshot_dir: Path) -> None:
    tabs = [browser.new_page(viewport={"width": 1280, "height": 900}) for _ in range(2)]
    for tab in tabs:
        tab.set_default_timeout(WAIT_S * 1000)
        tab.goto(f"http://127.0.0.1:{editor.port}/")
        tab.get_by_role("button", name="Save", exact=True).wait_for()
    wait_for(lambda: len(editor.server.get_clients()) == 2, "both tabs to connect")
    case_id = editor.session.case_id

    editor.panel.title.value = "Edited in a tab"  # an unsaved edit, shared by both tabs
    tabs[0].get_by_role("button", name="Save", exact=True).click()
    wait_for(lambda: state.store.get(case_id).version == 2, "the save")
    time.sleep(2.0)  # a notification would be on screen by now
    for index, tab in enumerate(tabs):
        assert tab.get_by_text(FOREIGN).count() == 0, f"tab {index} warns about its own save"
        assert "saved version 2" in tab.get_by_text("saved version 2").first.inner_text()
    assert state.store.get(case_id).case.title == "Edited in a tab"
    tabs[1].screenshot(path=str(screenshot_dir / "editor_two_tabs_saved.png"))

    editor.panel.title.value = "Edited again, not saved"
    theirs = state.store.get(case_id).case.model_copy(update={"title": "changed over REST"})
    state.store.update(case_id, theirs, expected_version=2)
    for tab in tabs:  # a real foreign write is still reported, in every tab (the toast closes after 8 s)
        tab.locator(TOAST, has_text=FOREIGN).wait_for()
    tabs[0].screenshot(path=str(screenshot_dir / "editor_two_tabs_foreign.png"))
    for tab in tabs:
        assert tab.get_by_text("Version 3 was stored elsewhere").count() >= 1
    for tab in tabs:
        tab.close()
