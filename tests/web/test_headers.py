"""Security headers on every response of the app: pages, API answers, errors and the API docs."""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

from app.headers import SECURITY_HEADERS


@pytest.mark.parametrize(("method", "path"), [
    ("GET", "/"), ("GET", "/study"), ("GET", "/api/cases"), ("GET", "/api/cases/no-such-case"),
    ("GET", "/static/js/main.js"), ("GET", "/openapi.json"), ("OPTIONS", "/api/cases"), ("DELETE", "/api/illusions"),
])
def test_every_response_carries_the_security_headers(client, method: str, path: str) -> None:
    headers = client.request(method, path).headers
    for name in ("X-Frame-Options", "X-Content-Type-Options", "Referrer-Policy", "Content-Security-Policy"):
        assert headers[name] == SECURITY_HEADERS[name], name
    policy = headers["Content-Security-Policy"]
    assert "default-src 'self'" in policy and "frame-ancestors 'none'" in policy
    script_src = re.search(r"script-src ([^;]*)", policy)
    assert script_src is not None and "unsafe-inline" not in script_src.group(1)


def test_a_413_carries_them_too(client) -> None:
    response = client.post("/api/cases", content=b"x" * 3_000_000, headers={"content-type": "application/json"})
    assert response.status_code == 413
    assert response.headers["X-Frame-Options"] == "DENY"


@pytest.mark.parametrize("path", ["/docs", "/redoc", "/docs/oauth2-redirect"])
def test_docs_pages_allow_exactly_their_inline_scripts(client, path: str) -> None:
    response = client.get(path)
    found = re.search(r"script-src ([^;]*)", response.headers["Content-Security-Policy"])
    assert found is not None
    script_src = found.group(1)
    inline = re.findall(r"<script>", response.text)
    assert "unsafe-inline" not in script_src
    assert script_src.count("'sha256-") == len(inline)
    assert response.headers["X-Frame-Options"] == "DENY"


def assert_security_headers(headers) -> None:
    for name, value in SECURITY_HEADERS.items():
        assert headers[name] == value, name


def test_an_unexpected_500_carries_them_and_the_error_body(app) -> None:
    def broken() -> None:
        raise RuntimeError("/srv/data/cases went away")

    app.add_api_route("/api/broken", broken, methods=["GET"])
    with TestClient(app, raise_server_exceptions=False) as client:
        response = client.get("/api/broken")
    assert response.status_code == 500
    assert_security_headers(response.headers)
    assert response.json() == {"detail": "internal server error: the request could not be completed", "field": None}


def test_a_route_that_fails_inside_the_store_answers_500_with_them(app, state, monkeypatch) -> None:
    def fail(*args, **kwargs):
        raise OSError(f"disk gone under {state.settings.data_dir}")

    monkeypatch.setattr(state.store, "list", fail)
    with TestClient(app, raise_server_exceptions=False) as client:
        response = client.get("/api/cases")
    assert response.status_code == 500
    assert_security_headers(response.headers)
    assert str(state.settings.data_dir) not in response.text
