"""The backdrop beyond the roadside: seeded, clear of every road corridor, low distant hills, present where it
should be, dark at night."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.case import Case
from lanevil_core.pipeline.compile import compile_scene, roadside_inputs
from lanevil_core.render import render_frame
from lanevil_core.typed import SceneKind
from lanevil_core.world.backdrop import (
    CAMERA_HEIGHT_M,
    MAX_HILL_ELEVATION_DEG,
    SUBURB_BEHIND,
    backdrop_meshes,
    garden_tree,
)
from lanevil_core.world.road_layout import RoadNetwork, build_network
from lanevil_core.world.scene import FIRST_OBJECT_ID, Mesh
from lanevil_core.world.scenery import Clearance, corridor_half_width, roadside_meshes

HILLS = ("near hills", "far hills")


def backdrop(kind: SceneKind, road: str = "straight", density: float = 1.0,
             seed: int = 0) -> tuple[RoadNetwork, list[Mesh]]:
    spec = Case.model_validate({"scene": {"kind": kind, "density": density}, "road": {"type": road}})
    network = build_network(spec.road, kind)
    return network, backdrop_meshes(roadside_inputs(spec), network, Clearance(network), np.random.default_rng(seed))


def test_same_case_gives_the_same_backdrop_and_the_seed_changes_it() -> None:
    _, a = backdrop("rural", "bend", seed=3)
    _, b = backdrop("rural", "bend", seed=3)
    _, c = backdrop("rural", "bend", seed=4)
    assert [m.name for m in a] == [m.name for m in b]
    for field in ("vertices", "faces", "colors"):
        joined_a, joined_b = (np.concatenate([getattr(m, field) for m in x]) for x in (a, b))
        np.testing.assert_array_equal(joined_a, joined_b)
    hills_a = next(m for m in a if m.name == "near hills")
    hills_c = next(m for m in c if m.name == "near hills")
    assert not np.array_equal(hills_a.vertices, hills_c.vertices)


@pytest.mark.parametrize(("kind", "expected"), [
    ("urban", set()),
    ("suburban", {"near hills", "houses behind left", "houses behind right"}),
    ("highway", {"near hills", "far hills", "tree line left piece 0", "tree line right piece 0"}),
    ("rural", {"near hills", "far hills", "hedgerow left piece 0", "wood right piece 0", "field hedges"}),
    ("tunnel_approach", {"near hills", "far hills", "tree line left piece 0"}),
])
def test_each_scene_kind_gets_its_backdrop(kind: SceneKind, expected: set[str]) -> None:
    _, meshes = backdrop(kind)
    names = {mesh.name for mesh in meshes}
    assert expected <= names, (kind, sorted(names))
    if not expected:
        assert not meshes


def test_a_tunnel_runs_into_a_wooded_ridge_above_its_tube() -> None:
    case = Case.model_validate({"scene": {"kind": "tunnel_approach"}})
    network = build_network(case.road, "tunnel_approach")
    meshes = roadside_meshes(roadside_inputs(case), network, np.random.default_rng(0))
    ridge = next(mesh for mesh in meshes if mesh.name == "wooded ridge")
    s, t, h = network.main.line.road_coordinates(ridge.vertices)
    over_tube = (np.abs(t) < corridor_half_width(network.main) + 1.0) & (s < network.main.line.length)
    assert over_tube.any() and h[over_tube].min() > 8.0  # above the tube's roof, never inside it
    assert "ridge forest edge" in {mesh.name for mesh in meshes}


def test_no_backdrop_density_places_no_vegetation() -> None:
    _, meshes = backdrop("rural", density=0.0)
    assert {mesh.name for mesh in meshes} == set(HILLS)


@pytest.mark.parametrize("road", ["straight", "bend", "crossroad"])
@pytest.mark.parametrize("kind", ["suburban", "highway", "rural", "tunnel_approach"])
def test_vegetation_keeps_clear_of_every_corridor(kind: SceneKind, road: str) -> None:
    network, meshes = backdrop(kind, road, density=3.0)
    lines = [mesh for mesh in meshes if mesh.name not in HILLS]
    assert lines
    for piece in network.pieces:
        for mesh in lines:
            s, t, _ = piece.line.road_coordinates(mesh.vertices)
            inside = (s > piece.s_start + 0.5) & (s < piece.line.length - 0.5)
            assert np.all(np.abs(t[inside]) > corridor_half_width(piece) + 2.0), (mesh.name, road)


@pytest.mark.parametrize("road", ["straight", "bend", "s_curve", "crossroad", "uphill", "downhill"])
def test_distant_hills_stay_low_and_beyond_the_road(road: str) -> None:
    network, meshes = backdrop("highway", road)
    eyes = np.concatenate([piece.line.to_world(piece.line.s[::20], 0.0, CAMERA_HEIGHT_M) for piece in network.pieces])
    for mesh in (m for m in meshes if m.name in HILLS):
        offset = mesh.vertices[None, :, :] - eyes[:, None, :]
        distance = np.linalg.norm(offset[..., :2], axis=-1)
        assert distance.min() > 300.0, mesh.name  # far beyond every road point
        elevation = np.degrees(np.arctan2(offset[..., 2], distance))
        assert elevation.max() <= MAX_HILL_ELEVATION_DEG + 1e-6, (mesh.name, elevation.max())


def test_night_hills_are_dark_silhouettes() -> None:
    case = Case.model_validate({"scene": {"kind": "highway"}, "sun": {"altitude": -20.0},
                                "camera": {"width": 320, "height": 180}})
    scene = compile_scene(case)
    frame = render_frame(scene, 0, (320, 180))
    index = [i for i, mesh in enumerate(scene.meshes) if mesh.name in HILLS]
    hills = np.isin(frame.object_id, np.asarray(index) + FIRST_OBJECT_ID)
    assert hills.sum() > 50
    luminance = frame.rgb.astype(float).mean(-1)
    rows = np.flatnonzero(hills.any(1))
    sky_above = luminance[max(rows.min() - 6, 0):rows.min()][frame.object_id[max(rows.min() - 6, 0):rows.min()] == 0]
    assert luminance[hills].mean() < 40.0
    assert luminance[hills].mean() <= sky_above.mean() + 2.0


@pytest.mark.parametrize("seed", range(6))
def test_a_garden_tree_behind_the_houses_is_a_tree_on_its_own_foot(seed: int) -> None:
    width = 6.0
    mesh = garden_tree(np.random.default_rng(seed), width)
    low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    assert low[2] < 0.0 < 2.0 < high[2] <= SUBURB_BEHIND.height[1] * 1.35  # from the ground up, trunk and crown
    foot = mesh.vertices[mesh.vertices[:, 2] < 0.5]
    assert np.allclose(foot[:, :2].mean(axis=0), (width / 2, 0.0), atol=0.6)  # its trunk at the middle of its plot
    assert len(mesh.faces) > 100  # branches and leaf clusters, not a lump
