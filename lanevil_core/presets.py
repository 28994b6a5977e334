"""Named weather presets (CARLA 0.9.16 numbers) that fill a case's weather and sun fields.

A case always stores the numbers; a preset name is only a way to fill them.
"""

from __future__ import annotations

from typing import Final

# name: (cloudiness, precipitation, precipitation_deposits, sun_altitude, fog_density, wetness)
_TABLE: Final[dict[str, tuple[float, float, float, float, float, float]]] = {
    "ClearNoon": (5, 0, 0, 45, 2, 0),
    "CloudyNoon": (60, 0, 0, 45, 3, 0),
    "WetNoon": (5, 0, 50, 45, 3, 0),
    "WetCloudyNoon": (60, 0, 50, 45, 3, 0),
    "SoftRainNoon": (20, 30, 50, 45, 3, 0),
    "MidRainyNoon": (60, 60, 60, 45, 3, 0),
    "HardRainNoon": (100, 100, 90, 45, 7, 0),
    "ClearSunset": (5, 0, 0, 15, 2, 0),
    "CloudySunset": (60, 0, 0, 15, 3, 0),
    "WetSunset": (5, 0, 50, 15, 2, 0),
    "SoftRainSunset": (20, 30, 50, 15, 2, 0),
    "ClearNight": (5, 0, 0, -90, 60, 0),
    "WetNight": (5, 0, 50, -90, 60, 60),
}

PRESET_NAMES: Final[tuple[str, ...]] = tuple(_TABLE)


def preset_values(name: str) -> dict[str, dict[str, float]]:
    """Return ``{"weather": {...}, "sun": {...}}`` field values for a preset name.

    Raises KeyError naming the valid presets when ``name`` is unknown.
    """
    if name not in _TABLE:
        raise KeyError(f"unknown weather preset {name!r}; choose one of {', '.join(PRESET_NAMES)}")
    cloud, rain, puddles, altitude, fog, wetness = _TABLE[name]
    # Rain wets the road even when CARLA's preset leaves `wetness` at 0.
    wet = max(wetness, rain, 0.6 * puddles)
    return {
        "weather": {
            "cloudiness": cloud,
            "precipitation": rain,
            "precipitation_deposits": puddles,
            "wetness": wet,
            "fog_density": fog,
            "fog_distance": 0.0 if fog < 10 else 75.0,
        },
        "sun": {
            "altitude": altitude,
            "azimuth": 0.0,
            # Overcast skies dim the direct sun; night has none.
            "intensity": 0.0 if altitude <= 0 else round(1.0 - 0.7 * cloud / 100.0, 3),
        },
    }
