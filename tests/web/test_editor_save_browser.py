"""Browser tabs on the editor: each has its own edits and view settings (a Quality or Detector chosen in one does
not show in a tab opened after); Save in one tab shows no "stored elsewhere" warning in either (the other, clean,
takes the version), and a real write from elsewhere (REST) over a tab's unsaved edits still warns that tab.
Screenshots: tests/web/_screenshots/editor_two_tabs_*.png, editor_tabs_own_settings.png."""

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
SLOW_MS = 180_000  # a click waits for the page, which SwiftShader draws slowly on a busy machine
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


def dropdowns(page) -> list[str]:
    """The values the page's dropdowns show, but the 3D view's (the test fixture switches it as the tab opens)."""
    return page.locator("input[role=combobox]").evaluate_all(
        "(inputs) => inputs.filter((i) => !i.closest('.mantine-Flex-root')?.querySelector('label')?.textContent"
        "  ?.startsWith('3D view')).map((i) => i.value)")


def open_tab(browser, editor: Editor, url: str):
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.set_default_timeout(SLOW_MS)
    newest = max(editor.tabs, default=-1)
    page.goto(url)
    page.get_by_role("button", name="Save", exact=True).wait_for()
    return page, editor.tab(timeout=WAIT_S, after=newest)


def test_save_in_one_of_two_tabs_warns_no_tab(browser, editor: Editor, editor_url: str,
                                              state: AppState, screenshot_dir: Path) -> None:
    (page0, tab0), (page1, tab1) = open_tab(browser, editor, editor_url), open_tab(browser, editor, editor_url)
    assert tab0 is not tab1 and tab0.session.case_id == tab1.session.case_id
    case_id = tab0.session.case_id

    tab0.cases.title.value = "Edited in a tab"  # an unsaved edit of the first tab only
    assert tab1.case.title != "Edited in a tab"
    page0.get_by_role("button", name="Save", exact=True).click()
    wait_for(lambda: state.store.get(case_id).version == 2, "the save")
    time.sleep(2.0)  # a notification would be on screen by now
    for index, page in enumerate((page0, page1)):
        assert page.get_by_text(FOREIGN).count() == 0, f"tab {index} warns about a save it should take"
    page0.get_by_text("saved version 2").first.wait_for()
    page1.get_by_text("version 2 arrived from the store").first.wait_for()  # the clean tab took it
    assert state.store.get(case_id).case.title == tab1.case.title == "Edited in a tab"
    page1.screenshot(path=str(screenshot_dir / "editor_two_tabs_saved.png"))

    tab1.cases.title.value = "Edited again, not saved"  # the second tab's own unsaved edit
    theirs = state.store.get(case_id).case.model_copy(update={"title": "changed over REST"})
    state.store.update(case_id, theirs, expected_version=2)
    page1.locator(TOAST, has_text=FOREIGN).wait_for()  # a foreign write over unsaved edits is reported
    page1.screenshot(path=str(screenshot_dir / "editor_two_tabs_foreign.png"))
    assert page1.get_by_text("Version 3 was stored elsewhere").count() >= 1
    page0.get_by_text("version 3 arrived from the store").first.wait_for()  # the clean tab takes it
    assert page0.get_by_text(FOREIGN).count() == 0 and tab0.case.title == "changed over REST"
    for page in (page0, page1):
        page.close()


def test_view_settings_stay_in_their_tab(browser, editor: Editor, editor_url: str, pick, screenshot_dir: Path) -> None:
    """Quality and Detector chosen in one tab do not show in a tab opened after (open tabs: test_editor_tabs.py)."""
    page0, tab0 = open_tab(browser, editor, editor_url)
    defaults = dropdowns(page0)
    assert "draft" in defaults and "none" in defaults
    pick(page0, "draft", "full")
    pick(page0, "none", "hough")
    wait_for(lambda: (tab0.display.quality.value, tab0.display.detector.value) == ("full", "hough"), "the first tab")
    page1, tab1 = open_tab(browser, editor, editor_url)
    assert tab1 is not tab0 and (tab1.display.quality.value, tab1.display.detector.value) == ("draft", "none")
    assert dropdowns(page1) == defaults
    assert "full" in dropdowns(page0) and "hough" in dropdowns(page0)
    page1.screenshot(path=str(screenshot_dir / "editor_tabs_own_settings.png"), timeout=SLOW_MS)
    for page in (page0, page1):
        page.close()
