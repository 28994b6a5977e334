"""The demo website in headless Chromium against a live server on the small test store (only ``fence_shadow``).

Checks that sliders re-render the frames (debounced, ending on the latest value), the overlay toggle, the detector
select (magenta lanes and an accuracy caption under each frame), the card's editor link, error and "not in this
library" states, keyboard use, and layouts at desktop and phone widths (screenshots saved).
"""

from __future__ import annotations

import json
import re
import time

import pytest

pytestmark = pytest.mark.browser

CARD = "#card-fence_shadow"
PERTURBED = f'{CARD} figure[data-role="perturbed"] img'
ORIGINAL = f'{CARD} figure[data-role="original"] img'
TIMEOUT_MS = 20_000

# True once the picture of `sel` shows a new API URL (not `old`), decoded and no longer loading.
SHOWS_NEW = """([sel, old]) => {
  const img = document.querySelector(sel);
  return img && !img.hidden && img.dataset.src && img.dataset.src !== old && img.complete && img.naturalWidth > 0
    && img.closest("figure").getAttribute("aria-busy") === "false";
}"""
# FNV-1a over the decoded pixels of an <img>: equal pictures hash equal.
PIXEL_HASH = """(sel) => {
  const img = document.querySelector(sel);
  const canvas = document.createElement("canvas");
  canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
  const context = canvas.getContext("2d");
  context.drawImage(img, 0, 0);
  const data = context.getImageData(0, 0, canvas.width, canvas.height).data;
  let hash = 0x811c9dc5;
  for (let i = 0; i < data.length; i += 1) hash = Math.imul(hash ^ data[i], 16777619) >>> 0;
  return hash;
}"""
BROKEN_IMAGES = """() => [...document.images].filter((img) => !img.hidden && img.offsetParent !== null
  && (!img.complete || img.naturalWidth === 0)).length"""
SETTLED = """() => [...document.querySelectorAll(".card")].every((card) =>
  ["ready", "missing", "error"].includes(card.dataset.state)
  && [...card.querySelectorAll("figure")].every((figure) => figure.getAttribute("aria-busy") !== "true"))"""


def shown(page, sel: str) -> dict:
    return page.eval_on_selector(sel, "(img) => ({src: img.src, url: img.dataset.src, width: img.naturalWidth})")


def wait_new(page, sel: str, old: str | None) -> dict:
    page.wait_for_function(SHOWS_NEW, arg=[sel, old or ""], timeout=TIMEOUT_MS)
    return shown(page, sel)


def open_card(page, live_server) -> tuple[dict, dict]:
    page.goto(live_server.url + "/")
    page.locator(CARD).scroll_into_view_if_needed()
    return wait_new(page, ORIGINAL, None), wait_new(page, PERTURBED, None)


def load_every_card(page) -> None:
    """Scroll to the end (cards load lazily) and wait until every card has settled."""
    page.wait_for_selector("body[data-ready]")
    for card in page.locator(".card").all():
        card.scroll_into_view_if_needed()
    page.wait_for_function(SETTLED, timeout=TIMEOUT_MS)
    page.evaluate("window.scrollTo(0, 0)")


