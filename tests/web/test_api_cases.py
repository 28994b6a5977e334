"""``/api/cases`` and ``/api/illusions``: CRUD, filters, optimistic versioning, ids that cannot escape the store,
body limits and the error format."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.api.limits import UPLOADS_PER_REQUEST
from app.main import create_app
from lanevil_core.case import default_markings
from lanevil_core.illusions import REGISTRY

FENCE = "fence_shadow-00_uphill_rural_noon"  # the fence shadow's representative original
SHADOW_ID = f"{FENCE}-03_level3"


def files_under(root: Path) -> set[Path]:
    return {path for path in root.rglob("*") if path.is_file()}


def stock_case(client, case_id: str = SHADOW_ID) -> dict:
    return client.get(f"/api/cases/{case_id}").json()["case"]


# ------------------------------------------------------------------------------------------ listing


def test_list_returns_summaries(client) -> None:
    body = client.get("/api/cases").json()
    assert body["count"] == len(body["data"]) == 6
    row = next(row for row in body["data"] if row["id"] == SHADOW_ID)
    assert (row["category"], row["type"], row["severity"], row["version"]) == ("shadow", "fence_shadow", 3, 1)
    assert [row["id"] for row in body["data"]] == sorted(row["id"] for row in body["data"])


def test_openapi_describes_the_listing_and_the_envelope(client) -> None:
    schema = client.get("/openapi.json").json()
    components, paths = schema["components"]["schemas"], schema["paths"]

    def body_schema(path: str, method: str, status: str) -> dict:
        ref = paths[path][method]["responses"][status]["content"]["application/json"]["schema"]["$ref"]
        return components[ref.rsplit("/", 1)[1]]

    listing = body_schema("/api/cases", "get", "200")
    assert set(listing["required"]) == {"data", "count"}
    row_schema = components[listing["properties"]["data"]["items"]["$ref"].rsplit("/", 1)[1]]
    rows = client.get("/api/cases").json()["data"]
    assert all(set(row) == set(row_schema["properties"]) == set(row_schema["required"]) for row in rows)
    envelope = client.get(f"/api/cases/{SHADOW_ID}").json()
    for path, method, status in [("/api/cases/{case_id}", "get", "200"), ("/api/cases", "post", "201"),
                                 ("/api/cases/{case_id}", "put", "200"), ("/api/cases/{case_id}", "patch", "200")]:
        described = body_schema(path, method, status)
        assert set(described["properties"]) == set(envelope), (path, method)
        assert described["properties"]["case"] == {"$ref": "#/components/schemas/Case"}
        assert "ETag" in paths[path][method]["responses"][status]["headers"]


@pytest.mark.parametrize(("query", "expected"), [
    ("category=clean", {"clean-00_straight_urban", "clean-01_bend_suburban"}),
    ("category=shadow", {f"{FENCE}-00_original", f"{FENCE}-01_level1", SHADOW_ID, f"{FENCE}-05_level5"}),
    ("type=fence_shadow&category=shadow", {f"{FENCE}-00_original", f"{FENCE}-01_level1", SHADOW_ID,
                                           f"{FENCE}-05_level5"}),
    ("category=traffic", set()),
    ("type=road_crack", set()),
])
def test_list_filters(client, query: str, expected: set[str]) -> None:
    body = client.get(f"/api/cases?{query}").json()
    assert {row["id"] for row in body["data"]} == expected
    assert body["count"] == len(expected)


@pytest.mark.parametrize(("query", "field", "name"), [("category=weather", "category", "weather"),
                                                      ("type=fog_bank", "type", "fog_bank")])
def test_list_rejects_unknown_filters(client, query: str, field: str, name: str) -> None:
    response = client.get(f"/api/cases?{query}")
    assert response.status_code == 422
    assert response.json()["field"] == field and name in response.json()["detail"]


# ------------------------------------------------------------------------------------------ create / read


def test_create_bare_case_gets_id_from_title(client) -> None:
    case = {**stock_case(client), "title": "My Rainy Test"}
    response = client.post("/api/cases", json=case)
    assert response.status_code == 201
    body = response.json()
    assert body["id"] == "my-rainy-test" and body["version"] == 1 and body["case"]["title"] == "My Rainy Test"
    assert response.headers["location"].endswith("/api/cases/my-rainy-test")
    assert response.headers["etag"] == '"1"'
    assert client.get(response.headers["location"]).json()["case"] == body["case"]


def test_create_envelope_with_id_and_conflict(client) -> None:
    envelope = {"id": "my-case", "case": stock_case(client)}
    assert client.post("/api/cases", json=envelope).status_code == 201
    again = client.post("/api/cases", json=envelope)
    assert again.status_code == 409 and "my-case" in again.json()["detail"]


@pytest.mark.parametrize(("body", "field"), [
    ({"road": {"lanes_per_direction": 9}}, "road.lanes_per_direction"),
    ({"case": {"ego": {"frames": 2}}}, "case.ego.frames"),
    ({"case": {}, "colour": "red"}, "colour"),
    ({"id": "Bad Id", "case": {}}, "id"),
    ({"illusions": [{"type": "no_such_illusion"}]}, "illusions.0"),
    ({"road": {"marking_standard": "atlantis"}}, "road.marking_standard"),
    ({"road": {"markings": [{"type": "botts_dots", "wear": 2.0}] * 5}}, "road.markings.0.wear"),
])
def test_create_rejects_bad_cases_naming_the_field(client, body: dict, field: str) -> None:
    response = client.post("/api/cases", json=body)
    assert response.status_code == 422
    assert response.json()["field"].startswith(field)
    assert response.json()["detail"].startswith(field)


@pytest.mark.parametrize("payload", [b"[1, 2]", b"{not json", b'"text"', b""])
def test_malformed_bodies_are_422_not_500(client, payload: bytes) -> None:
    response = client.post("/api/cases", content=payload, headers={"content-type": "application/json"})
    assert response.status_code == 422
    assert set(response.json()) == {"detail", "field"}


def test_get_unknown_case_is_404(client) -> None:
    response = client.get("/api/cases/no-such-case")
    assert response.status_code == 404 and response.json()["field"] == "case_id"


def test_get_revalidates_with_etag(client) -> None:
    first = client.get(f"/api/cases/{SHADOW_ID}")
    assert first.headers["etag"] == '"1"'
    assert client.get(f"/api/cases/{SHADOW_ID}", headers={"If-None-Match": '"1"'}).status_code == 304
    assert client.get(f"/api/cases/{SHADOW_ID}", headers={"If-None-Match": '"7"'}).status_code == 200


# ------------------------------------------------------------------------------------------ update / versions


def test_put_with_if_match_bumps_version(client) -> None:
    case = {**stock_case(client), "title": "renamed"}
    response = client.put(f"/api/cases/{SHADOW_ID}", json=case, headers={"If-Match": '"1"'})
    assert response.status_code == 200
    assert response.json()["version"] == 2 and response.headers["etag"] == '"2"'
    assert client.get(f"/api/cases/{SHADOW_ID}").json()["case"]["title"] == "renamed"


@pytest.mark.parametrize("if_match", ['"1"', "1", 'W/"1"'])
def test_put_with_stale_if_match_is_409(client, if_match: str) -> None:
    case = stock_case(client)
    assert client.put(f"/api/cases/{SHADOW_ID}", json=case).json()["version"] == 2  # someone else's write
    response = client.put(f"/api/cases/{SHADOW_ID}", json={**case, "title": "mine"}, headers={"If-Match": if_match})
    assert response.status_code == 409
    assert response.json()["field"] == "version" and "version 2" in response.json()["detail"]
    assert client.get(f"/api/cases/{SHADOW_ID}").json()["case"]["title"] != "mine"


def test_put_envelope_read_back_with_stale_body_version_is_409(client) -> None:
    envelope = client.get(f"/api/cases/{SHADOW_ID}").json()
    envelope["case"]["title"] = "first"
    assert client.put(f"/api/cases/{SHADOW_ID}", json=envelope).status_code == 200
    envelope["case"]["title"] = "second"  # still says version 1
    response = client.put(f"/api/cases/{SHADOW_ID}", json=envelope)
    assert response.status_code == 409 and "version 2" in response.json()["detail"]


def test_put_bare_case_with_body_version(client) -> None:
    case = stock_case(client)
    assert client.put(f"/api/cases/{SHADOW_ID}", json={**case, "version": 1}).json()["version"] == 2
    assert client.put(f"/api/cases/{SHADOW_ID}", json={**case, "version": 1}).status_code == 409


@pytest.mark.parametrize(("headers", "body_extra", "field"), [
    ({"If-Match": '"abc"'}, {}, "If-Match"),
    ({"If-Match": '"1"'}, {"version": 2}, "version"),
    ({}, {"version": "one"}, "version"),
    ({}, {"version": True}, "version"),
])
def test_put_rejects_bad_versions(client, headers: dict, body_extra: dict, field: str) -> None:
    response = client.put(f"/api/cases/{SHADOW_ID}", json={**stock_case(client), **body_extra}, headers=headers)
    assert response.status_code == 422 and response.json()["field"] == field


def test_put_unknown_case_is_404(client) -> None:
    assert client.put("/api/cases/nothing-here", json=stock_case(client)).status_code == 404


def test_put_envelope_with_other_id_is_422(client) -> None:
    response = client.put(f"/api/cases/{SHADOW_ID}", json={"id": "other", "case": stock_case(client)})
    assert response.status_code == 422 and response.json()["field"] == "id"


def test_concurrent_writers_of_one_version_one_wins(client, state) -> None:
    """N threads write version 1 at once: exactly one succeeds, the others get 409, nothing is lost silently."""
    case = stock_case(client)
    writers = 8
    barrier = threading.Barrier(writers)
    statuses: dict[int, int] = {}

    def write(number: int) -> None:
        barrier.wait()
        response = client.put(f"/api/cases/{SHADOW_ID}", json={**case, "title": f"writer {number}"},
                              headers={"If-Match": '"1"'})
        statuses[number] = response.status_code

    threads = [threading.Thread(target=write, args=(number,)) for number in range(writers)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    winners = [number for number, status in statuses.items() if status == 200]
    assert len(winners) == 1
    assert sorted(statuses.values()) == [200] + [409] * (writers - 1)
    record = state.store.get(SHADOW_ID)
    assert record.version == 2 and record.case.title == f"writer {winners[0]}"


# ------------------------------------------------------------------------------------------ patch


def test_patch_merges_and_resets_with_null(client) -> None:
    response = client.patch(f"/api/cases/{SHADOW_ID}", json={"title": "patched", "sun": {"altitude": 12.5}},
                            headers={"If-Match": '"1"', "content-type": "application/merge-patch+json"})
    assert response.status_code == 200
    case = response.json()["case"]
    assert case["title"] == "patched" and case["sun"]["altitude"] == 12.5
    assert case["illusions"] == stock_case(client)["illusions"]  # untouched fields stay
    reset = client.patch(f"/api/cases/{SHADOW_ID}", json={"title": None, "version": 2}).json()
    assert reset["version"] == 3 and reset["case"]["title"] == ""


def test_patching_the_lane_count_re_derives_markings_unless_given(client) -> None:
    custom = [{"type": t} for t in ("none", "white_solid", "yellow_solid", "botts_dots", "white_solid")]
    url = f"/api/cases/{SHADOW_ID}"
    assert client.patch(url, json={"road": {"markings": custom}}).status_code == 200
    same = client.patch(url, json={"road": {"lanes_per_direction": 2}}).json()["case"]["road"]
    assert [m["type"] for m in same["markings"]] == [m["type"] for m in custom]  # an unchanged count keeps them
    road = client.patch(url, json={"road": {"lanes_per_direction": 3}}).json()["case"]["road"]
    assert [m["type"] for m in road["markings"]] == [m.type for m in default_markings(3)]
    given = [{"type": "white_solid"}] * 3
    road = client.patch(url, json={"road": {"lanes_per_direction": 1, "markings": given}}).json()["case"]["road"]
    assert [m["type"] for m in road["markings"]] == ["white_solid"] * 3
    wrong = client.patch(url, json={"road": {"lanes_per_direction": 2, "markings": given}})
    assert wrong.status_code == 422 and "markings needs 5 entries" in wrong.json()["detail"]


def test_put_with_the_defaults_of_another_lane_count_re_derives_them(client) -> None:
    document = client.get(f"/api/cases/{SHADOW_ID}").json()["case"]
    document["road"].update(lanes_per_direction=3, markings=[m.model_dump() for m in default_markings(2)])
    road = client.put(f"/api/cases/{SHADOW_ID}", json=document).json()["case"]["road"]
    assert len(road["markings"]) == 7


def test_patch_stale_and_invalid(client) -> None:
    assert client.patch(f"/api/cases/{SHADOW_ID}", json={"title": "a"}).status_code == 200
    stale = client.patch(f"/api/cases/{SHADOW_ID}", json={"title": "b"}, headers={"If-Match": '"1"'})
    assert stale.status_code == 409 and "version 2" in stale.json()["detail"]
    invalid = client.patch(f"/api/cases/{SHADOW_ID}", json={"sun": {"altitude": 300}})
    assert invalid.status_code == 422 and invalid.json()["field"] == "sun.altitude"


# ------------------------------------------------------------------------------------------ delete


def test_delete_honours_if_match(client, state) -> None:
    assert client.delete(f"/api/cases/{SHADOW_ID}", headers={"If-Match": '"4"'}).status_code == 409
    assert client.delete(f"/api/cases/{SHADOW_ID}", headers={"If-Match": '"1"'}).status_code == 204
    assert SHADOW_ID not in state.store
    assert not (state.store.folder / f"{SHADOW_ID}.json").exists()
    assert client.get(f"/api/cases/{SHADOW_ID}").status_code == 404
    assert client.delete(f"/api/cases/{SHADOW_ID}").status_code == 404


# ------------------------------------------------------------------------------------------ ids and limits


@pytest.mark.parametrize("case_id", ["..%2F..%2Fevil", "..%2Fevil", "%2e%2e%2Fevil", "..", ".evil", "Evil",
                                     "evil%00", "evil.json", "a" * 81, "evil%5C..%5Cx", "%20evil"])
def test_ids_cannot_escape_the_store(client, settings, case_id: str) -> None:
    root = Path(settings.data_dir).parent
    before = files_under(root)
    case = stock_case(client)
    responses = [client.get(f"/api/cases/{case_id}"), client.put(f"/api/cases/{case_id}", json=case),
                 client.patch(f"/api/cases/{case_id}", json={"title": "x"}), client.delete(f"/api/cases/{case_id}"),
                 client.get(f"/api/cases/{case_id}/frames/0.png?width=64&height=64"),
                 client.post("/api/cases", json={"id": case_id.replace("%2F", "/"), "case": case})]
    assert {response.status_code for response in responses} <= {404, 405, 422}
    assert files_under(root) == before
    assert not any("evil" in path.name for path in root.rglob("*"))


def test_body_over_limit_is_413(client, settings) -> None:
    big = b"{" + b" " * settings.max_body_bytes + b"}"
    response = client.post("/api/cases", content=big, headers={"content-type": "application/json"})
    assert response.status_code == 413 and response.json()["field"] == "body"


def test_streamed_body_over_limit_is_413(client, settings) -> None:
    """A chunked body without Content-Length is cut off once it passes the limit."""
    chunk = b" " * 65536

    def chunks():
        for _ in range(settings.max_body_bytes // len(chunk) + 4):
            yield chunk

    response = client.post("/api/cases", content=chunks(), headers={"content-type": "application/json"})
    assert response.status_code == 413


# ------------------------------------------------------------------------------------------ registry


def test_illusions_registry(client) -> None:
    body = client.get("/api/illusions").json()
    assert body["count"] == len(REGISTRY) == 14
    assert [info["name"] for info in body["data"]] == list(REGISTRY)
    fence = next(info for info in body["data"] if info["name"] == "fence_shadow")
    assert fence["category"] == "shadow" and len(fence["severity"]) == 5
    assert fence["parameters"]["severity"]["maximum"] == 5 and "default" in fence["parameters"]["severity"]
    assert body["categories"]["shadow"] == [name for name, cls in REGISTRY.items() if cls.CATEGORY == "shadow"]
    assert "illusions" in body["case_schema"]["properties"]
    suns = {info["name"]: info["sun"] for info in body["data"]}  # what the demo's sun sliders may do per type
    assert (suns["fence_shadow"], suns["sunlight_reflection"], suns["road_crack"]) == ("overrides", "table", "case")


def test_multipart_uploads_have_their_own_limit(settings, state) -> None:
    """Multipart bodies (study images) may pass ``max_body_bytes`` up to ``UPLOADS_PER_REQUEST`` uploads' worth."""
    small = settings.model_copy(update={"max_body_bytes": 1024, "max_upload_bytes": 2048})
    with TestClient(create_app(small, state)) as client:
        files = {"files": ("big.bin", b"\0" * 4096, "application/octet-stream")}
        response = client.post("/api/cases", files=files)
        assert response.status_code == 415  # not a JSON case: refused for its content type, not by the size limit
        over = b"\0" * (UPLOADS_PER_REQUEST * 2048 + 1)
        response = client.post("/api/cases", content=over, headers={"content-type": "multipart/form-data; boundary=x"})
        assert response.status_code == 413 and response.json()["field"] == "body"
        assert client.post("/api/cases", content=b" " * 1025,
                           headers={"content-type": "application/json"}).status_code == 413


