"""A user's camera from its calibration: ``lanevil dataset --camera FILE.json`` renders through the camera a
real-trained detector knows.

The file holds what a calibration (OpenCV's ``calibrateCamera``, a vehicle's camera datasheet) and a tape measure
give; every other field of the case camera (``case.Camera``) keeps its default::

    {
      "image_size": [1280, 720],                     // required: width, height (px)
      "fx": 1004.0, "fy": 1004.0,                    // focal length (px); or "K": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]
      "cx": 640.0, "cy": 352.0,                      //   or "hfov" (degrees); principal point default: the centre
      "distortion": [-0.06, 0.01, 0.0, 0.0, 0.0],    // OpenCV's k1, k2, p1, p2[, k3]
      "height": 1.55,                                // required: mount height above the road (m)
      "pitch": 3.5,                                  // degrees, positive looks down; or instead
      "horizon_row": 290,                            //   the image row of the flat road's horizon, or
      "vanishing_point": [652, 290],                 //   where the straight road's lines meet (also gives yaw), or
      "lane_labels": "straight_frames.json",         //   TuSimple labels of straight-road frames it is found from
      "yaw": 0.0, "roll": 0.0, "x": 1.6, "y": 0.0,   // optional: degrees; mount ahead of / left of the vehicle (m)
      "bonnet_row": 672,                             // optional: the row where the bonnet starts at the centre column
      "bonnet": {"reach": 2.2, "drop": 0.5},         //   or the bonnet itself (``case.Bonnet``)
      "sensor": {"noise": 1.0}                       // optional: ``case.Sensor`` fields
    }

A horizon row or vanishing point (read off a few straight-road frames of the camera: where the lane lines meet;
or found from those frames' TuSimple lane labels, ``camera.vanishing``; a relative path is read from the
calibration file's folder) gives the pitch ``atan((cy - v) / fy)`` and, from the vanishing point's column, the yaw
``atan(cos(pitch) (u - cx) / fx)`` (the mount turns by yaw, then pitches);
both are measured through the lens (undistorted first). A bonnet row gives the bonnet's reach for a front edge
``bonnet_drop`` below the camera (default 0.5 m). Pixels are square: ``fx`` and ``fy`` must agree within 1 %.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from ..case import Camera
from ..files import read_json
from .lens import undistort

SQUARE_TOLERANCE = 0.01
DEFAULT_BONNET_DROP = 0.5


class Calibration(BaseModel):
    """The calibration file (module docstring)."""

    model_config = ConfigDict(extra="forbid")

    image_size: tuple[int, int]
    fx: float | None = Field(None, gt=0)
    fy: float | None = Field(None, gt=0)
    cx: float | None = None
    cy: float | None = None
    K: tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]] | None = None
    hfov: float | None = Field(None, gt=10, lt=170)
    distortion: list[float] = Field(default_factory=list, max_length=5)
    height: float = Field(gt=0)
    pitch: float | None = None
    horizon_row: float | None = None
    vanishing_point: tuple[float, float] | None = None
    lane_labels: str | None = None
    yaw: float | None = None
    roll: float = 0.0
    x: float | None = None
    y: float = 0.0
    bonnet_row: float | None = None
    bonnet_drop: float = Field(DEFAULT_BONNET_DROP, gt=0)
    bonnet: dict[str, Any] | None = None
    sensor: dict[str, Any] | None = None

    @model_validator(mode="after")
    def _one_of_each(self) -> Calibration:
        focal = [name for name in ("fx", "K", "hfov") if getattr(self, name) is not None]
        if len(focal) != 1:
            raise ValueError("give the focal length once: fx (and fy), K or hfov")
        tilt = [name for name in ("pitch", "horizon_row", "vanishing_point", "lane_labels")
                if getattr(self, name) is not None]
        if len(tilt) > 1:
            raise ValueError(f"give one of pitch, horizon_row, vanishing_point, lane_labels (not {' and '.join(tilt)})")
        if (self.vanishing_point is not None or self.lane_labels is not None) and self.yaw is not None:
            raise ValueError("the vanishing point gives the yaw: leave yaw out")
        if self.bonnet_row is not None and self.bonnet is not None:
            raise ValueError("give bonnet_row or bonnet, not both")
        if len(self.distortion) not in (0, 4, 5):
            raise ValueError("distortion: OpenCV's [k1, k2, p1, p2] or [k1, k2, p1, p2, k3]")
        return self

    def intrinsics(self) -> tuple[float, float, float, float]:
        """(fx, fy, cx, cy) in pixels."""
        width, height = self.image_size
        if self.K is not None:
            (fx, _, cx), (_, fy, cy), _ = self.K
            return fx, fy, cx, cy
        if self.hfov is not None:
            fx = fy = 0.5 * width / math.tan(math.radians(self.hfov) / 2)
        else:
            assert self.fx is not None
            fx, fy = self.fx, self.fy if self.fy is not None else self.fx
        return fx, fy, self.cx if self.cx is not None else width / 2, self.cy if self.cy is not None else height / 2

    @property
    def coefficients(self) -> tuple[float, float, float, float, float]:
        k1, k2, p1, p2, k3 = [*self.distortion, 0.0, 0.0, 0.0, 0.0, 0.0][:5] if self.distortion else [0.0] * 5
        return k1, k2, p1, p2, k3


def _ideal(calibration: Calibration, u: float, v: float) -> tuple[float, float]:
    """Ideal normalised coordinates of the pixel point (u, v) (continuous image coordinates) seen through the lens."""
    fx, fy, cx, cy = calibration.intrinsics()
    x, y = undistort(np.array([(u - cx) / fx]), np.array([(v - cy) / fy]), calibration.coefficients)
    return float(x[0]), float(y[0])


def camera_fields(calibration: Calibration) -> dict[str, Any]:
    """The ``case.Camera`` fields of a calibration (validated by ``Camera``)."""
    width, height = calibration.image_size
    fx, fy, cx, cy = calibration.intrinsics()
    if abs(fx - fy) > SQUARE_TOLERANCE * fx:
        raise ValueError(f"fx {fx:g} and fy {fy:g} differ by more than 1 %: the camera model has square pixels")
    fields: dict[str, Any] = {"width": width, "height": height, "focal": fx, "cx": cx, "cy": cy,
                              "z": calibration.height, "roll": calibration.roll, "y": calibration.y}
    k1, k2, p1, p2, k3 = calibration.coefficients
    fields["lens"] = {"k1": k1, "k2": k2, "p1": p1, "p2": p2, "k3": k3}
    pitch = calibration.pitch or 0.0
    yaw = calibration.yaw or 0.0
    if calibration.horizon_row is not None or calibration.vanishing_point is not None:
        u, v = calibration.vanishing_point or (cx, calibration.horizon_row or cy)
        x_ideal, y_ideal = _ideal(calibration, u, v)
        pitch = math.degrees(math.atan(-y_ideal))  # the horizon above the centre: the camera looks down
        if calibration.vanishing_point is not None:  # the mount turns by yaw, then pitches: x = tan(yaw) / cos(pitch)
            yaw = math.degrees(math.atan(x_ideal * math.cos(math.radians(pitch))))  # right of the centre: looks left
    fields.update(pitch=round(pitch, 4), yaw=round(yaw, 4))
    if calibration.x is not None:
        fields["x"] = calibration.x
    if calibration.bonnet is not None:
        fields["bonnet"] = calibration.bonnet
    elif calibration.bonnet_row is not None:
        _, y_ideal = _ideal(calibration, cx, calibration.bonnet_row)
        below = math.atan(y_ideal) + math.radians(pitch)  # the edge's angle below the horizontal
        if below <= 0:
            raise ValueError(f"bonnet_row {calibration.bonnet_row:g} is at or above the horizon")
        fields["bonnet"] = {"reach": round(calibration.bonnet_drop / math.tan(below), 3),
                            "drop": calibration.bonnet_drop}
    if calibration.sensor is not None:
        fields["sensor"] = calibration.sensor
    return fields


class CalibrationError(ValueError):
    """A calibration file that cannot be read or does not describe a camera (the message names the field)."""


def _first_error(error: ValidationError) -> str:
    first = error.errors()[0]
    where = ".".join(str(part) for part in first["loc"])
    return f"{where}: {first['msg']}" if where else first["msg"]


def labelled_vanishing_point(labels: Path) -> tuple[float, float]:
    """The vanishing point of the straight-road frames labelled in a TuSimple file (``camera.vanishing``)."""
    from .vanishing import vanishing_point

    if not labels.is_file():
        raise ValueError(f"lane_labels: {labels.name}: no such file")
    try:  # TuSimple JSON lines, read here: the label readers of metrics/ sit above the camera
        records = [json.loads(line) for line in labels.read_text(encoding="utf-8").splitlines() if line.strip()]
        pairs = [(record["lanes"], record["h_samples"]) for record in records]
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ValueError(f"lane_labels {labels.name}: not a TuSimple label file ({type(error).__name__})") from None
    try:
        return vanishing_point(pairs)
    except ValueError as error:
        raise ValueError(f"lane_labels {labels.name}: {error}") from None


def load_camera(path: str | Path) -> Camera:
    """The case camera described by the calibration file ``path``; raises ``CalibrationError``."""
    path = Path(path)
    data = read_json(path, f"--camera {path}", CalibrationError)
    try:
        calibration = Calibration.model_validate(data)
        if calibration.lane_labels is not None:
            calibration = calibration.model_copy(update={
                "vanishing_point": labelled_vanishing_point(path.parent / calibration.lane_labels),
                "lane_labels": None})
        return Camera.model_validate(camera_fields(calibration))
    except ValidationError as error:
        raise CalibrationError(f"--camera {path}: {_first_error(error)}") from None
    except ValueError as error:
        raise CalibrationError(f"--camera {path}: {error}") from None


CALIBRATION_SUFFIX = ".json"


def camera_choice(value: str) -> tuple[dict[str, Any], str]:
    """The camera fields of ``--camera VALUE`` and the label a dataset records: a preset name (``presets``), or
    a calibration file (a path ending ``.json``; the label is its file name). Raises ``CalibrationError``."""
    from ..presets import camera_preset_values

    if value.endswith(CALIBRATION_SUFFIX):
        return load_camera(value).model_dump(), Path(value).name
    try:
        return camera_preset_values(value), value
    except KeyError as error:
        raise CalibrationError(f"--camera {error.args[0]}, or a calibration file FILE.json") from None