def test_sliders_and_overlay_rerender_the_frames(page, live_server) -> None:
    page.route("**/api/detectors", lambda route: route.fulfill(  # no detector: the frames as rendered
        status=200, content_type="application/json", body=json.dumps({"data": [], "count": 0})))
    original, perturbed = open_card(page, live_server)
    assert "severity=3" in perturbed["url"] and "overlay=false" in perturbed["url"]
    assert "detector" not in perturbed["url"]
    assert perturbed["width"] == 480
    level3 = page.evaluate(PIXEL_HASH, PERTURBED)

    slider = page.locator(f"{CARD} input[data-control=severity]")
    slider.focus()
    page.keyboard.press("ArrowRight")
    page.keyboard.press("ArrowRight")  # keyboard: 3 -> 5
    assert slider.input_value() == "5"
    level5 = wait_new(page, PERTURBED, perturbed["url"])
    assert "severity=5" in level5["url"] and level5["src"] != perturbed["src"]
    assert page.evaluate(PIXEL_HASH, PERTURBED) != level3
    assert page.locator(f'{CARD} figure[data-role="perturbed"] .frame__label').inner_text() == "Perturbed · level 5"
    assert shown(page, ORIGINAL)["url"] == original["url"]  # severity leaves the original alone

    azimuth_value = page.locator(f'{CARD} output[data-output="azimuth"]')
    assert azimuth_value.inner_text() == "auto"  # the shadow illusion places its own sun until overridden
    before = page.evaluate(PIXEL_HASH, ORIGINAL)
    page.locator(f"{CARD} input[data-control=azimuth]").fill("120")
    assert azimuth_value.inner_text() == "120°"
    assert "behind-left" in page.get_attribute(f"{CARD} input[data-control=azimuth]", "aria-valuetext")
    moved = wait_new(page, ORIGINAL, original["url"])
    assert "sun_azimuth=120" in moved["url"]
    assert page.evaluate(PIXEL_HASH, ORIGINAL) != before
    sunny = wait_new(page, PERTURBED, level5["url"])
    assert "sun_azimuth=120" in sunny["url"] and "severity=5" in sunny["url"]
    assert "sun_altitude" not in sunny["url"]  # only the angle moved: the illusion keeps its own altitude
    captions = page.locator(f"{CARD} .frame__label").all_inner_texts()
    assert captions == ["Original · sun azimuth 120°", "Perturbed · level 5 · sun azimuth 120°"]

    before = page.evaluate(PIXEL_HASH, PERTURBED)
    page.locator(f"{CARD} input[data-control=altitude]").fill("20")
    caption = page.locator(f'{CARD} figure[data-role="perturbed"] .frame__label').inner_text()
    assert caption.endswith("sun azimuth 120°, altitude 20°")
    low_sun = wait_new(page, PERTURBED, sunny["url"])
    assert "sun_altitude=20" in low_sun["url"]
    assert page.evaluate(PIXEL_HASH, PERTURBED) != before

    before = page.evaluate(PIXEL_HASH, PERTURBED)
    page.locator("label[for=overlay-toggle]").click()
    overlaid = wait_new(page, PERTURBED, low_sun["url"])
    assert "overlay=true" in overlaid["url"]
    assert page.evaluate(PIXEL_HASH, PERTURBED) != before
    assert "overlay=true" in wait_new(page, ORIGINAL, moved["url"])["url"]
    assert "lanes drawn" in page.get_attribute(PERTURBED, "alt")


def test_a_slider_drag_ends_on_the_latest_value_with_few_requests(page, live_server) -> None:
    _, perturbed = open_card(page, live_server)
    requested: list[str] = []
    page.on("request", lambda request: requested.append(request.url) if "/frames/" in request.url else None)
    # a drag: five input events in one task, well inside the debounce delay
    page.eval_on_selector(f"{CARD} input[data-control=severity]", """(slider) => {
      for (const value of ["1", "2", "4", "5", "1"]) {
        slider.value = value;
        slider.dispatchEvent(new Event("input", {bubbles: true}));
      }
    }""")
    final = wait_new(page, PERTURBED, perturbed["url"])
    assert "severity=1" in final["url"]
    page.wait_for_timeout(400)
    assert shown(page, PERTURBED)["url"] == final["url"]
    images = [url for url in requested if ".jpg?" in url]
    scores = [url for url in requested if "/detections?" in url]
    assert len(images) == 1 and len(scores) == 1, requested  # the picture and its detector's score
    assert "severity=1" in scores[0] and "detector=ufld" in scores[0]


def test_reset_returns_to_the_first_render(page, live_server) -> None:
    original, perturbed = open_card(page, live_server)
    page.locator(f"{CARD} input[data-control=severity]").fill("1")
    page.locator(f"{CARD} input[data-control=azimuth]").fill("200")
    changed = wait_new(page, PERTURBED, perturbed["url"])["url"]
    moved = wait_new(page, ORIGINAL, original["url"])["url"]
    page.locator(f"{CARD} .card__reset").click()
    assert wait_new(page, PERTURBED, changed)["url"] == perturbed["url"]
    assert wait_new(page, ORIGINAL, moved)["url"] == original["url"]
    assert page.locator(f"{CARD} input[data-control=severity]").input_value() == "3"


