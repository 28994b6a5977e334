"""The study's pages in headless Chromium against a live server: the ``/study`` landing page lists open studies, an
organiser creates a study in the browser (cases x frames, uploaded photos, practice, gold and trap items), and a
study still rendering tells participants to wait. Screenshots go to tests/web/_screenshots/study_*.png."""

from __future__ import annotations

import io
import sqlite3
from pathlib import Path

import httpx
import numpy as np
import pytest
from PIL import Image

from app.study.db import connect, db_path
from app.study.records import get_study, set_status, study_items

FENCE = "fence_shadow-00_uphill_rural_noon"  # the fence shadow's representative original

pytestmark = pytest.mark.browser

ADMIN = {"Authorization": "Bearer test-admin"}
TIMEOUT_MS = 30_000


def photo(seed: int) -> bytes:
    pixels = np.random.default_rng(seed).integers(0, 256, (90, 160, 3), dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(pixels, "RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def create_study(live_server, title: str) -> dict:
    spec = {"title": title, "width": 160, "height": 90, "generated": {"cases": ["clean-00_straight_urban"]}}
    response = httpx.post(f"{live_server.url}/api/study/studies", json=spec, headers=ADMIN, timeout=60)
    assert response.status_code == 201, response.text
    return response.json()


def database(live_server) -> sqlite3.Connection:
    return connect(db_path(live_server.state.settings.data_dir))


def test_landing_page_lists_open_studies(page, live_server, screenshot_dir: Path) -> None:
    page.goto(f"{live_server.url}/study")
    page.wait_for_selector("#open-status:has-text('No study is open')", timeout=TIMEOUT_MS)
    ready = create_study(live_server, "Rendered or real?")
    rendering = create_study(live_server, "Not ready yet")
    db = database(live_server)
    try:
        set_status(db, rendering["id"], "rendering")
    finally:
        db.close()
    page.reload()
    link = page.locator(".study-link")
    link.wait_for(timeout=TIMEOUT_MS)
    assert link.all_inner_texts() == ["Rendered or real?"]  # a study still rendering is not offered
    assert link.get_attribute("href") == f"/study/{ready['id']}"
    assert "1 image to rate" in page.locator(".study-list li").inner_text()
    assert page.locator("#admin-link").get_attribute("href") == "/study/admin"
    assert page.title().startswith("Perception study")
    page.screenshot(path=str(screenshot_dir / "study_landing.png"), full_page=True)
    link.click()
    page.wait_for_selector("#screen-consent:not([hidden])", timeout=TIMEOUT_MS)


def test_organiser_creates_a_study_in_the_browser(page, live_server, screenshot_dir: Path) -> None:
    page.goto(f"{live_server.url}/study/admin")
    page.fill("#token", "test-admin")
    page.click("#token-form button")
    page.wait_for_selector("#create:not([hidden]) #case-list label", timeout=TIMEOUT_MS)
    page.fill("#spec-title", "Shadows and photos")
    page.fill("#spec-viewing", "2")
    page.fill("#spec-width", "160")
    page.fill("#spec-height", "90")
    page.fill("#case-filter", "fence level3")
    assert page.locator("#case-list label:visible").count() == 1
    page.check("#case-list input[value='fence_shadow-00_uphill_rural_noon-03_level3']")
    page.fill("#case-filter", "")
    page.check("#case-list input[value='clean-00_straight_urban']")
    page.fill("#spec-frames", "0, 10")
    page.wait_for_selector("#spec-camera option[value=carla]", state="attached", timeout=TIMEOUT_MS)
    page.select_option("#spec-camera", "carla")  # the presets come from the API's schema
    page.set_input_files("#spec-files", [
        {"name": "road_a.png", "mimeType": "image/png", "buffer": photo(1)},
        {"name": "road_b.png", "mimeType": "image/png", "buffer": photo(2)},
    ])
    page.click("[data-add=training]")
    page.click("[data-add=gold]")
    page.click("[data-add=trap]")
    rows = page.locator("#qc-items tbody tr")
    rows.nth(0).locator("[data-key=source]").select_option("case:fence_shadow-00_uphill_rural_noon-01_level1")
    rows.nth(0).locator("[data-key=garble]").uncheck()
    rows.nth(0).locator("[data-key=frame]").fill("500")  # beyond the case's frames: the server names the item
    rows.nth(1).locator("[data-key=source]").select_option("case:clean-01_bend_suburban")
    rows.nth(2).locator("[data-key=source]").select_option("upload:road_b.png")
    rows.nth(2).locator("[data-key=garble]").uncheck()
    rows.nth(2).locator("[data-key=answer]").select_option("4")
    assert "5 scored images (4 rendered, 1 photo), 1 practice, 1 gold and 1 trap items" in \
        page.locator("#create-summary").inner_text()

    page.click("#create-submit")
    page.wait_for_selector("#create-status.error", timeout=TIMEOUT_MS)
    assert "spec.items.0.frame" in page.locator("#create-status").inner_text()
    assert "invalid" in rows.nth(0).get_attribute("class")
    page.locator("#create").screenshot(path=str(screenshot_dir / "study_create_form.png"))

    rows.nth(0).locator("[data-key=frame]").fill("5")
    page.click("#create-submit")
    page.wait_for_selector("#create-status:has-text('is ready')", timeout=120_000)
    page.locator("#create").screenshot(path=str(screenshot_dir / "study_create_done.png"))
    url = page.locator("#create-status a").get_attribute("href")
    study_id = url.rsplit("/", 1)[1]
    page.wait_for_selector(f"#studies td:has-text('{study_id}')", timeout=TIMEOUT_MS)

    db = database(live_server)
    try:
        items = study_items(db, study_id)
        camera = get_study(db, study_id).camera
    finally:
        db.close()
    assert camera == "carla"
    assert [(item.role, item.case_id or item.upload_name) for item in items] == [
        ("training", f"{FENCE}-01_level1"), ("gold", "clean-01_bend_suburban"), ("trap", "road_b.png"),
        ("test", "clean-00_straight_urban"), ("test", "clean-00_straight_urban"), ("test", f"{FENCE}-03_level3"),
        ("test", f"{FENCE}-03_level3"), ("test", "road_a.png")]
    assert (items[0].frame, items[1].garbled, items[1].gold_min, items[1].gold_max) == (5, 1, 1, 2)
    assert items[2].trap_answer == 4 and items[3].frame == 0 and items[4].frame == 10
    page.screenshot(path=str(screenshot_dir / "study_admin.png"), full_page=True)


def test_a_study_still_rendering_asks_participants_to_wait(page, live_server, screenshot_dir: Path) -> None:
    study = create_study(live_server, "Prepared while you wait")
    db = database(live_server)
    try:
        set_status(db, study["id"], "rendering")
        page.goto(f"{live_server.url}/study/{study['id']}")
        page.wait_for_selector("#screen-preparing:not([hidden])", timeout=TIMEOUT_MS)
        assert page.locator("#screen-error").is_hidden()
        assert "This study is being prepared" in page.locator("#screen-preparing").inner_text()
        page.screenshot(path=str(screenshot_dir / "study_preparing.png"))
        set_status(db, study["id"], "ready")
    finally:
        db.close()
    page.wait_for_selector("#screen-consent:not([hidden])", timeout=TIMEOUT_MS)  # opens by itself
