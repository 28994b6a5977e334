"""The perception study on a real server: 100 concurrent participants, and one participant in headless Chromium."""

from __future__ import annotations

import io
import json
import sqlite3
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest
from PIL import Image
from test_study import ADMIN, image_bytes  # same folder, imported by its base name (no package)

from app.study.db import db_path

FENCE = "fence_shadow-00_uphill_rural_noon"  # the fence shadow's representative original

PARTICIPANTS = 100


def create_live(url: str, spec: dict[str, Any], files: dict[str, bytes]) -> dict[str, Any]:
    parts = [("files", (name, data, "application/octet-stream")) for name, data in files.items()]
    response = httpx.post(f"{url}/api/study/studies", data={"spec": json.dumps(spec)}, files=parts, headers=ADMIN,
                          timeout=120)
    assert response.status_code == 201, response.text
    return response.json()


def photo_bytes(size: tuple[int, int]) -> bytes:
    """A calm stand-in photo made with Pillow: sky and road gradients (PNG)."""
    width, height = size
    t_rows = np.linspace(0.0, 1.0, height)[:, None, None]
    sky = np.array([150, 180, 215]) * (1 - 0.3 * t_rows)
    road = np.array([70, 72, 76]) + 60 * (t_rows - 0.5)
    rgb = np.where(t_rows < 0.5, sky, road) * np.ones((1, width, 1))
    buffer = io.BytesIO()
    Image.fromarray(np.clip(rgb, 0, 255).astype(np.uint8), "RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def count_rows(data_dir: Path, sql: str, *params: Any) -> int:
    with sqlite3.connect(db_path(data_dir)) as db:
        return db.execute(sql, params).fetchone()[0]


def one_participant(url: str, study_id: str) -> list[int]:
    """Consent, rate every item (the first one twice), finish; the HTTP status of every request."""
    statuses = []
    with httpx.Client(base_url=f"{url}/api/study/studies/{study_id}", timeout=60) as client:
        joined = client.post("/participants", json={"consent": True})
        statuses.append(joined.status_code)
        plan = joined.json()
        ratings = f"/participants/{plan['participant_id']}/ratings"
        for index, entry in enumerate(plan["items"]):
            statuses.append(client.post(ratings, json={"item_id": entry["item_id"], "rating": 1 + index % 5}
                                        ).status_code)
        statuses.append(client.post(ratings, json={"item_id": plan["items"][0]["item_id"], "rating": 5}).status_code)
        statuses.append(client.post(f"/participants/{plan['participant_id']}/complete").status_code)
    return statuses


@pytest.mark.slow
def test_concurrent_participants_store_every_rating_once(live_server) -> None:
    spec = {"title": "Load", "width": 160, "height": 90,
            "items": [{"case_id": "clean-00_straight_urban"}, {"case_id": f"{FENCE}-05_level5"},
                      {"upload": "a.png"}, {"upload": "b.jpg"}, {"upload": "a.png", "role": "trap", "answer": 2}]}
    study = create_live(live_server.url, spec, {"a.png": image_bytes(1), "b.jpg": image_bytes(2, "JPEG")})
    started = time.perf_counter()
    with ThreadPoolExecutor(max_workers=PARTICIPANTS) as pool:
        outcomes = list(pool.map(lambda _: one_participant(live_server.url, study["id"]), range(PARTICIPANTS)))
    elapsed = time.perf_counter() - started
    statuses = Counter(status for outcome in outcomes for status in outcome)
    assert not [status for status in statuses if status >= 500], statuses
    items = len(study["items"])
    assert statuses == {201: PARTICIPANTS * (1 + items), 409: PARTICIPANTS, 200: PARTICIPANTS}, statuses
    data_dir = live_server.state.settings.data_dir
    assert count_rows(data_dir, "SELECT COUNT(*) FROM ratings") == PARTICIPANTS * items
    assert count_rows(data_dir, "SELECT COUNT(DISTINCT participant_id || ':' || item_id) FROM ratings") == \
        PARTICIPANTS * items
    assert count_rows(data_dir, "SELECT COUNT(*) FROM participants WHERE completed_at IS NOT NULL") == PARTICIPANTS
    print(f"{PARTICIPANTS} participants x {items + 3} requests in {elapsed:.2f} s")


@pytest.mark.browser
@pytest.mark.slow
def test_participant_completes_a_study_in_chromium(live_server, page, screenshot_dir) -> None:
    spec = {"title": "How natural do these road scenes look?", "width": 320, "height": 180, "viewing_seconds": 0.3,
            "items": [{"case_id": "fence_shadow-00_uphill_rural_noon-01_level1", "role": "training"},
                      {"case_id": "clean-00_straight_urban"}, {"case_id": f"{FENCE}-05_level5", "frame": 30},
                      {"upload": "photo.png"}, {"upload": "photo.png", "role": "trap", "answer": 2}]}
    study = create_live(live_server.url, spec, {"photo.png": photo_bytes((320, 180))})
    roles = {item["id"]: item for item in study["items"]}
    shots = screenshot_dir / "study"
    shots.mkdir(exist_ok=True)

    page.goto(f"{live_server.url}/study/{study['id']}")
    page.wait_for_selector("#screen-consent:not([hidden])")
    assert count_rows(live_server.state.settings.data_dir, "SELECT COUNT(*) FROM participants") == 0
    page.screenshot(path=str(shots / "01_consent.png"))
    assert page.is_disabled("#consent-yes")
    page.check("#consent-check")
    page.click("#consent-yes")
    page.wait_for_selector("#screen-instructions:not([hidden])")
    page.screenshot(path=str(shots / "02_instructions.png"))
    page.click("#start")
    for step in range(len(study["items"])):
        page.wait_for_selector("#stimulus:not([hidden])")
        item_id = int(page.get_attribute("#stimulus", "src").split("/items/")[1].split("/")[0])
        if step in (0, 1):
            page.screenshot(path=str(shots / f"03_viewing_{step}.png"))
        page.wait_for_selector("[data-rating]:not([disabled])")
        if step in (0, 1):
            page.screenshot(path=str(shots / f"04_rating_{step}.png"))
        item = roles[item_id]
        rating = item["trap_answer"] if item["role"] == "trap" else 4
        if step % 2:
            page.keyboard.press(str(rating))
        else:
            page.click(f"[data-rating='{rating}']")
        if item["role"] == "training":
            page.wait_for_selector("#screen-break:not([hidden])")
            page.screenshot(path=str(shots / "05_practice_done.png"))
            page.click("#continue")
    page.wait_for_selector("#screen-done:not([hidden])")
    page.screenshot(path=str(shots / "06_done.png"))

    data_dir = live_server.state.settings.data_dir
    assert count_rows(data_dir, "SELECT COUNT(*) FROM ratings") == len(study["items"])
    assert count_rows(data_dir, "SELECT COUNT(*) FROM participants WHERE completed_at IS NOT NULL") == 1
    results = httpx.get(f"{live_server.url}/api/study/studies/{study['id']}/results", headers=ADMIN).json()
    assert results["participants"]["included"] == 1
    assert results["groups"]["source"]["synthetic"]["mos"] == 4.0

    page.goto(f"{live_server.url}/study/admin#{study['id']}")
    page.fill("#token", "test-admin")
    page.click("#token-form button")
    page.wait_for_selector("#results:not([hidden])")
    page.screenshot(path=str(shots / "07_admin_results.png"), full_page=True)
