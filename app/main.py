"""The FastAPI application: REST API under ``/api``, the demo website at ``/``, the perception study at ``/study``."""

from __future__ import annotations

from fastapi import FastAPI, HTTPException, Request, Response
from fastapi.responses import RedirectResponse

from lanevil_core import __version__

from .api import openapi as api_openapi
from .api.allow import AllowMiddleware
from .api.case_bodies import CASE_BODY_SCHEMAS
from .api.errors import error_response, handle_exception, handle_server_error
from .api.limits import BodyLimitMiddleware
from .api.routes import router as api_router
from .api.routes.study import SCHEMAS as STUDY_SCHEMAS
from .docs import mount_docs
from .headers import SecurityHeadersMiddleware
from .jobs import JobNotFound
from .settings import Settings
from .site import mount_static
from .state import AppState
from .store import InvalidId, StoreError
from .study.pages import router as study_router


def create_app(settings: Settings | None = None, state: AppState | None = None) -> FastAPI:
    """Build the app around ``state`` (default: opened from ``settings``, default: the environment)."""
    settings = settings or (state.settings if state else Settings())
    state = state or AppState.open(settings)
    app = FastAPI(title="LanEvil Studio", version=__version__, docs_url=None, redoc_url=None,
                  description="Editable 3D lane-detection robustness cases: store, render, export, study. Errors of "
                              "`/api` answer `{\"detail\": \"<field>: <message>\", \"field\": \"<field>\"}`.")
    app.state.lanevil = state
    app.add_middleware(AllowMiddleware)
    app.add_middleware(BodyLimitMiddleware, max_body_bytes=settings.max_body_bytes,
                       max_upload_bytes=settings.max_upload_bytes)
    app.add_middleware(SecurityHeadersMiddleware)  # added last = outermost: 413s carry the headers too
    for error in (StoreError, JobNotFound):  # the API's error body for store/job errors raised by any route
        app.add_exception_handler(error, handle_exception)
    app.add_exception_handler(Exception, handle_server_error)  # any other exception: a 500 with the headers
    app.include_router(api_router)  # every resource under /api
    app.include_router(study_router)  # the study's pages
    mount_docs(app)  # /docs and /redoc with their scripts served here, not from a CDN
    api_openapi.install(app, settings, {**STUDY_SCHEMAS, **CASE_BODY_SCHEMAS})
    mount_static(app)
    app.state.editor_port = None  # set by the server once the viser editor listens
    app.state.open_in_editor = None  # the editor's open_case(case_id) for the next tab, set with editor_port
    app.add_api_route("/editor", _editor_redirect, methods=["GET"], include_in_schema=False)
    return app


def _editor_redirect(request: Request, case: str | None = None) -> Response:
    """``/editor`` -> the viser editor on the same host name, so users need only the backend's address.
    ``/editor?case=ID`` has the editor tab this redirect opens start on stored case ``ID``."""
    port = request.app.state.editor_port
    if port is None:
        raise HTTPException(503, detail="the editor is not running (start it with `lanevil serve`)")
    if case is not None:
        try:
            request.app.state.lanevil.store.get(case)
        except StoreError as error:
            return error_response(422 if isinstance(error, InvalidId) else 404, f"case: {error}", "case")
        if request.app.state.open_in_editor is not None:
            request.app.state.open_in_editor(case)
    host = request.url.hostname or "127.0.0.1"
    host = f"[{host}]" if ":" in host else host
    return RedirectResponse(f"{request.url.scheme}://{host}:{port}/", status_code=307)
