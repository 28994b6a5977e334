"""User meshes: a vehicle's ``mesh_file`` names a model uploaded to ``POST /api/meshes``, never a server path."""

from __future__ import annotations

import io
import json
import struct
from pathlib import Path

import pytest
import trimesh
from fastapi.testclient import TestClient

from app.main import create_app
from app.state import AppState

JSON = {"content-type": "application/json"}
FIELD = "illusions.0.vehicle.mesh_file"
VEHICLE = {"type": "vehicle", "severity": 2, "kind": "van"}


def box_glb(size: tuple[float, float, float] = (4.0, 2.0, 1.5)) -> bytes:
    return trimesh.Scene(trimesh.creation.box(size)).export(file_type="glb")


def glb_of(document: bytes) -> bytes:
    """A binary glTF whose only chunk is ``document`` (the JSON chunk, padded to 4 bytes as the format asks)."""
    document += b" " * (-len(document) % 4)
    return b"glTF" + struct.pack("<III", 2, 20 + len(document), len(document)) + b"JSON" + document


def nested(depth: int) -> bytes:
    return b'{"asset":' * depth + b"1" + b"}" * depth


def upload(client, name: str, data: bytes):
    return client.post("/api/meshes", files={"file": (name, io.BytesIO(data), "application/octet-stream")})


def vehicle_case(mesh_file: str) -> dict:
    return {"title": "van", "ego": {"frames": 50}, "illusions": [{**VEHICLE, "mesh_file": mesh_file}]}


@pytest.mark.parametrize("mesh_file", ["/etc/passwd", "/proc/self/environ", "../../etc/hostname", "a/b.glb",
                                       "x.txt", "TMP_GLB", "missing.glb"])
def test_a_mesh_file_outside_uploads_is_refused(client, tmp_path: Path, mesh_file: str) -> None:
    if mesh_file == "TMP_GLB":  # a real model elsewhere on the server
        (tmp_path / "elsewhere.glb").write_bytes(box_glb())
        mesh_file = str(tmp_path / "elsewhere.glb")
    created = client.post("/api/cases", json=vehicle_case(mesh_file))
    assert created.status_code == 422, created.text
    assert created.json()["field"] == FIELD
    enveloped = client.post("/api/cases", json={"case": vehicle_case(mesh_file)})
    assert enveloped.json()["field"] == f"case.{FIELD}"
    for method in ("PUT", "PATCH"):
        changed = client.request(method, "/api/cases/clean-00_straight_urban", json=vehicle_case(mesh_file))
        assert (changed.status_code, changed.json()["field"]) == (422, FIELD)
    rendered = client.post("/api/render", json=vehicle_case(mesh_file))
    assert (rendered.status_code, rendered.json()["field"]) == (422, FIELD)


def test_an_uploaded_mesh_renders(client, state) -> None:
    response = upload(client, "My Van.glb", box_glb())
    assert response.status_code == 201, response.text
    name = response.json()["name"]
    assert name == "My_Van.glb"
    assert client.get("/api/meshes").json() == {"data": [name], "count": 1}
    created = client.post("/api/cases", json=vehicle_case(name))
    assert created.status_code == 201, created.text
    frame = client.get(f"/api/cases/{created.json()['id']}/frames/0.png?width=160&height=90")
    assert frame.status_code == 200 and frame.headers["content-type"] == "image/png"
    assert upload(client, "My Van.glb", box_glb()).status_code == 201  # the same bytes again: nothing changes
    assert upload(client, "My Van.glb", box_glb((3, 2, 1))).status_code == 409


@pytest.mark.parametrize(("name", "data", "status"), [
    ("notes.txt", b"hello", 415),
    ("../../evil.glb", b"not a model", 422),
    ("big.obj", b"v 0 0 0\n" * 10, 422),
    ("external.gltf", b'{"asset": {"version": "2.0"}, "buffers": [{"uri": "/etc/passwd", "byteLength": 4}]}', 422),
])
def test_bad_uploads_name_file(client, state, name: str, data: bytes, status: int) -> None:
    response = upload(client, name, data)
    assert response.status_code == status, response.text
    assert response.json()["field"] == "file"
    assert list(state.meshes_dir.iterdir()) == []  # nothing half-written stays


def test_too_many_faces_and_too_large_are_refused(client, settings) -> None:
    dense = trimesh.creation.icosphere(subdivisions=7)  # 327,680 faces
    response = upload(client, "dense.glb", trimesh.Scene(dense).export(file_type="glb"))
    assert (response.status_code, response.json()["field"]) == (422, "file")
    assert "60000" in response.json()["detail"]
    large = upload(client, "large.glb", b"\0" * (settings.max_upload_bytes + 1))
    assert (large.status_code, large.json()["field"]) == (413, "file")