@pytest.mark.parametrize(("document", "field"), [
    ({"illusions": [{"type": "fence_shadow", "severity": "3"}]}, "illusions.0.fence_shadow.severity"),
    ({"illusions": [{"type": "fence_shadow", "severity": True}]}, "illusions.0.fence_shadow.severity"),
    ({"seed": "3"}, "seed"),
    ({"seed": 3.5}, "seed"),
    ({"ego": {"frames": True}}, "ego.frames"),
    ({"sun": {"azimuth": "120"}}, "sun.azimuth"),
    ({"sun": {"azimuth": False}}, "sun.azimuth"),
])
def test_numbers_are_strict(client, document: dict, field: str) -> None:
    response = client.post("/api/cases", json={"title": "strict", **document})
    assert response.status_code == 422, response.text
    assert response.json()["field"] == field


def test_a_whole_number_written_with_a_fraction_is_an_integer(client) -> None:
    """JSON Schema's ``integer`` is any number without a fractional part: ``3.0`` is one, as the schema says."""
    response = client.post("/api/cases", content=b'{"title": "whole", "seed": 3.0, "ego": {"frames": 5e1}}',
                           headers={"content-type": "application/json"})
    assert response.status_code == 201, response.text
    assert response.json()["case"]["seed"] == 3 and response.json()["case"]["ego"]["frames"] == 50
    assert response.json()["case"]["sun"]["azimuth"] == 30.0
