"""The viser editor: one server, and one ``EditorTab`` per connected browser tab.

viser calls ``on_client_connect`` for every tab that opens (a reload is a new tab), and the editor builds that
tab's panel, 3D view and preview in the tab's own client-scoped GUI and scene. Nothing a tab sets (open case,
unsaved edits, severity, sun, detector, quality, frame) is kept at server level, so a new tab starts from the
stored case and the panel's defaults, never from what another tab did. ``launch_editor`` starts it.
"""

from __future__ import annotations

import threading
import time

import viser

from ..state import AppState
from .origins import OriginCheck, hooking_requests
from .page import browser_webgl, serve_page
from .tab import EditError, EditorTab


class Editor:
    """The editor served by one ``viser.ViserServer`` over the backend's ``AppState``: its tabs by client id."""

    def __init__(self, state: AppState, server: viser.ViserServer) -> None:
        self.state = state
        self.server = server
        self.tabs: dict[int, EditorTab] = {}
        self._next_case: str | None = None
        self._gone: set[int] = set()  # tabs closed while their panel was still being built
        self._changed = threading.Condition()
        self._stopped = False
        server.on_client_connect(self._connect)
        server.on_client_disconnect(self._disconnect)

    @property
    def port(self) -> int:
        """The port viser really listens on."""
        return self.server.get_port()

    def open_case(self, case_id: str) -> None:
        """Have the next tab that connects open stored case ``case_id`` (``/editor?case=ID`` redirects a new tab
        here right after); tabs already open keep their case."""
        if case_id not in self.state.store:
            raise EditError(f"case_id: no case {case_id!r} in the store")
        with self._changed:
            self._next_case = case_id

    def tab(self, client_id: int | None = None, timeout: float = 60.0, after: int = -1) -> EditorTab:
        """The tab of ``client_id`` (None: the newest with an id above ``after``), waiting up to ``timeout`` s."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while True:
                ids = [i for i in self.tabs if (i > after if client_id is None else i == client_id)]
                if ids:
                    return self.tabs[max(ids)]
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError(f"no editor tab connected within {timeout:g} s")
                self._changed.wait(remaining)

    def stop(self) -> None:
        """Stop every tab, then the viser server."""
        with self._changed:
            self._stopped = True
            tabs = list(self.tabs.values())
            self.tabs.clear()
        for tab in tabs:
            tab.stop()
        self.server.stop()

    def _connect(self, client: viser.ClientHandle) -> None:
        with self._changed:
            case_id, self._next_case = self._next_case, None
        tab = EditorTab(self.state, client, case_id, browser_webgl(self.server, client.client_id))
        with self._changed:
            if self._stopped or client.client_id in self._gone:
                self._gone.discard(client.client_id)
                stale = True
            else:
                self.tabs[client.client_id] = tab
                stale = False
            self._changed.notify_all()
        if stale:
            tab.stop()

    def _disconnect(self, client: viser.ClientHandle) -> None:
        with self._changed:
            tab = self.tabs.pop(client.client_id, None)
            if tab is None:
                self._gone.add(client.client_id)
            self._changed.notify_all()
        if tab is not None:
            tab.stop()


def launch_editor(state: AppState, host: str = "127.0.0.1", port: int = 8080, api_port: int | None = None) -> Editor:
    """Start the viser editor on ``host:port`` (0 = any free port) over ``state``; ``editor.port`` is the real one.

    Its websocket takes pages of its own and the API's port (``api_port``, default the settings') on loopback and
    ``host``, and ``state.settings.allowed_origins`` (``origins.py``); other origins get a 403."""
    bound: list[int] = []
    ports = {state.settings.port if api_port is None else api_port}
    check = OriginCheck(host, lambda: {*bound, *ports}, state.settings.allowed_origins)
    with hooking_requests([check.process_request, serve_page]):
        server = viser.ViserServer(host=host, port=port, label="LanEvil editor", verbose=False)
    bound.append(server.get_port())
    return Editor(state, server)
