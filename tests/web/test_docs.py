"""``/docs`` and ``/redoc`` work without internet: every script, style and icon they load is served by the app;
``/favicon.ico`` and the pages' icon link."""

from __future__ import annotations

import re

import pytest

from app.site import FAVICON_URL, STATIC_DIR

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


def test_the_redoc_bundle_loads_no_image_from_a_cdn(client) -> None:
    bundle = client.get("/docs-assets/redoc.standalone.js")
    assert bundle.status_code == 200 and bundle.headers["content-type"].startswith("text/javascript")
    assert "cdn.redoc.ly" not in bundle.text and 'src:"data:image/svg+xml;base64,' in bundle.text
    assert not re.search(r"""src:\s*["']https?://""", bundle.text)


@pytest.mark.parametrize("page", ["/", "/docs", "/redoc", "/study", "/study/admin", "/study/no-such-study"])
def test_pages_link_the_local_icon_and_favicon_ico_is_served(client, page: str) -> None:
    html = client.get(page).text
    icons = re.findall(r'<link rel="(?:shortcut )?icon"[^>]*href="([^"]+)"', html)
    assert icons and all(icon.startswith("/") for icon in icons), icons
    assert client.get(icons[0]).status_code == 200
    icon = client.get("/favicon.ico")
    assert icon.status_code == 200 and icon.headers["content-type"] == "image/x-icon"
    assert icon.content[:4] == b"\x00\x00\x01\x00"  # an ICO header


def test_every_static_page_links_the_icon() -> None:
    pages = sorted(STATIC_DIR.rglob("*.html"))
    assert len(pages) >= 4  # the demo site and the study's pages (participant.html needs a study to be served)
    for page in pages:
        assert f'<link rel="icon" href="{FAVICON_URL}"' in page.read_text(), page
