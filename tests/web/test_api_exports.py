"""Zip exports in the benchmark layout, direct and as background jobs with progress."""

from __future__ import annotations

import io
import json
import time
import zipfile

import pytest
from PIL import Image

import app.api.routes.exports as exports
from lanevil_core.case import Case

SHADOW_ID = "fence_shadow-00_uphill_rural_noon-03_level3"


def wait_for_job(client, url: str, timeout_s: float = 120) -> list[dict]:
    """Poll a job until it finishes; return every state seen."""
    seen = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        seen.append(client.get(url).json())
        if seen[-1]["status"] in ("done", "failed"):
            return seen
        time.sleep(0.1)
    raise AssertionError(f"job at {url} did not finish: {seen[-1]}")


def test_small_export_answers_the_zip_in_benchmark_layout(client) -> None:
    response = client.get(f"/api/cases/{SHADOW_ID}/export.zip?frames=4:6")
    assert response.status_code == 200 and response.headers["content-type"] == "application/zip"
    assert f'filename="{SHADOW_ID}.zip"' in response.headers["content-disposition"]
    archive = zipfile.ZipFile(io.BytesIO(response.content))
    folder = f"Shadow/Fence/{SHADOW_ID}"
    assert sorted(archive.namelist()) == [f"{folder}/{name}" for name in
                                         ("000004.png", "000005.png", "case.json", "labels.json")]
    labels = [json.loads(line) for line in archive.read(f"{folder}/labels.json").decode().splitlines()]
    assert [record["raw_file"] for record in labels] == ["000004.png", "000005.png"]
    assert Image.open(io.BytesIO(archive.read(f"{folder}/000004.png"))).size == (1280, 720)
    case = Case.model_validate_json(archive.read(f"{folder}/case.json"))
    assert case == Case.model_validate(client.get(f"/api/cases/{SHADOW_ID}").json()["case"])
    # the labels match what the labels endpoint serves for those frames
    served = client.get(f"/api/cases/{SHADOW_ID}/labels?frames=4:6").text.splitlines()
    assert [json.loads(line) for line in served] == labels


def test_clean_and_original_cases_use_their_folders(client) -> None:
    clean = zipfile.ZipFile(io.BytesIO(client.get("/api/cases/clean-00_straight_urban/export.zip?frames=0").content))
    assert "Clean/clean-00_straight_urban/000000.png" in clean.namelist()
    original = zipfile.ZipFile(io.BytesIO(
        client.get("/api/cases/fence_shadow-00_uphill_rural_noon-00_original/export.zip?frames=0").content))
    assert "Shadow/Fence/fence_shadow-00_uphill_rural_noon-00_original/labels.json" in original.namelist()


def test_long_export_becomes_a_job(client, monkeypatch) -> None:
    monkeypatch.setattr(exports, "SYNC_EXPORT_FRAMES", 1)
    response = client.get(f"/api/cases/{SHADOW_ID}/export.zip?frames=0:3")
    assert response.status_code == 202
    job = response.json()
    assert job["kind"] == "export" and job["case_id"] == SHADOW_ID and job["total"] == 3
    assert response.headers["location"] == job["links"]["self"]
    seen = wait_for_job(client, response.headers["location"])
    assert seen[-1]["status"] == "done" and seen[-1]["done"] == 3 and seen[-1]["progress"] == 1.0
    progress = [state["progress"] for state in seen]
    assert progress == sorted(progress)
    for body in (job, *seen):  # what the OpenAPI document says the job looks like, no field more or less
        assert exports.ExportJob.model_validate(body).model_dump() == body
    archive = zipfile.ZipFile(io.BytesIO(client.get(job["links"]["download"]).content))
    assert len([name for name in archive.namelist() if name.endswith(".png")]) == 3


def test_default_export_of_every_frame_is_a_job(client, state) -> None:
    """Without ``frames`` the whole case is exported, which is far over the direct limit."""
    assert exports.SYNC_EXPORT_FRAMES == 10
    response = client.get(f"/api/cases/{SHADOW_ID}/export.zip")
    assert response.status_code == 202 and response.json()["total"] == 100
    job = state.jobs.get(response.json()["id"])
    download = client.get(response.json()["links"]["download"])
    assert download.status_code == 409 and download.json()["field"] == "job_id"
    assert client.delete(response.headers["location"]).status_code == 200
    assert job.finished.wait(60)
    assert client.get(response.headers["location"]).json()["status"] == "cancelled"
    assert client.get(response.json()["links"]["download"]).status_code == 409
    assert not list(state.jobs.folder.glob("*.zip"))


