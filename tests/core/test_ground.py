"""The land beyond the road: verges, fields and lawns of the grass material (``render/ground.py``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.case import load_case
from lanevil_core.labels.lanes import tusimple_record
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame, renderer
from lanevil_core.render.ground import FIELDS, INNER_M, LAND, LAWNS, NO_LAND, ground, ground_table
from lanevil_core.typed import SceneKind
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.scene import ID_ROAD

ROOT = Path(__file__).resolve().parents[2]
RURAL = ROOT / "scenes" / "00_clean" / "02_s_curve_rural.json"


def albedo_over(table: np.ndarray, s: np.ndarray, t: np.ndarray, foot: float, wetness: float = 0.0) -> np.ndarray:
    """(n, 3) ground albedo at road points (s, t) of piece 0 with a square footprint ``foot``, no noise."""
    return np.array([ground(table, 0, float(a), float(b), foot, foot, 0.0, 0.0, wetness)[:3]
                     for a, b in zip(s, t, strict=True)])


@pytest.mark.parametrize(("kind", "land"), [("rural", FIELDS), ("highway", FIELDS), ("suburban", LAWNS),
                                             ("urban", NO_LAND), ("tunnel_approach", NO_LAND)])
def test_each_scene_kind_gets_its_land(kind: SceneKind, land: float) -> None:
    case = load_case(RURAL)
    case = case.model_copy(update={"scene": case.scene.model_copy(update={"kind": kind})})
    network = build_network(case.road, kind)
    table = ground_table(network.pieces)
    assert table[0, LAND] == land
    main = network.main
    assert table[0, INNER_M] == pytest.approx(main.half_width + sum(strip.width for strip in main.strips[:-1]))


def test_fields_are_a_patchwork_with_a_verge_and_fade_with_distance() -> None:
    table = np.array([[5.0, FIELDS]])
    s = np.linspace(0.0, 1500.0, 3001)
    near = albedo_over(table, s, np.full(s.shape, 5.0 + 60.0), 0.01)
    # fields of several colours along the road: the green channel's share and the brightness both spread
    green_share = near[:, 1] / near.sum(axis=1)
    assert np.ptp(green_share) > 0.12 and np.ptp(near.sum(axis=1)) > 0.15
    verge = albedo_over(table, s[:50], np.full(50, -(5.0 + 1.5)), 0.01)
    assert np.ptp(verge, axis=0).max() < 1e-9  # one band along the road
    assert not np.allclose(verge[0], near.mean(axis=0), atol=0.005)
    # the same point filtered over a wide footprint varies far less along a short stretch than point samples do
    fine_s = np.linspace(300.0, 302.0, 400)
    sharp = albedo_over(table, fine_s, np.full(400, 5.0 + 20.0), 0.002)
    wide = albedo_over(table, fine_s, np.full(400, 5.0 + 20.0), 3.0)
    assert wide.std(axis=0).max() < 0.25 * max(sharp.std(axis=0).max(), 1e-6)


def test_wet_ground_is_darker() -> None:
    table = np.array([[5.0, FIELDS]])
    s = np.linspace(0.0, 400.0, 200)
    t = np.full(s.shape, 40.0)
    dry, wet = albedo_over(table, s, t, 0.05), albedo_over(table, s, t, 0.05, wetness=1.0)
    assert np.all(wet < dry)


def test_lawns_are_mown_in_stripes() -> None:
    table = np.array([[5.0, LAWNS]])
    u = np.linspace(0.5, 10.0, 2000)
    s = np.linspace(0.0, 200.0, 2000)
    across = albedo_over(table, np.full(u.shape, 7.0), 5.0 + u, 0.005)
    along = albedo_over(table, s, np.full(s.shape, 8.0), 0.005)
    stripes = max(np.ptp(across[:, 1]), np.ptp(along[:, 1]))
    assert stripes > 0.01


@pytest.mark.slow
def test_the_carriageway_and_labels_are_unchanged_and_frames_deterministic() -> None:
    case = load_case(RURAL)
    case = case.model_copy(update={"camera": case.camera.model_copy(update={"width": 320, "height": 180})})
    scene = compile_scene(case)
    patchwork = render_frame(scene, 30)
    again = render_frame(compile_scene(case), 30)
    assert np.array_equal(patchwork.rgb, again.rgb)
    saved = renderer.ground_table

    def plain(pieces: list) -> np.ndarray:
        table = saved(pieces)
        table[:, LAND] = NO_LAND
        return table

    renderer.ground_table = plain
    try:
        before = render_frame(dataclasses.replace(scene, cache={}), 30)
    finally:
        renderer.ground_table = saved
    assert not np.array_equal(patchwork.rgb, before.rgb)
    assert np.array_equal(patchwork.object_id, before.object_id)
    assert np.array_equal(patchwork.depth, before.depth)
    road = patchwork.object_id == ID_ROAD  # the carriageway and its paint, away from its silhouette (antialiased)
    inner = road.copy()
    inner[1:-1, 1:-1] &= road[:-2, 1:-1] & road[2:, 1:-1] & road[1:-1, :-2] & road[1:-1, 2:]
    assert inner.sum() > 5000
    assert np.array_equal(patchwork.rgb[inner], before.rgb[inner])
    assert tusimple_record(scene, 30, patchwork, "f.jpg") == tusimple_record(scene, 30, before, "f.jpg")
