"""The demo website: ``static/index.html`` at ``/``, the files under ``static/`` at ``/static``, and the site's icon.

Pages link the SVG icon (``FAVICON_URL``); ``/favicon.ico`` answers the request browsers make on their own (and
for pages that link none) with the same picture as ``static/favicon.ico`` (16, 32 and 48 px, drawn after the SVG)."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, FastAPI, HTTPException
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles

STATIC_DIR = Path(__file__).resolve().parent.parent / "static"
FAVICON_URL = "/static/img/lanes.svg"

router = APIRouter(include_in_schema=False)


def _static_file(name: str, what: str, media_type: str, headers: dict[str, str] | None = None) -> FileResponse:
    path = STATIC_DIR / name
    if not path.is_file():
        raise HTTPException(404, detail=f"{what} is not installed (static/{name})")
    return FileResponse(path, media_type=media_type, headers=headers)


@router.get("/")
def index() -> FileResponse:
    return _static_file("index.html", "the demo website", "text/html")


@router.get("/favicon.ico")
def favicon() -> FileResponse:
    return _static_file("favicon.ico", "the site's icon", "image/x-icon", {"Cache-Control": "public, max-age=86400"})


def mount_static(app: FastAPI) -> None:
    """Serve ``static/`` at ``/static`` and the site's index at ``/``."""
    STATIC_DIR.mkdir(exist_ok=True)
    app.include_router(router)
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")
