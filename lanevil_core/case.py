"""The editable case: everything needed to reproduce a drive's frames, as a pydantic model.

A case file is JSON with a ``schema_version``. Units: metres, seconds, degrees in files.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictFloat, StrictInt, ValidationError, model_validator

from .files import write_atomic
from .illusions import IllusionSpec
from .presets import preset_values
from .typed import LineType, RoadType, SceneKind, Turn

SCHEMA_VERSION: Literal[1] = 1

# Real marking dimensions (m): paint width, dash length and gap (MUTCD-style 3 m / 9 m).
PAINT_WIDTH_M = 0.15
DASH_M = 3.0
GAP_M = 9.0
DOUBLE_LINE_SPACING_M = 0.12  # clear space between the two lines of a double marking
BOTTS_DOT_DIAMETER_M = 0.12
BOTTS_DOT_SPACING_M = 1.2


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)


class Marking(_Model):
    """The paint on one lane boundary."""

    type: LineType = "white_dashed"
    width: StrictFloat = Field(PAINT_WIDTH_M, gt=0.02, le=0.6, description="paint width of one line (m)")
    dash: StrictFloat = Field(DASH_M, gt=0.1, le=50, description="dash length (m)")
    gap: StrictFloat = Field(GAP_M, ge=0.1, le=50, description="gap between dashes (m)")

    @model_validator(mode="before")
    @classmethod
    def _from_name(cls, data: Any) -> Any:
        if isinstance(data, str):
            return {"type": data}
        return data


def default_markings(lanes_per_direction: int) -> list[Marking]:
    """Yellow double centre line, white dashed lane lines, white solid edges (left to right)."""
    n = lanes_per_direction
    dashed: list[LineType] = ["white_dashed"] * (n - 1)
    names: list[LineType] = ["white_solid", *dashed, "yellow_double_solid", *dashed, "white_solid"]
    return [Marking(type=name) for name in names]


class Road(_Model):
    """Road layout: a reference line (line/arc/clothoid pieces), an elevation profile, lanes and paint.

    The reference line is the centre line between the two driving directions; the ego drives on its right.
    """

    type: RoadType = "straight"
    length: StrictFloat = Field(400.0, ge=100.0, le=3000.0, description="length of the main road (m)")
    lanes_per_direction: StrictInt = Field(2, ge=1, le=4)
    lane_width: StrictFloat = Field(3.5, ge=2.5, le=5.0, description="lane width (m)")
    radius: StrictFloat = Field(150.0, ge=30.0, le=5000.0, description="bend radius (bend, s_curve) (m)")
    turn: Turn = Field("left", description="direction of the (first) bend")
    grade: StrictFloat = Field(0.06, ge=0.0, le=0.15, description="slope of uphill/downhill roads (rise/run)")
    junction_s: StrictFloat = Field(70.0, ge=20.0, description="distance along the road of a junction's centre (m)")
    markings: list[Marking] = Field(
        default_factory=list,
        description="paint of every lane boundary, left to right as seen by the ego "
        "(2 * lanes_per_direction + 1 entries; empty = defaults)",
    )
    paint: StrictBool = Field(
        True,
        description="false removes every lane marking from the world (the paint-free control: the lane labels "
        "stay, so a detector that still finds the lanes reads the road's layout, not its paint)",
    )

    @model_validator(mode="after")
    def _fill_markings(self) -> Road:
        expected = 2 * self.lanes_per_direction + 1
        if not self.markings:
            object.__setattr__(self, "markings", default_markings(self.lanes_per_direction))
        elif len(self.markings) != expected:
            raise ValueError(
                f"markings needs {expected} entries (2 * lanes_per_direction + 1), got {len(self.markings)}"
            )
        if self.junction_s >= self.length - 20:
            raise ValueError("junction_s must lie at least 20 m before the end of the road")
        return self


class Scene(_Model):
    """What stands beside the road."""

    kind: SceneKind = "suburban"
    density: StrictFloat = Field(1.0, ge=0.0, le=3.0, description="how many roadside props (1 = typical)")


class Weather(_Model):
    """The numeric fields of CARLA's WeatherParameters (0-100 except distances)."""

    cloudiness: StrictFloat = Field(5.0, ge=0, le=100)
    precipitation: StrictFloat = Field(0.0, ge=0, le=100)
    precipitation_deposits: StrictFloat = Field(0.0, ge=0, le=100, description="puddles")
    wetness: StrictFloat = Field(0.0, ge=0, le=100)
    fog_density: StrictFloat = Field(2.0, ge=0, le=100)
    fog_distance: StrictFloat = Field(0.0, ge=0, le=1000, description="distance where fog starts (m)")


class Sun(_Model):
    """The sun: azimuth counter-clockwise from world +X (the road's start heading), altitude above the horizon."""

    azimuth: StrictFloat = Field(30.0, ge=-360, le=360, description="degrees, 0 = ahead at the start, 90 = left")
    altitude: StrictFloat = Field(45.0, ge=-90, le=90, description="degrees above the horizon")
    intensity: StrictFloat = Field(1.0, ge=0, le=3, description="luminance of direct sun (1 = clear noon)")


class Camera(_Model):
    """Pinhole camera on the ego vehicle (x forward, z up in the vehicle frame)."""

    width: StrictInt = Field(1280, ge=64, le=4096)
    height: StrictInt = Field(720, ge=64, le=4096)
    fov: StrictFloat = Field(90.0, gt=10, lt=170, description="horizontal field of view (degrees)")
    x: StrictFloat = Field(1.0, ge=-5, le=5, description="mount position ahead of the vehicle origin (m)")
    y: StrictFloat = Field(0.0, ge=-2, le=2, description="mount position to the left (m)")
    z: StrictFloat = Field(3.0, gt=0.3, le=6, description="mount height above the road (m)")
    pitch: StrictFloat = Field(0.0, ge=-45, le=45, description="degrees, positive looks down")
    yaw: StrictFloat = Field(0.0, ge=-30, le=30, description="degrees, positive looks left of the vehicle's heading")


