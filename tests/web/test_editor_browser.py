"""The editor in headless Chromium: the scene loads, a click on the road places an illusion, the severity slider
changes the preview, Save stores the case. Screenshots go to tests/web/_screenshots/editor_*.png."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from app.editor import Editor, launch_editor
from app.editor.preview import PreviewResult
from app.state import AppState

if TYPE_CHECKING:
    from playwright.sync_api import Dialog

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ROAD_CLICK = (470, 660)  # on the ego's carriageway in the start view (camera behind and above the ego)
WAIT_S = 90.0
SHOT_MS = 180_000  # SwiftShader draws slowly on a busy machine


@pytest.fixture
def editor(state: AppState) -> Iterator[Editor]:
    editor = launch_editor(state, host="127.0.0.1", port=0)
    yield editor
    editor.stop()


def open_page(browser, editor: Editor, url: str):
    """A new page on the editor, and the tab the editor built for it."""
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.set_default_timeout(SHOT_MS)
    page.goto(url)
    return page, editor.tab(timeout=WAIT_S)


def wait_for(condition: Callable[[], bool], what: str, timeout: float = WAIT_S) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


def test_place_an_illusion_scrub_severity_and_save(browser, editor: Editor, editor_url: str, state: AppState,
                                                    screenshot_dir: Path) -> None:
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.set_default_timeout(SHOT_MS)
    page.goto(editor_url)
    page.wait_for_selector("canvas", timeout=WAIT_S * 1000)
    tab = editor.tab(timeout=WAIT_S)
    wait_for(lambda: tab.view.surface is not None, "the scene")
    preview = page.locator("img[src^='blob:']").first
    preview.wait_for(timeout=WAIT_S * 1000)
    time.sleep(8)  # meshes fade in
    page.screenshot(path=str(screenshot_dir / "editor_1_opened.png"), timeout=SHOT_MS)

    case_id = tab.session.case_id
    combos = page.locator("input[role=combobox]")
    place = combos.nth(combos.evaluate_all("(inputs) => inputs.findIndex((i) => i.value.startsWith('(pick a type'))"))
    place.click()
    page.get_by_role("option", name="vehicle", exact=True).click()
    wait_for(lambda: tab.illusions.place_type.value == "vehicle", "the Place dropdown")
    page.mouse.click(*ROAD_CLICK)
    wait_for(lambda: any(ill.type == "vehicle" for ill in tab.case.illusions), "the placed vehicle")
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(3)
    page.screenshot(path=str(screenshot_dir / "editor_2_placed.png"), timeout=SHOT_MS)
    before = preview.screenshot(timeout=SHOT_MS)
    placed: Any = tab.case.illusions[-1]  # an illusion placed on the road: it has an s
    assert tab.selected == len(tab.case.illusions) - 1 and 10.0 < placed.s < 80.0

    drag_thumb(page, page.locator("[role=slider][aria-valuemax='5']"), 300)  # to the right end
    wait_for(lambda: tab.case.illusions[-1].severity == 5, "severity 5")
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(2)
    after = preview.screenshot(timeout=SHOT_MS)
    assert after != before, "the preview did not change with the severity"
    page.screenshot(path=str(screenshot_dir / "editor_3_severity.png"), timeout=SHOT_MS)

    page.get_by_role("button", name="Save", exact=True).click()
    wait_for(lambda: state.store.get(case_id).version == 2, "the save")
    stored = state.store.get(case_id).case.illusions[-1]
    assert stored.type == "vehicle" and stored.severity == 5 and stored.s == placed.s
    page.close()


def test_detector_dropdown_draws_lanes_and_scores_the_preview(browser, editor: Editor, editor_url: str, pick,
                                                               screenshot_dir: Path) -> None:
    page, tab = open_page(browser, editor, editor_url)
    wait_for(lambda: tab.view.surface is not None, "the scene")
    preview = page.locator("img[src^='blob:']").first
    preview.wait_for(timeout=WAIT_S * 1000)
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(2)
    before = preview.screenshot(timeout=SHOT_MS)
    seen = [before]
    for current, name in (("none", "hough"), ("hough", "ufld")):
        pick(page, current, name)
        wait_for(lambda name=name: tab.display.detector.value == name, f"the Detector dropdown at {name}")
        assert tab.preview.wait_idle(WAIT_S)
        score = page.get_by_text(f"{name} (magenta):").first
        score.wait_for(timeout=WAIT_S * 1000)
        time.sleep(2)
        shot = preview.screenshot(timeout=SHOT_MS)
        assert shot not in seen, f"the preview did not change with the {name} detector"
        seen.append(shot)
        assert "accuracy" in score.locator("xpath=..").inner_text()
    page.mouse.move(400, 450)  # off the panel: no hover hint over the dropdowns
    time.sleep(1)
    page.screenshot(path=str(screenshot_dir / "editor_4_detector.png"), timeout=SHOT_MS)
    page.close()


def test_camera_preset_and_sliders_in_the_browser(browser, editor: Editor, editor_url: str,
                                                  pick, screenshot_dir: Path) -> None:
    page, tab = open_page(browser, editor, editor_url)
    wait_for(lambda: tab.view.surface is not None, "the scene")
    preview = page.locator("img[src^='blob:']").first
    preview.wait_for(timeout=WAIT_S * 1000)
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(2)
    before = preview.screenshot(timeout=SHOT_MS)
    page.get_by_text("Camera", exact=True).first.click()  # open the folder
    pick(page, "(the case's camera)", "dashcam")
    wait_for(lambda: tab.case.camera.bonnet is not None, "the dash cam's bonnet in the case")
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(2)
    after = preview.screenshot(timeout=SHOT_MS)
    assert after != before, "the preview did not change with the camera preset"
    assert page.get_by_label("Bonnet in view").is_checked()
    page.mouse.move(400, 450)
    time.sleep(1)
    page.screenshot(path=str(screenshot_dir / "editor_5_camera.png"), timeout=SHOT_MS)
    page.close()


INJECTION = '<iframe srcdoc="<script>alert(1)</script>"></iframe><img src=x onerror=alert(2)> [x](javascript:alert(3))'


def test_an_injected_case_and_error_show_as_text(browser, editor: Editor, editor_url: str,
                                                 state: AppState, monkeypatch) -> None:
    record = state.store.create(state.store.list()[0].case.model_copy(
        update={"title": INJECTION, "description": INJECTION}), case_id="injected")
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    dialogs: list[str] = []

    def dismiss(dialog: Dialog) -> None:
        dialogs.append(dialog.message)
        dialog.dismiss()

    page.on("dialog", dismiss)
    page.goto(editor_url)
    page.wait_for_selector("canvas", timeout=WAIT_S * 1000)
    tab = editor.tab(timeout=WAIT_S)
    scripts_before = page.locator("script").count()
    tab.cases.case_id.value = record.id
    assert tab.preview.wait_idle(WAIT_S)

    def fail(*args: object, **kwargs: object) -> None:
        raise FileNotFoundError(f"obstacle model not found: {INJECTION}")

    monkeypatch.setattr(state.frames, "frame", fail)
    tab.display.frame.value = 2
    assert tab.preview.wait_idle(WAIT_S)
    page.get_by_text("obstacle model not found", exact=False).first.wait_for(timeout=WAIT_S * 1000)
    time.sleep(2)
    assert dialogs == []
    assert page.locator("iframe").count() == 0
    assert page.locator("img[src='x']").count() == 0
    assert page.locator("a[href^='javascript']").count() == 0
    assert page.locator("script").count() == scripts_before
    assert "<iframe srcdoc=" in page.get_by_text("obstacle model not found", exact=False).first.inner_text()


def drag_thumb(page, thumb, dx: float) -> None:
    """Drag a slider's thumb ``dx`` pixels sideways (arrow keys would also steer viser's camera)."""
    thumb.scroll_into_view_if_needed()
    box = thumb.bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] / 2 + dx, box["y"] + box["height"] / 2, steps=8)
    page.mouse.up()


def test_quality_dropdown_drafts_while_the_sun_slider_moves(browser, editor: Editor, editor_url: str, pick,
                                                             screenshot_dir: Path) -> None:
    page, tab = open_page(browser, editor, editor_url)
    page.locator("img[src^='blob:']").first.wait_for(timeout=WAIT_S * 1000)
    assert tab.preview.wait_idle(WAIT_S) and tab.display.quality.value == "draft"
    shown: list[bool] = []  # whether each pushed preview was a draft
    publish = tab.preview._publish

    def publish_and_note(result: PreviewResult) -> None:
        shown.append(result.request.draft)
        publish(result)

    tab.preview._publish = publish_and_note
    altitude = page.locator("[role=slider][aria-valuemax='90']")  # Sun altitude, -10 to 90 degrees
    drag_thumb(page, altitude, -120)
    wait_for(lambda: tab.case.sun.altitude != 45.0, "the sun to move")
    assert tab.preview.wait_idle(WAIT_S)
    assert shown[0] and not shown[-1], shown  # drafts first, then the exact frame
    assert tab.last_result.rgb.shape == (360, 640, 3)

    pick(page, "draft", "full")
    wait_for(lambda: tab.display.quality.value == "full", "the Quality dropdown at full")
    assert tab.preview.wait_idle(WAIT_S)
    shown.clear()
    drag_thumb(page, altitude, 80)
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(1)
    assert tab.preview.wait_idle(WAIT_S)
    assert shown and not any(shown), shown
    page.get_by_text("Frame 0 · 640×360").first.wait_for(timeout=WAIT_S * 1000)
    page.mouse.move(400, 450)
    time.sleep(1)
    page.screenshot(path=str(screenshot_dir / "editor_6_quality.png"), timeout=SHOT_MS)
    page.close()