def test_post_exports_reports_progress_until_done(client) -> None:
    response = client.post("/api/exports", json={"case_id": "clean-01_bend_suburban", "frames": "10:12"})
    assert response.status_code == 202
    job = response.json()
    assert job["status"] in ("queued", "running") and job["frames"] == "10:12"
    assert job["folder"] == "Clean/clean-01_bend_suburban"
    final = wait_for_job(client, job["links"]["self"])[-1]
    assert final["status"] == "done" and final["finished_at"] >= final["created_at"]
    download = client.get(job["links"]["download"])
    assert download.status_code == 200 and download.headers["content-type"] == "application/zip"
    names = zipfile.ZipFile(io.BytesIO(download.content)).namelist()
    assert "Clean/clean-01_bend_suburban/000011.png" in names


@pytest.mark.parametrize(("body", "status", "field"), [
    ({"case_id": "nothing"}, 404, "case_id"),
    ({"case_id": "../x"}, 422, "case_id"),
    ({"case_id": SHADOW_ID, "frames": "90:200"}, 422, "frames"),
    ({"frames": "0:2"}, 422, "case_id"),
])
def test_post_exports_rejects_bad_requests(client, body: dict, status: int, field: str) -> None:
    response = client.post("/api/exports", json=body)
    assert response.status_code == status and response.json()["field"] == field


@pytest.mark.parametrize("job_id", ["0" * 32, "../../etc", "x"])
def test_unknown_jobs_are_404(client, job_id: str) -> None:
    assert client.get(f"/api/exports/{job_id}").status_code == 404
    assert client.get(f"/api/exports/{job_id}/download").status_code == 404


def test_identical_export_requests_share_one_job(client, state) -> None:
    body = {"case_id": SHADOW_ID, "frames": "0:50"}
    first = client.post("/api/exports", json=body)
    again = client.post("/api/exports", json=body)
    direct = client.get(f"/api/cases/{SHADOW_ID}/export.zip?frames=0:50")
    assert first.status_code == again.status_code == direct.status_code == 202
    assert first.json()["id"] == again.json()["id"] == direct.json()["id"]
    other = client.post("/api/exports", json={"case_id": SHADOW_ID, "frames": "0:49"})
    assert other.json()["id"] != first.json()["id"]
    for job_id in (first.json()["id"], other.json()["id"]):
        client.delete(f"/api/exports/{job_id}")


def test_a_client_past_its_share_of_the_queue_gets_429_with_retry_after(client, state, monkeypatch) -> None:
    monkeypatch.setattr(state.jobs, "max_per_client", 2)
    ids = [client.post("/api/exports", json={"case_id": SHADOW_ID, "frames": f"0:{stop}"}).json()["id"]
           for stop in (90, 91)]
    refused = client.post("/api/exports", json={"case_id": SHADOW_ID, "frames": "0:92"})
    assert refused.status_code == 429 and int(refused.headers["retry-after"]) >= 1
    assert refused.json()["field"] is None and "2 jobs queued or running" in refused.json()["detail"]
    assert client.get(f"/api/cases/{SHADOW_ID}/export.zip?frames=0:93").status_code == 429
    monkeypatch.setattr(state.jobs, "max_unfinished", 2)
    monkeypatch.setattr(state.jobs, "max_per_client", 10)
    full = client.post("/api/exports", json={"case_id": SHADOW_ID, "frames": "0:94"})
    assert full.status_code == 429 and "retry-after" in full.headers
    assert "the most it takes" in full.json()["detail"]
    for job_id in ids:
        client.delete(f"/api/exports/{job_id}")


def test_a_case_of_two_illusion_types_is_filed_under_mixed(client) -> None:
    """Exports and the listing name both types, not only the first illusion's (the study: test_study.py)."""
    case = client.get(f"/api/cases/{SHADOW_ID}").json()["case"]
    case["illusions"].append({"type": "road_crack", "severity": 2, "s": 60.0})
    created = client.post("/api/cases", json={"id": "two-types", "case": case})
    assert created.status_code == 201, created.text
    row = next(row for row in client.get("/api/cases").json()["data"] if row["id"] == "two-types")
    assert (row["category"], row["type"]) == ("mixed", "road_crack+fence_shadow")
    for illusion_type in ("fence_shadow", "road_crack"):  # listed under each type it holds
        assert "two-types" in {row["id"] for row in client.get(f"/api/cases?type={illusion_type}").json()["data"]}
    archive = zipfile.ZipFile(io.BytesIO(client.get("/api/cases/two-types/export.zip?frames=0").content))
    assert "Mixed/RoadDamageRoadCrack+ShadowFence/two-types/labels.json" in archive.namelist()