class Ego(_Model):
    """The ego vehicle drives its lane at constant speed."""

    lane: StrictInt = Field(0, ge=0, description="lane of the ego's direction, 0 = next to the centre line")
    start_s: StrictFloat = Field(10.0, ge=0, description="start position along the road (m)")
    speed: StrictFloat = Field(10.0, ge=0, le=60, description="m/s")
    fps: StrictFloat = Field(10.0, gt=0, le=120)
    frames: StrictInt = Field(100, ge=50, le=300)


class Case(_Model):
    """An editable 3D lane-detection case."""

    schema_version: Literal[1] = SCHEMA_VERSION
    title: str = ""
    description: str = ""
    road: Road = Field(default_factory=Road)
    scene: Scene = Field(default_factory=Scene)
    weather: Weather = Field(default_factory=Weather)
    sun: Sun = Field(default_factory=Sun)
    camera: Camera = Field(default_factory=Camera)
    ego: Ego = Field(default_factory=Ego)
    illusions: list[IllusionSpec] = Field(default_factory=list)
    seed: StrictInt = Field(0, ge=0, le=2**32 - 1)

    @model_validator(mode="before")
    @classmethod
    def _apply_preset(cls, data: Any) -> Any:
        """A ``"preset": "ClearNoon"`` key fills the weather and sun numbers it names (fields given explicitly
        win); the case then stores only the numbers."""
        if not isinstance(data, dict) or "preset" not in data:
            return data
        data = dict(data)
        name = data.pop("preset")
        try:
            values = preset_values(str(name))
        except KeyError as error:
            raise ValueError(f"preset: {error.args[0]}") from None
        for section in ("weather", "sun"):
            given = data.get(section) or {}
            if not isinstance(given, dict):
                continue
            data[section] = {**values[section], **given}
        return data

    @model_validator(mode="after")
    def _check_drive(self) -> Case:
        if self.ego.lane >= self.road.lanes_per_direction:
            raise ValueError(
                f"ego.lane {self.ego.lane} does not exist: road has {self.road.lanes_per_direction} "
                "lanes per direction"
            )
        end_s = self.ego.start_s + self.ego.speed * (self.ego.frames - 1) / self.ego.fps
        if end_s > self.road.length - 60.0:
            raise ValueError(
                f"ego drives to s={end_s:.0f} m but the road is {self.road.length:.0f} m long "
                "(keep 60 m of road ahead of the last frame)"
            )
        return self

    def frame_time(self, frame: int) -> float:
        """Time (s) of frame ``frame``."""
        return frame / self.ego.fps

    def ego_s(self, frame: int) -> float:
        """Distance along the road (m) of the ego at frame ``frame``."""
        return self.ego.start_s + self.ego.speed * self.frame_time(frame)

    def with_preset(self, name: str) -> Case:
        """A copy with weather and sun numbers filled from a named preset (sun azimuth kept)."""
        values = preset_values(name)
        sun = {**values["sun"], "azimuth": self.sun.azimuth}
        return self.model_copy(update={"weather": Weather(**values["weather"]), "sun": Sun(**sun)})


MESHES_FOLDER = "meshes"


def case_meshes_dir(case_path: str | Path) -> Path:
    """Where the library and the CLI read a case file's user meshes from: the ``meshes/`` folder beside it."""
    return Path(case_path).parent / MESHES_FOLDER


class CaseError(ValueError):
    """A case file that cannot be read; the message names the field."""


def _describe(error: ValidationError) -> str:
    first = error.errors()[0]
    where = ".".join(str(part) for part in first["loc"])
    message = first["msg"].removeprefix("Value error, ")
    more = len(error.errors()) - 1
    suffix = f" (and {more} more error{'s' if more > 1 else ''})" if more else ""
    return f"{where}: {message}{suffix}" if where else f"{message}{suffix}"


def parse_case(data: dict[str, Any] | str, source: str = "case") -> Case:
    """Validate a dict or JSON text as a Case, raising CaseError with a one-line message."""
    try:
        if isinstance(data, str):
            return Case.model_validate_json(data)
        return Case.model_validate(data)
    except ValidationError as error:
        raise CaseError(f"{source}: {_describe(error)}") from None


def load_case(path: str | os.PathLike[str]) -> Case:
    """Read a case JSON file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise CaseError(f"{path}: cannot read ({error.strerror})") from None
    try:
        json.loads(text)
    except json.JSONDecodeError as error:
        raise CaseError(f"{path}: not valid JSON (line {error.lineno}, column {error.colno}: {error.msg})") from None
    return parse_case(text, source=str(path))


def case_json(case: Case) -> str:
    """Canonical JSON text of a case (stable key order, trailing newline)."""
    return case.model_dump_json(indent=2) + "\n"


def save_case(case: Case, path: str | os.PathLike[str]) -> None:
    """Write a case atomically (temp file + rename), so a crash never leaves half a file."""
    write_atomic(Path(path), case_json(case).encode("utf-8"))


def case_schema() -> dict[str, Any]:
    """JSON schema of a case file (illusions as a discriminated union on ``type``)."""
    return Case.model_json_schema()


__all__ = [
    "Camera",
    "Case",
    "CaseError",
    "Ego",
    "Marking",
    "Road",
    "Scene",
    "Sun",
    "Weather",
    "case_json",
    "case_schema",
    "load_case",
    "parse_case",
    "save_case",
    "write_atomic",
]
