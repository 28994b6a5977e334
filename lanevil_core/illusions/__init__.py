"""The registry of environmental illusions, one module per category."""

from __future__ import annotations

from typing import Annotated, Union

from pydantic import Field

from . import reflection, road_damage, shadow, traffic  # noqa: F401  (modules register their types)
from .base import CATEGORIES, REGISTRY, Category, CompileContext, Illusion, register

ILLUSION_TYPES: tuple[str, ...] = tuple(REGISTRY)

# The ``illusions`` list of a case: a discriminated union on ``type``.
if len(REGISTRY) >= 2:
    IllusionSpec = Annotated[Union[tuple(REGISTRY.values())], Field(discriminator="type")]  # type: ignore[valid-type]
else:  # while the registry is being filled
    IllusionSpec = Illusion  # type: ignore[misc]

__all__ = [
    "CATEGORIES",
    "ILLUSION_TYPES",
    "REGISTRY",
    "Category",
    "CompileContext",
    "Illusion",
    "IllusionSpec",
    "register",
]
