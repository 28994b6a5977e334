"""Lighting and atmosphere from weather and sun numbers."""

from __future__ import annotations

from typing import Protocol

import numpy as np
import numpy.typing as npt

from ..typed import FloatArray
from .scene import Environment


class WeatherInputs(Protocol):
    """The weather numbers the environment reads (a case's ``weather`` is one): CARLA's 0-100 scales, the fog's
    start in m."""

    cloudiness: float
    precipitation: float
    precipitation_deposits: float
    wetness: float
    fog_density: float
    fog_distance: float


class SunInputs(Protocol):
    """The sun the environment reads (a case's ``sun`` is one): azimuth and altitude in degrees, the luminance of
    its beam (1 = clear noon)."""

    azimuth: float
    altitude: float
    intensity: float


NIGHT_EXPOSURE = 2.2
PHOTO_DETAIL = 1.5  # surface texture of a case seen through a real camera's sensor (0 in the ideal render)
# Radiance scale at 1 m, on the beam's axis, of each of the ego's two low-beam headlights (on at night). The beam
# is cut off just below the horizon (render.lighting.beam_weight), so it lights the road ahead and the paint on it,
# not the houses and trees beside it.
HEADLIGHT_INTENSITY = 120.0
# The night sky (linear rgb at the zenith and the horizon): a moonless sky a few hundred times darker than a lit
# road (about 0.003 cd/m2 against 1 cd/m2 under street lamps), a little lighter and warmer low down where the
# towns' light scatters.
NIGHT_ZENITH = np.array([0.0002, 0.0003, 0.0007], np.float32)
NIGHT_HORIZON = np.array([0.0016, 0.0014, 0.0015], np.float32)

# Daylight of a photographed case (docs/realism.md, "Sun and sky in proportion"). Clear-sky beam and diffuse by the
# ASHRAE clear-sky model (ASHRAE Handbook of Fundamentals; Threlkeld & Jordan 1958), its 21 April row:
# beam normal E_DN = A exp(-B / sin(altitude)) W/m2, diffuse on the ground E_d = C E_DN.
ASHRAE_A_W_M2, ASHRAE_B, ASHRAE_C = 1136.0, 0.180, 0.097
# Clouds (Kasten & Czeplak 1980, N = cloud cover 0..1): global G(N) = G_clear (1 - 0.75 N**3.4), the diffuse part
# of it D/G rising from its clear-sky value to 1 as N**2 (their 0.3 + 0.7 N**2 with 0.3 the clear share).
KC_GLOBAL, KC_GLOBAL_POWER = 0.75, 3.4
# Anisotropic sky (Hay & Davies 1980): the share beam / extraterrestrial irradiance of the diffuse light is
# circumsolar, seen from the sun's direction, so a shadow loses it with the beam.
SOLAR_CONSTANT_W_M2 = 1361.0
# The renderer's irradiance unit: sun_intensity 1 = the clear-sky beam of a sun at the zenith, SUN_SCALE on a face
# square to it (render.lighting); the sky's ambient is in units of its colour's luminance (render.shading).
SKY_AMBIENT_GAIN = 2.2
SUN_SCALE = 3.2
LUMA = np.array([0.2126, 0.7152, 0.0722])
MODEL_MIN_ALTITUDE_DEG = 5.0
NIGHT_AMBIENT = 0.01


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


def clear_sky(altitude_deg: float) -> tuple[float, float]:
    """(beam normal, diffuse on the ground) W/m2 of a clear sky for a sun ``altitude_deg`` above the horizon."""
    sin_alt = max(np.sin(np.radians(altitude_deg)), 0.02)
    beam = ASHRAE_A_W_M2 * float(np.exp(-ASHRAE_B / sin_alt))
    return beam, ASHRAE_C * beam


def daylight(altitude_deg: float, cloud: float) -> tuple[float, float]:
    """(beam normal, diffuse on the ground) W/m2 under ``cloud`` cover (0..1): the clear sky's thinned by the
    clouds (Kasten & Czeplak)."""
    beam, diffuse = clear_sky(altitude_deg)
    sin_alt = max(np.sin(np.radians(altitude_deg)), 0.02)
    global_clear = beam * sin_alt + diffuse
    global_cloudy = global_clear * (1.0 - KC_GLOBAL * cloud**KC_GLOBAL_POWER)
    share = diffuse / global_clear
    diffuse_share = share + (1.0 - share) * cloud**2
    return global_cloudy * (1.0 - diffuse_share) / sin_alt, global_cloudy * diffuse_share


def _beam_through_clouds(altitude_deg: float, cloud: float) -> float:
    """The share of a clear sky's beam that ``cloud`` cover lets through (Kasten & Czeplak)."""
    altitude = max(altitude_deg, MODEL_MIN_ALTITUDE_DEG)
    return daylight(altitude, cloud)[0] / clear_sky(altitude)[0]


