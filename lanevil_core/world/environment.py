"""Lighting and atmosphere from a case's weather and sun numbers."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from ..typed import FloatArray
from .scene import Environment

if TYPE_CHECKING:  # the case model imports the illusions, which use sun_direction
    from ..case import Case


NIGHT_EXPOSURE = 2.2
PHOTO_DETAIL = 1.5  # surface texture of a case seen through a real camera's sensor (0 in the ideal render)
HEADLIGHT_INTENSITY = 35.0  # radiance scale at 1 m of each of the ego's two headlights (on at night)


def sun_direction(azimuth_deg: float, altitude_deg: float) -> FloatArray:
    """(3,) unit vector from the ground towards the sun (azimuth CCW from +X, altitude above the horizon)."""
    az, alt = np.radians(azimuth_deg), np.radians(altitude_deg)
    return np.array([np.cos(alt) * np.cos(az), np.cos(alt) * np.sin(az), np.sin(alt)])


def _mix(a: npt.ArrayLike, b: npt.ArrayLike, k: float) -> np.ndarray:
    return (np.asarray(a) * (1.0 - k) + np.asarray(b) * k).astype(np.float32)


NIGHT_SUN_ALTITUDE_DEG = -2.0  # at or below this sun altitude it is night: lamps glow, headlights are on


def is_night(sun_altitude_deg: float) -> bool:
    """Whether a sun this high (degrees) makes a night scene."""
    return sun_altitude_deg <= NIGHT_SUN_ALTITUDE_DEG


def environment_for(case: Case) -> Environment:
    """Sun, sky, wetness and fog of a case (before illusions change them)."""
    weather, sun = case.weather, case.sun
    cloud = weather.cloudiness / 100.0
    altitude = sun.altitude
    night = is_night(altitude)
    day = float(np.clip((altitude - NIGHT_SUN_ALTITUDE_DEG) / 12.0, 0.0, 1.0))  # twilight ramp
    low = float(np.clip(1.0 - altitude / 30.0, 0.0, 1.0))  # warm light near the horizon
    sun_color = _mix([1.0, 0.97, 0.92], [1.0, 0.62, 0.32], low * 0.8)
    clear_zenith, clear_horizon = np.array([0.16, 0.32, 0.75]), np.array([0.62, 0.74, 0.92])
    grey = np.array([0.55, 0.57, 0.6])
    zenith = _mix(clear_zenith, grey * 0.8, cloud) * day + np.array([0.004, 0.006, 0.015]) * (1 - day)
    horizon = _mix(_mix(clear_horizon, [0.95, 0.7, 0.5], low * 0.6 * (1 - cloud)), grey, cloud)
    horizon = horizon * day + np.array([0.01, 0.012, 0.02]) * (1 - day)
    direct = sun.intensity * day * (1.0 - 0.85 * cloud)
    return Environment(
        sun_dir_world=sun_direction(sun.azimuth, max(altitude, 0.5)),
        sun_intensity=float(direct),
        sun_color=sun_color,
        sky_zenith=zenith.astype(np.float32),
        sky_horizon=horizon.astype(np.float32),
        ambient=float(0.25 + 0.35 * cloud) * day + 0.01 * (1 - day),
        wetness=float(np.clip(max(weather.wetness, weather.precipitation) / 100.0, 0.0, 1.0)),
        puddles=weather.precipitation_deposits / 100.0,
        fog_density=0.0004 + weather.fog_density / 100.0 * 0.03,
        fog_distance=weather.fog_distance,
        cloudiness=cloud,
        penumbra=0.004 + 0.03 * cloud + 0.01 / max(sun.intensity, 0.1),
        exposure=1.0 if not night else NIGHT_EXPOSURE,
        night=night,
        headlights=HEADLIGHT_INTENSITY if night else 0.0,
        detail=PHOTO_DETAIL if case.camera.sensor is not None else 0.0,
    )
