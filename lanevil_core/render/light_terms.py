"""The light a pixel receives (numba helpers inlined into ``shading``): the sun's diffuse and glossy terms, every
lamp's through its beam, their sum with the sky's ambient and the face's emission, and the blend towards a
reflection. The light table, the beams and the highlight lobes are ``lighting``'s."""

from __future__ import annotations

import numpy as np

from ._jit import kernel
from .lighting import BEAM_LOW, LIGHT_BEAM, LIGHT_POWER, LIGHT_R, beam_weight, glossy_lobe, lobe_shape


@kernel(inline="always")
def sun_lit(sun_dir: np.ndarray, sun: np.ndarray, visibility: float, n_dot_l: float, nx: float, ny: float,
            nz: float, dx: float, dy: float, dz: float, roughness: float, fresnel: float,
            shiny: float) -> tuple[float, float, float, float, float, float]:
    """(diffuse irradiance rgb, specular radiance rgb) of the sun seen with ``visibility``."""
    sun_x, sun_y, sun_z = sun_dir[0], sun_dir[1], sun_dir[2]  # read before any branch (see ``_jit``)
    sun_r, sun_g, sun_b = sun[0], sun[1], sun[2]
    k = n_dot_l * visibility
    spec = 0.0
    if visibility > 0.0 and shiny > 0.0:
        hx, hy, hz = sun_x - dx, sun_y - dy, sun_z - dz
        n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
        exponent, normalisation, cutoff = lobe_shape(roughness)
        spec = visibility * glossy_lobe(n_dot_h, exponent, normalisation, cutoff) * fresnel * 0.25 * shiny
    return sun_r * k, sun_g * k, sun_b * k, sun_r * spec, sun_g * spec, sun_b * spec


@kernel(inline="always")
def lamp_light(lights: np.ndarray, px: float, py: float, pz: float, nx: float, ny: float, nz: float, dx: float,
               dy: float, dz: float, roughness: float, fresnel: float, shiny: float,
               retro: float) -> tuple[float, float, float, float, float, float]:
    """(diffuse irradiance rgb, specular radiance rgb) of every lamp at world point p, each through its beam
    (``beam_weight``); the ego's low beams also come back from the road by ``retro`` (its retroreflection, as a
    share of the beam's irradiance square to it; 0 off the road)."""
    light_r = light_g = light_b = 0.0
    spec_r = spec_g = spec_b = 0.0
    if lights.shape[0] == 0:
        return light_r, light_g, light_b, spec_r, spec_g, spec_b
    lobe = lobe_shape(roughness)
    for i in range(lights.shape[0]):
        lx = lights[i, 0] - px
        ly = lights[i, 1] - py
        lz = lights[i, 2] - pz
        d2 = lx * lx + ly * ly + lz * lz
        inv_dl = 1.0 / np.sqrt(d2)
        ndl = (nx * lx + ny * ly + nz * lz) * inv_dl
        if ndl <= 0.0:
            continue
        power = lights[i, LIGHT_POWER] / (d2 + 1.0) * beam_weight(lights, i, -lx * inv_dl, -ly * inv_dl,
                                                                  -lz * inv_dl)
        if power <= 0.0:
            continue
        hx, hy, hz = lx * inv_dl - dx, ly * inv_dl - dy, lz * inv_dl - dz
        n_dot_h = (nx * hx + ny * hy + nz * hz) / np.sqrt(hx * hx + hy * hy + hz * hz)
        k_spec = power * glossy_lobe(n_dot_h, lobe[0], lobe[1], lobe[2]) * fresnel * (0.1 + shiny)
        k_diff = power * (ndl + (retro if lights[i, LIGHT_BEAM] == BEAM_LOW else 0.0))
        light_r += lights[i, LIGHT_R] * k_diff
        light_g += lights[i, LIGHT_R + 1] * k_diff
        light_b += lights[i, LIGHT_R + 2] * k_diff
        spec_r += lights[i, LIGHT_R] * k_spec
        spec_g += lights[i, LIGHT_R + 1] * k_spec
        spec_b += lights[i, LIGHT_R + 2] * k_spec
    return light_r, light_g, light_b, spec_r, spec_g, spec_b


@kernel(inline="always")
def shade_lit(color: tuple[float, float, float], ambient: np.ndarray, up: float, emission: np.ndarray, f: int,
              glow: float, sun: tuple[float, float, float, float, float, float],
              lamps: tuple[float, float, float, float, float, float]) -> tuple[float, float, float]:
    """Albedo ``color`` under the sun, the lamps and the sky's ambient (times ``up``), plus specular and the face's
    emission times ``glow`` (the share of a lit window that is glass, not bars; else 1)."""
    return (color[0] * (sun[0] + lamps[0] + ambient[0] * up) + sun[3] + lamps[3] + emission[f, 0] * glow,
            color[1] * (sun[1] + lamps[1] + ambient[1] * up) + sun[4] + lamps[4] + emission[f, 1] * glow,
            color[2] * (sun[2] + lamps[2] + ambient[2] * up) + sun[5] + lamps[5] + emission[f, 2] * glow)


@kernel(inline="always")
def blend(r: float, g: float, b: float, ref: tuple[float, float, float], strength: float) -> tuple[float, float, float]:
    """(r, g, b) mixed towards the reflected colour ``ref`` by ``strength``."""
    return (r * (1.0 - strength) + ref[0] * strength, g * (1.0 - strength) + ref[1] * strength,
            b * (1.0 - strength) + ref[2] * strength)