def test_a_stored_case_whose_mesh_is_missing_answers_4xx(client, state) -> None:
    name = upload(client, "van.glb", box_glb()).json()["name"]
    case_id = client.post("/api/cases", json=vehicle_case(name)).json()["id"]
    (state.meshes_dir / name).unlink()
    urls = [("GET", f"/api/cases/{case_id}/frames/1.png?width=160&height=90", None),
            ("GET", f"/api/cases/{case_id}/labels?frames=0:2", None),
            ("GET", f"/api/cases/{case_id}/frames/2/detections?detector=hough&width=160&height=90", None),
            ("GET", f"/api/cases/{case_id}/export.zip?frames=0:2", None),
            ("POST", "/api/exports", {"case_id": case_id}),
            ("POST", "/api/drives", {"case_id": case_id, "seconds": 1})]
    for method, url, body in urls:
        response = client.request(method, url, json=body)
        assert response.status_code == 422, (url, response.text)
        assert response.json()["field"] == FIELD
    assert client.get(f"/api/cases/{case_id}").status_code == 200


@pytest.mark.parametrize("old_path", ["/etc/passwd", "../../etc/hostname",
                                      '<iframe srcdoc="<script>alert(1)</script>">'])
def test_a_case_stored_with_a_mesh_path_still_opens_and_answers_422(settings, old_path: str) -> None:
    """Cases written before ``mesh_file`` became a name: the store opens, the case reads, its frames are a 422."""
    first = AppState.open(settings)
    record = first.store.create(first.store.get("clean-00_straight_urban").case, case_id="old-van")
    first.jobs.shutdown()
    path = settings.data_dir / "cases" / "old-van.json"
    stored = json.loads(path.read_text())
    stored["case"]["illusions"] = [{**VEHICLE, "mesh_file": old_path}]
    path.write_text(json.dumps(stored))
    state = AppState.open(settings)
    try:
        with TestClient(create_app(settings, state)) as client:
            assert client.get(f"/api/cases/{record.id}").status_code == 200
            frame = client.get(f"/api/cases/{record.id}/frames/0.png?width=160&height=90")
            assert (frame.status_code, frame.json()["field"]) == (422, FIELD)
            assert "upload it first" in frame.json()["detail"]
    finally:
        state.jobs.shutdown()


def test_a_study_of_a_case_whose_mesh_is_missing_is_a_422(client, state) -> None:
    name = upload(client, "van.glb", box_glb()).json()["name"]
    case_id = client.post("/api/cases", json=vehicle_case(name)).json()["id"]
    (state.meshes_dir / name).unlink()
    spec = {"title": "vans", "width": 160, "height": 90, "generated": {"cases": [case_id]}}
    response = client.post("/api/study/studies", json=spec, headers={"Authorization": "Bearer test-admin"})
    assert response.status_code == 422, response.text
    assert response.json()["field"].endswith("mesh_file")


@pytest.mark.parametrize("depth", [100, 1_000, 100_000])
@pytest.mark.parametrize("suffix", ["gltf", "glb"])
def test_deeply_nested_gltf_is_a_422_naming_file(client, state, depth: int, suffix: str) -> None:
    data = nested(depth) if suffix == "gltf" else glb_of(nested(depth))
    response = client.post("/api/meshes", files={"file": (f"deep.{suffix}", io.BytesIO(data), "model/gltf+json")})
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "file"
    assert "nested deeper than 64 levels" in response.json()["detail"]
    assert response.headers["X-Frame-Options"] == "DENY" and "Content-Security-Policy" in response.headers
    assert list(state.meshes_dir.iterdir()) == []


@pytest.mark.parametrize("uri", ["../../../../../../etc/hostname", "../admin_token", "/etc/passwd",
                                 "file:///etc/passwd", "buffer.bin"])
@pytest.mark.parametrize("part", ["buffers", "images"])
def test_a_glb_naming_another_file_is_refused_without_reading_it(client, state, uri: str, part: str) -> None:
    document = {"asset": {"version": "2.0"}, part: [{"uri": uri, "byteLength": 8}]}
    response = upload(client, "escape.glb", glb_of(json.dumps(document).encode()))
    assert (response.status_code, response.json()["field"]) == (422, "file")
    assert "refers to other files" in response.json()["detail"]
    assert str(state.settings.data_dir) not in response.text and "resolver" not in response.text


@pytest.mark.parametrize("data", [b"", b"glTF", b"glTF\x02\0\0\0\xff\xff\0\0\xff\xff\0\0BIN\0", b"\x89PNG\r\n"])
def test_a_glb_without_its_header_and_json_chunk_is_refused(client, data: bytes) -> None:
    response = upload(client, "broken.glb", data)
    assert (response.status_code, response.json()["field"]) == (422, "file")
    assert "GLB" in response.json()["detail"]
