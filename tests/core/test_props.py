"""Props and vegetation: real dimensions, resting on the ground, faces wound outwards, deterministic, renderable."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.case import Road
from lanevil_core.world import buildings, facade, people, props, vegetation, vehicles
from lanevil_core.world.primitives import box, cylinder, loft, merge, pose_on_road, prism, transformed
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.scene import Mesh


def extents(mesh: Mesh) -> np.ndarray:
    return mesh.vertices.max(0) - mesh.vertices.min(0)


def signed_volume(mesh: Mesh) -> float:
    """Enclosed volume (m3) for closed meshes; measured about the vertex mean so one-sided panels (windows)
    add little and rigid motions change nothing."""
    p = mesh.vertices - mesh.vertices.mean(0)
    a, b, c = (p[mesh.faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def outward_share(mesh: Mesh) -> float:
    """Share of the face area whose normal points away from the bounding-box centre."""
    tri = mesh.vertices[mesh.faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    centre = 0.5 * (mesh.vertices.min(0) + mesh.vertices.max(0))
    away = np.einsum("ij,ij->i", normal, tri.mean(1) - centre) > 0
    area = np.linalg.norm(normal, axis=1)
    return float(area[away].sum() / area.sum())


def assert_renderable(mesh: Mesh) -> None:
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape[1] == 3
    assert mesh.faces.dtype == np.int32 and mesh.faces.max() < len(mesh.vertices)
    assert mesh.colors.shape == (len(mesh.faces), 3) and mesh.colors.dtype == np.float32
    assert np.all(mesh.colors >= 0) and np.all(mesh.colors <= 1)
    assert np.isfinite(mesh.vertices).all()


RNG = np.random.default_rng


# (builder, expected length x width x height in m, tolerance)
SIZED = {
    "car": (lambda: vehicles.car(), (4.5, 1.8, 1.45), 0.12),
    "van": (lambda: vehicles.van(), (5.2, 2.0, 2.3), 0.12),
    "truck": (lambda: vehicles.truck(), (8.0, 2.5, 3.4), 0.15),
    "bicycle": (lambda: people.bicycle_with_rider(RNG(0)), (1.8, 0.55, 1.75), 0.12),
}


@pytest.mark.parametrize("name", SIZED)
def test_vehicle_sized_props_have_real_dimensions(name: str) -> None:
    build, size, tol = SIZED[name]
    mesh = build()
    assert_renderable(mesh)
    np.testing.assert_allclose(extents(mesh), size, atol=tol)
    assert abs(mesh.vertices[:, 2].min()) < 0.01  # wheels touch the ground
    centre = 0.5 * (mesh.vertices.min(0) + mesh.vertices.max(0))
    assert abs(centre[0]) < 0.15 and abs(centre[1]) < 0.05  # origin at the footprint centre


@pytest.mark.parametrize("name", ["car", "van", "truck"])
def test_vehicles_wind_faces_outwards(name: str) -> None:
    mesh = SIZED[name][0]()
    length, width, height = SIZED[name][1]
    assert signed_volume(mesh) > 0.4 * length * width * height
    assert outward_share(mesh) > 0.75  # wheels' inner caps rightly face the body


def test_vehicle_lights_glow_only_when_on() -> None:
    dark, lit = vehicles.car(), vehicles.car(lights_on=True)
    assert dark.emission is None
    assert lit.emission is not None and lit.emission.shape == (len(lit.faces), 3)
    glowing = lit.emission.max(1) > 0
    front = lit.vertices[lit.faces[glowing]].mean(1)[:, 0]
    assert (front > 1.8).any() and (front < -1.8).any()  # headlights at the front, tail lights at the back
    red = lit.emission[glowing & (lit.vertices[lit.faces].mean(1)[:, 0] < 0)]
    assert np.all(red[:, 0] > 5 * red[:, 2])


def test_vehicle_body_colour_and_dark_glass() -> None:
    car = vehicles.car((0.5, 0.0, 0.0))
    share_body = np.mean(np.all(np.isclose(car.colors, (0.5, 0.0, 0.0)), axis=1))
    assert share_body > 0.05
    tri = car.vertices[car.faces]
    high = tri.mean(1)[:, 2] > 1.0  # glasshouse
    assert np.any(car.colors[high].max(1) < 0.05)


def test_pedestrian_is_a_person_sized_standing_figure() -> None:
    for walking in (False, True):
        person = people.pedestrian(RNG(3), walking=walking)
        assert_renderable(person)
        size = extents(person)
        assert abs(size[2] - 1.75) < 0.03
        assert 0.4 < size[1] < 0.8 and size[0] < (1.0 if walking else 0.45)
        assert abs(person.vertices[:, 2].min()) < 0.01
    tall = people.pedestrian(RNG(3), height=1.9)
    assert abs(extents(tall)[2] - 1.9) < 0.03


def test_pedestrian_colours_come_from_rng_or_arguments() -> None:
    a, b = people.pedestrian(RNG(1)), people.pedestrian(RNG(1))
    np.testing.assert_array_equal(a.colors, b.colors)
    shirts = {tuple(people.pedestrian(RNG(seed)).colors.max(0).round(3)) for seed in range(8)}
    assert len(shirts) > 2
    red = people.pedestrian(RNG(1), shirt=(0.9, 0.0, 0.0))
    assert np.any(np.all(np.isclose(red.colors, (0.9, 0.0, 0.0)), axis=1))


def test_trees_and_bushes_stand_on_the_ground() -> None:
    for seed in range(6):
        for conifer in (True, False):
            tree = vegetation.tree(RNG(seed), conifer=conifer)
            assert_renderable(tree)
            assert 4.0 < extents(tree)[2] < 15.0  # a poplar grows taller than the drawn height
            assert -0.4 < tree.vertices[:, 2].min() <= 0.0
        shrub = vegetation.bush(RNG(seed))
        assert extents(shrub)[2] < 2.0 and shrub.vertices[:, 2].min() < 0.05
    tree = vegetation.tree(RNG(0), height=8.0, conifer=False)
    assert abs(tree.vertices[:, 2].max() - 8.0) < 1.5


def test_leaves_are_marked_for_the_renderer_and_bark_is_not() -> None:
    for seed in range(4):
        for conifer in (True, False):
            tree = vegetation.tree(RNG(seed), conifer=conifer)
            assert tree.finish is not None and tree.finish.shape == (len(tree.faces),)
            leaves = tree.finish == facade.LEAVES
            assert (tree.finish[~leaves] == facade.PLAIN).all()
            # the crown is leaves (greener than red), the trunk and branches bark (browner)
            assert (tree.colors[leaves, 1] > tree.colors[leaves, 0]).all()
            assert (tree.colors[~leaves, 0] > tree.colors[~leaves, 1]).all() and (~leaves).sum() >= 16
        shrub = vegetation.bush(RNG(seed))
        assert shrub.finish is not None and (shrub.finish == facade.LEAVES).all()


def test_a_house_roof_is_tiled_up_its_slopes() -> None:
    roof = buildings.gable_roof(5.3, 4.4, 5.75, 3.0, buildings.ROOFS[0])
    assert roof.finish is not None and roof.uv is not None
    tiled = roof.finish == facade.TILES
    assert tiled.sum() == 4  # two slopes, two triangles each; the soffit and gable ends stay plain
    slope = float(np.hypot(4.4, 3.0))
    for face in roof.faces[tiled]:
        z, v = roof.vertices[face, 2], roof.uv[face, 1]
        np.testing.assert_allclose(v, np.where(z > 5.75 + 1e-6, slope, 0.0), atol=1e-5)  # up from the eaves
        np.testing.assert_allclose(roof.uv[face, 0], roof.vertices[face, 0], atol=1e-5)  # along them
    home = buildings.house(RNG(2), 10.0, 8.0)
    assert home.finish is not None and (home.finish == facade.TILES).sum() == 4


def test_building_and_house_fill_their_footprint() -> None:
    block = buildings.building(RNG(0), 20.0, 12.0, 16.0, shopfront=True)
    assert_renderable(block)
    np.testing.assert_allclose(extents(block), (20.5, 12.5, 16.9), atol=0.1)  # cornice, footing
    assert outward_share(block) > 0.85  # all but the parapet's underside
    tri = block.vertices[block.faces]
    on_pane = (np.abs(np.abs(tri[..., 1]) - 6.02) < 1e-6).all(1) | (np.abs(np.abs(tri[..., 0]) - 10.02) < 1e-6).all(1)
    assert on_pane.sum() >= 2 * 2 * 4 * 5  # a grid of window panes (two triangles each) on the facades
    sills = (np.abs(np.abs(tri[..., 1]) - 6.0 - buildings.SILL_DEPTH_M) < 1e-6).any(1) \
        | (np.abs(np.abs(tri[..., 0]) - 10.0 - buildings.SILL_DEPTH_M) < 1e-6).any(1)
    assert sills.sum() == on_pane.sum()  # each with a sill jutting out under it
    assert len(np.unique(block.colors[on_pane].round(4), axis=0)) > 10  # panes show the sky, rooms, curtains
    home = buildings.house(RNG(1), 10.0, 8.0, storeys=2)
    size = extents(home)
    assert 10.0 <= size[0] < 11.0 and 8.0 <= size[1] < 9.0 and 7.0 < size[2] < 10.0


def test_building_faces_carry_their_finish_and_facade_coordinates() -> None:
    walls, shops, doors = set(), 0, 0
    for seed in range(12):
        shop = seed % 2 == 0
        block = buildings.building(RNG(seed), 20.0, 12.0, 16.0, shopfront=shop)
        assert block.finish is not None and block.uv is not None
        assert block.finish.shape == (len(block.faces),) and block.uv.shape == (len(block.vertices), 2)
        tri = block.vertices[block.faces]
        on_pane = ((np.abs(np.abs(tri[..., 1]) - 6.02) < 1e-6).all(1)
                   | (np.abs(np.abs(tri[..., 0]) - 10.02) < 1e-6).all(1)) & (tri[..., 2].min(1) > 0.9)  # not the door
        assert (block.finish[on_pane] == facade.GLASS).all()  # every window pane is glass
        pane_uv = block.uv[block.faces[block.finish == facade.GLASS]].reshape(-1, 2)
        assert np.abs(pane_uv[:, 0]).max() <= 0.7 + 1e-6  # across the pane from its centre ...
        assert pane_uv[:, 1].min() > -1e-6 and pane_uv[:, 1].max() < facade.PANE_HEIGHT_M + 1e-5  # ... up from its foot
        wall_faces = np.isin(block.finish, facade.WALL_FINISHES)
        assert wall_faces.sum() == 8  # four walls, two triangles each
        walls.add(int(block.finish[wall_faces][0]))
        # along a wall, u grows by the wall's length and v is the height above the ground
        wall_uv = block.uv[block.faces[wall_faces]]
        np.testing.assert_allclose(wall_uv[..., 1], tri[wall_faces][..., 2], atol=1e-5)
        if shop:
            shops += int((block.finish == facade.SHOP_GLASS).sum() == 2)
        else:
            front = (np.abs(tri[..., 1] - 6.02) < 1e-6).all(1) & (tri[..., 2].max(1) < 2.5) & (tri[..., 2].min(1) >= 0)
            doors += int(front.sum() >= 2)
    assert walls == set(facade.WALL_FINISHES)  # brick, render and panels all occur
    assert shops == 6 and doors == 6  # every shop has its window, every other block its door
    np.testing.assert_array_equal(buildings.building(RNG(5), 20.0, 12.0, 16.0).uv,
                                  buildings.building(RNG(5), 20.0, 12.0, 16.0).uv)  # deterministic


def test_merge_and_transform_keep_the_finish() -> None:
    block = buildings.building(RNG(2), 14.0, 10.0, 9.6)
    plain = box((1.0, 1.0, 1.0))
    both = merge([plain, block])
    assert both.finish is not None and both.uv is not None
    assert (both.finish[:12] == facade.PLAIN).all() and (both.uv[:len(plain.vertices)] == 0).all()
    np.testing.assert_array_equal(both.finish[12:], block.finish)
    moved = transformed(block, pose_on_road(build_network(Road(), "urban").main.line, 30.0, 12.0, 0.5))
    np.testing.assert_array_equal(moved.finish, block.finish)
    np.testing.assert_array_equal(moved.uv, block.uv)
    assert merge([plain, plain]).finish is None


def test_jersey_barrier_profile() -> None:
    barrier = props.jersey_barrier(4.0)
    np.testing.assert_allclose(extents(barrier), (4.0, 0.61, 0.81), atol=1e-6)
    assert signed_volume(barrier) == pytest.approx(4.0 * 0.3, rel=0.15)  # ~0.3 m2 cross-section


def test_tunnel_portal_keeps_its_opening_clear() -> None:
    width, height = 16.0, 6.0
    portal = props.tunnel_portal(width, height, lining=8.0)
    assert_renderable(portal)
    tri = portal.vertices[portal.faces]
    probes = np.concatenate([tri.mean(1), portal.vertices[portal.faces].reshape(-1, 3)])
    inside = ((np.abs(probes[:, 1]) < width / 2 - 0.01) & (probes[:, 2] > 0.01) & (probes[:, 2] < height - 0.01)
              & (probes[:, 0] > -30.0) & (probes[:, 0] < 8.0))
    assert not inside.any()
    assert portal.vertices[:, 2].max() > height + 5.0  # a hill rises over it
    assert portal.vertices[:, 0].min() < -5.0  # and its foot reaches out in front


def test_props_are_deterministic() -> None:
    for build in (vegetation.tree, vegetation.bush, people.pedestrian, people.bicycle_with_rider, buildings.house):
        a, b = build(RNG(7)), build(RNG(7))
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.colors, b.colors)


def test_primitives_are_closed_and_outward() -> None:
    solids = [box((2.0, 1.0, 0.5), (1.0, 2.0, 3.0)), cylinder(0.3, 1.0, sections=8),
              cylinder(0.2, segment=[(0, 0, 0), (1, 1, 1)]), prism([(0, 0), (2, 0), (1, 1)], -1, 1),
              prism([(0, 1), (1, 0), (0, 0)], 0, 2, axis="x"),
              loft([[(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 0, 2), (1, 0, 2), (1, 1, 2)]])]
    for solid in solids:
        assert signed_volume(solid) > 0
    np.testing.assert_allclose(signed_volume(solids[0]), 1.0)
    merged = merge(solids[:2], name="both", kind="test")
    assert len(merged.faces) == len(solids[0].faces) + len(solids[1].faces)
    assert merged.name == "both" and signed_volume(merged) > 1.0


def test_pose_on_road_stands_upright_along_the_heading() -> None:
    line = build_network(Road(type="bend", radius=80.0), "suburban").main.line
    for s in (10.0, 90.0, 150.0):
        T = pose_on_road(line, s, -3.0, yaw=0.3, h=0.1)
        np.testing.assert_allclose(T[:3, 2], (0.0, 0.0, 1.0))  # +Z straight up
        heading = float(line.heading_at(s)) + 0.3
        np.testing.assert_allclose(T[:3, 0], (np.cos(heading), np.sin(heading), 0.0), atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], line.to_world(s, -3.0, 0.1))
    car = transformed(vehicles.car(), pose_on_road(line, 100.0, -1.75))
    assert signed_volume(car) == pytest.approx(signed_volume(vehicles.car()))


def test_primitives_reuse_their_geometry_and_hand_out_meshes_of_their_own() -> None:
    """Boxes and cylinders are built once per shape (traffic builds the same wheels for every vehicle) and equal
    trimesh's own; a mesh handed out can be moved in place without changing the next one."""
    import trimesh

    segment = [(1.2, 0.6, 0.33), (1.2, 0.85, 0.33)]
    wheel = cylinder(0.33, segment=segment, sections=12, color=(0.1, 0.1, 0.1), name="tyre")
    direct = trimesh.creation.cylinder(radius=0.33, segment=np.array(segment), sections=12)
    assert np.array_equal(wheel.vertices, direct.vertices) and np.array_equal(wheel.faces, direct.faces)
    assert wheel.name == "tyre" and wheel.colors.shape == (len(wheel.faces), 3)
    crate = box((1.0, 2.0, 0.5), center=(0.0, 1.0, 0.25))
    assert np.array_equal(crate.vertices, trimesh.creation.box(extents=(1.0, 2.0, 0.5)).vertices + (0.0, 1.0, 0.25))
    wheel.vertices += 10.0  # posing a mesh moves its own arrays
    crate.vertices[:] = 0.0
    again = cylinder(0.33, segment=np.array(segment), sections=12)
    assert np.array_equal(again.vertices, direct.vertices) and again.vertices.flags.writeable
    assert np.array_equal(box([1.0, 2.0, 0.5], center=np.array([0.0, 1.0, 0.25])).vertices.max(0), (0.5, 2.0, 0.5))
    with pytest.raises(ValueError, match="height or a segment"):
        cylinder(0.3)


