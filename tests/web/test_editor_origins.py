"""The editor's websocket refuses handshakes from foreign pages (403) and takes its own (101): a raw handshake."""

from __future__ import annotations

import base64
import os
import socket
from collections.abc import Iterator

import pytest

from app.editor import Editor, launch_editor
from app.editor.origins import OriginCheck
from app.settings import Settings
from app.state import AppState


def handshake_status(port: int, origin: str | None, host: str = "127.0.0.1") -> int:
    key = base64.b64encode(os.urandom(16)).decode("ascii")
    lines = ["GET / HTTP/1.1", f"Host: {host}:{port}", "Upgrade: websocket", "Connection: Upgrade",
             f"Sec-WebSocket-Key: {key}", "Sec-WebSocket-Version: 13", "Sec-WebSocket-Protocol: viser-v1"]
    if origin is not None:
        lines.append(f"Origin: {origin}")
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(("\r\n".join(lines) + "\r\n\r\n").encode("ascii"))
        status_line = sock.recv(4096).split(b"\r\n", 1)[0].decode("ascii")
    return int(status_line.split()[1])


@pytest.fixture
def bare_editor(state: AppState) -> Iterator[Editor]:
    editor = launch_editor(state, host="127.0.0.1", port=0, api_port=8123)
    yield editor
    editor.stop()


def test_foreign_origins_are_refused_and_own_ones_taken(bare_editor: Editor) -> None:
    port = bare_editor.port
    for origin in ("http://evil.example", f"http://evil.example:{port}", "null", "http://127.0.0.1:1",
                   f"file://127.0.0.1:{port}"):
        assert handshake_status(port, origin) == 403, origin
    for own in (f"http://127.0.0.1:{port}", f"http://localhost:{port}", "http://localhost:8123",
                f"http://[::1]:{port}", None):
        assert handshake_status(port, own) == 101, own


def test_the_page_itself_is_still_served(bare_editor: Editor) -> None:
    with socket.create_connection(("127.0.0.1", bare_editor.port), timeout=10) as sock:
        sock.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nOrigin: http://evil.example\r\n\r\n")
        assert sock.recv(64).startswith(b"HTTP/1.1 200")


def test_allowed_origins_setting_and_listening_everywhere() -> None:
    settings = Settings(allowed_origins="http://studio.example:8080, https://other.example")
    assert settings.allowed_origins == ["http://studio.example:8080", "https://other.example"]
    check = OriginCheck("127.0.0.1", lambda: {8080}, settings.allowed_origins)
    assert check.allows("http://studio.example:8080") and not check.allows("http://studio.example:9000")
    everywhere = OriginCheck("0.0.0.0", lambda: {8080})
    assert everywhere.allows("http://192.168.1.5:8080", "192.168.1.5:8080")
    assert not everywhere.allows("http://evil.example", "192.168.1.5:8080")
    assert OriginCheck("127.0.0.1", lambda: {8080}, ["*"]).allows("http://anything.example")
