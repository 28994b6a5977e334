"""The API's documentation pages, ``/docs`` (Swagger UI) and ``/redoc``, served whole by this app.

FastAPI's default pages load Swagger UI and ReDoc from a CDN, so they are blank on a machine without internet. The
same pages are built here with FastAPI's own ``get_swagger_ui_html``/``get_redoc_html`` and point at the scripts,
styles and icon that the ``fastapi-offline`` package ships (Swagger UI 5, which reads OpenAPI 3.1), served at
``/docs-assets``. Only those files of the package are used.
"""

from __future__ import annotations

from pathlib import Path

import fastapi_offline
from fastapi import APIRouter, FastAPI, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import HTMLResponse
from fastapi.staticfiles import StaticFiles

from .headers import inline_script_policy

ASSETS_DIR = Path(fastapi_offline.__file__).resolve().parent / "static"
ASSETS_URL = "/docs-assets"
DOCS_URL, REDOC_URL, OAUTH2_REDIRECT_URL = "/docs", "/redoc", "/docs/oauth2-redirect"
SWAGGER_PARAMETERS = {"tryItOutEnabled": True, "displayRequestDuration": True, "defaultModelsExpandDepth": 0}

router = APIRouter(include_in_schema=False)


def _openapi_url(request: Request) -> str:
    return f"{request.scope.get('root_path', '')}{request.app.openapi_url}"


def _asset(request: Request, name: str) -> str:
    return f"{request.scope.get('root_path', '')}{ASSETS_URL}/{name}"


def with_inline_scripts_allowed(page: HTMLResponse) -> HTMLResponse:
    """``page`` with a Content-Security-Policy that lets exactly its own inline start-up scripts run."""
    page.headers["Content-Security-Policy"] = inline_script_policy(bytes(page.body).decode("utf-8"))
    return page


@router.get(DOCS_URL)
def swagger_ui(request: Request) -> HTMLResponse:
    page = get_swagger_ui_html(openapi_url=_openapi_url(request), title=f"{request.app.title} API",
                               swagger_js_url=_asset(request, "swagger-ui-bundle.js"),
                               swagger_css_url=_asset(request, "swagger-ui.css"),
                               swagger_favicon_url=_asset(request, "favicon.png"),
                               oauth2_redirect_url=OAUTH2_REDIRECT_URL, swagger_ui_parameters=SWAGGER_PARAMETERS)
    return with_inline_scripts_allowed(page)


@router.get(OAUTH2_REDIRECT_URL)
def swagger_ui_redirect() -> HTMLResponse:
    return with_inline_scripts_allowed(get_swagger_ui_oauth2_redirect_html())


@router.get(REDOC_URL)
def redoc(request: Request) -> HTMLResponse:
    page = get_redoc_html(openapi_url=_openapi_url(request), title=f"{request.app.title} API",
                          redoc_js_url=_asset(request, "redoc.standalone.js"),
                          redoc_favicon_url=_asset(request, "favicon.png"), with_google_fonts=False)
    return with_inline_scripts_allowed(page)


def mount_docs(app: FastAPI) -> None:
    """Serve ``/docs``, ``/redoc`` and their assets (create the app with ``docs_url=None, redoc_url=None``)."""
    app.include_router(router)
    app.mount(ASSETS_URL, StaticFiles(directory=ASSETS_DIR), name="docs-assets")
