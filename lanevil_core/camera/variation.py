"""Random cameras for a train split that sees every camera a detector may meet: a preset as the base (its lens,
bonnet and sensor), then the mount, field of view, principal point row, lens, bonnet, exposure, noise, blur, colour
and compression drawn from ranges around real dash and front cameras. Every call makes the same number of draws,
so what a caller draws afterwards does not shift."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..presets import CAMERA_PRESET_NAMES, camera_preset_values
from .lens import covers

HFOV_DEG = (45.0, 100.0)
HEIGHT_M = (1.2, 3.5)
# Most dash and windscreen cameras sit 1.2-1.6 m over the road (a car's roof is about 1.45 m); the paper's 3 m
# camera and trucks' and buses' cameras fill the rest of HEIGHT_M. A lane line's slope in the image is its lateral
# offset over the camera's height, so a detector that places lanes from the whole frame learns this prior.
CAR_HEIGHT_M = (1.2, 1.6)
CAR_HEIGHT_SHARE = 0.6
AHEAD_M = (0.4, 2.0)
PITCH_DEG = (-2.0, 6.0)  # positive looks down
ROLL_DEG = (-2.0, 2.0)
YAW_DEG = (-2.0, 2.0)
BONNET_SHARE = 0.4
BONNET_REACH_M = (1.8, 2.8)
BONNET_DROP_M = (0.35, 0.7)
K1 = (-0.22, 0.0)
K2 = (0.0, 0.05)
EXPOSURE_BIAS_EV = (-0.8, 0.8)
NOISE = (0.3, 3.0)
SHUTTER_S = (0.0, 0.012)
VIGNETTING = (0.0, 0.55)
SATURATION = (1.05, 1.75)
CONTRAST = (0.95, 1.3)
WHITE_BALANCE_K = (4500.0, 7500.0)
SHARPEN = (0.0, 1.2)
COMPRESSION_SHARE = 0.6
JPEG_QUALITY = (35, 95)
# The principal point's row, up to this share of the height off the middle: with the pitch it puts the horizon
# anywhere from about 20 to 70 % down the image (cropped and tilted real footage: Udacity's highway clips put it at
# 57-62 %), so row-anchor detectors meet lanes that leave the image at every height.
PRINCIPAL_ROW_SHIFT = 0.12
DRAWS = 23


def _pick(u: float, lo_hi: tuple[float, float], digits: int = 3) -> float:
    lo, hi = lo_hi
    return round(lo + (hi - lo) * u, digits)


def _height(u: float) -> float:
    """The mount height for one uniform draw ``u``: within CAR_HEIGHT_M for a share CAR_HEIGHT_SHARE of draws,
    above it up to HEIGHT_M's top for the rest (one draw either way)."""
    if u < CAR_HEIGHT_SHARE:
        return _pick(u / CAR_HEIGHT_SHARE, CAR_HEIGHT_M, 2)
    return _pick((u - CAR_HEIGHT_SHARE) / (1.0 - CAR_HEIGHT_SHARE), (CAR_HEIGHT_M[1], HEIGHT_M[1]), 2)


Spans = tuple[tuple[float, float], ...]  # one or more (lo, hi) intervals a value is drawn from


@dataclass(frozen=True)
class MountSpans:
    """Where a drawn camera's field of view (degrees), mount height (m) and pitch (degrees) may lie instead of
    the ranges above (a held-out draw: cameras outside what the train split saw)."""

    fov_deg: Spans
    height_m: Spans
    pitch_deg: Spans


def pick_spans(u: float, spans: Spans, digits: int = 3) -> float:
    """The value at ``u`` (0-1) along the intervals of ``spans`` laid end to end (each as likely as its length):
    one uniform draw whatever the number of intervals."""
    total = sum(hi - lo for lo, hi in spans)
    at = float(u) * total
    for lo, hi in spans:
        if at <= hi - lo:
            return round(lo + at, digits)
        at -= hi - lo
    return round(spans[-1][1], digits)


def random_camera(rng: np.random.Generator, size: tuple[int, int] = (1280, 720),
                  spans: MountSpans | None = None) -> dict[str, Any]:
    """Camera fields (a dict for ``Case.camera``) of an image of ``size`` drawn from the ranges above (field of
    view, height and pitch from ``spans`` when given), always ``DRAWS`` uniform draws."""
    u = rng.uniform(0.0, 1.0, DRAWS)
    camera = camera_preset_values(CAMERA_PRESET_NAMES[int(u[0] * len(CAMERA_PRESET_NAMES))])
    camera.update(width=size[0], height=size[1])
    if spans is None:
        fov, height, pitch = _pick(u[1], HFOV_DEG, 1), _height(u[2]), _pick(u[4], PITCH_DEG, 2)
    else:
        fov = pick_spans(u[1], spans.fov_deg, 1)
        height, pitch = pick_spans(u[2], spans.height_m, 2), pick_spans(u[4], spans.pitch_deg, 2)
    camera.update(fov=fov, z=height, x=_pick(u[3], AHEAD_M, 2),
                  pitch=pitch, roll=_pick(u[5], ROLL_DEG, 2), yaw=_pick(u[6], YAW_DEG, 2),
                  lens={"k1": _pick(u[7], K1, 4), "k2": _pick(u[8], K2, 4)})
    camera["bonnet"] = ({"reach": _pick(u[10], BONNET_REACH_M, 2), "drop": _pick(u[11], BONNET_DROP_M, 2)}
                        if u[9] < BONNET_SHARE else None)
    camera["sensor"] = {
        "bias": _pick(u[12], EXPOSURE_BIAS_EV, 2), "noise": _pick(u[13], NOISE, 2),
        "shutter": _pick(u[14], SHUTTER_S, 4), "vignetting": _pick(u[15], VIGNETTING, 2),
        "saturation": _pick(u[16], SATURATION, 2), "contrast": _pick(u[17], CONTRAST, 2),
        "white_balance": _pick(u[18], WHITE_BALANCE_K, 0), "sharpen": _pick(u[19], SHARPEN, 2),
        "compression": int(round(_pick(u[21], JPEG_QUALITY, 0))) if u[20] < COMPRESSION_SHARE else None,
    }
    camera["cy"] = round(camera["height"] * (0.5 + PRINCIPAL_ROW_SHIFT * (2.0 * u[22] - 1.0)), 1)
    camera["lens"] = _within_view(camera["lens"], camera["fov"], camera["width"], camera["height"], camera["cy"])
    return camera


def _within_view(lens: dict[str, float], fov: float, width: int, height: int, cy: float) -> dict[str, float]:
    """The drawn lens, weakened by halves until it covers the whole image at ``fov`` from the principal point row
    ``cy`` (a strong barrel on a wide view would turn back inside the image)."""
    focal = 0.5 * width / math.tan(math.radians(fov) / 2)
    corner = math.hypot(width / 2, max(cy, height - cy)) / focal
    k1, k2 = lens["k1"], lens["k2"]
    while not covers((k1, k2, 0.0, 0.0, 0.0), corner):
        k1, k2 = round(k1 / 2, 4), round(k2 / 2, 4)
    return {"k1": k1, "k2": k2}
