"""The perception study's routes: creation (uploads, renders, gold, trap), the participant flow, results and CSV."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import sqlite3
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi import FastAPI
from fastapi.testclient import TestClient
from PIL import Image
from pydantic import TypeAdapter

from app.main import create_app
from app.state import AppState
from app.study import bodies
from app.study.db import SCHEMA, connect, db_path
from app.study.order import participant_order
from app.study.records import StudyItem

ADMIN = {"Authorization": "Bearer test-admin"}
SIZE = {"width": 160, "height": 90}
T_975 = {2: 4.302653, 5: 2.570582, 11: 2.200985}  # Student t quantiles (0.975; 2, 5, 11 d.o.f.), from tables


def image_bytes(seed: int, fmt: str = "PNG", size: tuple[int, int] = (160, 90)) -> bytes:
    """A photo stand-in made here with Pillow (noise, so it does not compress to nothing)."""
    pixels = np.random.default_rng(seed).integers(0, 256, (size[1], size[0], 3), dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(pixels, "RGB").save(buffer, format=fmt)
    return buffer.getvalue()


def create(client: TestClient, spec: dict[str, Any], files: dict[str, bytes] | None = None,
           headers: dict[str, str] = ADMIN) -> Any:
    parts = [("files", (name, data, "application/octet-stream")) for name, data in (files or {}).items()]
    return client.post("/api/study/studies", data={"spec": json.dumps(spec)}, files=parts or None,
                       headers=headers)


def with_settings(state: AppState, **changes: Any) -> FastAPI:
    """An app on the same store and services with some settings changed."""
    changed = state.settings.model_copy(update=changes)
    return create_app(changed, dataclasses.replace(state, settings=changed))


def small_study(client: TestClient, **extra: Any) -> dict[str, Any]:
    """Two generated frames, two real uploads, a garbled gold item, a trap item and a training item."""
    spec = {"title": "Naturalness", **SIZE, "viewing_seconds": 0.5, "items": [
        {"case_id": "clean-00_straight_urban", "frame": 0},
        {"case_id": "fence_shadow-00_uphill_rural_noon-03_level3", "frame": 0},
        {"upload": "real_a.png"},
        {"upload": "real_b.jpg"},
        {"case_id": "clean-01_bend_suburban", "role": "gold", "garble": True, "expect": [1, 2]},
        {"upload": "real_a.png", "role": "trap", "answer": 2},
        {"case_id": "fence_shadow-00_uphill_rural_noon-01_level1", "role": "training"},
    ], **extra}
    response = create(client, spec, {"real_a.png": image_bytes(1), "real_b.jpg": image_bytes(2, "JPEG")})
    assert response.status_code == 201, response.text
    return response.json()


def join(client: TestClient, study_id: str) -> dict[str, Any]:
    response = client.post(f"/api/study/studies/{study_id}/participants", json={"consent": True})
    assert response.status_code == 201, response.text
    return response.json()


def rate(client: TestClient, study_id: str, participant_id: str, item_id: int, rating: int) -> Any:
    return client.post(f"/api/study/studies/{study_id}/participants/{participant_id}/ratings",
                       json={"item_id": item_id, "rating": rating, "response_ms": 800})


def test_create_stores_every_image_once(client, state, settings) -> None:
    study = small_study(client)
    assert study["status"] == "ready" and study["viewing_ms"] == 500 and study["job"] is None
    items = study["items"]
    assert [item["role"] for item in items] == ["test", "test", "test", "test", "gold", "trap", "training"]
    assert [item["source"] for item in items] == ["synthetic", "synthetic", "real", "real", "synthetic", "real",
                                                  "synthetic"]
    assert items[1]["illusion_type"] == "fence_shadow" and items[1]["severity"] == 3
    assert items[0]["illusion_type"] is None and items[0]["severity"] == 0
    assert (items[4]["gold_min"], items[4]["gold_max"], items[5]["trap_answer"]) == (1, 2, 2)
    folder = Path(settings.data_dir) / "study" / study["id"] / "items"
    assert sorted(p.name for p in folder.iterdir()) == ["000.png", "001.png", "002.png", "003.jpg", "004.png",
                                                        "005.png", "006.png"]
    renders = state.frames.renders
    real = client.get(items[2]["image_url"])
    assert real.status_code == 200 and real.headers["content-type"] == "image/png"
    assert real.content == image_bytes(1)  # uploads are served byte for byte
    assert client.get(items[3]["image_url"]).headers["content-type"] == "image/jpeg"
    generated = Image.open(io.BytesIO(client.get(items[0]["image_url"]).content))
    assert generated.size == (160, 90)
    trap = np.asarray(Image.open(io.BytesIO(client.get(items[5]["image_url"]).content)).convert("RGB"))
    assert (np.abs(trap.astype(int) - np.asarray(Image.open(io.BytesIO(image_bytes(1))))).sum(axis=2) > 0).mean() > 0.1
    assert state.frames.renders == renders  # served from disk, never rendered again


def test_large_study_renders_in_a_background_job(client, state) -> None:
    cases = ["clean-00_straight_urban", "fence_shadow-00_uphill_rural_noon-05_level5", "clean-01_bend_suburban"]
    spec = {"title": "Many frames", **SIZE, "generated": {"cases": cases,
                                                          "frames": [0, 10, 20]}}
    response = create(client, spec)
    assert response.status_code == 202, response.text
    body = response.json()
    assert body["status"] == "rendering" and body["job"]["kind"] == "study" and len(body["items"]) == 9
    assert client.post(f"/api/study/studies/{body['id']}/participants", json={"consent": True}).status_code == 409
    state.jobs.get(body["job"]["id"]).finished.wait(120)
    detail = client.get(f"/api/study/studies/{body['id']}", headers=ADMIN).json()
    assert detail["status"] == "ready" and detail["job"]["status"] == "done"
    assert client.get(detail["items"][8]["image_url"]).status_code == 200


def test_json_spec_without_uploads(client) -> None:
    spec = {"title": "Synthetic only", **SIZE, "generated": {"cases": ["clean-00_straight_urban"]}}
    response = client.post("/api/study/studies", headers=ADMIN, json=spec)
    assert response.status_code == 201, response.text
    assert [item["case_id"] for item in response.json()["items"]] == ["clean-00_straight_urban"]


def test_a_study_sees_its_cases_through_one_camera_preset(client) -> None:
    """``camera``: every generated item through a preset (the paper's `carla` camera here), recorded with the
    study; without it each case keeps its own camera."""
    images = {}
    for camera in (None, "carla"):
        spec = {"title": f"through {camera}", **SIZE, "camera": camera,
                "generated": {"cases": ["clean-00_straight_urban"], "frames": [20]}}
        response = client.post("/api/study/studies", headers=ADMIN, json=spec)
        assert response.status_code == 201, response.text
        study = response.json()
        assert study["camera"] == camera
        assert client.get(f"/api/study/studies/{study['id']}", headers=ADMIN).json()["camera"] == camera
        images[camera] = np.asarray(Image.open(io.BytesIO(client.get(study["items"][0]["image_url"]).content)))
    assert images[None].shape == images["carla"].shape == (90, 160, 3)
    # the carla camera sits 3 m up on a 90 deg lens with a sensor: another picture of the same drive
    assert np.abs(images[None].astype(int) - images["carla"].astype(int)).mean() > 5.0


def test_a_study_file_of_an_earlier_version_gains_the_camera_column(tmp_path) -> None:
    path = tmp_path / "old" / "study.sqlite3"
    path.parent.mkdir()
    old = sqlite3.connect(path)
    old.executescript(SCHEMA.replace("    camera TEXT,\n", ""))
    old.execute("INSERT INTO studies (id, title, question, consent_text, instructions, viewing_ms, width, height, "
                "status, created_at) VALUES ('a1b2c3d4e5f6', 't', 'q', 'c', 'i', 500, 160, 90, 'ready', 0)")
    old.commit()
    old.close()
    db = connect(path)
    try:
        columns = [row[1] for row in db.execute("PRAGMA table_info(studies)")]
        assert "camera" in columns
        assert tuple(db.execute("SELECT camera, title FROM studies").fetchone()) == (None, "t")
    finally:
        db.close()


def test_a_case_of_two_illusion_types_is_its_own_study_group(client) -> None:
    case = client.get("/api/cases/fence_shadow-00_uphill_rural_noon-03_level3").json()["case"]
    case["illusions"].append({"type": "road_crack", "severity": 2, "s": 60.0})
    assert client.post("/api/cases", json={"id": "two-types", "case": case}).status_code == 201
    spec = {"title": "Mixed", **SIZE, "generated": {"cases": ["two-types"]}}
    response = client.post("/api/study/studies", headers=ADMIN, json=spec)
    assert response.status_code == 201, response.text
    item = response.json()["items"][0]
    assert item["illusion_type"] == "road_crack+fence_shadow" and item["category"] == "mixed"


def test_admin_routes_need_the_token(client, state) -> None:
    spec = {"title": "x", "generated": {"cases": ["clean-00_straight_urban"]}}
    assert create(client, spec, headers={}).status_code == 401
    wrong = create(client, spec, headers={"Authorization": "Bearer nope"})
    assert wrong.status_code == 401 and wrong.json()["field"] == "authorization"
    assert client.get("/api/study/studies").status_code == 401
    closed = with_settings(state, admin_token=None)
    with TestClient(closed) as closed_client:
        answer = closed_client.get("/api/study/studies", headers=ADMIN)
    assert answer.status_code == 403 and "LANEVIL_ADMIN_TOKEN" in answer.json()["detail"]


@pytest.mark.parametrize(("spec", "files", "status", "field"), [
    ({"title": ""}, {}, 422, "spec.title"),
    ({"title": "x", "items": [{"case_id": "no-such-case"}]}, {}, 422, "spec.items.0.case_id"),
    ({"title": "x", "items": [{"case_id": "clean-00_straight_urban", "frame": 5000}]}, {}, 422, "spec.items.0.frame"),
    ({"title": "x", "items": [{"upload": "missing.png"}]}, {}, 422, "spec.items.0.upload"),
    ({"title": "x", "items": [{"case_id": "clean-00_straight_urban", "role": "gold"}]}, {}, 422, "spec.items.0"),
    ({"title": "x", "items": [{"case_id": "clean-00_straight_urban", "role": "trap", "answer": 7}]}, {}, 422,
     "spec.items.0.answer"),
    ({"title": "x", "items": [{"case_id": "clean-00_straight_urban", "role": "training"}]}, {}, 422, "spec.items"),
    ({"title": "x", "width": 99999}, {"a.png": image_bytes(1)}, 422, "spec.width"),
    ({"title": "x"}, {"notes.png": b"this is not an image"}, 422, "files.0"),
    ({"title": "x"}, {"a.gif": b"GIF89a\x01\x00\x01\x00\x00\x00\x00;"}, 422, "files.0"),
    ({"title": "x", "viewing_seconds": 0}, {}, 422, "spec.viewing_seconds"),
    ({"title": "x", "generated": {"cases": ["clean-00_straight_urban"], "frames": [False]}}, {}, 422,
     "spec.generated.frames.0"),
    ({"title": "x", "items": [{"case_id": "clean-00_straight_urban", "frame": "3"}]}, {}, 422, "spec.items.0.frame"),
    ({"title": "x", "width": True}, {}, 422, "spec.width"),
    ({"title": "x", "camera": "gopro"}, {}, 422, "spec.camera"),
])
def test_bad_specs_name_the_field(client, spec, files, status, field) -> None:
    response = create(client, spec, files)
    assert response.status_code == status, response.text
    assert response.json()["field"] == field


def test_spec_that_is_not_json_is_422(client) -> None:
    response = client.post("/api/study/studies", data={"spec": "{nope"}, headers=ADMIN,
                           files=[("files", ("a.png", image_bytes(1), "image/png"))])
    assert response.status_code == 422 and response.json()["field"] == "spec"


def test_upload_over_the_limit_is_413(state) -> None:
    small = with_settings(state, max_upload_bytes=4096)
    with TestClient(small) as small_client:
        response = create(small_client, {"title": "x"}, {"big.png": image_bytes(3, size=(64, 64))})
    assert response.status_code == 413


def test_participant_flow(client) -> None:
    study = small_study(client)
    sid = study["id"]
    page = client.get(f"/study/{sid}")
    assert page.status_code == 200 and "text/html" in page.headers["content-type"]
    assert client.get("/study/0123456789ab").status_code == 404
    public = client.get(f"/api/study/studies/{sid}/public").json()
    assert public["training_items"] == 1 and public["rated_items"] == 6 and "consent_text" in public
    refused = client.post(f"/api/study/studies/{sid}/participants", json={"consent": False})
    assert refused.status_code == 422 and refused.json()["field"] == "consent"
    with sqlite3.connect(db_path(client.app.state.lanevil.settings.data_dir)) as db:
        assert db.execute("SELECT COUNT(*) FROM participants").fetchone()[0] == 0  # nothing before consent
    plan = join(client, sid)
    pid = plan["participant_id"]
    training_id = study["items"][6]["id"]
    assert plan["items"][0] == {"item_id": training_id, "training": True,
                                "image_url": f"/api/study/studies/{sid}/items/{training_id}/image"}
    assert sorted(entry["item_id"] for entry in plan["items"]) == sorted(item["id"] for item in study["items"])
    again = client.get(f"/api/study/studies/{sid}/participants/{pid}").json()
    assert again["items"] == plan["items"] and again["rated"] == []
    first = plan["items"][1]["item_id"]
    assert rate(client, sid, pid, first, 6).json()["field"] == "rating"
    assert rate(client, sid, pid, first, 0).status_code == 422
    assert rate(client, sid, pid, 999_999, 3).status_code == 404
    assert rate(client, sid, "f" * 32, first, 3).status_code == 404
    assert rate(client, "0123456789ab", pid, first, 3).status_code == 404
    assert rate(client, sid, pid, first, 4).status_code == 201
    duplicate = rate(client, sid, pid, first, 2)
    assert duplicate.status_code == 409 and duplicate.json()["field"] == "item_id"
    incomplete = client.post(f"/api/study/studies/{sid}/participants/{pid}/complete")
    assert incomplete.status_code == 409 and incomplete.json()["field"] == "ratings"
    for entry in plan["items"]:
        if entry["item_id"] != first:
            assert rate(client, sid, pid, entry["item_id"], 3).status_code == 201
    assert client.post(f"/api/study/studies/{sid}/participants/{pid}/complete").json()["completed"] is True
    status = client.get(f"/api/study/studies/{sid}/participants/{pid}").json()
    assert status["completed"] and len(status["rated"]) == 7
    with sqlite3.connect(db_path(client.app.state.lanevil.settings.data_dir)) as db:
        rows = db.execute("SELECT rating FROM ratings WHERE participant_id = ? AND item_id = ?", (pid, first))
        assert rows.fetchall() == [(4,)]  # the refused resubmission changed nothing


def test_every_json_answer_matches_its_openapi_model(client) -> None:
    """The models the OpenAPI document names (``app/study/bodies.py``) describe the bodies, no field more or less."""

    def same(model: Any, body: Any) -> None:
        adapter = TypeAdapter(model)
        assert adapter.dump_python(adapter.validate_python(body), mode="json") == body

    study = small_study(client)
    sid = study["id"]
    same(bodies.StudyDetail, study)
    same(list[bodies.StudyRow], client.get("/api/study/studies", headers=ADMIN).json())
    same(bodies.StudyDetail, client.get(f"/api/study/studies/{sid}", headers=ADMIN).json())
    same(list[bodies.OpenStudy], client.get("/api/study/open").json())
    same(bodies.PublicStudy, client.get(f"/api/study/studies/{sid}/public").json())
    plan = join(client, sid)
    same(bodies.ParticipantPlan, plan)
    pid = plan["participant_id"]
    for entry in plan["items"]:
        same(bodies.RatingBody, rate(client, sid, pid, entry["item_id"], 3).json())
    same(bodies.Completed, client.post(f"/api/study/studies/{sid}/participants/{pid}/complete").json())
    same(bodies.ParticipantPlan, client.get(f"/api/study/studies/{sid}/participants/{pid}").json())
    same(bodies.StudyResults, client.get(f"/api/study/studies/{sid}/results", headers=ADMIN).json())


def _item(item_id: int, role: str, position: int) -> StudyItem:
    return StudyItem(item_id, "s", position, role, "real", None, None, None, None, None, None, None, 0, None, None,
                     None, "f", "image/png")


def test_order_is_seeded_by_participant() -> None:
    items = [_item(10, "training", 0), _item(11, "training", 1)] + [_item(20 + i, "test", 2 + i) for i in range(12)]
    first = participant_order(items, "0123456789ab", "a" * 32)
    assert first == participant_order(items, "0123456789ab", "a" * 32)
    assert first[:2] == [10, 11] and sorted(first[2:]) == list(range(20, 32))
    others = {tuple(participant_order(items, "0123456789ab", f"{n:032x}")) for n in range(5)}
    assert len(others) == 5 and tuple(first) not in others


def test_exclusions_and_mos_by_hand(client) -> None:
    study = small_study(client)
    sid = study["id"]
    s_clean, s_fence, r_a, r_b, gold, trap, training = (item["id"] for item in study["items"])
    good = [  # clean, fence (severity 3), real a, real b; gold within [1, 2]; trap answered 2
        {s_clean: 4, s_fence: 3, r_a: 5, r_b: 4, gold: 1, trap: 2, training: 5},
        {s_clean: 5, s_fence: 2, r_a: 4, r_b: 3, gold: 2, trap: 2, training: 1},
        {s_clean: 3, s_fence: 3, r_a: 4, r_b: 5, gold: 1, trap: 2, training: 3},
    ]
    bad = [
        {s_clean: 1, s_fence: 1, r_a: 1, r_b: 1, gold: 4, trap: 2, training: 3},  # fails gold
        {s_clean: 1, s_fence: 1, r_a: 1, r_b: 1, gold: 1, trap: 5, training: 3},  # fails the trap
        {s_clean: 1, s_fence: 1, training: 3},  # incomplete
        {s_clean: 1, s_fence: 1, r_a: 1, r_b: 1, gold: 5, trap: 1, training: 3},  # fails both
    ]
    for answers in good + bad:
        pid = join(client, sid)["participant_id"]
        for item_id, value in answers.items():
            assert rate(client, sid, pid, item_id, value).status_code == 201
    results = client.get(f"/api/study/studies/{sid}/results", headers=ADMIN).json()
    assert results["participants"] == {"total": 7, "included": 3, "excluded": 4,
                                       "excluded_by_reason": {"incomplete": 1, "gold": 2, "trap": 2}}
    groups = results["groups"]

    def check(result: dict[str, Any], values: list[int]) -> None:
        n = len(values)
        mos = sum(values) / n
        std = (sum((v - mos) ** 2 for v in values) / (n - 1)) ** 0.5
        half = T_975[n - 1] * std / n ** 0.5
        assert result["n"] == n
        assert result["mos"] == pytest.approx(mos, abs=1e-9) and result["std"] == pytest.approx(std, abs=1e-9)
        assert result["ci_low"] == pytest.approx(mos - half, abs=1e-5)
        assert result["ci_high"] == pytest.approx(mos + half, abs=1e-5)

    check(groups["source"]["synthetic"], [4, 3, 5, 2, 3, 3])  # MOS 3.3333, CI 2.2495 .. 4.4172
    assert groups["source"]["synthetic"]["ci_low"] == pytest.approx(2.24948, abs=1e-4)
    check(groups["source"]["real"], [5, 4, 4, 3, 4, 5])  # MOS 4.1667
    check(groups["illusion_type"]["clean"], [4, 5, 3])
    check(groups["illusion_type"]["fence_shadow"], [3, 2, 3])
    check(groups["severity"]["0"], [4, 5, 3])
    check(groups["severity"]["3"], [3, 2, 3])
    check(groups["overall"]["all"], [4, 3, 5, 4, 5, 2, 4, 3, 3, 3, 4, 5])
    assert set(groups["item"]) == {str(i) for i in (s_clean, s_fence, r_a, r_b)}  # gold/trap/training unscored
    assert results["ratings"] == {"total": 3 * 7 + 7 + 7 + 3 + 7, "used": 12}

    raw = list(csv.DictReader(io.StringIO(client.get(f"/api/study/studies/{sid}/ratings.csv", headers=ADMIN).text)))
    assert len(raw) == results["ratings"]["total"]
    assert {row["exclusion_reasons"] for row in raw} == {"", "gold", "trap", "incomplete", "gold;trap"}
    summary = client.get(f"/api/study/studies/{sid}/summary.csv", headers=ADMIN)
    assert summary.headers["content-type"].startswith("text/csv")
    rows = {(row["grouping"], row["group"]): row for row in csv.DictReader(io.StringIO(summary.text))}
    assert rows[("source", "synthetic")]["mos"] == "3.3333" and rows[("source", "synthetic")]["n"] == "6"
    assert rows[("source", "real")]["ci_low"] == f"{4.1666667 - 2.570582 * 0.7527727 / 6 ** 0.5:.4f}"


def test_results_of_an_unknown_study_are_404(client) -> None:
    assert client.get("/api/study/studies/0123456789ab/results", headers=ADMIN).status_code == 404
    assert client.get("/api/study/studies/nope/summary.csv", headers=ADMIN).status_code == 404


def test_new_study_is_listed(client) -> None:
    study = small_study(client)
    listing = client.get("/api/study/studies", headers=ADMIN).json()
    assert [entry["id"] for entry in listing] == [study["id"]] and listing[0]["participants"] == 0
    assert time.time() - listing[0]["created_at"] < 600


def test_the_study_landing_page_is_served(client) -> None:
    response = client.get("/study")
    assert response.status_code == 200 and response.headers["content-type"].startswith("text/html")
    assert "Open studies" in response.text and 'href="/study/admin"' in response.text
    assert client.get("/static/study/index.js").status_code == 200
    assert client.get("/static/study/create.js").status_code == 200


def test_open_studies_lists_ready_studies_for_everyone(client, state) -> None:
    assert client.get("/api/study/open").json() == []
    ready = client.post("/api/study/studies", headers=ADMIN,
                        json={"title": "Open one", **SIZE, "generated": {"cases": ["clean-00_straight_urban"]}}).json()
    spec = {"title": "Still rendering", **SIZE, "generated": {"cases": ["clean-00_straight_urban",
                                                                       "fence_shadow-00_uphill_rural_noon-05_level5"],
                                                             "frames": [0, 10, 20, 30, 40]}}
    rendering = create(client, spec).json()
    assert rendering["status"] == "rendering"
    public = client.get(f"/api/study/studies/{rendering['id']}/public").json()
    assert public["status"] == "rendering" and public["preparing"]["total"] == 10
    listed = client.get("/api/study/open").json()  # no token needed
    assert [entry["id"] for entry in listed] == [ready["id"]]
    assert listed[0] == {"id": ready["id"], "title": "Open one", "question": ready["question"], "viewing_ms": 3000,
                         "participant_url": f"/study/{ready['id']}", "training_items": 0, "rated_items": 1}
    assert state.jobs.get(rendering["job"]["id"]).finished.wait(120)
    assert client.get(f"/api/study/studies/{rendering['id']}/public").json()["preparing"] is None
    assert len(client.get("/api/study/open").json()) == 2


def test_spec_may_come_as_a_json_part_and_empty_file_parts_are_skipped(client) -> None:
    """What /docs (Swagger UI) and generated clients send: the spec as an application/json part, an empty file."""
    spec = {"title": "From a client", **SIZE, "generated": {"cases": ["clean-00_straight_urban"]}}
    parts = [("spec", ("blob", json.dumps(spec).encode(), "application/json")),
             ("files", ("", b"", "application/octet-stream")),
             ("files", ("real.png", image_bytes(3), "image/png"))]
    response = client.post("/api/study/studies", files=parts, headers=ADMIN)
    assert response.status_code == 201, response.text
    assert [item["upload_name"] for item in response.json()["items"]] == [None, "real.png"]
