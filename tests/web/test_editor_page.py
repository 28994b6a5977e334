"""The editor's page: viser's page with the editor's script, and the script's report read back at connect."""

from __future__ import annotations

from types import SimpleNamespace

from websockets.datastructures import Headers
from websockets.http11 import Request

from app.editor.page import SCRIPT, BrowserWebGL, browser_webgl, page_html, serve_page


def request(path: str, **headers: str) -> Request:
    return Request(path, Headers(headers))


def test_the_page_carries_the_script_first_and_other_files_stay_viser_s() -> None:
    html = page_html().decode()
    assert html.index(SCRIPT) < html.index("<script", html.index(SCRIPT) + len(SCRIPT))  # before viser's code
    answer = serve_page(None, request("/?fixedDpr=0.25"))  # type: ignore[arg-type]
    assert answer is not None and answer.status_code == 200 and answer.body == page_html()
    assert serve_page(None, request("/assets/index.js")) is None  # type: ignore[arg-type]
    assert serve_page(None, request("/", Upgrade="websocket")) is None  # type: ignore[arg-type]
    assert "UNMASKED_RENDERER_WEBGL" in SCRIPT and "stopImmediatePropagation" in SCRIPT


def server_with(cookie: str | None) -> SimpleNamespace:
    headers = Headers({"Cookie": cookie} if cookie is not None else {})
    connection = SimpleNamespace(request=SimpleNamespace(headers=headers))
    return SimpleNamespace(_websock_server=SimpleNamespace(_live_connections={3: connection}))


def test_the_page_s_report_is_read_from_the_handshake_cookies() -> None:
    software = server_with("lanevil_webgl=software; lanevil_renderer=ANGLE%20(SwiftShader%20Device)")
    found = browser_webgl(software, 3)  # type: ignore[arg-type]
    assert found == BrowserWebGL(software=True, renderer="ANGLE (SwiftShader Device)")
    assert browser_webgl(server_with("lanevil_webgl=hardware"), 3).software is False  # type: ignore[arg-type]
    assert browser_webgl(server_with(None), 3) == BrowserWebGL()  # type: ignore[arg-type]  # not the page
    assert browser_webgl(software, 4) == BrowserWebGL()  # type: ignore[arg-type]  # no such client
