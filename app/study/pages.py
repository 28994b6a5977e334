"""The study's HTML pages: ``/study`` (what the study is, the open studies, the way to the organiser's page),
``/study/<study_id>`` for participants, ``/study/admin`` for the organiser (results, and creating studies).

All are static files from ``static/study/`` (plain HTML, CSS and JavaScript, served at ``/static/study/``) that
talk to ``/api/study``. The participant page is answered with 404 for an unknown study id.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, HTTPException
from fastapi.responses import FileResponse, HTMLResponse

from .deps import DbDep
from .records import NotFound, get_study

STATIC_STUDY = Path(__file__).resolve().parents[2] / "static" / "study"
NOT_FOUND_PAGE = """<!doctype html><html lang="en"><head><meta charset="utf-8"><title>Study not found</title>
<link rel="icon" href="/static/img/lanes.svg" type="image/svg+xml">
<link rel="stylesheet" href="/static/study/study.css"></head><body><main class="card"><h1>Study not found</h1>
<p>This link does not lead to a study. Please check the address you were given.</p></main></body></html>"""

router = APIRouter(prefix="/study", include_in_schema=False)


def _page(name: str) -> FileResponse:
    path = STATIC_STUDY / name
    if not path.is_file():
        raise HTTPException(404, detail=f"the study pages are not installed (static/study/{name})")
    return FileResponse(path, media_type="text/html", headers={"Cache-Control": "no-cache"})


@router.get("")
def landing_page() -> FileResponse:
    return _page("index.html")


@router.get("/admin")
def admin_page() -> FileResponse:
    return _page("admin.html")


@router.get("/{study_id}", response_model=None)
def participant_page(study_id: str, db: DbDep) -> FileResponse | HTMLResponse:
    try:
        get_study(db, study_id)
    except NotFound:
        return HTMLResponse(NOT_FOUND_PAGE, status_code=404)
    return _page("participant.html")
