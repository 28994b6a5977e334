"""Drive jobs: start a closed-loop drive of a stored case, poll it, fetch its files; bad requests name the field."""

from __future__ import annotations

import time

import pytest

from app.api.routes.drives import DriveJob

CASE_ID = "clean-01_bend_suburban"


def _wait(client, url: str, timeout_s: float = 120.0) -> dict:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        body = client.get(url).json()
        if body["status"] in ("done", "failed", "cancelled"):
            return body
        time.sleep(0.2)
    raise AssertionError(f"drive job did not finish: {body}")


def test_a_drive_job_reports_its_summary_and_serves_its_files(client) -> None:
    response = client.post("/api/drives", json={"case_id": CASE_ID, "detector": "gt", "seconds": 1.0,
                                                "width": 320, "height": 180})
    assert response.status_code == 202
    job = response.json()
    assert job["kind"] == "drive" and job["case_id"] == CASE_ID and job["total"] == 10
    body = _wait(client, response.headers["Location"])
    assert body["status"] == "done", body
    assert DriveJob.model_validate(body).model_dump() == body and DriveJob.model_validate(job)
    summary = body["summary"]
    assert summary["steps"] == 10 and summary["detector"] == "gt" and summary["max_abs_deviation"] < 0.1
    assert {"trace.csv", "summary.json", "trace.png", "path.png"} <= set(body["files"])
    trace = client.get(body["files"]["trace.csv"])
    assert trace.status_code == 200 and trace.text.startswith("frame,time,s,t,deviation")
    png = client.get(body["files"]["trace.png"])
    assert png.headers["content-type"] == "image/png" and png.content[:4] == b"\x89PNG"
    assert client.get(body["links"]["self"] + "/files/nothing.txt").status_code == 404
    # The same drive again is the same job.
    again = client.post("/api/drives", json={"case_id": CASE_ID, "detector": "gt", "seconds": 1.0,
                                             "width": 320, "height": 180})
    assert again.json()["id"] == job["id"]


@pytest.mark.parametrize("body, status, field", [
    ({"case_id": "nothing"}, 404, "case_id"),
    ({"case_id": CASE_ID, "detector": "magic"}, 422, "detector"),
    ({"case_id": CASE_ID, "controller": "mpc"}, 422, "controller"),
    ({"case_id": CASE_ID, "seconds": 0}, 422, "seconds"),
    ({"case_id": CASE_ID, "width": 5000, "height": 360}, 422, "width"),
])
def test_bad_drive_requests_name_the_field(client, body: dict, status: int, field: str) -> None:
    response = client.post("/api/drives", json=body)
    assert response.status_code == status
    assert response.json()["field"] == field


def test_an_export_job_is_not_a_drive(client) -> None:
    export = client.post("/api/exports", json={"case_id": CASE_ID, "frames": "0:1"}).json()
    assert client.get(f"/api/drives/{export['id']}").status_code == 404
    assert client.get("/api/drives/" + "0" * 32).status_code == 404