def test_api_errors_are_shown_on_the_card(page, live_server, screenshot_dir) -> None:
    _, perturbed = open_card(page, live_server)
    body = json.dumps({"detail": "severity: the renderer is out of paint", "field": "severity"})
    page.route("**/frames/0.jpg?*severity=2*", lambda route: route.fulfill(
        status=422, content_type="application/json", body=body))
    page.locator(f"{CARD} input[data-control=severity]").fill("2")
    error = page.locator(f'{CARD} figure[data-role="perturbed"] .frame__error')
    error.wait_for(state="visible", timeout=TIMEOUT_MS)
    assert "severity: the renderer is out of paint" in error.inner_text()
    page.locator(CARD).screenshot(path=str(screenshot_dir / "demo-card-error.png"))
    assert shown(page, PERTURBED)["url"] == perturbed["url"]  # the last good picture stays
    page.unroute("**/frames/0.jpg?*severity=2*")
    error.locator("button").click()
    assert "severity=2" in wait_new(page, PERTURBED, perturbed["url"])["url"]
    assert error.is_hidden()


def assert_missing_types_say_so(page) -> None:
    """The store holds only fence_shadow: the 13 other cards say so, with no broken images anywhere."""
    assert page.locator(".card").count() == 14
    assert page.locator('.card[data-state="missing"]').count() == 13
    crack = page.locator("#card-road_crack")
    assert crack.get_attribute("data-state") == "missing"
    assert "Not in this library" in crack.locator(".card__missing").inner_text()
    assert crack.locator("img:visible").count() == 0
    assert crack.locator(".controls").is_hidden()
    assert page.evaluate(BROKEN_IMAGES) == 0
    assert page.locator(f'{CARD}[data-state="ready"] img:visible').count() == 2


@pytest.mark.parametrize(("name", "width", "height"), [("desktop", 1280, 900), ("phone", 390, 844)])
def test_layout_and_missing_types(browser, live_server, screenshot_dir, name, width, height) -> None:
    context = browser.new_context(viewport={"width": width, "height": height}, device_scale_factor=1)
    page = context.new_page()
    try:
        page.goto(live_server.url + "/")
        load_every_card(page)
        assert_missing_types_say_so(page)
        assert page.evaluate("document.documentElement.scrollWidth") <= width  # no sideways scrolling
        columns = page.evaluate("""() => getComputedStyle(document.querySelector('.cards'))
          .gridTemplateColumns.split(' ').length""")
        assert columns == (1 if width < 700 else 2)
        page.screenshot(path=str(screenshot_dir / f"demo-{name}.png"))
        page.locator(CARD).scroll_into_view_if_needed()
        page.locator(CARD).screenshot(path=str(screenshot_dir / f"demo-{name}-card.png"))
        page.screenshot(path=str(screenshot_dir / f"demo-{name}-full.png"), full_page=True)
    finally:
        context.close()


def test_listing_and_registry_errors_are_shown(page, live_server) -> None:
    body = json.dumps({"detail": "store: not reachable"})
    page.route("**/api/cases?type=fence_shadow", lambda route: route.fulfill(
        status=503, content_type="application/json", body=body))
    page.goto(live_server.url + "/")
    page.locator(CARD).scroll_into_view_if_needed()
    error = page.locator(f"{CARD} .card__error")
    error.wait_for(state="visible", timeout=TIMEOUT_MS)
    assert "store: not reachable" in error.inner_text()
    assert page.get_attribute(CARD, "data-state") == "error"
    page.unroute("**/api/cases?type=fence_shadow")
    error.locator("button").click()
    wait_new(page, PERTURBED, None)
    assert error.is_hidden()

    page.route("**/api/illusions", lambda route: route.fulfill(
        status=500, content_type="application/json", body=json.dumps({"detail": "registry exploded"})))
    page.reload()
    banner = page.locator("#page-error")
    banner.wait_for(state="visible", timeout=TIMEOUT_MS)
    assert "registry exploded" in banner.inner_text()


