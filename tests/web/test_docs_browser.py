"""``/docs`` and ``/redoc`` render in headless Chromium with every request off this machine blocked, as on a machine
without internet. Screenshots go to tests/web/_screenshots/docs_*.png."""

from __future__ import annotations

import io
import json
from pathlib import Path
from urllib.parse import urlparse

import httpx
import numpy as np
import pytest
from PIL import Image

pytestmark = pytest.mark.browser

LOCAL_HOSTS = {"127.0.0.1", "localhost", "::1", "[::1]"}
TIMEOUT_MS = 30_000


def photo() -> bytes:
    buffer = io.BytesIO()
    Image.fromarray(np.full((90, 160, 3), 120, dtype=np.uint8), "RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def offline(page) -> list[str]:
    """Abort every request to a host other than this machine; return the list of what was blocked."""
    blocked: list[str] = []

    def route(request_route) -> None:
        url = request_route.request.url
        if url.startswith(("data:", "blob:")) or urlparse(url).hostname in LOCAL_HOSTS:
            request_route.continue_()
        else:
            blocked.append(url)
            request_route.abort()

    page.route("**/*", route)
    return blocked


def test_swagger_ui_renders_offline_and_can_create_a_study(page, live_server, screenshot_dir: Path) -> None:
    blocked = offline(page)
    page.goto(f"{live_server.url}/docs")
    title = page.locator(".swagger-ui .info .title")
    title.wait_for(timeout=TIMEOUT_MS)
    assert "LanEvil Studio" in title.inner_text()
    page.wait_for_selector(".opblock", timeout=TIMEOUT_MS)
    assert page.locator(".opblock").count() >= 25
    assert page.locator("button.authorize").count() == 1  # the organiser token scheme
    page.screenshot(path=str(screenshot_dir / "docs_offline.png"))

    page.click("button.authorize")
    page.fill(".auth-container input", "test-admin")
    page.click(".auth-btn-wrapper button.authorize")
    page.click(".auth-btn-wrapper button.btn-done")

    create = page.locator("#operations-study-post_study_api_study_studies_post")
    create.locator(".opblock-summary").click()
    body = create.locator(".opblock-section-request-body")
    spec = body.locator("textarea").first
    spec.wait_for(timeout=TIMEOUT_MS)  # try-it-out mode is on from the start
    assert "multipart/form-data" in body.inner_text()
    assert '"clean-00_straight_urban"' in spec.input_value()
    spec.fill(json.dumps({"title": "Made in /docs", "width": 160, "height": 90,
                          "generated": {"cases": ["clean-00_straight_urban"]}}))
    body.get_by_role("button", name="Add string item").click()
    body.locator("input[type=file]").set_input_files(
        [{"name": "road.png", "mimeType": "image/png", "buffer": photo()}])
    create.locator("button.execute").click()
    status = create.locator(".live-responses-table tbody .response-col_status").first
    status.wait_for(timeout=60_000)
    create.scroll_into_view_if_needed()
    create.screenshot(path=str(screenshot_dir / "docs_offline_create_study.png"))
    assert status.inner_text().strip() == "201", create.locator(".live-responses-table").inner_text()
    studies = httpx.get(f"{live_server.url}/api/study/studies", headers={"Authorization": "Bearer test-admin"})
    assert [study["title"] for study in studies.json()] == ["Made in /docs"]
    detail = httpx.get(f"{live_server.url}/api/study/studies/{studies.json()[0]['id']}",
                       headers={"Authorization": "Bearer test-admin"}).json()
    assert [item["upload_name"] or item["case_id"] for item in detail["items"]] == ["clean-00_straight_urban",
                                                                                    "road.png"]
    assert blocked == [], blocked


def test_redoc_renders_offline(page, live_server) -> None:
    blocked = offline(page)
    page.goto(f"{live_server.url}/redoc")
    page.wait_for_selector("h1:has-text('LanEvil Studio')", timeout=TIMEOUT_MS)
    assert page.locator("text=Create a study (organiser)").count() >= 1
    assert blocked == [], blocked  # ReDoc's "by Redocly" badge image is inlined, not loaded from its CDN
