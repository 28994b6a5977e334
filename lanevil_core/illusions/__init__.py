"""The registry of environmental illusions, one module per category."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Union

from pydantic import Field

# Import order is registry order: the benchmark's category order.
from . import road_damage, traffic, shadow, reflection  # noqa: F401  # isort: skip
from .base import CATEGORIES, REGISTRY, Category, CompileContext, EgoDrive, Illusion, MeshFileError, register

ILLUSION_TYPES: tuple[str, ...] = tuple(REGISTRY)

# The ``illusions`` list of a case: a discriminated union on ``type``. A type checker sees the base class, whose
# interface every member of the union has.
if TYPE_CHECKING:
    IllusionSpec = Illusion
elif len(REGISTRY) >= 2:
    # Union[...] over the registry's tuple of classes: X | Y has no spelling for a tuple built at run time.
    IllusionSpec = Annotated[Union[tuple(REGISTRY.values())], Field(discriminator="type")]  # noqa: UP007
else:  # while the registry is being filled
    IllusionSpec = Illusion

__all__ = [
    "CATEGORIES",
    "ILLUSION_TYPES",
    "REGISTRY",
    "Category",
    "CompileContext",
    "EgoDrive",
    "Illusion",
    "MeshFileError",
    "IllusionSpec",
    "register",
]