def in_proportion(env: Environment, air_mass: bool = True) -> None:
    """Set ``env``'s sun and sky irradiance in the physical proportion of daylight at its sun's altitude and its
    cloudiness (the photographed path; the ideal render keeps its own numbers).

    ``env.sun_intensity`` stays the sun's clearness (1 = a clear sky's beam; ``environment_for`` thins it by the
    case's clouds as the daylight model does; illusions raise it for a harder sun); the beam now also falls with
    the air mass at low altitude, and the sky's diffuse light on the ground is the daylight model's for that
    altitude and cloud cover. The circumsolar part of that diffuse light comes from around the sun and is shaded
    with it (Hay & Davies): it joins the sun's beam, and only the rest lights the shadows from the open sky.
    ``air_mass`` False: the sun was set by an illusion whose table gives its light as seen (1 = a clear noon sun),
    so its beam keeps that; the sky's light still follows its altitude."""
    if env.night or env.sun_intensity <= 0.0:
        return
    altitude = float(np.degrees(np.arcsin(np.clip(env.sun_dir_world[2], -1.0, 1.0))))
    model_altitude = max(altitude, MODEL_MIN_ALTITUDE_DEG)  # the clear-sky fits hold above a few degrees
    zenith_beam, _ = clear_sky(90.0)
    beam, _ = clear_sky(model_altitude)
    _, diffuse = daylight(model_altitude, env.cloudiness)
    day = float(np.clip((altitude - NIGHT_SUN_ALTITUDE_DEG) / 12.0, 0.0, 1.0))
    sky = 0.5 * np.asarray(env.sky_zenith, np.float64) + 0.5 * np.asarray(env.sky_horizon, np.float64)
    beam_now = env.sun_intensity * (beam if air_mass else zenith_beam)
    # Hay & Davies' anisotropy index, of a beam no brighter than a clear sky's (illusions push the sun beyond it)
    circumsolar = min(env.sun_intensity, 1.0) * beam / SOLAR_CONSTANT_W_M2
    sin_alt = float(np.sin(np.radians(model_altitude)))
    env.sun_intensity = float((beam_now + circumsolar * day * diffuse / sin_alt) / zenith_beam)
    isotropic = (1.0 - circumsolar) * day * diffuse
    env.ambient = float(max(SUN_SCALE * isotropic / zenith_beam / (SKY_AMBIENT_GAIN * float(LUMA @ sky)),
                            NIGHT_AMBIENT))


def environment_for(weather: WeatherInputs, sun: SunInputs, photographed: bool) -> Environment:
    """Sun, sky, wetness and fog of a weather and a sun (before illusions change them); ``photographed``: seen
    through a real camera's sensor (its daylight in proportion, the road's surface detail)."""
    cloud = weather.cloudiness / 100.0
    altitude = sun.altitude
    night = is_night(altitude)
    day = float(np.clip((altitude - NIGHT_SUN_ALTITUDE_DEG) / 12.0, 0.0, 1.0))  # twilight ramp
    low = float(np.clip(1.0 - altitude / 30.0, 0.0, 1.0))  # warm light near the horizon
    sun_color = _mix([1.0, 0.97, 0.92], [1.0, 0.62, 0.32], low * 0.8)
    clear_zenith, clear_horizon = np.array([0.16, 0.32, 0.75]), np.array([0.62, 0.74, 0.92])
    grey = np.array([0.55, 0.57, 0.6])
    zenith = _mix(clear_zenith, grey * 0.8, cloud) * day + NIGHT_ZENITH * (1 - day)
    horizon = _mix(_mix(clear_horizon, [0.95, 0.7, 0.5], low * 0.6 * (1 - cloud)), grey, cloud)
    horizon = horizon * day + NIGHT_HORIZON * (1 - day)
    direct = sun.intensity * day * (_beam_through_clouds(altitude, cloud) if photographed else 1.0 - 0.85 * cloud)
    return Environment(
        sun_dir_world=sun_direction(sun.azimuth, max(altitude, 0.5)),
        sun_intensity=float(direct),
        sun_color=sun_color,
        sky_zenith=zenith.astype(np.float32),
        sky_horizon=horizon.astype(np.float32),
        ambient=float(0.25 + 0.35 * cloud) * day + NIGHT_AMBIENT * (1 - day),
        wetness=float(np.clip(max(weather.wetness, weather.precipitation) / 100.0, 0.0, 1.0)),
        puddles=weather.precipitation_deposits / 100.0,
        fog_density=0.0004 + weather.fog_density / 100.0 * 0.03,
        fog_distance=weather.fog_distance,
        cloudiness=cloud,
        penumbra=0.004 + 0.03 * cloud + 0.01 / max(sun.intensity, 0.1),
        exposure=1.0 if not night else NIGHT_EXPOSURE,
        night=night,
        headlights=HEADLIGHT_INTENSITY if night else 0.0,
        detail=PHOTO_DETAIL if photographed else 0.0,
    )
