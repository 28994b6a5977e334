"""The illusion interface and registry.

An illusion is a small pydantic model (its ``type`` is the stable name used in case files, the API and exports)
with a ``severity`` 1-5, a ``seed``, placement on the road and a five-row ``SEVERITY`` table. ``compile`` turns it
into real scene elements (meshes, road-surface layers, lights, sun and wetness changes), never a 2D overlay.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StrictFloat, StrictInt

if TYPE_CHECKING:
    from ..world.road_layout import RoadNetwork
    from ..world.scene import Environment, Mesh, PointLight, SurfaceLayer

Category = Literal["road_damage", "traffic", "shadow", "reflection"]
CATEGORIES: tuple[Category, ...] = ("road_damage", "traffic", "shadow", "reflection")

# Where an illusion lands by default: this far ahead of the ego's start, so the first frames see it.
DEFAULT_AHEAD_M = 22.0
# Where an illusion that runs along the road ends by default: this far past the ego's last position, so the last
# frames still see it ahead.
BEYOND_DRIVE_M = 30.0
MAX_ROAD_LENGTH_M = 3000.0  # the longest main road a case may have (``Road.length``)
Unit = Annotated[StrictFloat, Field(ge=0.0, le=1.0)]
RGB = tuple[Unit, Unit, Unit]  # a linear RGB colour of a case file


@dataclass(frozen=True)
class EgoDrive:
    """What an illusion reads of its case: the ego's lane and its scripted drive along the main road."""

    lane: int  # the ego's lane of its direction, 0 = next to the centre line
    start_s: float  # where the drive starts on the main road (m)
    end_s: float  # where the ego is at the last frame (m)
    road_length: float  # the case's road length (m)


@dataclass
class CompileContext:
    """What an illusion may read (the case's seed and sun, the ego's drive, the road) and add to (meshes, layers,
    lights, environment); the shadow of a low sun may also leave out roadside buildings that would swallow it. Built
    by ``compile_scene`` from the case, so the illusions need not know the case model."""

    seed: int  # the case's seed
    drive: EgoDrive
    network: RoadNetwork
    env: Environment
    meshes: list[Mesh] = field(default_factory=list)
    layers: list[SurfaceLayer] = field(default_factory=list)
    lights: list[PointLight] = field(default_factory=list)
    source: int = -1  # index of the illusion being compiled
    user_meshes: dict[int, Mesh] = field(default_factory=dict)  # illusion index -> its ``mesh_file``, as read
    case_sun_altitude: float = 90.0  # the case's own sun (degrees), whatever illusions before this one set

    def rng(self, seed: int) -> np.random.Generator:
        """The one source of randomness for an illusion: case seed, illusion index and illusion seed."""
        return np.random.default_rng([self.seed, self.source + 1, seed])

    def add_mesh(self, mesh: Mesh) -> None:
        mesh.source = self.source
        self.meshes.append(mesh)

    def add_layer(self, layer: SurfaceLayer) -> None:
        layer.source = self.source
        self.layers.append(layer)

    def add_light(self, light: PointLight) -> None:
        light.source = self.source
        self.lights.append(light)


class MeshFileError(ValueError):
    """A ``mesh_file`` that names no readable model in the meshes folder; ``field`` is its path in the case."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message


@dataclass(frozen=True)
class Level:
    """Base of the severity rows: each illusion type's row is a frozen dataclass of what one level sets."""


def _type_required(schema: dict[str, Any]) -> None:
    """``type`` is the tag of the case's ``illusions`` union: a document names it even though it has a default."""
    schema["required"] = ["type", *(name for name in schema.get("required", []) if name != "type")]


class Illusion(BaseModel):
    """Base of every illusion type. Subclasses set ``type`` (a Literal), ``CATEGORY`` and ``SEVERITY``."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, json_schema_extra=_type_required)

    CATEGORY: ClassVar[Category]
    # Whether the type places the sun itself (a shadow across the lanes, glare on water, night): of several such
    # illusions in one case the last one's sun is rendered (``Environment.sun_set_by`` names who set it).
    SETS_SUN: ClassVar[bool] = False
    # Five rows, level 1 (subtle) to 5 (most deceptive): what each level sets.
    SEVERITY: ClassVar[tuple[Level, ...]]

    type: str
    severity: StrictInt = Field(3, ge=1, le=5, description="1 = subtle ... 5 = most deceptive")
    seed: StrictInt = Field(0, ge=0, le=2**32 - 1)
    s: StrictFloat | None = Field(
        None, ge=0, le=MAX_ROAD_LENGTH_M,
        description="distance along the road where it starts (m); empty = just ahead of the ego start",
    )

    def level(self) -> Level:
        """The severity table row of this illusion's level (subclasses narrow the type to their row's)."""
        return self.SEVERITY[self.severity - 1]

    def start_s(self, drive: EgoDrive) -> float:
        """Where along the road the illusion starts."""
        return self.s if self.s is not None else drive.start_s + DEFAULT_AHEAD_M

    def compile(self, ctx: CompileContext) -> None:  # pragma: no cover - every registered type overrides
        raise TypeError(f"{type(self).__name__} does not define compile()")


REGISTRY: dict[str, type[Illusion]] = {}


def register(cls: type[Illusion]) -> type[Illusion]:
    """Class decorator: add an illusion type to the registry under its ``type`` literal."""
    name = cls.model_fields["type"].default
    if not isinstance(name, str) or name in REGISTRY:
        raise ValueError(f"illusion {cls.__name__} needs a unique default 'type', got {name!r}")
    if len(cls.SEVERITY) != 5:
        raise ValueError(f"illusion {name} needs a five-row SEVERITY table")
    REGISTRY[name] = cls
    return cls
