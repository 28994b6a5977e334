"""``GET /api/illusions``: the illusion registry (what ``lanevil illusions --json`` prints) and the case schema."""

from __future__ import annotations

from functools import cache
from typing import Any

from fastapi import APIRouter

from lanevil_core.case import case_schema
from lanevil_core.cli.library import illusion_info
from lanevil_core.illusions import CATEGORIES, REGISTRY

from .errors import ApiRoute

router = APIRouter(tags=["illusions"], route_class=ApiRoute)


@cache
def registry_document() -> dict[str, Any]:
    """Every illusion type (category, parameters with types/ranges/defaults/descriptions, five-row severity
    table), the types of each category, and the JSON schema of case documents. Fixed for the process's life."""
    infos = [illusion_info(cls) for cls in REGISTRY.values()]
    by_category = {category: [info["name"] for info in infos if info["category"] == category]
                   for category in CATEGORIES}
    return {"data": infos, "count": len(infos), "categories": by_category, "case_schema": case_schema()}


@router.get("/illusions", summary="The illusion registry and the case schema")
def get_illusions() -> dict[str, Any]:
    """``{"data": [{name, category, description, parameters, severity}, ...], "count", "categories",
    "case_schema"}``."""
    return registry_document()
