"""The human perception study: pages under ``/study``, its API under ``/api/study``."""

from fastapi import APIRouter

router = APIRouter()
