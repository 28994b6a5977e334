"""Frames, ``POST /api/render`` and labels: formats, overlay, overrides, cache headers and validation."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image

SHADOW_ID = "fence_shadow-00_uphill_rural_noon-03_level3"
FRAME = f"/api/cases/{SHADOW_ID}/frames"
SMALL = "width=160&height=90"


def decode(response) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(response.content)).convert("RGB"))


@pytest.mark.parametrize(("fmt", "media_type", "pil_format"), [("png", "image/png", "PNG"),
                                                                ("jpg", "image/jpeg", "JPEG")])
def test_frame_formats(client, fmt: str, media_type: str, pil_format: str) -> None:
    response = client.get(f"{FRAME}/4.{fmt}?{SMALL}")
    assert response.status_code == 200
    assert response.headers["content-type"] == media_type
    image = Image.open(io.BytesIO(response.content))
    assert (image.format, image.size) == (pil_format, (160, 90))
    assert response.headers["cache-control"] == "no-cache"
    assert response.headers["etag"].startswith('"') and len(response.headers["etag"]) == 34


def test_overlay_draws_lanes_on_the_same_frame(client) -> None:
    plain = decode(client.get(f"{FRAME}/0.png?{SMALL}"))
    overlay = decode(client.get(f"{FRAME}/0.png?{SMALL}&overlay=true"))
    changed = np.any(plain != overlay, axis=2).mean()
    assert 0.005 < changed < 0.5  # lane strokes, not a different picture


def test_if_none_match_is_304_without_rendering(client, state) -> None:
    first = client.get(f"{FRAME}/2.png?{SMALL}")
    renders = state.frames.renders
    again = client.get(f"{FRAME}/2.png?{SMALL}", headers={"If-None-Match": first.headers["etag"]})
    assert again.status_code == 304 and again.content == b""
    assert again.headers["etag"] == first.headers["etag"]
    assert state.frames.renders == renders
    other = client.get(f"{FRAME}/2.jpg?{SMALL}", headers={"If-None-Match": first.headers["etag"]})
    assert other.status_code == 200 and other.headers["etag"] != first.headers["etag"]


def test_editing_a_case_changes_the_etag(client) -> None:
    before = client.get(f"{FRAME}/1.png?{SMALL}").headers["etag"]
    client.patch(f"/api/cases/{SHADOW_ID}", json={"sun": {"altitude": 20}})
    after = client.get(f"{FRAME}/1.png?{SMALL}", headers={"If-None-Match": before})
    assert after.status_code == 200 and after.headers["etag"] != before


def test_overrides_render_a_variant_without_saving(client, state) -> None:
    base = client.get(f"{FRAME}/0.png?{SMALL}")
    low_sun = client.get(f"{FRAME}/0.png?{SMALL}&sun_altitude=8&sun_azimuth=120&sun_intensity=0.6")
    mild = client.get(f"{FRAME}/0.png?{SMALL}&severity=1")
    assert low_sun.status_code == mild.status_code == 200
    etags = {base.headers["etag"], low_sun.headers["etag"], mild.headers["etag"]}
    assert len(etags) == 3
    assert np.abs(decode(base).astype(int) - decode(low_sun)).mean() > 2
    record = state.store.get(SHADOW_ID)
    assert record.version == 1 and record.case.sun.altitude != 8 and record.severity == 3


@pytest.mark.parametrize(("query", "field"), [
    ("width=32", "width"), ("height=5000", "height"), ("width=32&height=90", "width"),
    ("width=160&height=5000", "height"), ("width=abc&height=90", "width"),
    (f"{SMALL}&severity=6", "severity"), (f"{SMALL}&sun_altitude=120", "sun_altitude"),
    (f"{SMALL}&sun_intensity=-1", "sun_intensity"), (f"{SMALL}&sun_azimuth=nan", "sun_azimuth"),
    (f"{SMALL}&sun_azimuth=inf", "sun_azimuth"), (f"{SMALL}&overlay=maybe", "overlay"),
])
def test_bad_render_queries_are_422_naming_the_parameter(client, query: str, field: str) -> None:
    response = client.get(f"{FRAME}/0.png?{query}")
    assert response.status_code == 422
    assert response.json()["field"] == field and response.json()["detail"].startswith(field)


@pytest.mark.parametrize(("path", "status"), [("100.png", 404), ("-1.png", 404), ("x.png", 422), ("0.gif", 422)])
def test_bad_frames(client, path: str, status: int) -> None:
    assert client.get(f"{FRAME}/{path}?{SMALL}").status_code == status


@pytest.mark.parametrize(("query", "shape"), [("width=160", (90, 160, 3)), ("height=90", (90, 160, 3)),
                                              ("width=64", (64, 64, 3))])
def test_one_side_alone_keeps_the_case_cameras_aspect_ratio(client, query: str, shape: tuple) -> None:
    response = client.get(f"{FRAME}/0.jpg?{query}")
    assert response.status_code == 200, response.text
    assert decode(response).shape == shape


def test_default_size_is_the_case_camera_capped_by_settings(app, client) -> None:
    settings = app.state.lanevil.settings
    settings.max_width, settings.max_height = 320, 180
    image = decode(client.get(f"{FRAME}/0.jpg"))
    assert image.shape == (180, 320, 3)


def test_render_unsaved_case(client) -> None:
    case = client.get(f"/api/cases/{SHADOW_ID}").json()["case"]
    response = client.post(f"/api/render?{SMALL}&frame=2&format=jpg", json=case)
    assert response.status_code == 200 and response.headers["content-type"] == "image/jpeg"
    assert decode(response).shape == (90, 160, 3)
    stored = client.get(f"{FRAME}/2.png?{SMALL}")
    posted = client.post(f"/api/render?{SMALL}&frame=2", json={"case": case})
    assert np.array_equal(decode(stored), decode(posted))  # same case content, same pixels
    assert client.post(f"/api/render?{SMALL}&frame=2", json=case,
                       headers={"If-None-Match": posted.headers["etag"]}).status_code == 304


@pytest.mark.parametrize("frame", [500, -1])
def test_render_of_a_frame_the_case_lacks_is_404_as_for_a_stored_case(client, frame: int) -> None:
    response = client.post(f"/api/render?{SMALL}&frame={frame}", json={})
    assert (response.status_code, response.json()["field"]) == (404, "frame")


@pytest.mark.parametrize(("query", "body", "field"), [
    (SMALL, {"camera": {"fov": 400}}, "camera.fov"),
    (SMALL, {"case": {"ego": {"speed": -1}}}, "case.ego.speed"),
    (f"{SMALL}&format=bmp", {}, "format"),
])
def test_render_rejects_bad_input(client, query: str, body: dict, field: str) -> None:
    response = client.post(f"/api/render?{query}", json=body)
    assert response.status_code == 422 and response.json()["field"] == field


# ------------------------------------------------------------------------------------------ labels


def test_tusimple_labels_are_json_lines(client) -> None:
    response = client.get(f"/api/cases/{SHADOW_ID}/labels?frames=3:5")
    assert response.status_code == 200 and response.headers["content-type"].startswith("application/x-ndjson")
    records = [json.loads(line) for line in response.text.splitlines()]
    assert [record["raw_file"] for record in records] == ["000003.png", "000004.png"]
    assert [record["frame"] for record in records] == [3, 4]
    for record in records:
        assert len(record["h_samples"]) == 56 and record["h_samples"][0] == 160
        assert 2 <= len(record["lanes"]) <= 5
        assert all(len(lane) == len(record["h_samples"]) for lane in record["lanes"])
        assert any(0 <= x < 1280 for lane in record["lanes"] for x in lane)


def test_culane_labels(client) -> None:
    body = client.get(f"/api/cases/{SHADOW_ID}/labels?format=culane&frames=7").json()
    assert body["format"] == "culane" and body["size"] == [1640, 590] and list(body["lines"]) == ["7"]
    lanes = body["lines"]["7"].splitlines()
    assert 2 <= len(lanes) <= 4
    values = [float(value) for value in lanes[0].split()]
    assert len(values) % 2 == 0 and values[1] == 590  # x y pairs from the bottom row up


def test_labels_default_to_the_first_frame(client) -> None:
    lines = client.get(f"/api/cases/{SHADOW_ID}/labels").text.splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["raw_file"] == "000000.png"


@pytest.mark.parametrize("frames", ["0:51", "5:5", "0:101", "a:b", "1:2:3", "-1:3", "100"])
def test_labels_frame_ranges_are_checked(client, frames: str) -> None:
    response = client.get(f"/api/cases/{SHADOW_ID}/labels?frames={frames}")
    assert response.status_code == 422 and response.json()["field"] == "frames"


def test_labels_cap_names_frames(client) -> None:
    response = client.get(f"/api/cases/{SHADOW_ID}/labels?frames=0:60")
    assert response.status_code == 422
    assert response.json()["detail"] == "frames: at most 50 frames per request (asked for 60: 0:60)"
