"""Shared fixtures: small, fast cases; plug-in detectors (an HTTP lane server, an installed entry point, a
trained ONNX mask model)."""

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
    """Importer of a script of the repository that is not a package module (``experiments/defences.py``,
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
        assert gray is not None
        height, width = gray.shape
        self.sizes.append((width, height))
        self.content_types.append(content_type)
        bright = np.concatenate([[False], gray.mean(axis=0) > 200, [False]])
        edges = np.flatnonzero(np.diff(bright.astype(np.int8)))
        centers = [(start + end - 1) / 2.0 for start, end in zip(edges[::2], edges[1::2], strict=True)]
        lanes = [[[x, 0.0], [x, height - 1.0]] for x in centers]
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


MASK_INPUT_SIZE = (128, 72)


@pytest.fixture(scope="session")
def trained_mask_model(tmp_path_factory) -> Path:
    """A two-layer lane-line segmenter trained for a few steps on drawn white lines, exported to ONNX with its
    sidecar (a ``mask`` head; the frame's top quarter cropped; real_trained); trained once per test run."""
    import json
    import warnings

    import cv2
    import numpy as np

    torch = pytest.importorskip("torch")
    torch.manual_seed(0)
    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    width, height = MASK_INPUT_SIZE
    images, masks = [], []
    for _ in range(16):
        rgb = np.full((height, width, 3), rng.integers(20, 90), np.uint8)
        mask = np.zeros((height, width), np.uint8)
        for _ in range(2):
            start = (int(rng.integers(0, width)), height - 1)
            end = (int(rng.integers(0, width)), int(rng.integers(0, height // 2)))
            cv2.line(rgb, start, end, (255, 255, 255), 2)
            cv2.line(mask, start, end, 1, 2)
        noise = rng.normal(0, 8, rgb.shape)
        images.append(np.clip(rgb + noise, 0, 255).astype(np.uint8))
        masks.append(mask)
    x = torch.tensor((np.stack(images).astype(np.float32) / 255.0 - 0.5) / 0.5).permute(0, 3, 1, 2)
    y = torch.tensor(np.stack(masks), dtype=torch.float32)[:, None]
    model = torch.nn.Sequential(torch.nn.Conv2d(3, 8, 3, padding=1), torch.nn.ReLU(), torch.nn.Conv2d(8, 1, 1))
    optimiser = torch.optim.Adam(model.parameters(), lr=0.03)
    for _ in range(150):
        optimiser.zero_grad()
        loss = torch.nn.functional.binary_cross_entropy_with_logits(model(x), y, pos_weight=torch.tensor(4.0))
        loss.backward()
        optimiser.step()
    folder = tmp_path_factory.mktemp("mask_model")
    path = folder / "lanes.onnx"
    model.eval()
    with torch.no_grad(), warnings.catch_warnings():  # the TorchScript exporter, as lanevil_core.learn.export
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(model, x[:1], str(path), input_names=["image"], output_names=["mask"], dynamo=False)
    (folder / "lanes.json").write_text(json.dumps({
        "head": "mask", "input_size": list(MASK_INPUT_SIZE), "mean": [0.5] * 3, "std": [0.5] * 3,
        "color_order": "bgr", "crop": [0.0, 0.25, 1.0, 1.0], "logits": True, "threshold": 0.5,
        "real_trained": True}))
    return path


@pytest.fixture
def mask_model(trained_mask_model: Path, tmp_path: Path) -> Path:
    """A copy of the trained mask model and its sidecar in the test's own folder (free to change)."""
    import shutil

    for source in (trained_mask_model, trained_mask_model.with_suffix(".json")):
        shutil.copy(source, tmp_path / source.name)
    return tmp_path / trained_mask_model.name


PLUGIN_MODULE = '''
"""A plug-in detector installed for a test: the brightest column of the bottom row is its one lane."""
import numpy as np

from lanevil_core.detect.plugin import LaneDetector


class BrightColumn(LaneDetector):
    input_size = (160, 90)
    real_trained = True

    def detect(self, rgb):
        assert rgb.shape == (90, 160, 3), rgb.shape
        x = float(np.argmax(rgb[-1].sum(axis=1)))
        return [[[x, 0.0], [x, rgb.shape[0] - 1.0]]]


class Broken:
    def __init__(self):
        raise RuntimeError("no weights file")
'''


@pytest.fixture
def installed_plugin(tmp_path: Path, monkeypatch) -> Any:
    """A real installed distribution: a module and its ``*.dist-info`` with ``entry_points.txt`` on sys.path, so
    ``importlib.metadata`` finds its ``lanevil.detectors`` entry points ``bright``, ``broken`` and ``ufld``."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "bright_lanes.py").write_text(PLUGIN_MODULE)
    info = site / "bright_lanes-1.2.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: bright-lanes\nVersion: 1.2.0\n")
    (info / "entry_points.txt").write_text("[lanevil.detectors]\nbright = bright_lanes:BrightColumn\n"
                                           "broken = bright_lanes:Broken\nufld = bright_lanes:BrightColumn\n")
    monkeypatch.syspath_prepend(str(site))
    yield site
    sys.modules.pop("bright_lanes", None)
