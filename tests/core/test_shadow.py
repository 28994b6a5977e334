"""Shadow illusions: severity tables, determinism, JSON round trip, sun placement and where the shadows fall."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError

from lanevil_core.case import Case, case_json, parse_case
from lanevil_core.illusions import REGISTRY
from lanevil_core.illusions.shadow import MIN_FENCE_SUN_DEG, FenceShadow
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.world.road_geometry import ReferenceLine
from lanevil_core.world.scene import CompiledScene

SHADOW_TYPES = ("streetlight_shadow", "fence_shadow", "rail_shadow", "wire_shadow")
LEVELS = (1, 2, 3, 4, 5)


def compiled(illusion: dict, **case_fields) -> CompiledScene:
    """The compiled scene of a case holding one illusion (no roadside props unless asked: faster)."""
    case_fields.setdefault("scene", {"density": 0.0})
    return compile_scene(Case(illusions=[illusion], **case_fields))


def own_vertices(scene: CompiledScene) -> np.ndarray:
    """(n, 3) world vertices of every mesh the illusion (index 0) added."""
    meshes = [mesh.vertices for mesh in scene.meshes if mesh.source == 0]
    assert meshes, "the illusion added no mesh"
    return np.concatenate(meshes)


def road_coords(line: ReferenceLine, p_world: np.ndarray) -> np.ndarray:
    """(n, 3) s, t, h of world points: nearest 1 m sample of the reference line, then projection."""
    s_out = np.empty(len(p_world))
    xy, s_samples = line.xy[::10], line.s[::10]
    for chunk in np.array_split(np.arange(len(p_world)), max(1, len(p_world) // 2000)):
        d2 = ((p_world[chunk, None, :2] - xy[None, :, :2]) ** 2).sum(-1)
        s_out[chunk] = s_samples[np.argmin(d2, axis=1)]
    origin, tangent, left = line.frame(s_out)
    flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
    delta = p_world - origin
    s = s_out + (delta[:, :2] * flat).sum(1)
    origin = line.frame(s)[0]
    return np.stack([s, ((p_world - origin) * left).sum(1), p_world[:, 2] - origin[:, 2]], axis=1)


def shadow_points(scene: CompiledScene, upright: bool = False) -> np.ndarray:
    """(n, 2) x, y where the sun ray through each raised vertex of the illusion meets the flat road z = 0.
    ``upright``: the structure is solid below its vertices (poles), so the shadow of the whole upright under each
    vertex counts, sampled every tenth of its length."""
    p_world = own_vertices(scene)
    p_world = p_world[p_world[:, 2] > 0.3]
    if upright:
        p_world = np.concatenate([p_world * [1.0, 1.0, k] for k in np.linspace(0.1, 1.0, 10)])
    sun = scene.env.sun_dir_world
    return (p_world - sun * (p_world[:, 2:3] / sun[2]))[:, :2]


@pytest.mark.parametrize("name", SHADOW_TYPES)
def test_severity_tables_are_monotone(name: str) -> None:
    table: Sequence[Any] = REGISTRY[name].SEVERITY  # each family its own row type
    assert REGISTRY[name].CATEGORY == "shadow"
    assert all(type(row) is type(table[0]) for row in table)
    altitude = [row.sun_altitude for row in table]
    intensity = [row.sun_intensity for row in table]
    penumbra = [row.penumbra for row in table]
    assert all(a >= b for a, b in zip(altitude, altitude[1:]))
    assert all(a <= b for a, b in zip(intensity, intensity[1:]))
    assert all(a >= b for a, b in zip(penumbra, penumbra[1:]))
    # Either one sun for every level (the level grows the structure), or a sun that gets lower or harder.
    constant_sun = len(set(altitude)) == len(set(intensity)) == len(set(penumbra)) == 1
    assert constant_sun or altitude[0] > altitude[-1] or intensity[0] < intensity[-1]


@pytest.mark.parametrize("severity", LEVELS)
@pytest.mark.parametrize("name", SHADOW_TYPES)
def test_every_level_compiles_deterministically(name: str, severity: int) -> None:
    first = compiled({"type": name, "severity": severity, "seed": 7})
    again = compiled({"type": name, "severity": severity, "seed": 7})
    mine = [mesh for mesh in first.meshes if mesh.source == 0]
    assert mine and len(mine) == sum(mesh.source == 0 for mesh in again.meshes)
    for a, b in zip(mine, [mesh for mesh in again.meshes if mesh.source == 0]):
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
        assert np.array_equal(a.colors, b.colors) and a.name == b.name
    assert np.array_equal(first.env.sun_dir_world, again.env.sun_dir_world)
    level: Any = REGISTRY[name].SEVERITY[severity - 1]
    assert first.env.sun_intensity == level.sun_intensity
    assert first.env.penumbra == level.penumbra
    altitude = np.degrees(np.arcsin(first.env.sun_dir_world[2]))
    table_altitude = level.sun_altitude
    if name == "fence_shadow":  # solved from the road, no higher than the table's
        assert MIN_FENCE_SUN_DEG - 1e-9 <= altitude <= table_altitude + 1e-9
    else:
        assert altitude == pytest.approx(table_altitude)


@pytest.mark.parametrize("name", SHADOW_TYPES)
def test_json_round_trip(name: str) -> None:
    case = Case(illusions=[{"type": name, "severity": 4, "seed": 3, "s": 40.0, "side": "left",
                            "sun_altitude": 33.0, "sun_intensity": 1.2}])
    back = parse_case(case_json(case))
    assert back == case
    illusion: Any = back.illusions[0]
    assert illusion.type == name and illusion.sun_altitude == 33.0
    assert parse_case({"illusions": [{"type": name}]}).illusions[0].severity == 3


def test_sun_overrides_win_over_the_table() -> None:
    scene = compiled({"type": "fence_shadow", "severity": 5, "sun_altitude": 33.0, "sun_azimuth": 100.0,
                      "sun_intensity": 0.7})
    sun = scene.env.sun_dir_world
    assert np.degrees(np.arcsin(sun[2])) == pytest.approx(33.0)
    assert np.degrees(np.arctan2(sun[1], sun[0])) == pytest.approx(100.0)
    assert scene.env.sun_intensity == 0.7


def test_ambient_stays_from_the_case() -> None:
    plain = compile_scene(Case(weather={"cloudiness": 40.0}))
    shaded = compiled({"type": "streetlight_shadow", "severity": 5}, weather={"cloudiness": 40.0})
    assert shaded.env.ambient == plain.env.ambient


@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("name", SHADOW_TYPES)
def test_default_sun_stands_on_the_structure_side_and_ahead(name: str, side: str) -> None:
    scene = compiled({"type": name, "side": side, "s": 90.0}, road={"type": "bend", "radius": 80.0})
    _, tangent, left = scene.network.main.line.frame(90.0)
    sun = scene.env.sun_dir_world
    assert np.sign(sun @ left) == (1.0 if side == "left" else -1.0)
    assert sun @ tangent > 0.0


@pytest.mark.parametrize("name", ["streetlight_shadow", "fence_shadow", "wire_shadow"])
@pytest.mark.parametrize("severity", [3, 5])
def test_shadows_fall_on_the_ego_lane_in_view(name: str, severity: int) -> None:
    case = Case(illusions=[{"type": name, "severity": severity}])
    # straight road along +X: x = s, y = t
    x, y = shadow_points(compiled(case.illusions[0].model_dump()), upright=name == "streetlight_shadow").T
    ego_lane = (y > -case.road.lane_width) & (y < 0.0)
    in_view = (x > case.ego.start_s + 5.0) & (x < case.ego_s(case.ego.frames - 1) + 30.0)
    assert (ego_lane & in_view).sum() > 20


@pytest.mark.parametrize("name", ["streetlight_shadow", "fence_shadow"])
def test_shadows_reach_further_across_with_severity(name: str) -> None:
    reach = [shadow_points(compiled({"type": name, "severity": level}))[:, 1].max() for level in LEVELS]
    assert all(a < b for a, b in zip(reach, reach[1:]))
    # the strongest level crosses the centre line (lamps) or ends in the ego lane (the fence, see below)
    assert reach[-1] > (0.0 if name == "streetlight_shadow" else -Case().road.lane_width)


@pytest.mark.parametrize("severity", LEVELS)
def test_wire_shadows_run_along_the_ego_lane(severity: int) -> None:
    scene = compiled({"type": "wire_shadow", "severity": severity})
    wires = own_vertices(scene)
    wires = wires[(wires[:, 2] > 6.0) & (wires[:, 1] < -5.0)]  # the row along the right side
    sun = scene.env.sun_dir_world
    t_shadow = wires[:, 1] - sun[1] * wires[:, 2] / sun[2]
    assert -3.5 < np.median(t_shadow) < 0.0


def test_rail_deck_shades_the_whole_carriageway() -> None:
    case = Case(illusions=[{"type": "rail_shadow", "severity": 5}])
    scene = compiled(case.illusions[0].model_dump())
    x, y = shadow_points(scene).T
    half = scene.network.main.half_width
    assert y.min() < -half and y.max() > half
    assert x.min() < case.ego.start_s + 22.0  # the shadow reaches back towards the ego


@pytest.mark.parametrize("road", [{"type": "bend", "radius": 60.0, "turn": "right"}, {"type": "uphill"},
                                  {"type": "crossroad", "junction_s": 60.0}])
@pytest.mark.parametrize("name", SHADOW_TYPES)
def test_nothing_stands_on_a_carriageway(name: str, road: dict) -> None:
    scene = compiled({"type": name, "severity": 5, "s": 45.0, "side": "left"}, road=road)
    p_world = own_vertices(scene)
    for piece in scene.network.pieces:
        s, t, h = road_coords(piece.line, p_world).T
        on_road = (np.abs(t) < piece.half_width) & (s > piece.s_start) & (s < piece.line.length)
        assert on_road.sum() == 0 or h[on_road].min() > 4.4  # only decks and wires pass over a road


def test_streetlights_leave_the_junction_mouth_free() -> None:
    scene = compiled({"type": "streetlight_shadow", "severity": 5, "side": "both"},
                     road={"type": "t_junction", "junction_s": 80.0})
    piece = scene.network.main
    names = [mesh.name for mesh in scene.meshes if mesh.source == 0]
    assert len(names) == len(set(names)) > 6
    for mesh in (m for m in scene.meshes if m.source == 0 and "right" in m.name):
        s, t, _ = road_coords(piece.line, mesh.vertices[:1]).T
        assert not any(g0 <= s[0] <= g1 for g0, g1, side in piece.gaps if side == -1)


@pytest.mark.parametrize("bad", [{"type": "wire_shadow", "wire_radius": 0.01},
                                 {"type": "fence_shadow", "side": "middle"},
                                 {"type": "rail_shadow", "clearance": 2.0},
                                 {"type": "streetlight_shadow", "sun_altitude": 95.0}])
def test_bad_fields_are_refused(bad: dict) -> None:
    field = next(key for key in bad if key != "type")
    with pytest.raises(ValidationError, match=field):
        Case(illusions=[bad])


@pytest.mark.parametrize("name", ["streetlight_shadow", "fence_shadow", "wire_shadow"])
def test_posts_keep_clear_of_the_lamps_already_there(name: str) -> None:
    scene = compiled({"type": name, "severity": 5}, scene={"kind": "urban", "density": 1.0})
    piece = scene.network.main
    lamps = np.concatenate([m.vertices for m in scene.meshes if m.source == -1 and m.kind in ("streetlight", "pole")])
    mine = own_vertices(scene)
    s_lamp, t_lamp, h_lamp = road_coords(piece.line, lamps).T
    s_mine, t_mine, h_mine = road_coords(piece.line, mine).T
    lamp_feet = np.stack([s_lamp, t_lamp], 1)[h_lamp < -0.05]
    my_feet = np.stack([s_mine, t_mine], 1)[h_mine < -0.05]
    assert len(lamp_feet) and len(my_feet)
    gap = np.sqrt(((lamp_feet[:, None] - my_feet[None]) ** 2).sum(-1)).min()
    assert gap > 0.5


def test_fence_sun_stays_while_the_fence_grows() -> None:
    scenes = [compiled({"type": "fence_shadow", "severity": level}) for level in LEVELS]
    assert np.ptp([s.env.sun_dir_world for s in scenes], axis=0).max() < 1e-9
    assert len({s.env.sun_intensity for s in scenes}) == 1  # one sun, its strength too: only the fence grows
    height = np.array([own_vertices(s)[:, 2].max() for s in scenes])
    assert all(a < b for a, b in zip(height, height[1:]))  # so its shadow reaches further across


def test_each_level_fence_holds_the_one_before() -> None:
    """The boards are laid from the bottom: below its own top, a lower level's fence has its boards' edges where the
    next level's has them, so its shade and its lines of light stay where they were and the next level adds."""
    scenes = [compiled({"type": "fence_shadow", "severity": level}) for level in LEVELS]
    heights = [level.height for level in FenceShadow.SEVERITY]
    edges = [set(np.round(own_vertices(s)[:, 2], 3)) for s in scenes]
    for lower, higher, height in zip(edges, edges[1:], heights):
        assert {z for z in lower if z < height - 1e-3} <= higher


