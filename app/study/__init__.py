"""The human perception study: pages under ``/study``, its API under ``/api/study``.

An organiser creates a study from generated frames and uploaded real photos (``api.post_study``); participants
rate each image once on the 5-point ACR scale; results are MOS with 95 % CIs per source, illusion type and
severity after screening raters on gold and trapping items (``stats``). See ``docs/study.md``.
"""

from fastapi import APIRouter

from .api import router as api_router
from .pages import router as pages_router

router = APIRouter()
router.include_router(api_router)
router.include_router(pages_router)

__all__ = ["router"]
