"""Structures: sane bounds, closed meshes, and geometry that follows the road through bends and slopes."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
import trimesh

from lanevil_core.case import Road
from lanevil_core.world.road_geometry import ReferenceLine
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.scene import Mesh
from lanevil_core.world.structures import (
    FOOTING_M,
    clear_runs,
    fence,
    ground_height,
    guard_rail,
    outside_gaps,
    overhead_rail,
    power_lines,
    streetlight,
    streetlight_lamp_offset,
    wire,
)


@pytest.fixture(scope="module")
def bend() -> ReferenceLine:
    return build_network(Road(type="bend", radius=60.0), "suburban").main.line


@pytest.fixture(scope="module")
def hill() -> ReferenceLine:
    return build_network(Road(type="uphill", grade=0.1), "suburban").main.line


def road_coords(line: ReferenceLine, p_world: np.ndarray) -> np.ndarray:
    """(n, 3) s, t, h of world points (nearest sample of the dense reference line, then exact projection)."""
    d2 = ((p_world[:, None, :2] - line.xy[None, :, :2]) ** 2).sum(-1)
    s_near = line.s[np.argmin(d2, axis=1)]
    origin, tangent, left = line.frame(s_near)
    flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
    delta = p_world - origin
    s = s_near + (delta[:, :2] * flat).sum(1)
    t = (delta * left).sum(1)
    origin_exact = line.frame(s)[0]
    return np.stack([s, t, p_world[:, 2] - origin_exact[:, 2]], axis=1)


def assert_well_formed(mesh: Mesh) -> None:
    assert mesh.vertices.dtype == np.float64 and mesh.faces.dtype == np.int32
    assert mesh.colors.shape == (len(mesh.faces), 3) and mesh.colors.dtype == np.float32
    assert np.isfinite(mesh.vertices).all()
    assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
    assert (mesh.colors >= 0).all() and (mesh.colors <= 1).all()
    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    solid.merge_vertices()
    assert solid.is_watertight and solid.is_winding_consistent and solid.volume > 0


def test_streetlight_local_frame() -> None:
    mesh = streetlight(height=9.0, arm=2.0)
    assert_well_formed(mesh)
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    assert lo[2] == pytest.approx(-FOOTING_M) and 8.9 < hi[2] < 9.2
    assert hi[1] == pytest.approx(2.0 + 0.375, abs=0.01)  # lamp head reaches over +Y
    assert lo[1] > -0.3 and abs(lo[0]) < 0.3 and abs(hi[0]) < 0.3
    assert mesh.emission is None


def test_streetlight_lamp_offset_sits_under_the_glowing_glass() -> None:
    mesh = streetlight(height=8.0, arm=1.5, emissive=True)
    assert mesh.emission is not None
    glowing = mesh.emission.sum(1) > 0
    assert 0 < glowing.sum() < len(mesh.faces)
    glass = mesh.vertices[np.unique(mesh.faces[glowing])]
    lamp = streetlight_lamp_offset(8.0, 1.5)
    assert glass[:, 1].min() < lamp[1] < glass[:, 1].max()
    assert glass[:, 0].min() < lamp[0] < glass[:, 0].max()
    assert 0.0 < glass[:, 2].min() - lamp[2] < 0.05


def test_guard_rail_follows_the_bend(bend: ReferenceLine) -> None:
    mesh = guard_rail(bend, 40.0, 120.0, t=-8.0)
    assert_well_formed(mesh)
    assert mesh.gloss == pytest.approx(0.4)
    s, t, h = road_coords(bend, mesh.vertices).T
    assert s.min() > 39.8 and s.max() < 120.2
    assert t.min() > -8.4 and t.max() < -7.9  # beam faces the road, posts behind it
    assert h.min() == pytest.approx(-FOOTING_M, abs=1e-6) and h.max() == pytest.approx(0.75, abs=1e-6)
    beam = h > 0.43
    assert h[beam].min() == pytest.approx(0.44, abs=1e-6)


def test_guard_rail_on_the_left_faces_the_road(bend: ReferenceLine) -> None:
    s, t, h = road_coords(bend, guard_rail(bend, 40.0, 80.0, t=8.0).vertices).T
    assert t.min() > 7.9 and t.max() < 8.4


def test_fence_slats_and_slope(hill: ReferenceLine) -> None:
    mesh = fence(hill, 30.0, 90.0, t=-9.0, height=2.0, slat_width=0.1, slat_gap=0.2)
    assert_well_formed(mesh)
    s, t, h = road_coords(hill, mesh.vertices).T
    assert h.min() == pytest.approx(-FOOTING_M, abs=0.01) and h.max() == pytest.approx(2.1, abs=0.01)
    assert -9.2 < t.min() and t.max() < -8.8
    slat_fronts = np.abs(t + 9.0 - 0.125) < 0.005  # the road-side face of each slat, nothing else out there
    assert slat_fronts.sum() == 4 * 200  # 60 m / 0.3 m pitch, 4 front corners per slat


def test_overhead_rail_keeps_the_span_clear(bend: ReferenceLine) -> None:
    mesh = overhead_rail(bend, 80.0, span=20.0, deck_width_along_s=16.0, clearance_height=5.5)
    assert_well_formed(mesh)
    s, t, h = road_coords(bend, mesh.vertices).T
    over_road = np.abs(t) < 10.0 - 1e-3
    assert h[over_road].min() >= 5.5 - 1e-6
    assert s.min() > 71.9 and s.max() < 88.1


@pytest.mark.parametrize("slots_along", ["s", "t"])
def test_overhead_rail_lets_light_through_its_slots(slots_along: Literal["s", "t"]) -> None:
    line = build_network(Road(), "suburban").main.line  # straight along +X: road frame = world frame
    mesh = overhead_rail(line, 80.0, span=20.0, deck_width_along_s=16.0, slot_width=0.3, slot_pitch=1.0,
                         slots_along=slots_along)
    grid = np.stack(np.meshgrid(np.linspace(74, 86, 167), np.linspace(-8, 8, 131)), -1).reshape(-1, 2)
    open_share = 1.0 - covered_from_above(mesh, grid).mean()
    assert open_share == pytest.approx(0.3, abs=0.04)


def covered_from_above(mesh: Mesh, p_xy: np.ndarray) -> np.ndarray:
    """(n,) bool: a vertical ray at p_xy (n, 2) meets some face of the mesh."""
    tri = mesh.vertices[mesh.faces][:, :, :2]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    keep = np.abs(area) > 1e-9
    a, b, c, area = a[keep], b[keep], c[keep], area[keep]
    hit = np.zeros(len(p_xy), bool)
    for chunk in np.array_split(np.arange(len(p_xy)), 16):
        p = p_xy[chunk, None, :]
        w0 = ((b[:, 0] - p[..., 0]) * (c[:, 1] - p[..., 1]) - (b[:, 1] - p[..., 1]) * (c[:, 0] - p[..., 0])) / area
        w1 = ((c[:, 0] - p[..., 0]) * (a[:, 1] - p[..., 1]) - (c[:, 1] - p[..., 1]) * (a[:, 0] - p[..., 0])) / area
        hit[chunk] = ((w0 >= 0) & (w1 >= 0) & (1 - w0 - w1 >= 0)).any(axis=1)
    return hit


def test_power_lines_cross_high_above_the_road(bend: ReferenceLine) -> None:
    mesh = power_lines(bend, 40.0, 150.0, t_poles=(-10.0, 10.0), n_wires=2, wire_radius=0.03, heights=8.0,
                       sag=0.5, cross_every=1, cross_skew=8.0)
    assert_well_formed(mesh)
    s, t, h = road_coords(bend, mesh.vertices).T
    over_road = np.abs(t) < 9.0
    assert over_road.sum() > 100  # wires span the road
    assert h[over_road].min() > 8.0 - 0.5 - 0.1
    assert h.max() == pytest.approx(8.6, abs=0.01)


def test_power_line_wires_have_the_requested_thickness() -> None:
    line = build_network(Road(), "suburban").main.line
    mesh = power_lines(line, 40.0, 75.0, t_poles=(-10.0,), n_wires=1, wire_radius=0.05, heights=9.0, sag=0.0)
    wire = mesh.vertices[(mesh.vertices[:, 0] > 50) & (mesh.vertices[:, 0] < 65)]
    assert wire[:, 2].max() - wire[:, 2].min() == pytest.approx(0.1, abs=1e-6)
    assert wire[:, 1].max() - wire[:, 1].min() == pytest.approx(0.1, abs=1e-6)
    with pytest.raises(ValueError, match="wire_radius"):
        power_lines(line, 40.0, 75.0, t_poles=(-10.0,), wire_radius=0.01)


def test_a_wire_that_does_not_move_is_finite() -> None:
    # a zero span (both ends at one point) has no direction; its prism must still be finite, not NaN
    vertices, _ = wire(np.array([[5.0, 2.0, 9.0], [5.0, 2.0, 9.0], [6.0, 2.0, 9.0]]), 0.05)
    assert np.isfinite(vertices).all()


def test_builders_are_deterministic(bend: ReferenceLine) -> None:
    a = power_lines(bend, 40.0, 150.0, (-10.0, 10.0), cross_every=2)
    b = power_lines(bend, 40.0, 150.0, (-10.0, 10.0), cross_every=2)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def test_ground_height_walks_the_cross_section() -> None:
    piece = build_network(Road(lanes_per_direction=2, lane_width=3.5), "suburban").main
    assert ground_height(piece, -3.0) == 0.0
    assert ground_height(piece, -7.3) == 0.0  # asphalt shoulder
    assert ground_height(piece, 7.6) == pytest.approx(0.12)  # kerb
    assert ground_height(piece, -9.0) == pytest.approx(0.12)  # sidewalk
    assert ground_height(piece, -30.0) == pytest.approx(0.12)  # grass beyond


def test_bad_spans_are_refused(bend: ReferenceLine) -> None:
    with pytest.raises(ValueError):
        guard_rail(bend, 50.0, 40.0, -8.0)
    with pytest.raises(ValueError):
        overhead_rail(bend, 80.0, 20.0, slot_width=1.2, slot_pitch=1.0)


def test_diagonal_crossings_end_on_a_pole() -> None:
    line = build_network(Road(), "suburban").main.line
    mesh = power_lines(line, 40.0, 110.0, t_poles=(-10.0, 10.0), n_wires=2, wire_radius=0.03, heights=8.0,
                       pole_spacing=35.0, cross_every=1, cross_skew=12.0)
    p_world = mesh.vertices
    poles_left = p_world[(p_world[:, 2] < 0.0) & (p_world[:, 1] > 9.0)]  # pole feet below the ground, left row
    feet_s = np.unique(np.round(poles_left[:, 0]))
    for s_far in (52.0, 87.0, 122.0):  # 40, 75, 110 + 12 m; the last one lies beyond s1 but still on the road
        assert np.any(np.abs(feet_s - s_far) < 0.5)


def test_gaps_keep_poles_and_piers_out() -> None:
    line = build_network(Road(), "suburban").main.line
    gaps = [(60.0, 80.0, -1)]
    mesh = power_lines(line, 40.0, 110.0, t_poles=(-10.0,), pole_spacing=10.0, gaps=gaps)
    feet = mesh.vertices[mesh.vertices[:, 2] < 0.0]
    assert not np.any((feet[:, 0] > 59.0) & (feet[:, 0] < 81.0))
    assert np.any(np.abs(mesh.vertices[:, 0] - 70.0) < 2.0)  # wires still span the gap
    deck = overhead_rail(line, 70.0, span=20.0, deck_width_along_s=30.0, gaps=gaps)
    low = deck.vertices[deck.vertices[:, 2] < 4.0]
    assert not np.any((low[:, 0] > 59.0) & (low[:, 0] < 81.0) & (low[:, 1] < 0.0))
    assert np.any((low[:, 0] > 59.0) & (low[:, 0] < 81.0) & (low[:, 1] > 0.0))  # the other side keeps its piers


def test_clear_runs_and_outside_gaps() -> None:
    gaps = [(50.0, 60.0, -1), (70.0, 75.0, 1)]
    assert clear_runs(40.0, 100.0, -8.0, gaps) == [(40.0, 50.0), (60.0, 100.0)]
    assert clear_runs(40.0, 100.0, 8.0, gaps) == [(40.0, 70.0), (75.0, 100.0)]
    assert outside_gaps(np.array([45.0, 55.0, 72.0]), -8.0, gaps).tolist() == [True, False, True]