@pytest.mark.parametrize("lanes", [1, 2, 3])
def test_fence_shadow_edge_falls_in_the_ego_lane_at_level_5(lanes: int) -> None:
    case = Case(road={"lanes_per_direction": lanes}, illusions=[{"type": "fence_shadow", "severity": 5}])
    scene = compiled(case.illusions[0].model_dump(), road={"lanes_per_direction": lanes})
    # straight road along +X: y = t; the fence stands on the right, its shadow's far edge is the top's shadow
    top = own_vertices(scene)
    top = top[top[:, 2] > top[:, 2].max() - 0.01]
    t_edge = np.median(top[:, 1] - scene.env.sun_dir_world[1] * top[:, 2] / scene.env.sun_dir_world[2])
    t_center = scene.network.lane_center_t(case.ego.lane)
    assert abs(t_edge - t_center) < case.road.lane_width / 2


def test_board_fence_lets_lines_of_light_through_parallel_to_the_road() -> None:
    scene = compiled({"type": "fence_shadow", "severity": 5})
    fence_vertices = own_vertices(scene)
    # the boards' heights: every gap between two boards is a line of light at t = t_fence + z / tan(altitude)
    z = np.unique(np.round(fence_vertices[:, 2], 3))
    gap = FenceShadow.SEVERITY[4].gap
    edges = np.diff(z)
    assert np.sum(np.isclose(edges, gap, atol=2e-3)) >= 2  # at least two gaps of the table's size
