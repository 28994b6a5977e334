"""Shared fixtures: small, fast cases."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from lanevil_core.case import Case

SMALL_SIZE = (320, 180)
ROOT = Path(__file__).resolve().parents[1]


def _merge(base: dict[str, Any], extra: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in extra.items():
        out[key] = _merge(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    return out


@pytest.fixture
def make_case() -> Callable[..., Case]:
    """Factory of valid cases: a 320x180 camera, 50 frames, no roadside props; keyword sections override."""

    def factory(**sections: Any) -> Case:
        base = {
            "camera": {"width": SMALL_SIZE[0], "height": SMALL_SIZE[1]},
            "ego": {"frames": 50},
            "scene": {"density": 0.0},
        }
        return Case.model_validate(_merge(base, sections))

    return factory


@pytest.fixture(scope="session")
def load_script() -> Callable[[str], ModuleType]:
    """Importer of a script of the repository that is not a package module (``bench/defences.py``,
    ``scripts/carla_run.py``), by its path from the repository root; registered under its file name."""

    def load(relative: str) -> ModuleType:
        path = ROOT / relative
        spec = importlib.util.spec_from_file_location(path.stem, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[path.stem] = module  # dataclasses defined in the script look their module up
        spec.loader.exec_module(module)
        return module

    return load


class LaneServer:
    """A real HTTP lane detector on a thread: white vertical stripes of the posted PNG are its lanes.

    Paths: ``/detect`` answers ``{"lanes": [[[x, top], [x, bottom]], ...], "scores": [...]}`` at each stripe's centre
    column; ``/nonsense`` answers text, ``/bad`` a lane that is not points, ``/fail`` HTTP 500, ``/slow`` after
    ``slow_s``, ``/reject`` HTTP 400. ``sizes`` are the (width, height) of the images received, ``content_types``
    their headers, ``calls`` per path, ``peak`` the most requests in flight at once.
    """

    def __init__(self) -> None:
        import threading
        from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

        self.sizes: list[tuple[int, int]] = []
        self.content_types: list[str] = []
        self.calls: dict[str, int] = {}
        self.in_flight = 0
        self.peak = 0
        self.slow_s = 1.0
        self.hold_s = 0.0  # /detect waits this long (to overlap requests)
        self._lock = threading.Lock()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:  # quiet
                pass

            def do_POST(self) -> None:  # noqa: N802 - http.server's name
                body = self.rfile.read(int(self.headers["Content-Length"]))
                with server._lock:
                    server.calls[self.path] = server.calls.get(self.path, 0) + 1
                    server.in_flight += 1
                    server.peak = max(server.peak, server.in_flight)
                try:
                    status, answer = server.answer(self.path, self.headers.get("Content-Type", ""), body)
                finally:
                    with server._lock:
                        server.in_flight -= 1
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(answer)))
                self.end_headers()
                self.wfile.write(answer)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def url(self, path: str = "/detect") -> str:
        return f"http://127.0.0.1:{self.httpd.server_address[1]}{path}"

    def answer(self, path: str, content_type: str, body: bytes) -> tuple[int, bytes]:
        import json
        import time

        import cv2
        import numpy as np

        if path == "/fail":
            return 500, b'{"error": "model crashed"}'
        if path == "/reject":
            return 400, b'{"error": "image too small"}'
        if path == "/nonsense":
            return 200, b"<html>hello</html>"
        if path == "/bad":
            return 200, json.dumps({"lanes": [[1, 2, 3]]}).encode()
        if path == "/slow":
            time.sleep(self.slow_s)
        time.sleep(self.hold_s)
        gray = cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_GRAYSCALE)
        height, width = gray.shape
        self.sizes.append((width, height))
        self.content_types.append(content_type)
        bright = np.concatenate([[False], gray.mean(axis=0) > 200, [False]])
        edges = np.flatnonzero(np.diff(bright.astype(np.int8)))
        centres = [(start + end - 1) / 2.0 for start, end in zip(edges[::2], edges[1::2], strict=True)]
        lanes = [[[x, 0.0], [x, height - 1.0]] for x in centres]
        return 200, json.dumps({"lanes": lanes, "scores": [1.0] * len(lanes)}).encode()

    def close(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def lane_server() -> Any:
    """A running ``LaneServer``, shut down after the test."""
    server = LaneServer()
    yield server
    server.close()


def striped_frame(columns: list[int], size: tuple[int, int] = SMALL_SIZE) -> Any:
    """(H, W, 3) uint8: a dark frame with 4 px wide white vertical stripes starting at ``columns``."""
    import numpy as np

    rgb = np.full((size[1], size[0], 3), 40, np.uint8)
    for column in columns:
        rgb[:, column:column + 4] = 255
    return rgb


@pytest.fixture
def stripes() -> Callable[..., Any]:
    return striped_frame


@pytest.fixture
def down_url() -> str:
    """The URL of a detector server that is down: a port just bound and closed again."""
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    return f"http://127.0.0.1:{port}/detect"
