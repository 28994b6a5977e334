"""Detectors in the API: ``GET /api/detectors``, a frame's detections and their score, and ``detector=`` on images."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from lanevil_core.detect import catalog as detector_catalog
from lanevil_core.detect.learned import BUNDLED_MODELS
from lanevil_core.detect.split import METHODS
from lanevil_core.labels.lanes import h_samples_for
from lanevil_core.labels.overlay import DETECTION_COLOR

SHADOW_ID = "fence_shadow-00_uphill_rural_noon-03_level3"
FRAME = f"/api/cases/{SHADOW_ID}/frames"
SIZE = "width=320&height=180"


def decode(response) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(response.content)).convert("RGB"))


@pytest.fixture
def no_shipped_models(monkeypatch, tmp_path) -> None:
    """As on an installation without the learned models' files."""
    monkeypatch.setattr(detector_catalog, "SHIPPED_MODELS", tmp_path / "models")


def test_detectors_lists_every_method_with_kind_and_model(client) -> None:
    body = client.get("/api/detectors").json()
    names = [*METHODS, *BUNDLED_MODELS]
    assert [entry["name"] for entry in body["data"]] == names and body["count"] == len(names)
    by_name = {entry["name"]: entry for entry in body["data"]}
    ufld = by_name["ufld"]
    assert ufld["kind"] == "learned" and ufld["available"] and ufld["reason"] is None
    assert 0.0 <= ufld["model"]["val_accuracy"] <= 1.0 and ufld["model"]["input_size"] == [320, 180]
    assert by_name["hough"] == {"name": "hough", "kind": "classical", "available": True, "reason": None,
                                "model": None, "source": None, "real_trained": False}
    assert all(entry["available"] or entry["reason"] for entry in body["data"])


def test_a_missing_model_is_listed_unavailable_and_refused(client, no_shipped_models) -> None:
    ufld = next(entry for entry in client.get("/api/detectors").json()["data"] if entry["name"] == "ufld")
    assert not ufld["available"] and "no ufld model" in ufld["reason"]
    for url in (f"{FRAME}/0/detections?detector=ufld&{SIZE}", f"{FRAME}/0.png?detector=ufld&{SIZE}"):
        response = client.get(url)
        assert response.status_code == 422, url
        assert response.json()["field"] == "detector" and "not available" in response.json()["detail"]


@pytest.mark.parametrize("detector", ["ufld", "hough"])
def test_detections_are_scored_against_the_labels_and_cached(client, state, detector: str) -> None:
    response = client.get(f"{FRAME}/3/detections?detector={detector}&{SIZE}")
    assert response.status_code == 200, response.text
    body = response.json()
    assert (body["case_id"], body["frame"], body["detector"]) == (SHADOW_ID, 3, detector)
    assert (body["width"], body["height"]) == (320, 180) and body["h_samples"] == h_samples_for(180)
    assert 0.0 <= body["accuracy"] <= 1.0 and body["fn"] <= 1.0 and body["run_time_ms"] >= 0.0
    assert body["lanes"] and all(len(lane) == len(body["h_samples"]) for lane in body["lanes"] + body["gt_lanes"])
    assert all(-2 <= x < 320 for lane in body["lanes"] for x in lane)
    assert len(body["gt_lanes"]) >= 2
    runs = state.frames.detector_runs
    assert client.get(f"{FRAME}/3/detections?detector={detector}&{SIZE}").json() == body
    assert state.frames.detector_runs == runs  # served from the frame service's cache


def test_detections_are_scored_against_the_frames_own_labels(client, state) -> None:
    """GT lanes and rows are the frame's TuSimple labels at its size; the learned model finds most of them."""
    body = client.get(f"{FRAME}/0/detections?detector=ufld&{SIZE}").json()
    labels = state.frames.frame(state.store.get(SHADOW_ID).case, 0, (320, 180)).record
    assert body["gt_lanes"] == labels["lanes"] and body["h_samples"] == labels["h_samples"]
    assert body["accuracy"] > 0.5


def test_detections_follow_the_scrubbing_parameters(client) -> None:
    base = client.get(f"{FRAME}/5/detections?detector=hough&{SIZE}").json()
    other = client.get(f"{FRAME}/5/detections?detector=hough&{SIZE}&severity=5&sun_azimuth=120").json()
    assert other["h_samples"] == base["h_samples"] and other["lanes"] != base["lanes"]
    default = client.get(f"{FRAME}/5/detections?detector=hough").json()
    assert (default["width"], default["height"]) == (1280, 720) and default["h_samples"] == h_samples_for(720)


@pytest.mark.parametrize(("url", "status", "field"), [
    ("/api/cases/no-such-case/frames/0/detections?detector=ufld", 404, "case_id"),
    (f"{FRAME}/100/detections?detector=ufld", 404, "frame"),
    (f"{FRAME}/0/detections", 422, "detector"),
    (f"{FRAME}/0/detections?detector=yolo", 422, "detector"),
    (f"{FRAME}/0/detections?detector=ufld&width=32", 422, "width"),
    (f"{FRAME}/0/detections?detector=ufld&severity=9", 422, "severity"),
    (f"{FRAME}/0/detections?detector=ufld&sun_altitude=200", 422, "sun_altitude"),
    (f"{FRAME}/0.png?detector=yolo", 422, "detector"),
    (f"{FRAME}/0.jpg?detector={'x' * 41}", 422, "detector"),
])
def test_bad_detection_requests_name_the_field(client, url: str, status: int, field: str) -> None:
    response = client.get(url)
    assert response.status_code == status, response.text
    assert response.json()["field"] == field and response.json()["detail"].startswith(f"{field}: ")


