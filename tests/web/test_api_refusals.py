"""Every refusal of the mesh upload and of the case routes names a field and a reason, never the server's folders
or a library's internals (trimesh's resolver and its ``allow_anywhere`` advice), and carries the security headers."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import trimesh
from test_api_meshes import box_glb, glb_of, nested, upload, vehicle_case  # same folder, by its base name

from app.headers import SECURITY_HEADERS
from lanevil_core.case import Case

ADMIN = {"Authorization": "Bearer test-admin"}
JSON = {"content-type": "application/json"}
CASE = "clean-00_straight_urban"
LEAKS = ("resolver", "allow_anywhere", "Traceback", "trimesh")


def escaping(part: str, uri: str) -> bytes:
    return json.dumps({"asset": {"version": "2.0"}, part: [{"uri": uri, "byteLength": 8}]}).encode()


def rotten_case(state) -> str:
    """A stored case whose vehicle names ``rotten.glb``, a file put in the uploads folder by hand (never checked)."""
    state.meshes_dir.mkdir(parents=True, exist_ok=True)
    (state.meshes_dir / "rotten.glb").write_bytes(b"glTF" + bytes(200))
    return state.store.create(Case.model_validate(vehicle_case("rotten.glb")), case_id="rotten").id


def upload_refusals(client, data_dir: Path) -> list:
    dense = trimesh.Scene(trimesh.creation.icosphere(subdivisions=7)).export(file_type="glb")
    no_triangles = glb_of(json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]}).encode())
    lying_accessor = glb_of(json.dumps({
        "asset": {"version": "2.0"}, "buffers": [{"byteLength": 10**9}], "bufferViews": [{"buffer": 0,
        "byteLength": 10**9}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 10**8,
        "type": "VEC3"}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}).encode())
    (data_dir / "uploads").mkdir(parents=True, exist_ok=True)
    (data_dir / "uploads" / "taken.glb").write_bytes(box_glb())
    files = [("notes.txt", b"hello"), ("../../evil.glb", b"not a model"), ("big.obj", b"v 0 0 0\n" * 10),
             ("-.glb", b"x"), ("deep.gltf", nested(100_000)), ("deep.glb", glb_of(nested(1_000))),
             ("nan.gltf", b'{"asset": NaN}'), ("latin.gltf", b'{"asset": "\xff"}'), ("broken.glb", b"glTF\x02"),
             ("dense.glb", dense), ("empty.glb", no_triangles), ("lying.glb", lying_accessor),
             ("random.glb", bytes(range(256)) * 64), ("random.obj", bytes(range(256)) * 64),
             ("taken.glb", box_glb((1, 2, 3))), ("large.glb", b"\0" * 20_000_001)]
    for part in ("buffers", "images"):
        for uri in ("../../../../../../etc/hostname", "../admin_token", str(data_dir / "admin_token")):
            files += [(f"escape-{part}.glb", glb_of(escaping(part, uri))), (f"escape-{part}.gltf", escaping(part, uri))]
    answers = [upload(client, name, data) for name, data in files]
    answers.append(client.post("/api/meshes", data={"other": "x"}, files={"model": ("a.glb", b"x")}))
    answers.append(client.post("/api/meshes", content=b"--x\r\n", headers={"content-type": "multipart/form-data"}))
    answers.append(client.post("/api/meshes", json={"file": "a.glb"}))
    return answers


def case_refusals(client, state) -> list:
    name = upload(client, "van.glb", box_glb()).json()["name"]
    gone = client.post("/api/cases", json=vehicle_case(name)).json()["id"]
    (state.meshes_dir / name).unlink()
    rotten = rotten_case(state)
    requests: list[tuple[str, str, dict[str, Any]]] = [
        ("GET", "/api/cases/NOT-AN-ID", {}), ("GET", "/api/cases/no-such-case", {}),
        ("GET", "/api/cases?category=nope", {}), ("GET", "/api/cases?type=nope", {}),
        ("POST", "/api/cases", {"content": b"{", "headers": JSON}),
        ("POST", "/api/cases", {"content": b"[" * 100_000, "headers": JSON}),
        ("POST", "/api/cases", {"content": b"{}", "headers": {"content-type": "text/plain"}}),
        ("POST", "/api/cases", {"json": {"road": {"lanes_per_direction": 9}}}),
        ("POST", "/api/cases", {"json": {"case": {}, "id": "Bad Id"}}),
        ("POST", "/api/cases", {"json": {"case": {}, "id": CASE}}),
        ("PUT", f"/api/cases/{CASE}", {"json": {}, "headers": {"If-Match": '"99"'}}),
        ("PUT", f"/api/cases/{CASE}", {"json": {}, "headers": {"If-Match": "null"}}),
        ("PATCH", f"/api/cases/{CASE}", {"json": {"ego": {"frames": 1}}}),
        ("DELETE", f"/api/cases/{CASE}", {"headers": {"If-Match": '"99"'}}),
        ("GET", f"/api/cases/{CASE}/frames/999.png", {}),
        ("GET", f"/api/cases/{CASE}/frames/0.png?width=0&height=0", {}),
        ("GET", f"/api/cases/{CASE}/frames/0.png?width=160&height=90&detector=nope", {}),
        ("GET", f"/api/cases/{CASE}/frames/0/detections?detector=nope", {}),
        ("GET", f"/api/cases/{CASE}/labels?frames=9:1", {}),
        ("GET", f"/api/cases/{CASE}/export.zip?frames=x", {}),
        ("POST", "/api/render", {"json": {"ego": {"frames": 1}}}),
        ("POST", "/api/exports", {"json": {"case_id": "no-such-case"}}),
        ("POST", "/api/drives", {"json": {"case_id": CASE, "detector": "nope"}}),
    ]
    for mesh_file in ("/etc/passwd", "../../etc/hostname", str(state.meshes_dir / "van.glb"), "missing.glb"):
        requests += [("POST", "/api/cases", {"json": vehicle_case(mesh_file)}),
                     ("PUT", f"/api/cases/{CASE}", {"json": vehicle_case(mesh_file)}),
                     ("POST", "/api/render", {"json": vehicle_case(mesh_file)})]
    for case_id in (gone, rotten):
        requests += [("GET", f"/api/cases/{case_id}/frames/1.png?width=160&height=90", {}),
                     ("GET", f"/api/cases/{case_id}/labels?frames=0:2", {}),
                     ("GET", f"/api/cases/{case_id}/frames/2/detections?detector=hough&width=160&height=90", {}),
                     ("GET", f"/api/cases/{case_id}/export.zip?frames=0:2", {})]
    requests += [("POST", "/api/exports", {"json": {"case_id": gone}}),
                 ("POST", "/api/drives", {"json": {"case_id": gone, "seconds": 1}}),
                 ("POST", "/api/study/studies", {"json": {"title": "x", "width": 160, "height": 90,
                                                          "generated": {"cases": [gone]}}, "headers": ADMIN})]
    return [client.request(method, url, **kwargs) for method, url, kwargs in requests]


def test_no_refusal_names_a_server_folder_or_the_loader(client, state, tmp_path: Path) -> None:
    data_dir = state.settings.data_dir
    answers = upload_refusals(client, data_dir) + case_refusals(client, state)
    folders = {str(tmp_path), str(tmp_path.resolve()), str(data_dir), str(data_dir.resolve())}
    statuses = set()
    for response in answers:
        where = f"{response.request.method} {response.request.url}: {response.status_code} {response.text[:300]}"
        assert 400 <= response.status_code < 500, where
        statuses.add(response.status_code)
        body = response.json()
        assert set(body) == {"detail", "field"} and body["field"], where
        assert not any(folder in response.text for folder in folders), where
        assert not any(leak in response.text for leak in LEAKS), where
        for header, value in SECURITY_HEADERS.items():
            assert response.headers[header] == value, where
    assert statuses >= {404, 409, 413, 415, 422}
    assert not any(path.name.startswith(".upload-") for path in state.meshes_dir.iterdir())


def test_a_hand_placed_unreadable_mesh_names_its_field_and_file(client, state) -> None:
    case_id = rotten_case(state)
    response = client.get(f"/api/cases/{case_id}/frames/1.png?width=160&height=90")
    assert response.status_code == 422
    assert response.json() == {"detail": "illusions.0.vehicle.mesh_file: rotten.glb: not a readable glb model",
                               "field": "illusions.0.vehicle.mesh_file"}



def test_a_job_that_fails_on_an_unreadable_mesh_says_so_without_folders(client, state) -> None:
    case_id = rotten_case(state)
    started = client.post("/api/exports", json={"case_id": case_id, "frames": "0:2"})
    assert started.status_code == 202, started.text
    job = state.jobs.get(started.json()["id"])
    assert job.finished.wait(120)
    body = client.get(f"/api/exports/{job.id}").json()
    assert body["status"] == "failed"
    assert body["error"] == "MeshFileError: illusions.0.vehicle.mesh_file: rotten.glb: not a readable glb model"
    assert str(state.settings.data_dir) not in client.get(f"/api/exports/{job.id}/download").text
