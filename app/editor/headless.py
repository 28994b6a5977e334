"""A browser tab without a browser: a websocket client that connects to the editor as viser's page does.

It sends the page's first camera pose (viser counts a client as connected, and builds its tab, only once it has
reported its camera), then reads and drops whatever the server sends until it is closed. The
editor builds a full ``EditorTab`` for it, which tests and benchmarks then drive through its panel handles.
"""

from __future__ import annotations

import threading

import msgspec
import viser
from viser import _messages
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from .editor import Editor
from .tab import EditorTab

FIRST_CAMERA = _messages.ViewerCameraMessage(
    wxyz=(1.0, 0.0, 0.0, 0.0), position=(0.0, 0.0, 10.0), fov=1.0, near=0.01, far=1000.0, image_height=720,
    image_width=1280, look_at=(0.0, 0.0, 0.0), up_direction=(0.0, 0.0, 1.0))


class HeadlessTab:
    """One websocket client of ``editor`` (``with HeadlessTab(editor) as tab:`` gives its ``EditorTab``)."""

    def __init__(self, editor: Editor, timeout: float = 60.0) -> None:
        self.editor = editor
        self.timeout = timeout
        self._socket: ClientConnection | None = None
        self._reader: threading.Thread | None = None

    def open(self) -> EditorTab:
        """Connect and return the tab the editor built for this connection."""
        newest = max(self.editor.tabs, default=-1)
        url = f"ws://127.0.0.1:{self.editor.port}"
        self._socket = connect(url, subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
                               max_size=None, open_timeout=self.timeout)
        self._socket.send(msgspec.msgpack.encode(FIRST_CAMERA.as_serializable_dict()))
        self._reader = threading.Thread(target=self._drain, args=(self._socket,), name="lanevil-headless-tab",
                                        daemon=True)
        self._reader.start()
        return self.editor.tab(timeout=self.timeout, after=newest)

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close()
        if self._reader is not None:
            self._reader.join(timeout=10)

    def __enter__(self) -> EditorTab:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @staticmethod
    def _drain(socket: ClientConnection) -> None:
        try:
            for _message in socket:
                pass
        except ConnectionClosed:
            pass
