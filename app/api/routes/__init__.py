"""The REST API's resources, one router module each, all mounted under ``/api`` here and nowhere else
(``docs/api.md``). A new resource is a module with ``router = APIRouter(tags=[...], route_class=ApiRoute, ...)``
added to ``RESOURCES``; what every route shares (errors, limits, dependencies, parameters) is in ``app/api/``."""

from fastapi import APIRouter

from ..openapi import API_PREFIX
from . import cases, detectors, drives, exports, illusions, images, labels, meshes, study

# In the order of the paths of /openapi.json.
RESOURCES = (cases, images, detectors, labels, exports, drives, illusions, meshes, study)

router = APIRouter(prefix=API_PREFIX)
for _module in RESOURCES:
    router.include_router(_module.router)

__all__ = ["RESOURCES", "router"]
