"""Security headers on every response of the app: pages, API answers, errors and the API docs."""

from __future__ import annotations

import re

import pytest

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
