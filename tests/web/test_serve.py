"""``lanevil serve`` end to end: one process starts uvicorn and the viser editor, prints both addresses, and
stops both cleanly on SIGTERM and on Ctrl+C (SIGINT)."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time

import httpx
import pytest

from app.settings import Settings

URL_PATTERN = re.compile(r"(website and API|editor)\s+(http://\S+/)")


def _start(settings: Settings) -> tuple[subprocess.Popen[str], dict[str, str]]:
    command = [sys.executable, "-m", "app.cli", "serve", "--port", "0", "--editor-port", "0",
               "--data", str(settings.data_dir), "--scenes", str(settings.scenes_dir)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    urls: dict[str, str] = {}
    deadline = time.monotonic() + 120
    assert process.stderr is not None
    while len(urls) < 2 and time.monotonic() < deadline:
        line = process.stderr.readline()
        if not line:
            break
        match = URL_PATTERN.search(line)
        if match:
            urls[match.group(1)] = match.group(2)
    return process, urls


def _wait_ready(url: str) -> httpx.Response:
    deadline = time.monotonic() + 60
    while True:
        try:
            return httpx.get(url, timeout=5)
        except httpx.TransportError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


@pytest.mark.slow
@pytest.mark.parametrize("stop_signal", [signal.SIGTERM, signal.SIGINT])
def test_serve_runs_backend_and_editor_and_stops_cleanly(settings: Settings, stop_signal: signal.Signals) -> None:
    process, urls = _start(settings)
    try:
        assert set(urls) == {"website and API", "editor"}, urls
        api, editor = urls["website and API"], urls["editor"]
        assert api.startswith("http://127.0.0.1:") and editor.startswith("http://127.0.0.1:")
        assert _wait_ready(api + "docs").status_code == 200
        assert _wait_ready(editor).status_code == 200  # viser serves its client page over HTTP too
        redirect = httpx.get(api + "editor", follow_redirects=False)
        assert redirect.status_code == 307 and redirect.headers["location"] == editor
        assert (settings.data_dir / "cases" / "fence_shadow-00_uphill_rural_noon-03_level3.json").is_file()
    finally:
        process.send_signal(stop_signal)
        code = process.wait(timeout=30)
    assert code == 0


def test_a_busy_port_is_named_and_exits_2(settings: Settings, capsys: pytest.CaptureFixture[str]) -> None:
    from app.cli import main
    from app.server import bind

    busy = bind("127.0.0.1", 0)
    port = busy.getsockname()[1]
    try:
        status = main(["serve", "--port", str(port), "--no-editor", "--data", str(settings.data_dir),
                       "--scenes", str(settings.scenes_dir)])
    finally:
        busy.close()
    err = capsys.readouterr().err.strip()
    assert status == 2 and len(err.splitlines()) == 1
    assert f"cannot listen on 127.0.0.1:{port}: address already in use" in err and "--port" in err
    assert not settings.data_dir.exists()  # refused before the store was opened
