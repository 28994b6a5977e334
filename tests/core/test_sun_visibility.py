"""The sun's shadow lookup over a pixel's footprint (``lighting.sun_visibility_over``): a footprint that spans
several stripes of a fine shadow averages them wherever it falls (no moiré), and a footprint of nothing reads the
point alone, as the ideal frame's ``sun_visibility`` does."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.render.lighting import FOOTPRINT_TAP_TEXELS, sun_visibility, sun_visibility_over
from lanevil_core.render.shadow_map import pool_extremes

SIZE = 256
PERIOD = 8  # texels: 4 shaded columns, then 4 lit ones (a slatted fence's shadow seen from far off)
RECEIVER_DEPTH = 10.0


@pytest.fixture(scope="module")
def striped_map() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(maps, cells, params, R_light) of one cascade, one texel per metre, light space = world space."""
    depth = np.full((SIZE, SIZE), 1e6, np.float32)  # nothing between the light and the receiver...
    depth[:, (np.arange(SIZE) % PERIOD) < PERIOD // 2] = 5.0  # ...except stripes of casters in front of it
    cells = pool_extremes([depth])[0]
    return depth[None], cells[None], np.array([[0.0, 0.0, 1.0]]), np.eye(3)


def _look(striped_map, x: float, du: tuple[float, float, float], dv: tuple[float, float, float]) -> float:
    maps, cells, params, R_light = striped_map
    return float(sun_visibility_over(x, 128.0, RECEIVER_DEPTH, 0.0, 0.0, 1.0, 0.0, 1.5, maps, cells, params,
                                     R_light, 0.0, du, dv))


def test_a_footprint_over_fine_stripes_averages_them_wherever_it_falls(striped_map):
    across = (4.0 * PERIOD * FOOTPRINT_TAP_TEXELS / 4.0, 0.0, 0.0)  # 4 taps, half a period apart
    along = (0.0, 1e-3, 0.0)
    xs = np.linspace(128.0, 128.0 + PERIOD, 17)
    filtered = [_look(striped_map, x, across, along) for x in xs]
    point = [_look(striped_map, x, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) for x in xs]
    assert max(point) > 0.95 and min(point) < 0.05  # read alone, the stripes beat with the pixel grid
    assert all(abs(v - 0.5) < 0.13 for v in filtered), filtered


def test_a_footprint_of_nothing_reads_the_point_as_the_ideal_frame_does(striped_map):
    maps, cells, params, R_light = striped_map
    for x in np.linspace(120.0, 140.0, 41):
        alone = sun_visibility(x, 128.0, RECEIVER_DEPTH, 0.0, 0.0, 1.0, 0.0, 1.5, maps, cells, params, R_light, 0.0)
        assert _look(striped_map, x, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) == alone
