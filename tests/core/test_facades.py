"""Building finishes and footways drawn per pixel: structure up close, its mean colour far away, never moire."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.render import facades as fc
from lanevil_core.render.materials import ASPHALT, CONCRETE, GRAIN, KERB, SLAB, surface_table
from lanevil_core.world import facade

WALL = (0.3, 0.12, 0.07)


def _wall(finish: int, u: np.ndarray, v: np.ndarray, foot: float) -> np.ndarray:
    """(n, 3) colours of a wall of ``finish`` at facade points (u, v) seen with footprint ``foot`` (no weathering)."""
    return np.array([fc.facade(finish, float(a), float(b), foot, foot, 0.0, 0.0, *WALL)[:3] for a, b in zip(u, v)])


@pytest.mark.parametrize("finish", [facade.BRICK, facade.PANELS, facade.TILES])
def test_walls_show_their_joints_up_close_and_their_mean_far_away(finish: int) -> None:
    rng = np.random.default_rng(0)
    u, v = rng.uniform(0.0, 20.0, 400), rng.uniform(2.0, 3.0, 400)  # one band of height, away from the foot
    near, far = _wall(finish, u, v, 0.002), _wall(finish, u, v, 3.0)
    assert near[:, 0].std() > 0.01  # bricks, panels and joints
    assert far[:, 0].std() < 1e-3  # a pixel over many units is their mean, wherever it falls
    assert abs(far[:, 0].mean() - near[:, 0].mean()) < 0.15 * near[:, 0].mean()  # the same mean, filtered


def test_brick_courses_are_75_mm_with_mortar_between() -> None:
    v = np.arange(0.0, 0.6, 0.0025) + 1.0
    grey = _wall(facade.BRICK, np.full(v.size, 0.1), v, 0.002)[:, 0]
    mortar = grey > 0.9 * fc.MORTAR_ALBEDO[0]  # the mortar is paler than this brick
    starts = v[1:][mortar[1:] & ~mortar[:-1]]
    np.testing.assert_allclose(np.diff(starts), fc.COURSE_M, atol=0.003)


def test_roof_tiles_lie_in_courses_at_their_gauge_each_shading_the_one_below() -> None:
    v = np.arange(0.0, 1.5, 0.0025) + 0.2
    grey = _wall(facade.TILES, np.full(v.size, 0.07), v, 0.002)[:, 0]
    butt = grey < 0.5 * WALL[0]  # the shadow under each course's lower edge
    starts = v[1:][butt[1:] & ~butt[:-1]]
    np.testing.assert_allclose(np.diff(starts), fc.TILE_GAUGE_M, atol=0.003)
    moss = fc.facade(facade.TILES, 0.07, 0.5, 3.0, 3.0, -1.0, 0.0, *WALL)[0]
    clean = fc.facade(facade.TILES, 0.07, 0.5, 3.0, 3.0, 0.0, 1.0, *WALL)[0]
    assert moss < clean  # moss darkens a roof; no sill streaks run down it


def test_lines_fade_to_their_mean_share_before_they_alias() -> None:
    x = np.linspace(0.0, 1.0, 997)
    for foot in (0.05, 0.1, 0.3):  # a footprint of at least half the period: no pattern left
        shares = [fc.lines(float(a), foot, 0.01, 0.075) for a in x]
        np.testing.assert_allclose(shares, 0.01 / 0.075, atol=1e-9)
    close = [fc.lines(float(a), 0.002, 0.01, 0.075) for a in x]
    assert max(close) == pytest.approx(1.0) and min(close) == pytest.approx(0.0)


def test_window_glass_has_bars_and_is_mostly_glass() -> None:
    _, _, _, bar = fc.glazing(facade.GLASS, 0.0, 0.5, 0.005, 0.005, 0.02, 0.02, 0.02)  # on the mullion
    _, _, _, pane = fc.glazing(facade.GLASS, 0.3, 0.5, 0.005, 0.005, 0.02, 0.02, 0.02)
    _, _, _, transom = fc.glazing(facade.GLASS, 0.3, facade.TRANSOM_M, 0.005, 0.005, 0.02, 0.02, 0.02)
    assert bar == pytest.approx(0.0) and transom == pytest.approx(0.0) and pane == pytest.approx(1.0)
    _, _, _, riser = fc.glazing(facade.SHOP_GLASS, 0.9, 0.1, 0.005, 0.005, 0.05, 0.05, 0.05)
    _, _, _, shop = fc.glazing(facade.SHOP_GLASS, 0.9, 1.2, 0.005, 0.005, 0.05, 0.05, 0.05)
    assert riser == pytest.approx(0.0) and shop == pytest.approx(1.0)


def test_footways_are_flags_and_kerbs_stones_the_carriageway_keeps_its_grain() -> None:
    t = np.arange(0.0, 1.8, 0.002)
    flags = np.array([fc.footway(False, 0.3, float(a), 0.002, 0.002, 1.0, 1.0, 1.0)[0] for a in t])
    joints = t[1:][(flags[1:] < 0.7) & (flags[:-1] >= 0.7)]
    np.testing.assert_allclose(np.diff(joints), fc.FLAG_M, atol=0.005)
    s = np.arange(0.0, 3.0, 0.002)
    kerb = np.array([fc.footway(True, float(a), 0.1, 0.002, 0.002, 1.0, 1.0, 1.0)[0] for a in s])
    assert (kerb < 0.7).any() and not (kerb[np.abs(s - 0.4) < 0.05] < 0.8).any()
    table = surface_table()
    assert table[ASPHALT, GRAIN] == table[SLAB, GRAIN] == 1.0
    assert table[CONCRETE, GRAIN] < 0.5 and table[KERB, GRAIN] < 0.5


def test_wall_finishes_are_drawn_per_building_from_calm_palettes() -> None:
    rng = np.random.default_rng(3)
    drawn = [facade.wall_finish(rng) for _ in range(200)]
    finishes = [finish for finish, _ in drawn]
    for finish, share in zip(facade.WALL_FINISHES, facade.WALL_SHARES):
        assert abs(finishes.count(finish) / 200 - share) < 0.1
    colors = np.array([color for _, color in drawn])
    assert colors.max() < 0.6 and colors.min() > 0.03
    assert len(np.unique(colors.round(4), axis=0)) > 100  # no two streets alike
