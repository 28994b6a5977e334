"""Errors name the real field and the real problem: malformed, non-JSON, non-finite and deeply nested bodies, study
uploads, and an OpenAPI description that documents the error body and statuses the API really answers."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image

from app.api.json_body import MAX_DEPTH, line_column
from app.api.routes.illusions import IllusionRegistry

ADMIN = {"Authorization": "Bearer test-admin"}
JSON = {"content-type": "application/json"}
SHADOW_ID = "fence_shadow-00_uphill_rural_noon-03_level3"


def post_case(client, payload: bytes, headers: dict[str, str] | None = None):
    return client.post("/api/cases", content=payload, headers=JSON if headers is None else headers)


def test_line_column_is_one_based() -> None:
    assert line_column("ab\ncd", 0) == (1, 1)
    assert line_column("ab\ncd", 4) == (2, 2)


def test_malformed_json_names_body_with_line_and_column(client) -> None:
    response = post_case(client, b'{"title": "x",\n "road": }')
    assert response.status_code == 422
    assert response.json() == {"detail": "body: invalid JSON at line 2 column 10: Expecting value", "field": "body"}


@pytest.mark.parametrize(("method", "url", "body"), [
    ("POST", "/api/cases", b'{"title": "x"}'),
    ("PUT", f"/api/cases/{SHADOW_ID}", b'{"title": "x"}'),
    ("PATCH", f"/api/cases/{SHADOW_ID}", b'{"title": "x"}'),
    ("POST", "/api/render", b'{"title": "x"}'),
    ("POST", "/api/exports", b'{"case_id": "fence_shadow-00_uphill_rural_noon-03_level3"}'),
])
@pytest.mark.parametrize("content_type", ["text/plain", "application/x-www-form-urlencoded", "application/xml", None])
def test_a_body_not_sent_as_json_is_415(client, method: str, url: str, body: bytes, content_type: str | None) -> None:
    headers = {"content-type": content_type} if content_type else {}
    response = client.request(method, url, content=body, headers=headers)
    assert response.status_code == 415, response.text
    assert response.json()["field"] == "Content-Type" and "application/json" in response.json()["detail"]


def test_json_content_types_with_parameters_and_merge_patch_are_read(client) -> None:
    response = post_case(client, b'{"title": "charset"}', {"content-type": "application/json; charset=utf-8"})
    assert response.status_code == 201
    patch = client.patch(f"/api/cases/{response.json()['id']}", content=b'{"title": "patched"}',
                         headers={"content-type": "application/merge-patch+json"})
    assert patch.status_code == 200 and patch.json()["case"]["title"] == "patched"


@pytest.mark.parametrize("constant", ["NaN", "Infinity", "-Infinity"])
def test_nan_and_infinity_are_refused(client, constant: str) -> None:
    payload = f'{{"title": "x",\n  "sun": {{"altitude": {constant}}}}}'.encode()
    response = post_case(client, payload)
    assert response.status_code == 422 and response.json()["field"] == "body"
    assert response.json()["detail"].startswith(f"body: {constant} at line 2 column 23 is not a JSON number")


def test_nan_inside_a_string_is_text(client) -> None:
    response = post_case(client, b'{"title": "NaN [[[ Infinity {{{"}')
    assert response.status_code == 201 and response.json()["case"]["title"] == "NaN [[[ Infinity {{{"


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 5_000, 200_000])
def test_deeply_nested_json_names_body(client, depth: int) -> None:
    payload = b'{"title": ' + b"[" * depth + b"]" * depth + b"}"
    response = post_case(client, payload)
    assert response.status_code == 422
    assert response.json()["field"] == "body" and f"nested deeper than {MAX_DEPTH} levels" in response.json()["detail"]


def test_a_body_that_is_not_utf8_names_body(client) -> None:
    response = post_case(client, b'{"title": "\xff"}')
    assert response.status_code == 422 and response.json()["field"] == "body"


def test_participant_routes_refuse_non_json_too(client) -> None:
    response = client.post("/api/study/studies/000000000000/participants", content=b"consent=true",
                           headers={"content-type": "application/x-www-form-urlencoded"})
    assert response.status_code == 415 and response.json()["field"] == "Content-Type"


# ------------------------------------------------------------------------------------------ study creation


def test_study_spec_errors_name_spec_with_line_and_column(client) -> None:
    response = client.post("/api/study/studies", headers=ADMIN, data={"spec": '{"title": "x",\n "width": NaN}'})
    assert response.status_code == 422 and response.json()["field"] == "spec"
    assert "NaN at line 2 column 11" in response.json()["detail"]
    response = client.post("/api/study/studies", headers=ADMIN, data={"spec": '{"title": }'})
    assert response.json() == {"detail": "spec: invalid JSON at line 1 column 11: Expecting value", "field": "spec"}


def test_study_creation_with_another_content_type_is_415(client) -> None:
    response = client.post("/api/study/studies", headers={**ADMIN, "content-type": "text/plain"}, content=b"{}")
    assert response.status_code == 415 and response.json()["field"] == "Content-Type"


def truncated_png() -> bytes:
    pixels = np.random.default_rng(0).integers(0, 256, (90, 160, 3), dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(pixels, "RGB").save(buffer, format="PNG")
    return buffer.getvalue()[: len(buffer.getvalue()) // 2]


@pytest.mark.parametrize(("data", "says"), [
    (b"not an image at all", "is not an image file"),
    (truncated_png(), "does not decode as a PNG or JPEG image"),
])
def test_upload_errors_never_show_object_reprs(client, data: bytes, says: str) -> None:
    spec = {"title": "x", "generated": {"cases": ["clean-00_straight_urban"]}}
    response = client.post("/api/study/studies", headers=ADMIN, data={"spec": json.dumps(spec)},
                           files=[("files", ("photo.png", data, "image/png"))])
    assert response.status_code == 422 and response.json()["field"] == "files.0"
    detail = response.json()["detail"]
    assert detail.startswith(f"files.0: photo.png {says}")
    assert "object at 0x" not in detail and "BytesIO" not in detail


# ------------------------------------------------------------------------------------------ the OpenAPI description


def operations(schema: dict):
    for path, item in schema["paths"].items():
        for method, operation in item.items():
            yield path, method, operation


def test_openapi_documents_the_error_body_and_statuses(client) -> None:
    schema = client.get("/openapi.json").json()
    assert "HTTPValidationError" not in schema["components"]["schemas"]
    assert set(schema["components"]["schemas"]["ErrorBody"]["properties"]) == {"detail", "field"}
    for path, method, operation in operations(schema):
        responses = operation["responses"]
        for status, response in responses.items():
            if status.startswith("4"):
                ref = response["content"]["application/json"]["schema"]["$ref"]
                assert ref == "#/components/schemas/ErrorBody", (path, method, status)
        if "requestBody" in operation:
            assert {"413", "415", "422"} <= set(responses), (path, method)
    paths = schema["paths"]
    assert "404" in paths["/api/cases/{case_id}"]["get"]["responses"]
    assert "409" in paths["/api/cases/{case_id}"]["put"]["responses"]
    assert "404" in paths["/api/cases/{case_id}/labels"]["get"]["responses"]
    exports = paths["/api/exports"]["post"]["responses"]
    assert "429" in exports and "Retry-After" in exports["429"]["headers"]
    assert "429" in paths["/api/cases/{case_id}/export.zip"]["get"]["responses"]


def test_every_json_answer_of_the_api_has_a_named_schema(client) -> None:
    schema = client.get("/openapi.json").json()
    undescribed = []
    for path, method, operation in operations(schema):
        for status, response in operation["responses"].items():
            body = response.get("content", {}).get("application/json")
            if not status.startswith("2") or body is None:
                continue
            named = body.get("schema") or {}
            if "$ref" not in named and "$ref" not in named.get("items", {}):  # a model, or a list of one
                undescribed.append((method, path, status))
    # Files served as they are: labels.json and a drive's summary.json.
    assert {(method, path) for method, path, _ in undescribed} <= {
        ("get", "/api/cases/{case_id}/labels"), ("get", "/api/drives/{job_id}/files/{name}")}, undescribed
    illusions = client.get("/api/illusions").json()
    assert IllusionRegistry.model_validate(illusions).model_dump() == illusions


def test_openapi_describes_study_creation(client) -> None:
    schema = client.get("/openapi.json").json()
    create = schema["paths"]["/api/study/studies"]["post"]
    content = create["requestBody"]["content"]
    form = content["multipart/form-data"]["schema"]
    assert form["required"] == ["spec"] and form["properties"]["files"]["items"]["format"] == "binary"
    assert form["properties"]["spec"]["$ref"] == "#/components/schemas/StudySpec"
    assert form["properties"]["spec"]["example"]["title"]
    assert content["multipart/form-data"]["encoding"]["spec"]["contentType"] == "application/json"
    assert content["application/json"]["schema"] == {"$ref": "#/components/schemas/StudySpec"}
    assert {"StudySpec", "ItemSpec", "GeneratedSet"} <= set(schema["components"]["schemas"])
    assert {"201", "202", "401", "403", "413", "415", "422"} <= set(create["responses"])
    assert create["security"] == [{"OrganiserToken": []}]


@pytest.mark.parametrize("method", ["PUT", "PATCH", "DELETE"])
@pytest.mark.parametrize("if_match", ["9" * 4400, '"' + "1" * 19 + '"', "null", "W/\"x\""])
def test_if_match_that_is_no_version_names_if_match(client, method: str, if_match: str) -> None:
    body = {} if method == "DELETE" else {"json": {"title": "x"}}
    response = client.request(method, f"/api/cases/{SHADOW_ID}", headers={"If-Match": if_match}, **body)
    assert response.status_code == 422
    assert response.json()["field"] == "If-Match"
    assert len(response.json()["detail"]) < 200


def test_if_match_pattern_is_documented(client) -> None:
    put = client.get("/openapi.json").json()["paths"]["/api/cases/{case_id}"]["put"]
    header = next(p for p in put["parameters"] if p["name"] == "If-Match")
    assert "pattern" in header["schema"]


def test_an_integer_over_the_digit_limit_names_body(client) -> None:
    response = post_case(client, b'{"title": "x", "seed": ' + b"9" * 4400 + b"}")
    assert response.status_code == 422
    assert response.json()["field"] == "body"
    assert "too long" in response.json()["detail"]


def test_an_empty_category_is_no_filter(client) -> None:
    assert client.get("/api/cases?category=&type=").json() == client.get("/api/cases").json()


@pytest.mark.parametrize(("path", "methods"), [
    ("/api/cases", "GET, OPTIONS, POST"),
    (f"/api/cases/{SHADOW_ID}", "DELETE, GET, OPTIONS, PATCH, PUT"),
])
def test_options_and_405_list_every_method_of_the_path(client, path: str, methods: str) -> None:
    response = client.options(path)
    assert response.status_code == 204
    assert response.headers["allow"] == methods
    assert client.request("TRACE", path).headers["allow"] == methods


def test_multipart_without_boundary_names_content_type(client) -> None:
    response = client.post("/api/study/studies", content=b"x",
                           headers={**ADMIN, "content-type": "multipart/form-data"})
    assert response.status_code == 422
    assert response.json()["field"] == "Content-Type"
