"""A real camera's response to the light of a rendered frame: metering, white balance, colour, tone curve, noise.

The renderer hands over scene-referred linear radiance (the old ideal pipeline maps 1.0 to a bright grey); this
module works out, per frame, the numbers of the sensor kernel (``render.develop``):

- **Auto-exposure** meters the frame as a camera does: the mean log luminance of the frame's middle 90 %
  (trimmed, so neither the sun's glint nor black tires rule it) is brought to middle grey (``KEY``), within the
  sensor's gain limits. The sky is in the metered frame, so shadowed asphalt falls dark and highlights clip.
  In the dark (a gain beyond ``BASE_GAIN``) the camera protects its highlights as automotive cameras do: the
  gain rises only as far as keeps ``HIGHLIGHT_PERCENTILE`` of the frame below clip, so the road in the
  headlights' beam keeps its paint instead of burning out (never below ``BASE_GAIN``: daylight is unchanged).
- **Gain and noise**: beyond ``BASE_GAIN`` the camera raises its analogue gain (ISO) instead of the exposure
  time; shot noise (Poisson, ~ sqrt(signal / full well)) and read noise (Gaussian) grow with it (EMVA 1288).
- **White balance**: von Kries gains from the scene's daylight to the camera's set colour temperature.
- **Tone curve**: a filmic curve (a power toe of ``contrast`` and a rational shoulder), then sRGB encoding,
  as one lookup table indexed by the square root of the clipped sensor value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..case import Sensor
from ..images import linear_to_srgb, srgb_to_linear
from ..typed import FloatArray, UInt8Array

KEY = 0.18  # middle grey the metered mean log luminance is brought to
TRIM = (5.0, 95.0)  # percentiles of log luminance kept by the meter
METER_STEP = 8  # the meter reads every 8th pixel of every 8th row
BASE_GAIN = 2.0  # exposure gain reached at base ISO (longest shutter); above it the analogue gain rises
HIGHLIGHT_PERCENTILE = 98.0  # above base ISO, the gain keeps this share of the metered frame below clip
FULL_WELL_E = 5000.0  # electrons at clip of a small automotive sensor pixel
READ_NOISE_E = 4.0  # read noise (electrons, rms) at base ISO
DAYLIGHT_K = 5600.0  # colour temperature of the renderer's sun and sky
LUMA = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709 luminance of linear RGB
TONE_LUT_SIZE = 16384  # evenly spaced sensor values: within one level of the exact curve, no square root per read
SHOULDER = 2.0  # the filmic curve's shoulder constant


@dataclass(frozen=True)
class Development:
    """The sensor kernel's numbers for one frame.

    Attributes:
        gain: exposure applied to scene radiance (sensor value 1.0 = clip).
        iso_gain: analogue gain over base ISO (>= 1); noise grows with it.
        channel_gain: (3,) float64 white-balance gains (green = 1).
        shot: shot-noise variance per unit of sensor value (already times ``iso_gain`` and the noise scale**2).
        read: read-noise standard deviation in sensor units.
        lut: (TONE_LUT_SIZE,) uint8 sRGB byte of evenly spaced sensor values after the filmic curve.
    """

    gain: float
    iso_gain: float
    channel_gain: FloatArray
    shot: float
    read: float
    lut: UInt8Array


def metered_gain(hdr: np.ndarray, sensor: Sensor) -> float:
    """Exposure gain for a (H, W, 3) float32 linear frame: trimmed mean log luminance to ``KEY`` (times the bias),
    clamped to the sensor's limits; ``sensor.gain`` in fixed mode."""
    if sensor.exposure == "fixed":
        return float(sensor.gain)
    sample = np.asarray(hdr[METER_STEP // 2::METER_STEP, METER_STEP // 2::METER_STEP], np.float64)
    luminance = np.maximum(sample @ LUMA, 1e-5).ravel()
    log_l = np.log2(luminance)
    lo, hi = np.percentile(log_l, TRIM)
    kept = log_l[(log_l >= lo) & (log_l <= hi)]
    mean_log = float(kept.mean()) if kept.size else float(log_l.mean())
    gain = float(np.clip(KEY * 2.0 ** (sensor.bias - mean_log), sensor.min_gain, sensor.max_gain))
    if gain > BASE_GAIN:  # in the dark, gain rises only while the lit road stays below clip (highlight priority)
        protected = 1.0 / max(float(np.percentile(luminance, HIGHLIGHT_PERCENTILE)), 1e-9)
        gain = max(BASE_GAIN, min(gain, protected))
    return gain


def blackbody_rgb(kelvin: float) -> FloatArray:
    """(3,) float64 linear RGB of a Planckian light of ``kelvin`` (a fit to CIE data, green = 1), 1,000-40,000 K."""
    t = kelvin / 100.0
    if t <= 66.0:
        r = 255.0
        g = 99.4708025861 * math.log(t) - 161.1195681661
        b = 0.0 if t <= 19.0 else 138.5177312231 * math.log(t - 10.0) - 305.0447927307
    else:
        r = 329.698727446 * (t - 60.0) ** -0.1332047592
        g = 288.1221695283 * (t - 60.0) ** -0.0755148492
        b = 255.0
    srgb = np.clip(np.array([r, g, b]) / 255.0, 1e-3, 1.0)
    linear = srgb_to_linear(srgb)
    return linear / linear[1]


def white_balance_gains(sensor: Sensor) -> FloatArray:
    """(3,) von Kries gains that render daylight as it would look balanced for ``sensor.white_balance``."""
    return blackbody_rgb(DAYLIGHT_K) / blackbody_rgb(sensor.white_balance)


def filmic(x: FloatArray, contrast: float) -> FloatArray:
    """Display-referred linear light in [0, 1] of sensor values ``x`` in [0, 1]: a power toe (``contrast``) under a
    rational shoulder, ``x**p * (1 + c) / (x**p + c)`` with ``c = SHOULDER``: middle grey (``KEY``) lands near 0.19,
    the clip point at 1 and highlights roll off before it."""
    xp = np.power(np.clip(x, 0.0, 1.0), contrast)
    return xp * (1.0 + SHOULDER) / (xp + SHOULDER)


@lru_cache(maxsize=16)
def tone_lut(contrast: float) -> UInt8Array:
    """(TONE_LUT_SIZE,) uint8: sRGB bytes of the filmic curve at sensor values ``i / (n - 1)``."""
    x = np.linspace(0.0, 1.0, TONE_LUT_SIZE)
    display = filmic(x, contrast)  # display-referred linear light in [0, 1]
    lut = np.clip(np.round(linear_to_srgb(display) * 255.0), 0, 255).astype(np.uint8)
    lut.setflags(write=False)
    return lut


def development(hdr: np.ndarray, sensor: Sensor) -> Development:
    """The sensor kernel's numbers for a (H, W, 3) float32 linear frame."""
    gain = metered_gain(hdr, sensor)
    iso_gain = max(1.0, gain / BASE_GAIN)
    shot = sensor.noise**2 * iso_gain / FULL_WELL_E
    read = sensor.noise * READ_NOISE_E * iso_gain / FULL_WELL_E
    return Development(gain, iso_gain, white_balance_gains(sensor), shot, read, tone_lut(round(sensor.contrast, 4)))
