"""``GET /api/illusions``: the illusion registry (what ``lanevil illusions --json`` prints) and the case schema."""

from __future__ import annotations

from functools import cache
from typing import Any

from fastapi import APIRouter
from pydantic import BaseModel, Field

from lanevil_core.case import case_schema
from lanevil_core.illusions import CATEGORIES, REGISTRY
from lanevil_core.illusions.info import illusion_info

from ..errors import ApiRoute

router = APIRouter(tags=["illusions"], route_class=ApiRoute)


class IllusionInfo(BaseModel):
    name: str
    category: str
    description: str
    parameters: dict[str, dict[str, Any]] = Field(description="field -> type, range, default, description")
    severity: list[dict[str, Any]] = Field(description="the five-row severity table, level 1 first")
    sun: str = Field(description="case: the type leaves the sun alone; overrides: it places the sun and its sun_* "
                                 "fields (the sun sliders) move it; table: its severity table places the sun")


class IllusionRegistry(BaseModel):
    data: list[IllusionInfo]
    count: int
    categories: dict[str, list[str]] = Field(description="category -> its illusion types")
    case_schema: dict[str, Any] = Field(description="the JSON schema of case documents")


@cache
def registry_document() -> dict[str, Any]:
    """Every illusion type (category, parameters with types/ranges/defaults/descriptions, five-row severity
    table), the types of each category, and the JSON schema of case documents. Fixed for the process's life."""
    infos = [illusion_info(cls) for cls in REGISTRY.values()]
    by_category = {category: [info["name"] for info in infos if info["category"] == category]
                   for category in CATEGORIES}
    return {"data": infos, "count": len(infos), "categories": by_category, "case_schema": case_schema()}


@router.get("/illusions", summary="The illusion registry and the case schema", response_model=None,
            responses={200: {"model": IllusionRegistry}})
def get_illusions() -> dict[str, Any]:
    """``{"data": [{name, category, description, parameters, severity}, ...], "count", "categories",
    "case_schema"}``."""
    return registry_document()
