"""The API's documentation pages, ``/docs`` (Swagger UI) and ``/redoc``, served whole by this app.

FastAPI's default pages load Swagger UI and ReDoc from a CDN, so they are blank on a machine without internet. The
same pages are built here with FastAPI's own ``get_swagger_ui_html``/``get_redoc_html`` and point at the scripts,
styles that the ``fastapi-offline`` package ships (Swagger UI 5, which reads OpenAPI 3.1), served at
``/docs-assets``, with the site's own icon. ReDoc's bundle draws a "by Redocly" badge whose image it loads from
``cdn.redoc.ly``; it is served here with that image inlined (a ``data:`` URL of the site's icon), so the page makes
no request off this machine.
"""

from __future__ import annotations

import base64
import functools
from pathlib import Path

import fastapi_offline
from fastapi import APIRouter, FastAPI, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import HTMLResponse, Response
from fastapi.staticfiles import StaticFiles

from .headers import inline_script_policy
from .site import FAVICON_URL, STATIC_DIR

ASSETS_DIR = Path(fastapi_offline.__file__).resolve().parent / "static"
ASSETS_URL = "/docs-assets"
DOCS_URL, REDOC_URL, OAUTH2_REDIRECT_URL = "/docs", "/redoc", "/docs/oauth2-redirect"
REDOC_JS = "redoc.standalone.js"
REDOC_BADGE_URL = "https://cdn.redoc.ly/redoc/logo-mini.svg"
SWAGGER_PARAMETERS = {"tryItOutEnabled": True, "displayRequestDuration": True, "defaultModelsExpandDepth": 0}

router = APIRouter(include_in_schema=False)


def _openapi_url(request: Request) -> str:
    return f"{request.scope.get('root_path', '')}{request.app.openapi_url}"


def _asset(request: Request, name: str) -> str:
    return f"{request.scope.get('root_path', '')}{ASSETS_URL}/{name}"


def _favicon(request: Request) -> str:
    return f"{request.scope.get('root_path', '')}{FAVICON_URL}"


@functools.cache
def offline_redoc_js() -> bytes:
    """ReDoc's bundle with its badge image inlined instead of loaded from the CDN."""
    bundle = (ASSETS_DIR / REDOC_JS).read_bytes()
    icon = (STATIC_DIR / FAVICON_URL.removeprefix("/static/")).read_bytes()
    return bundle.replace(REDOC_BADGE_URL.encode(), b"data:image/svg+xml;base64," + base64.b64encode(icon))


def with_inline_scripts_allowed(page: HTMLResponse) -> HTMLResponse:
    """``page`` with a Content-Security-Policy that lets exactly its own inline start-up scripts run."""
    page.headers["Content-Security-Policy"] = inline_script_policy(bytes(page.body).decode("utf-8"))
    return page


@router.get(DOCS_URL)
def swagger_ui(request: Request) -> HTMLResponse:
    page = get_swagger_ui_html(openapi_url=_openapi_url(request), title=f"{request.app.title} API",
                               swagger_js_url=_asset(request, "swagger-ui-bundle.js"),
                               swagger_css_url=_asset(request, "swagger-ui.css"),
                               swagger_favicon_url=_favicon(request),
                               oauth2_redirect_url=OAUTH2_REDIRECT_URL, swagger_ui_parameters=SWAGGER_PARAMETERS)
    return with_inline_scripts_allowed(page)


@router.get(OAUTH2_REDIRECT_URL)
def swagger_ui_redirect() -> HTMLResponse:
    return with_inline_scripts_allowed(get_swagger_ui_oauth2_redirect_html())


@router.get(REDOC_URL)
def redoc(request: Request) -> HTMLResponse:
    page = get_redoc_html(openapi_url=_openapi_url(request), title=f"{request.app.title} API",
                          redoc_js_url=_asset(request, REDOC_JS), redoc_favicon_url=_favicon(request),
                          with_google_fonts=False)
    return with_inline_scripts_allowed(page)


# Declared before the assets are mounted, so this route answers for the bundle instead of the package's file.
@router.get(f"{ASSETS_URL}/{REDOC_JS}")
def redoc_js() -> Response:
    return Response(offline_redoc_js(), media_type="text/javascript")


def mount_docs(app: FastAPI) -> None:
    """Serve ``/docs``, ``/redoc`` and their assets (create the app with ``docs_url=None, redoc_url=None``)."""
    app.include_router(router)
    app.mount(ASSETS_URL, StaticFiles(directory=ASSETS_DIR), name="docs-assets")
