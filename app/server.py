"""One process, one command: the FastAPI backend under uvicorn and the viser editor, sharing one case store.

uvicorn owns the main thread (and its SIGINT/SIGTERM handling); viser runs its own websocket server on a
background thread. When uvicorn stops, the editor and the job pool are stopped too.
"""

from __future__ import annotations

import contextlib
import errno
import signal
import socket
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass

import uvicorn

from .main import create_app
from .memory import limit_malloc_arenas
from .settings import Settings
from .state import AppState
from .study.token import TOKEN_FILE, with_organiser_token


@dataclass(frozen=True)
class Urls:
    """Where a running server can be reached."""

    api: str
    editor: str | None


class _Server(uvicorn.Server):
    """uvicorn, but a Ctrl+C / SIGTERM only asks it to stop: the caller then stops the editor and returns, instead
    of the signal being raised again (uvicorn's default) and killing the process before the editor is closed."""

    @contextlib.contextmanager
    def capture_signals(self) -> Iterator[None]:
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        handled = (signal.SIGINT, signal.SIGTERM)
        previous = {sig: signal.signal(sig, self.handle_exit) for sig in handled}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


class ListenError(Exception):
    """The API's address cannot be bound (a busy port, an address this machine does not have)."""


def bind(host: str, port: int) -> socket.socket:
    """A listening TCP socket on ``host:port`` (port 0: any free port)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((host, port))
    sock.listen(128)
    sock.set_inheritable(True)
    return sock


def listen(host: str, port: int) -> socket.socket:
    """``bind``, or a ``ListenError`` that names the address and port and says what to do."""
    try:
        return bind(host, port)
    except OSError as error:
        reason = (error.strerror or str(error)).lower()
        hint = " (another server runs there: stop it, or choose another port with --port; 0 = any free port)" \
            if error.errno == errno.EADDRINUSE else ""
        raise ListenError(f"cannot listen on {_http_host(host)}:{port}: {reason}{hint}") from None


def _http_host(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def serve(settings: Settings) -> int:
    """Run the backend (and the editor, unless ``settings.editor`` is off) until Ctrl+C / SIGTERM."""
    limit_malloc_arenas(settings.malloc_arenas)  # before any thread starts (memory.py)
    sock = listen(settings.host, settings.port)  # first: a busy port fails at once, before the store is opened
    settings, new_token = with_organiser_token(settings)
    state = AppState.open(settings)
    app = create_app(settings, state)
    api_port = sock.getsockname()[1]
    editor = None
    if settings.editor:
        from .editor import launch_editor

        editor = launch_editor(state, host=settings.host, port=settings.editor_port, api_port=api_port)
        app.state.editor_port = editor.port
        app.state.open_in_editor = editor.open_case
    urls = Urls(api=f"http://{_http_host(settings.host)}:{api_port}/",
                editor=f"http://{_http_host(settings.host)}:{editor.port}/" if editor else None)
    print(f"LanEvil Studio: {len(state.store)} cases in {settings.data_dir}", file=sys.stderr)
    print(f"  website and API  {urls.api}  (API docs {urls.api}docs, study {urls.api}study)", file=sys.stderr)
    if urls.editor:
        print(f"  editor           {urls.editor}  (also {urls.api}editor)", file=sys.stderr, flush=True)
    if new_token:
        print(f"study organiser token: {settings.admin_token} (stored in {settings.data_dir / TOKEN_FILE})",
              file=sys.stderr, flush=True)
    server = _Server(uvicorn.Config(app, log_level="info", timeout_graceful_shutdown=5))
    try:
        server.run(sockets=[sock])
    finally:
        if editor is not None:
            editor.stop()
        state.jobs.shutdown()
        sock.close()
    print("LanEvil Studio: stopped", file=sys.stderr)
    return 0
