"""The demo website: ``static/index.html`` at ``/`` and the files under ``static/`` at ``/static``."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, FastAPI, HTTPException
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles

STATIC_DIR = Path(__file__).resolve().parent.parent / "static"

router = APIRouter(include_in_schema=False)


@router.get("/")
def index() -> FileResponse:
    page = STATIC_DIR / "index.html"
    if not page.is_file():
        raise HTTPException(404, detail="the demo website is not installed (static/index.html)")
    return FileResponse(page, media_type="text/html")


def mount_static(app: FastAPI) -> None:
    """Serve ``static/`` at ``/static`` and the site's index at ``/``."""
    STATIC_DIR.mkdir(exist_ok=True)
    app.include_router(router)
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")
