"""Ambient occlusion of the ground (``render.packed.sky_past``, ``ground_occlusion``): the sky the ground sees past
what stands on it and hangs over it."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.case import load_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render.packed import AO_REACH_M, _wide_columns, pack_scene, sky_past
from lanevil_core.world.scene import ID_ROAD

CELL = 0.25
STOCK = "scenes/00_clean/01_bend_suburban.json"


def _wall(height: float, bottom: float = 0.0, size: int = 64, at: int = 32) -> tuple[np.ndarray, np.ndarray]:
    tops, bottoms = np.zeros((size, size)), np.zeros((size, size))
    tops[:, at:] = height
    bottoms[:, at:] = bottom
    return tops, bottoms


def test_open_ground_sees_the_whole_sky() -> None:
    tops, bottoms = np.zeros((20, 30)), np.zeros((20, 30))
    assert np.all(sky_past(tops, bottoms, CELL) == 1.0)


def test_a_wall_darkens_its_foot_most_and_nothing_beyond_reach() -> None:
    tops, bottoms = _wall(6.0)
    sky = sky_past(tops, bottoms, CELL)[32]
    foot, metre, far = sky[31], sky[28], sky[32 - int(AO_REACH_M[-1] / CELL) - 2]
    assert foot < metre < far == 1.0
    assert 0.45 < foot < 0.7  # about half the sky is behind a tall wall at its foot (cosine-weighted: a bit more)


def test_an_overhang_blocks_less_than_a_wall_of_the_same_height() -> None:
    wall = sky_past(*_wall(3.0), CELL)[32, 28]
    overhang = sky_past(*_wall(3.0, bottom=2.0), CELL)[32, 28]
    assert wall < overhang < 1.0


def test_casters_narrower_than_two_cells_occlude_nothing() -> None:
    top = np.full((40, 40), -np.inf)
    bottom = np.full((40, 40), np.inf)
    ground = np.zeros((40, 40))
    top[20, 5:35], bottom[20, 5:35] = 8.0, 7.9  # a wire
    top[10, 10], bottom[10, 10] = 6.0, 0.0  # a pole
    top[28:32, 28:32], bottom[28:32, 28:32] = 1.5, 0.3  # a car's corner, 1 m across
    tops, bottoms = _wide_columns(top, bottom, ground)
    assert tops[20].max() == 0.0 and tops[10, 10] == 0.0
    assert np.all(tops[28:32, 28:32] == 1.5) and np.all(bottoms[28:32, 28:32] == 0.3)


@settings(max_examples=25, deadline=None)
@given(height=st.floats(0.1, 20.0), grow=st.floats(1.01, 3.0), bottom_share=st.floats(0.0, 0.99))
def test_occlusion_is_a_share_and_grows_with_the_caster(height: float, grow: float, bottom_share: float) -> None:
    low = sky_past(*_wall(height, bottom_share * height, size=24, at=12), CELL)
    high = sky_past(*_wall(height * grow, bottom_share * height, size=24, at=12), CELL)
    assert np.all((low >= 0.0) & (low <= 1.0)) and np.all((high >= 0.0) & (high <= 1.0))
    assert np.all(high <= low + 1e-6)


def test_the_suburb_darkens_the_ground_by_its_walls_not_the_carriageway() -> None:
    scene = compile_scene(load_case(STOCK))
    packed = pack_scene(scene)
    x0, y0, per_m = packed.overhead_params
    road = packed.vertices[packed.faces[packed.face_object == ID_ROAD].ravel()]
    cells = ((road[:, 1] - y0) * per_m).astype(int), ((road[:, 0] - x0) * per_m).astype(int)
    inside = (cells[0] >= 0) & (cells[0] < packed.overhead.shape[0]) & (cells[1] >= 0) & \
        (cells[1] < packed.overhead.shape[1])
    on_road = packed.overhead[cells[0][inside], cells[1][inside]]
    assert np.median(on_road) > 0.97  # the carriageway is open to the sky ...
    assert (packed.overhead < 0.8).mean() > 0.001  # ... the feet of walls, cars and hedges are not
