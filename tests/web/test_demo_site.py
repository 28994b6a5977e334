"""The demo website at ``/``: page structure, every referenced asset served, and the API calls it builds on."""

from __future__ import annotations

import posixpath
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from lanevil_core.illusions import CATEGORIES, REGISTRY

STATIC = Path(__file__).resolve().parents[2] / "static"
JS_IMPORT = re.compile(r"""^\s*import\s[^;]*?from\s+["'](\.{1,2}/[^"']+)["']""", re.MULTILINE)
CSS_URL = re.compile(r"""url\(\s*["']?(/static/[^"')]+)""")


class PageParser(HTMLParser):
    """Collects tag attributes of the page (outside and inside ``<template>``)."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append((tag, dict(attrs)))

    def find(self, tag: str, **attrs: str) -> list[dict[str, str | None]]:
        return [a for t, a in self.tags if t == tag and all(a.get(k.rstrip("_")) == v for k, v in attrs.items())]


@pytest.fixture
def page(client) -> PageParser:
    response = client.get("/")
    assert response.status_code == 200
    assert response.headers["content-type"].startswith("text/html")
    parser = PageParser()
    parser.feed(response.text)
    return parser


def static_references(parser: PageParser) -> set[str]:
    """``/static/...`` URLs of the page, of the ES modules it imports (transitively) and of its stylesheets."""
    found = {url for _, a in parser.tags for key in ("src", "href")
             if (url := a.get(key) or "").startswith("/static/")}
    pending = list(found)
    while pending:
        url = pending.pop()
        text = (STATIC / url.removeprefix("/static/")).read_text(encoding="utf-8")
        if url.endswith(".js"):
            nested = {posixpath.normpath(posixpath.join(posixpath.dirname(url), spec))
                      for spec in JS_IMPORT.findall(text)}
        elif url.endswith(".css"):
            nested = set(CSS_URL.findall(text))
        else:
            nested = set()
        pending.extend(nested - found)
        found |= nested
    return found


def test_page_structure(page: PageParser) -> None:
    assert page.find("html", lang="en")
    assert page.find("meta", name="viewport")
    assert page.find("h1")
    sections = [a["data-category"] for a in page.find("section") if a.get("data-category")]
    assert sections == list(CATEGORIES)  # one section per category, in benchmark order
    assert page.find("script", type="module", src="/static/js/main.js")
    assert page.find("template", id="card-template") and page.find("template", id="frame-template")
    assert page.find("input", type="checkbox", id="overlay-toggle")
    assert page.find("label", for_="overlay-toggle")
    links = {a["href"] for a in page.find("a")}
    assert {"/editor", "/docs", "/study"} <= links


def test_card_template_controls_are_labelled(page: PageParser) -> None:
    sliders = [a for a in page.find("input", type="range")]
    assert {a["data-control"] for a in sliders} == {"severity", "azimuth", "altitude"}
    severity = next(a for a in sliders if a["data-control"] == "severity")
    assert (severity["min"], severity["max"], severity["step"]) == ("1", "5", "1")
    labelled = {a["data-for"] for a in page.find("label") if a.get("data-for")}
    assert labelled == {"severity", "azimuth", "altitude"}
    assert all("alt" in a for a in page.find("img"))


def test_every_referenced_asset_is_served(client, page: PageParser) -> None:
    references = static_references(page)
    assert {"/static/css/site.css", "/static/js/main.js", "/static/js/card.js", "/static/js/api.js",
            "/static/js/latest-image.js", "/static/img/lanes.svg"} <= references
    for url in sorted(references):
        response = client.get(url)
        assert response.status_code == 200, url
        assert response.content, url
    assert client.get("/static/js/main.js").headers["content-type"].split(";")[0] in {
        "text/javascript", "application/javascript"}


def test_no_external_resources(page: PageParser) -> None:
    """The site works offline: no CDN scripts, stylesheets or fonts."""
    urls = [a.get(key) or "" for _, a in page.tags for key in ("src", "href")]
    assert not [url for url in urls if re.match(r"(https?:)?//", url)]
    for path in [*STATIC.glob("css/*.css"), *STATIC.glob("js/*.js")]:
        assert not re.search(r"https?://|@import", path.read_text(encoding="utf-8")), path.name


def test_api_the_page_builds_on(client) -> None:
    """The registry feeds the cards; a type's listing holds the stock ids the cards pick; a missing type is empty."""
    registry = client.get("/api/illusions").json()["data"]
    assert [info["name"] for info in registry] == list(REGISTRY)
    assert all(len(info["severity"]) == 5 for info in registry)
    ids = {row["id"] for row in client.get("/api/cases", params={"type": "fence_shadow"}).json()["data"]}
    assert {"fence_shadow-00_uphill_rural_noon-00_original", "fence_shadow-00_uphill_rural_noon-03_level3"} <= ids
    assert client.get("/api/cases", params={"type": "road_crack"}).json()["data"] == []
    envelope = client.get("/api/cases/fence_shadow-00_uphill_rural_noon-03_level3").json()
    assert {"azimuth", "altitude", "intensity"} <= set(envelope["case"]["sun"])


def test_frame_url_the_page_builds_renders_a_jpeg(client) -> None:
    response = client.get("/api/cases/fence_shadow-00_uphill_rural_noon-03_level3/frames/0.jpg",
                          params={"width": 160, "height": 90, "overlay": "true", "severity": 5,
                                  "sun_azimuth": 90, "sun_altitude": 30})
    assert response.status_code == 200
    assert response.headers["content-type"] == "image/jpeg"
    assert response.content[:2] == b"\xff\xd8"


def test_detector_select_and_score_line(client, page: PageParser) -> None:
    """The toolbar's detector select (filled from /api/detectors) and the score line under each frame."""
    assert page.find("select", id="detector-select") and page.find("label", for_="detector-select")
    assert any("hidden" in a for a in page.find("span", class_="frame__score"))
    assert "/static/js/latest-score.js" in static_references(page)
    names = [entry["name"] for entry in client.get("/api/detectors").json()["data"]]
    assert "ufld" in names  # the page's default
    response = client.get("/api/cases/fence_shadow-00_uphill_rural_noon-03_level3/frames/0/detections",
                          params={"width": 160, "height": 90, "detector": "hough", "severity": 5, "sun_azimuth": 90,
                                  "sun_altitude": 30})
    assert response.status_code == 200 and 0.0 <= response.json()["accuracy"] <= 1.0
