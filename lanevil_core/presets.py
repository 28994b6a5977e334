"""Named weather presets (CARLA 0.9.16 numbers) that fill a case's weather and sun fields, and named cameras.

A case always stores the numbers; a preset name is only a way to fill them.
"""

from __future__ import annotations

import copy
from typing import Any, Final, Literal, get_args

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


def sun_intensity(altitude_deg: float, cloudiness: float) -> float:
    """Luminance of the direct sun (1 = clear noon) for a sun altitude and cloud cover (0-100): overcast skies dim
    it, night has none."""
    return 0.0 if altitude_deg <= 0 else round(1.0 - 0.7 * cloudiness / 100.0, 3)


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
            "intensity": sun_intensity(altitude, cloud),
        },
    }


# Named cameras (numbers only; docs/cameras.md gives where each comes from). A case's ``"camera": {"preset": ...}``
# fills these fields; fields given beside the preset win.
CAMERA_PRESETS: Final[dict[str, dict[str, Any]]] = {
    # The paper's CARLA capture camera (1280x720, 90 deg, 1 m ahead and 3 m up, level) through CARLA's RGB camera
    # post-processing: histogram auto-exposure, filmic tone curve, motion blur over a 1/200 s shutter. No sensor
    # noise: CARLA's RGB camera has no noise or grain attribute, so its frames carry none. Its histogram
    # auto-exposure adapts over two stops only (ExposureMinEV 10 to ExposureMaxEV 12): the gain window is two stops
    # wide, its low end the gain our meter sets on the brightest clear-noon stock scenes (0.47-0.55), so daylight
    # is metered as before and a night is not brightened beyond what a dim day gets. No sharpening: CARLA renders
    # the image, no camera ISP processes it, and none of `sensor.camera.rgb`'s attributes sharpens.
    "carla": {"width": 1280, "height": 720, "fov": 90.0, "x": 1.0, "y": 0.0, "z": 3.0, "pitch": 0.0,
              "sensor": {"shutter": 0.005, "vignetting": 0.25, "noise": 0.0, "sharpen": 0.0, "min_gain": 0.45,
                         "max_gain": 1.8}},
    # A highway front camera behind the windscreen as in TuSimple's 1280x720 frames: the vanishing point near row
    # 290, about 62 deg across, a little barrel distortion, no bonnet in view.
    "tusimple": {"width": 1280, "height": 720, "fov": 62.0, "x": 1.6, "y": 0.0, "z": 1.55, "pitch": 3.5,
                 "lens": {"k1": -0.06, "k2": 0.01},
                 "sensor": {"shutter": 0.004, "vignetting": 0.3, "noise": 1.0, "saturation": 1.35}},
    # CULane's 1640x590 frames: a wide, short image with the horizon near row 260 and the bonnet at the bottom.
    "culane": {"width": 1640, "height": 590, "fov": 76.0, "x": 1.2, "y": 0.0, "z": 1.45, "pitch": 1.5,
               "lens": {"k1": -0.08, "k2": 0.015},
               "bonnet": {"reach": 2.2, "drop": 0.5},
               "sensor": {"shutter": 0.008, "vignetting": 0.35, "noise": 1.6, "saturation": 1.3}},
    # A typical consumer dash cam (1280x720, ~58 deg across, the horizon at rows 407-440, the bonnet from row
    # ~672, a barrel lens, strong sharpening and compression-era noise).
    "dashcam": {"width": 1280, "height": 720, "fov": 58.0, "x": 0.6, "y": 0.0, "z": 1.35, "pitch": -3.0,
                "lens": {"k1": -0.12, "k2": 0.03},
                "bonnet": {"reach": 2.3, "drop": 0.5},
                "sensor": {"shutter": 0.008, "vignetting": 0.45, "noise": 1.5, "sharpen": 0.9,
                           "saturation": 1.4}},
}

CAMERA_PRESET_NAMES: Final[tuple[str, ...]] = tuple(CAMERA_PRESETS)
# The preset names as a type, for models whose schema must list them (a study's ``camera``); kept equal to the keys.
CameraPreset = Literal["carla", "tusimple", "culane", "dashcam"]
assert get_args(CameraPreset) == CAMERA_PRESET_NAMES, "CameraPreset must name every camera preset, in order"


def camera_preset_values(name: str) -> dict[str, Any]:
    """The camera fields a preset sets (a fresh copy). Raises KeyError naming the valid presets."""
    if name not in CAMERA_PRESETS:
        raise KeyError(f"unknown camera preset {name!r}; choose one of {', '.join(CAMERA_PRESET_NAMES)}")
    return copy.deepcopy(CAMERA_PRESETS[name])
