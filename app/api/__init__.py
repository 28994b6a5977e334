"""The REST API under ``/api``: cases, frames, detectors, labels, exports, drives, the illusion registry,
uploaded meshes (``docs/api.md``)."""

from fastapi import APIRouter

from . import cases, detectors, drives, exports, illusions, images, labels, meshes
from .errors import ApiError, ErrorBody
from .limits import BodyLimitMiddleware

router = APIRouter()
for _module in (cases, images, detectors, labels, exports, drives, illusions, meshes):
    router.include_router(_module.router)

__all__ = ["ApiError", "BodyLimitMiddleware", "ErrorBody", "router"]
