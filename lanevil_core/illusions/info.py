"""One illusion type described for people and front ends: ``lanevil illusions`` and ``GET /api/illusions``."""

from __future__ import annotations

import dataclasses
from typing import Any

from .base import Illusion


def illusion_info(cls: type[Illusion]) -> dict[str, Any]:
    """Name, category, tunable parameters (with ranges and defaults) and the severity table of one type."""
    schema = cls.model_json_schema()
    parameters = {}
    for field, spec in schema.get("properties", {}).items():
        if field == "type":
            continue
        keys = ("type", "anyOf", "enum", "default", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum",
                "description")
        parameters[field] = {key: spec[key] for key in keys if key in spec}
    return {"name": cls.model_fields["type"].default, "category": cls.CATEGORY,
            "description": " ".join((cls.__doc__ or "").strip().split("\n\n")[0].split()), "parameters": parameters,
            "severity": [dataclasses.asdict(row) for row in cls.SEVERITY], "sun": sun_control(cls)}


def sun_control(cls: type[Illusion]) -> str:
    """How a type's sun relates to the case's: ``case`` (it leaves the sun alone), ``overrides`` (it places the
    sun itself, and its ``sun_*`` fields, which sun sliders set, move it) or ``table`` (its severity table places
    the sun; no slider moves it)."""
    if not cls.SETS_SUN:
        return "case"
    return "overrides" if all(f"sun_{name}" in cls.model_fields for name in ("azimuth", "altitude")) else "table"
