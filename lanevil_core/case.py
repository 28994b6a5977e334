"""The editable case: everything needed to reproduce a drive's frames, as a pydantic model.

A case file is JSON with a ``schema_version``. Units: metres, seconds, degrees in files.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    ValidationError,
    model_validator,
)

from .files import write_atomic
from .illusions import IllusionSpec
from .illusions.base import MAX_ROAD_LENGTH_M, RGB
from .presets import camera_preset_values, preset_values
from .typed import LineType, MarkingStandardName, Pavement, RoadType, SceneKind, Turn

SCHEMA_VERSION: Literal[1] = 1

# Real marking dimensions (m): paint width, dash length and gap (MUTCD-style 3 m / 9 m).
PAINT_WIDTH_M = 0.15
DASH_M = 3.0
GAP_M = 9.0
# Road a case keeps ahead of the ego's last frame (the camera sees that far down the road).
END_MARGIN_M = 60.0


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)


class Marking(_Model):
    """The paint on one lane boundary."""

    type: LineType = "white_dashed"
    width: StrictFloat = Field(PAINT_WIDTH_M, gt=0.02, le=0.6, description="paint width of one line (m)")
    dash: StrictFloat = Field(DASH_M, gt=0.1, le=50, description="dash length (m)")
    gap: StrictFloat = Field(GAP_M, ge=0.1, le=50, description="gap between dashes (m)")
    wear: StrictFloat = Field(
        0.0, ge=0.0, le=1.0,
        description="how worn the paint is (0 = fresh): it flakes off in chips along the line (where, by the case's "
        "seed), its edges are eaten in, the rest is dirtier, and far away the line fades evenly; the label stays "
        "(annotators label worn lines)",
    )

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


def resize_markings(markings: list[Marking], lanes_per_direction: int) -> list[Marking]:
    """``markings`` (left to right) for another lane count, keeping what they paint: both edges, the centre line,
    and each side's lane-line style (its line nearest the centre; the default where a side had no lane line).
    The defaults of one count become the defaults of the other."""
    old = (len(markings) - 1) // 2
    n = lanes_per_direction
    lane_line = default_markings(2)[1]
    left = markings[old - 1] if old > 1 else lane_line
    right = markings[old + 1] if old > 1 else lane_line
    return [markings[0], *[left] * (n - 1), markings[old], *[right] * (n - 1), markings[-1]]


def _default_of_other_count(markings: list[Marking]) -> bool:
    """Whether ``markings`` are exactly the defaults of some lane count (then a changed count re-derives them)."""
    lanes, odd = divmod(len(markings) - 1, 2)
    return odd == 0 and lanes >= 1 and markings == default_markings(lanes)


class Road(_Model):
    """Road layout: a reference line (line/arc/clothoid pieces), an elevation profile, lanes and paint.

    The reference line is the centre line between the two driving directions; the ego drives on its right.
    """

    type: RoadType = "straight"
    length: StrictFloat = Field(400.0, ge=100.0, le=MAX_ROAD_LENGTH_M, description="length of the main road (m)")
    lanes_per_direction: StrictInt = Field(2, ge=1, le=4)
    lane_width: StrictFloat = Field(3.5, ge=2.5, le=5.0, description="lane width (m)")
    radius: StrictFloat = Field(150.0, ge=30.0, le=5000.0, description="bend radius (bend, s_curve) (m)")
    turn: Turn = Field("left", description="direction of the (first) bend")
    grade: StrictFloat = Field(0.06, ge=0.0, le=0.15, description="slope of uphill/downhill roads (rise/run)")
    junction_s: StrictFloat = Field(70.0, ge=20.0, description="distance along the road of a junction's centre (m)")
    markings: list[Marking] = Field(
        default_factory=list,
        description="paint of every lane boundary, left to right as seen by the ego "
        "(2 * lanes_per_direction + 1 entries; empty = defaults; the defaults of another lane count are "
        "re-derived for this one)",
    )
    marking_standard: MarkingStandardName = Field(
        "custom",
        exclude_if=lambda value: value == "custom",
        description="the country's and road class's marking manual whose dash, gap and line widths every marking "
        "takes (us_mutcd: 10 ft / 30 ft; de_autobahn: 6 m / 12 m; de_urban: 3 m / 6 m; cn_fast: 6 m / 9 m; "
        "cn_slow: 2 m / 4 m); custom: each marking's own width, dash and gap",
    )
    pavement: Pavement = Field(
        "asphalt",
        description="what the carriageway is paved with: asphalt, or concrete slabs (jointed plain concrete "
        "pavement: 4.5 m slabs, one per lane, with sealed joints, as on concrete highways and bridge decks)",
    )
    paint: StrictBool = Field(
        True,
        description="false removes every lane marking from the world (the paint-free control: the lane labels "
        "stay, so a detector that still finds the lanes reads the road's layout, not its paint)",
    )
    # a case that keeps its material's own colour, or paints each marking to its own numbers, is written as before
    # these fields existed (same bytes, same sha256 in dataset manifests)
    surface_color: RGB | None = Field(
        None,
        exclude_if=lambda value: value is None,
        description="albedo of the carriageway's material (linear RGB: a darker or lighter asphalt, a fresh or "
        "aged concrete); empty = the material's own (asphalt 0.055, slabs 0.21)",
    )

    @model_validator(mode="after")
    def _fill_markings(self) -> Road:
        expected = 2 * self.lanes_per_direction + 1
        if not self.markings or _default_of_other_count(self.markings):
            # the defaults of another lane count (a case whose lanes changed): the defaults of this one
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




def _take_preset(data: Any, lookup: Callable[[str], dict[str, Any]]) -> tuple[dict[str, Any], dict[str, Any]] | None:
    """(the data without its ``preset`` key, the preset's values), or None when ``data`` names no preset."""
    if not isinstance(data, dict) or "preset" not in data:
        return None
    data = dict(data)
    name = data.pop("preset")
    try:
        return data, lookup(str(name))
    except KeyError as error:
        raise ValueError(f"preset: {error.args[0]}") from None


# Projected points are kept up to this factor past the image corners' radius (here and in ``camera.lens``).
LENS_VALID_MARGIN = 1.15


def lens_covers(distortion: tuple[float, float, float, float, float], corner_radius: float) -> bool:
    """Whether the radial polynomial reaches the distorted radius of the image's farthest corner (normalised
    coordinates) while still rising, with a margin, so every pixel of the image has one ray (``Camera``'s check;
    the camera package renders such lenses)."""
    k1, k2, _, _, k3 = distortion
    r = np.linspace(0.0, 8.0 * max(corner_radius, 1e-6), 8001)
    r2 = r * r
    slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2**2 + 7.0 * k3 * r2**3
    rising = np.argmax(slope <= 0.05) if np.any(slope <= 0.05) else r.size
    reach = r[:rising] * (1.0 + r2[:rising] * (k1 + r2[:rising] * (k2 + r2[:rising] * k3)))
    return bool(reach.size and reach.max() >= LENS_VALID_MARGIN * corner_radius)


class Lens(_Model):
    """Brown-Conrady lens distortion (OpenCV's k1, k2, p1, p2, k3) on normalised image coordinates. All zero is a
    pinhole; k1 < 0 is the barrel distortion of a wide dash-cam lens. Labels go through the same model."""

    k1: StrictFloat = Field(0.0, ge=-1.0, le=1.0, description="radial, r^2 term")
    k2: StrictFloat = Field(0.0, ge=-1.0, le=1.0, description="radial, r^4 term")
    k3: StrictFloat = Field(0.0, ge=-1.0, le=1.0, description="radial, r^6 term")
    p1: StrictFloat = Field(0.0, ge=-0.05, le=0.05, description="tangential (decentring)")
    p2: StrictFloat = Field(0.0, ge=-0.05, le=0.05, description="tangential (decentring)")

    @property
    def coefficients(self) -> tuple[float, float, float, float, float]:
        """OpenCV's order: (k1, k2, p1, p2, k3)."""
        return (self.k1, self.k2, self.p1, self.p2, self.k3)


class Bonnet(_Model):
    """The ego's bonnet (hood) in view: a rounded front edge below and ahead of the camera. Lane labels stop
    where it hides the road."""

    reach: StrictFloat = Field(1.6, ge=0.3, le=4.0, description="distance ahead of the camera to the front edge (m)")
    drop: StrictFloat = Field(0.45, ge=0.05, le=2.0, description="how far below the camera the front edge is (m)")
    width: StrictFloat = Field(1.75, ge=0.8, le=3.0, description="width of the bonnet (m)")
    crown: StrictFloat = Field(0.08, ge=0.0, le=0.5, description="how much lower its corners are than its middle (m)")
    color: RGB = Field((0.04, 0.045, 0.05), description="paint colour (linear RGB)")
    gloss: StrictFloat = Field(0.35, ge=0.0, le=1.0, description="share of the sky mirrored in the paint")


class Sensor(_Model):
    """What a real camera does to the light: metered auto-exposure within limits, white balance, colour and a
    filmic response, vignetting, ISP sharpening, sensor noise (shot + read, rising with gain) and motion blur over
    the exposure time. Deterministic per case seed and frame."""

    exposure: Literal["auto", "fixed"] = Field("auto", description="auto meters every frame; fixed uses `gain`")
    bias: StrictFloat = Field(0.0, ge=-3.0, le=3.0, description="exposure compensation (EV)")
    gain: StrictFloat = Field(1.0, gt=0.0, le=64.0, description="exposure of the fixed mode (1 = scene-referred)")
    min_gain: StrictFloat = Field(0.05, gt=0.0, le=64.0, description="auto-exposure's lower limit")
    max_gain: StrictFloat = Field(16.0, gt=0.0, le=256.0, description="auto-exposure's upper limit (longest shutter, "
                            "highest ISO)")
    white_balance: StrictFloat = Field(5600.0, ge=2000.0, le=12000.0, description="colour temperature the camera "
                                 "balances for (K); the scene's light is daylight (5600 K)")
    saturation: StrictFloat = Field(1.45, ge=0.0, le=3.0, description="colour matrix saturation (1 = none)")
    contrast: StrictFloat = Field(1.15, ge=0.5, le=2.0, description="slope of the filmic curve's toe and middle")
    vignetting: StrictFloat = Field(0.35, ge=0.0, le=1.0, description="light lost in the image corners (0-1)")
    softness: StrictFloat = Field(0.0, ge=0.0, le=5.0, exclude_if=lambda value: value == 0.0,  # files as before
                                  description="what the lens, demosaicing and noise "
                                  "reduction take of the finest detail: a Gaussian blur of this sigma (px at 1280 "
                                  "wide) before the ISP sharpens; 0 = none")
    sharpen: StrictFloat = Field(0.6, ge=0.0, le=3.0, description="ISP unsharp-mask amount")
    noise: StrictFloat = Field(1.0, ge=0.0, le=10.0, description="sensor noise scale (1 = a typical small sensor)")
    shutter: StrictFloat = Field(0.004, ge=0.0, le=0.1, description="exposure time for motion blur (s); 0 = none")
    compression: StrictInt | None = Field(None, ge=10, le=100, description="JPEG quality of the recording (a dash "
                                    "cam's compressed video); empty = none")


class Camera(_Model):
    """The ego's camera: intrinsics (horizontal FOV, or focal length and principal point), mount on the vehicle
    (x forward, y left, z up), lens distortion, an optional bonnet in view and an optional sensor model.

    ``{"preset": "dashcam"}`` fills the numbers of a named camera (``presets.CAMERA_PRESETS``); fields given
    explicitly win. Without ``sensor`` the frame is the ideal tone-mapped render of the paper's CARLA captures."""

    width: StrictInt = Field(1280, ge=64, le=4096)
    height: StrictInt = Field(720, ge=64, le=4096)
    fov: StrictFloat = Field(90.0, gt=10, lt=170, description="horizontal field of view (degrees)")
    focal: StrictFloat | None = Field(None, gt=10, le=20000, description="focal length (px at `width`); wins over fov")
    cx: StrictFloat | None = Field(None, ge=0, le=4096, description="principal point column (px); empty = centre")
    cy: StrictFloat | None = Field(None, ge=0, le=4096, description="principal point row (px); empty = centre")
    x: StrictFloat = Field(1.0, ge=-5, le=5, description="mount position ahead of the vehicle origin (m)")
    y: StrictFloat = Field(0.0, ge=-2, le=2, description="mount position to the left (m)")
    z: StrictFloat = Field(3.0, gt=0.3, le=6, description="mount height above the road (m)")
    pitch: StrictFloat = Field(0.0, ge=-45, le=45, description="degrees, positive looks down")
    yaw: StrictFloat = Field(0.0, ge=-30, le=30, description="degrees, positive looks left of the vehicle's heading")
    roll: StrictFloat = Field(0.0, ge=-30, le=30, description="degrees about the optical axis, positive turns the "
                        "image clockwise")
    lens: Lens = Field(default_factory=Lens)
    bonnet: Bonnet | None = Field(None, description="the ego's bonnet in view; empty = none")
    sensor: Sensor | None = Field(None, description="a real camera's exposure, response and noise; empty = ideal")

    @model_validator(mode="before")
    @classmethod
    def _apply_preset(cls, data: Any) -> Any:
        taken = _take_preset(data, camera_preset_values)
        if taken is None:
            return data
        rest, values = taken
        return {**values, **rest}

    @model_validator(mode="after")
    def _check_lens(self) -> Camera:
        f = self.focal_px
        cx = self.cx if self.cx is not None else self.width / 2
        cy = self.cy if self.cy is not None else self.height / 2
        corner = math.hypot(max(cx, self.width - cx) / f, max(cy, self.height - cy) / f)
        if not lens_covers(self.lens.coefficients, corner):
            raise ValueError("lens: this distortion turns back inside the image at this field of view "
                             "(weaken k1/k2/k3 or narrow the view)")
        return self

    @property
    def focal_px(self) -> float:
        """Focal length in pixels at ``width`` (from ``focal``, else from the horizontal FOV)."""
        if self.focal is not None:
            return self.focal
        return 0.5 * self.width / math.tan(math.radians(self.fov) / 2)

    @property
    def hfov(self) -> float:
        """Horizontal field of view (degrees) of the pinhole part."""
        return math.degrees(2 * math.atan(0.5 * self.width / self.focal_px))


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
        taken = _take_preset(data, preset_values)
        if taken is None:
            return data
        data, values = taken
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
        if end_s > self.road.length - END_MARGIN_M:
            raise ValueError(
                f"ego drives to s={end_s:.0f} m but the road is {self.road.length:.0f} m long "
                f"(keep {END_MARGIN_M:.0f} m of road ahead of the last frame)"
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


def seen_through(case: Case, preset: str) -> Case:
    """``case`` seen through camera preset ``preset`` (``presets.CAMERA_PRESETS``: its image size, lens, mount and
    sensor replace the case's camera; the world and the drive are unchanged). Raises KeyError naming the presets."""
    return case.model_copy(update={"camera": Camera.model_validate(camera_preset_values(preset))})


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
