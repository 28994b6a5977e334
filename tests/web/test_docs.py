"""``/docs`` and ``/redoc`` work without internet: every script, style and icon they load is served by the app."""

from __future__ import annotations

import re

import pytest

ASSET = re.compile(r"""(?:src|href|url)\s*[=:(]\s*['"]([^'"]+)['"]""")


@pytest.mark.parametrize(("page", "needs"), [("/docs", "swagger-ui-bundle.js"), ("/redoc", "redoc.standalone.js")])
def test_docs_pages_load_only_local_assets(client, page: str, needs: str) -> None:
    response = client.get(page)
    assert response.status_code == 200 and response.headers["content-type"].startswith("text/html")
    assets = ASSET.findall(response.text)
    assert any(url.endswith(needs) for url in assets), assets
    assert "http://" not in response.text and "https://" not in response.text
    for url in assets:
        assert url.startswith("/"), url
        fetched = client.get(url)
        assert fetched.status_code == 200 and len(fetched.content) > 0, url


def test_swagger_ui_is_version_5_which_reads_openapi_3_1(client) -> None:
    assert client.get("/openapi.json").json()["openapi"].startswith("3.1")
    bundle = client.get("/docs-assets/swagger-ui-bundle.js").text
    assert re.search(r'"5\.\d+\.\d+"', bundle)
