"""Shared fixtures of the web tests: an app on a small seeded store, a real uvicorn server, headless Chromium."""

from __future__ import annotations

import shutil
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import uvicorn
import viser
from fastapi import FastAPI
from fastapi.testclient import TestClient

from app.editor import Editor, EditorTab, HeadlessTab, launch_editor
from app.main import create_app
from app.server import bind
from app.settings import Settings
from app.state import AppState

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]  # WebGL (viser) without a GPU
# A small store keeps seeding fast: two clean cases and one illusion type's original and levels.
SMALL_LIBRARY = ["00_clean/00_straight_urban.json", "00_clean/01_bend_suburban.json",
                 *(f"30_shadow/fence_shadow/00_uphill_rural_noon/{name}.json"
                   for name in ("00_original", "01_level1", "03_level3", "05_level5"))]


def small_scenes(target: Path) -> Path:
    """Copy ``SMALL_LIBRARY`` (same relative paths) under ``target``; return it."""
    for relative in SMALL_LIBRARY:
        (target / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(SCENES / relative, target / relative)
    return target


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    """Settings on a fresh data folder seeded from the small library; admin token ``test-admin``."""
    return Settings(data_dir=tmp_path / "data", scenes_dir=small_scenes(tmp_path / "scenes"), port=0,
                    editor_port=0, admin_token="test-admin", frame_cache_bytes=64_000_000)


@pytest.fixture
def state(settings: Settings) -> Iterator[AppState]:
    state = AppState.open(settings)
    yield state
    state.jobs.shutdown()


@pytest.fixture
def app(settings: Settings, state: AppState) -> FastAPI:
    return create_app(settings, state)


@pytest.fixture
def client(app: FastAPI) -> Iterator[TestClient]:
    with TestClient(app) as test_client:
        yield test_client


@dataclass
class LiveServer:
    """A real uvicorn server on a free loopback port, running on a background thread."""

    url: str
    app: FastAPI
    state: AppState


@pytest.fixture
def live_server(app: FastAPI, state: AppState) -> Iterator[LiveServer]:
    sock = bind("127.0.0.1", 0)
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise RuntimeError("uvicorn did not start")
        time.sleep(0.02)
    yield LiveServer(url=f"http://127.0.0.1:{sock.getsockname()[1]}", app=app, state=state)
    server.should_exit = True
    thread.join(timeout=10)
    sock.close()


@pytest.fixture(scope="session")
def browser():
    """Headless Debian Chromium through Playwright (skipped with a reason when Chromium is not installed)."""
    if not CHROMIUM.exists():
        pytest.skip("Debian chromium is not installed (scripts/install-chromium installs it)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser):
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    page = context.new_page()
    yield page
    context.close()


SCREENSHOTS = REPO / "tests" / "web" / "_screenshots"


@pytest.fixture
def screenshot_dir() -> Path:
    """Where browser tests save what they saw (ignored by git; open the PNGs to look at them)."""
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    return SCREENSHOTS


def _pick(page, current: str, option: str) -> None:
    combos = page.locator("input[role=combobox]")
    index = combos.evaluate_all(f"(inputs) => inputs.findIndex((i) => i.value === {current!r})")
    assert index >= 0, f"no dropdown shows {current!r}"
    combos.nth(index).click()
    page.get_by_role("option", name=option, exact=True).click()


@pytest.fixture
def pick() -> Callable[..., None]:
    """``pick(page, current, option)``: choose ``option`` in the viser dropdown of ``page`` that now shows
    ``current`` (browser tests)."""
    return _pick


@pytest.fixture
def editor(state: AppState) -> Iterator[Editor]:
    """The viser editor on the test store for a browser test (a free port); stopped afterwards."""
    editor = launch_editor(state, host="127.0.0.1", port=0)
    yield editor
    editor.stop()


def _wait_for(condition: Callable[[], bool], what: str, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


@pytest.fixture
def wait_for() -> Callable[..., None]:
    """``wait_for(condition, what, timeout=90)``: poll until ``condition()`` holds, else fail naming ``what``."""
    return _wait_for


@pytest.fixture
def editor_url(editor: Editor) -> str:
    """The editor's page for a browser test, whose tabs get a light 3D view.

    The page finds Chromium's software WebGL (SwiftShader) and the tab starts with its 3D view off; tests that
    click the road turn it to ``light`` (no environment map, no shadow maps) as a user would with *3D view*, and
    close the start screen.
    SwiftShader spends about two CPU seconds on each full-resolution frame of a road scene and viser draws one a
    second even when idle (measured, CPU-s per second of an idle tab's GPU process: 1.9; at a quarter of the
    resolution 0.9; also without the environment map and shadow maps 0.2), so the page draws at a quarter of the
    resolution (viser's ``fixedDpr``)."""

    def light_view(client: viser.ClientHandle) -> None:
        tab = editor.tab(client.client_id, timeout=EDITOR_START_S)
        tab.display.set_view_mode("light")
        if tab.start is not None:  # the tests start on the case the tab opened behind the start screen
            tab.start.close()

    editor.server.on_client_connect(light_view)
    return f"http://127.0.0.1:{editor.port}/?fixedDpr=0.25"


EDITOR_START_S = 120.0  # the first preview compiles the numba kernels on a cold cache


@pytest.fixture
def editor_server(state: AppState) -> Iterator[Editor]:
    """The viser editor on the test store (a free port), no tab open yet; stopped afterwards."""
    editor = launch_editor(state, host="127.0.0.1", port=0)
    yield editor
    editor.stop()


@pytest.fixture
def tab(editor_server: Editor) -> Iterator[EditorTab]:
    """One tab of the editor (a headless websocket client), its first preview rendered."""
    with HeadlessTab(editor_server, timeout=EDITOR_START_S) as tab:
        assert tab.preview.wait_idle(EDITOR_START_S)
        yield tab