@pytest.mark.parametrize(("build", "half"), [
    (lambda rng, lit: buildings.building(rng, 22.0, 12.0, 19.2, shopfront=True, lit=lit), (11.0, 6.0)),
    (lambda rng, lit: buildings.house(rng, 11.0, 8.0, storeys=2, lit=lit), (5.5, 4.0))])
def test_lit_windows_glow_at_night_only(build, half) -> None:
    day, night = build(RNG(3), False), build(RNG(3), True)
    assert day.emission is None
    # the night's building is the day's, face for face, but for its light
    np.testing.assert_array_equal(day.vertices, night.vertices)
    np.testing.assert_array_equal(day.colors, night.colors)
    glowing = night.emission.max(1) > 0
    centre = night.vertices[night.faces].mean(1)
    on_facade = (np.abs(np.abs(centre[:, 0]) - half[0]) < 0.1) | (np.abs(np.abs(centre[:, 1]) - half[1]) < 0.1)
    assert glowing.any() and on_facade[glowing].all()  # panes (and a shop window) glow, not walls or roof
    lights = night.emission[glowing]
    assert (lights[:, 0] > lights[:, 2]).mean() > 0.5  # mostly warm lamps, some cold screens
    np.testing.assert_array_equal(build(RNG(3), True).emission, night.emission)  # deterministic