SCORE = f'{CARD} figure[data-role="{{}}"] .frame__score'
# True once the score line of `sel` shows an answer for a URL holding `part` (not a placeholder).
SCORED = """([sel, part]) => {
  const line = document.querySelector(sel);
  return line && !line.hidden && (line.dataset.src || "").includes(part)
    && ["fooled", "holds"].includes(line.dataset.verdict);
}"""


def wait_scored(page, role: str, part: str) -> str:
    page.wait_for_function(SCORED, arg=[SCORE.format(role), part], timeout=TIMEOUT_MS)
    return page.locator(SCORE.format(role)).inner_text()


def test_detector_lanes_and_accuracy_captions(page, live_server, screenshot_dir) -> None:
    original, perturbed = open_card(page, live_server)
    select = page.locator("#detector-select")
    assert select.input_value() == "ufld"  # the default
    assert "detector=ufld" in original["url"] and "detector=ufld" in perturbed["url"]
    for role in ("original", "perturbed"):
        text = wait_scored(page, role, "detector=ufld")
        assert re.fullmatch(r"ufld · accuracy\s\d{1,3}\.\d% · FP\s-?\d(\.\d\d?)? · FN\s\d(\.\d\d?)?", text), text
    detections = page.evaluate(f"""() => fetch(document.querySelector('{SCORE.format("perturbed")}').dataset.src)
      .then((r) => r.json())""")
    assert f"\xa0{100 * detections['accuracy']:.1f}%" in page.locator(SCORE.format("perturbed")).inner_text()
    page.locator(CARD).screenshot(path=str(screenshot_dir / "demo-card-detector.png"))

    before = page.evaluate(PIXEL_HASH, PERTURBED)
    select.select_option("hough")
    hough = wait_new(page, PERTURBED, perturbed["url"])
    assert "detector=hough" in hough["url"] and page.evaluate(PIXEL_HASH, PERTURBED) != before
    assert wait_scored(page, "perturbed", "detector=hough").startswith("hough · accuracy\xa0")

    page.locator(f"{CARD} input[data-control=azimuth]").fill("150")  # a slider moves the score with the frame
    assert wait_scored(page, "original", "sun_azimuth=150").startswith("hough · accuracy\xa0")
    assert "sun azimuth 150°" in page.locator(f'{CARD} figure[data-role="original"] .frame__label').inner_text()

    select.select_option("")
    plain = wait_new(page, PERTURBED, hough["url"])
    assert "detector" not in plain["url"]
    assert page.locator(f"{CARD} .frame__score:visible").count() == 0


def test_unavailable_detectors_are_listed_disabled(page, live_server) -> None:
    body = {"data": [{"name": "ufld", "kind": "learned", "available": False, "reason": "no ufld model",
                      "model": None},
                     {"name": "hough", "kind": "classical", "available": True, "reason": None, "model": None}],
            "count": 2}
    page.route("**/api/detectors", lambda route: route.fulfill(status=200, content_type="application/json",
                                                              body=json.dumps(body)))
    _, perturbed = open_card(page, live_server)
    assert page.locator("#detector-select").input_value() == "hough"  # the default is not installed
    assert page.locator("#detector-select option[value=ufld]").is_disabled()
    assert "detector=hough" in perturbed["url"]


def test_editor_link_opens_the_cards_case(page, live_server) -> None:
    opened: list[str] = []
    live_server.app.state.editor_port = 1  # a port nothing listens on: only the redirect is followed here
    live_server.app.state.open_in_editor = opened.append
    open_card(page, live_server)
    link = page.locator(f"{CARD} .card__edit")
    assert link.get_attribute("href") == "/editor?case=fence_shadow-00_uphill_rural_noon-03_level3"
    with page.expect_request("**/editor?case=*"):
        link.click(no_wait_after=True)
    deadline = time.monotonic() + 10
    while not opened and time.monotonic() < deadline:
        time.sleep(0.05)
    assert opened == ["fence_shadow-00_uphill_rural_noon-03_level3"]