def test_unknown_detector_lists_the_choices(client) -> None:
    detail = client.get(f"{FRAME}/0/detections?detector=yolo").json()["detail"]
    assert all(name in detail for name in METHODS)


def test_image_detector_draws_magenta_lanes_and_keys_the_etag(client, state) -> None:
    plain = client.get(f"{FRAME}/3.png?{SIZE}")
    found = client.get(f"{FRAME}/3.png?{SIZE}&detector=ufld")
    assert found.status_code == 200 and found.headers["etag"] != plain.headers["etag"]
    before, after = decode(plain), decode(found)
    changed = np.any(before != after, axis=2)
    assert 0.005 < changed.mean() < 0.5  # lane bands, not another picture
    assert np.all(after[changed] == DETECTION_COLOR, axis=1).mean() > 0.5
    hough = client.get(f"{FRAME}/3.png?{SIZE}&detector=hough")
    assert hough.headers["etag"] not in (plain.headers["etag"], found.headers["etag"])

    overlay = client.get(f"{FRAME}/3.png?{SIZE}&overlay=true")
    both = client.get(f"{FRAME}/3.png?{SIZE}&overlay=true&detector=ufld")
    assert both.headers["etag"] not in (overlay.headers["etag"], found.headers["etag"])
    assert not np.array_equal(decode(both), decode(overlay)) and not np.array_equal(decode(both), after)

    renders, runs = state.frames.renders, state.frames.detector_runs
    again = client.get(f"{FRAME}/3.png?{SIZE}&detector=ufld", headers={"If-None-Match": found.headers["etag"]})
    assert again.status_code == 304 and again.headers["etag"] == found.headers["etag"]
    assert (state.frames.renders, state.frames.detector_runs) == (renders, runs)
    assert client.get(f"{FRAME}/3.png?{SIZE}&detector=").headers["etag"] == plain.headers["etag"]  # empty = none


def test_render_of_an_unsaved_case_takes_a_detector(client) -> None:
    document = client.get(f"/api/cases/{SHADOW_ID}").json()["case"]
    plain = client.post(f"/api/render?frame=2&{SIZE}", json=document)
    found = client.post(f"/api/render?frame=2&{SIZE}&detector=birdseye", json=document)
    assert found.status_code == 200 and found.headers["etag"] != plain.headers["etag"]
    assert not np.array_equal(decode(found), decode(plain))


def test_openapi_documents_the_detector_routes(client) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    detections = paths["/api/cases/{case_id}/frames/{frame}/detections"]["get"]
    names = {param["name"] for param in detections["parameters"]}
    assert {"detector", "width", "height", "severity", "sun_azimuth"} <= names and "overlay" not in names
    image = paths["/api/cases/{case_id}/frames/{frame}.{fmt}"]["get"]
    detector = next(param for param in image["parameters"] if param["name"] == "detector")
    assert "magenta" in detector["description"]
    assert "/api/detectors" in paths


def test_a_plugin_server_is_listed_run_and_refused_when_down(client, monkeypatch, lane_server, down_url) -> None:
    monkeypatch.setenv("LANEVIL_DETECTORS", f"mine={lane_server.url()};down={down_url}")
    entries = {entry["name"]: entry for entry in client.get("/api/detectors").json()["data"]}
    assert entries["mine"]["kind"] == "http" and entries["mine"]["source"] == lane_server.url()
    response = client.get(f"{FRAME}/0/detections?detector=mine&{SIZE}")
    assert response.status_code == 200, response.text
    assert response.json()["detector"] == "mine" and lane_server.sizes == [(320, 180)]
    for url in (f"{FRAME}/0/detections?detector=down&{SIZE}", f"{FRAME}/0.png?detector=down&{SIZE}"):
        response = client.get(url)
        assert response.status_code == 422, url
        assert response.json()["field"] == "detector" and "cannot connect" in response.json()["detail"]
    response = client.post("/api/drives", json={"case_id": SHADOW_ID, "detector": "down"})
    assert response.status_code == 422 and "cannot connect" in response.json()["detail"]
    response = client.get(f"{FRAME}/0/detections?detector={lane_server.url()}&{SIZE}")
    assert response.status_code == 422  # a source is not a name here: the server calls no address it is given
    monkeypatch.setenv("LANEVIL_DETECTORS", "broken")
    response = client.get("/api/detectors")
    assert response.status_code == 422 and "NAME=SOURCE" in response.json()["detail"]


def test_an_onnx_model_and_an_installed_plugin_work_as_a_server_does(client, monkeypatch, mask_model,
                                                                     installed_plugin) -> None:
    monkeypatch.setenv("LANEVIL_DETECTORS", f"bdd-seg=onnx:{mask_model}")
    entries = {entry["name"]: entry for entry in client.get("/api/detectors").json()["data"]}
    assert (entries["bdd-seg"]["kind"], entries["bdd-seg"]["available"], entries["bdd-seg"]["real_trained"]) == \
        ("onnx", True, True)
    assert (entries["bright"]["kind"], entries["bright"]["real_trained"]) == ("plugin", True)
    assert not entries["broken"]["available"] and "no weights file" in entries["broken"]["reason"]
    for name in ("bdd-seg", "bright"):
        response = client.get(f"{FRAME}/0/detections?detector={name}&{SIZE}")
        assert response.status_code == 200, response.text
        body = response.json()
        assert body["detector"] == name and all(len(lane) == len(body["h_samples"]) for lane in body["lanes"])
        assert client.get(f"{FRAME}/0.png?detector={name}&{SIZE}").status_code == 200
    response = client.get(f"{FRAME}/0/detections?detector=broken&{SIZE}")
    assert response.status_code == 422 and "RuntimeError: no weights file" in response.json()["detail"]
