"""The renderer's procedural noise: flat mip pyramids and their filtered lookups."""

from __future__ import annotations

from functools import cache

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.render.surface import sample_noise
from lanevil_core.render.textures import NOISE_LEVELS, NOISE_SIZE, level_offset, noise_textures


@cache
def upsampled_fine() -> np.ndarray:
    """(levels, n, n): every level of the fine pyramid blown back up to the tile's texels (each level texel
    repeated 2^level times along both axes)."""
    pyramid = noise_textures()[0]
    levels = []
    for level in range(NOISE_LEVELS):
        side = NOISE_SIZE >> level
        texels = pyramid[level_offset(level):level_offset(level) + side * side].reshape(side, side)
        levels.append(np.repeat(np.repeat(texels, 1 << level, axis=0), 1 << level, axis=1))
    return np.stack(levels)


def reference_sample(levels: np.ndarray, texel_m: float, s: float, t: float, footprint_m: float) -> float:
    """Bilinear lookup in the upsampled level whose texel covers the footprint, written plainly."""
    level = 0
    while footprint_m / texel_m / 2.0**level > 1.0 and level < NOISE_LEVELS - 1:
        level += 1
    x, y = s / texel_m, t / texel_m
    i, j = int(np.floor(x)), int(np.floor(y))
    fx, fy = x - i, y - j
    n = NOISE_SIZE

    def at(a: int, b: int) -> float:
        return float(levels[level, a % n, b % n])

    return ((at(i, j) * (1 - fy) + at(i, j + 1) * fy) * (1 - fx)
            + (at(i + 1, j) * (1 - fy) + at(i + 1, j + 1) * fy) * fx)


def test_pyramid_levels_follow_each_other_and_are_box_filtered() -> None:
    fine, coarse = noise_textures()
    total = sum((NOISE_SIZE >> level) ** 2 for level in range(NOISE_LEVELS))
    assert fine.shape == coarse.shape == (total,) and fine.dtype == np.float32
    for level in range(NOISE_LEVELS):
        assert level_offset(level) == sum((NOISE_SIZE >> k) ** 2 for k in range(level))
    side = NOISE_SIZE // 2
    base = fine[:NOISE_SIZE * NOISE_SIZE].reshape(NOISE_SIZE, NOISE_SIZE)
    level1 = fine[level_offset(1):level_offset(1) + side * side].reshape(side, side)
    np.testing.assert_allclose(level1, base.reshape(side, 2, side, 2).mean(axis=(1, 3)), atol=1e-6)
    assert abs(float(fine.max())) <= 1.0 and abs(float(fine.min())) <= 1.0


@settings(max_examples=200, deadline=None)
@given(s=st.floats(-500.0, 500.0), t=st.floats(-40.0, 40.0), footprint=st.floats(0.0, 20.0),
       texel=st.sampled_from([0.025, 0.03, 0.1, 0.4]))
def test_lookup_is_bilinear_in_the_level_that_covers_the_footprint(s: float, t: float, footprint: float,
                                                                   texel: float) -> None:
    fine, _ = noise_textures()
    expected = reference_sample(upsampled_fine(), texel, s, t, footprint)
    assert abs(sample_noise(fine, texel, s, t, footprint) - expected) < 1e-5