def test_lit_share_varies_from_building_to_building() -> None:
    shares = []
    for seed in range(6):
        night = buildings.house(RNG(seed), 12.0, 8.0, storeys=2, lit=True)
        assert night.emission is not None
        shares.append(int((night.emission.max(1) > 0).sum()))  # same house, same windows: a drawn share lit
    assert max(shares) > 2 * min(shares)


def test_parked_vehicles_are_cheap_and_painted_from_the_palette() -> None:
    paints = set()
    for seed in range(40):
        length, width, build = vehicles.parked_vehicle(RNG(seed))
        vehicle = build()
        assert_renderable(vehicle)
        assert len(vehicle.faces) <= 330 and vehicle.emission is None  # lights off; octagonal wheels with hubs
        size = extents(vehicle)
        assert abs(size[0] - length) < 0.1 and abs(size[1] - width) < 0.1 and vehicle.vertices[:, 2].min() > -1e-6
        body = vehicle.colors[0]
        paints.add(int(np.argmin([np.abs(body / np.asarray(p) - 1.0).max() for p in vehicles.CAR_PAINTS])))
    assert len(paints) >= 4  # white, black, grey, silver and more


@pytest.mark.parametrize("aspect", props.SIGNAL_ASPECTS)
def test_traffic_signal_lights_one_lamp_towards_the_driver(aspect: str) -> None:
    signal = props.traffic_signal(aspect)
    assert_renderable(signal)
    assert signal.emission is not None
    lit = signal.emission.max(1) > 0
    centre = signal.vertices[signal.faces[lit]].mean((0, 1))
    assert centre[0] < -0.15 and 2.8 < centre[2] < 3.6  # on the head's face towards -X
    order = props.SIGNAL_HEAD_Z_M + 0.3 * (2 - props.SIGNAL_ASPECTS.index(aspect))
    assert abs(centre[2] - order) < 1e-6  # red on top, green at the bottom
    expected = np.asarray(props.SIGNAL_LAMPS[props.SIGNAL_ASPECTS.index(aspect)], np.float64) * props.SIGNAL_GLOW
    np.testing.assert_allclose(np.asarray(signal.emission[lit][0], np.float64), expected, rtol=1e-6)
