"""Road damage illusions: tables, determinism, JSON round trip, placement and a severity ladder that strengthens."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lanevil_core.case import Case, CaseError, case_json, parse_case
from lanevil_core.illusions import REGISTRY
from lanevil_core.illusions.road_damage import MAX_LAYER_TEXELS, GuardRail
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.world.scene import CompiledScene

SURFACE_TYPES = ("road_crack", "road_repair", "tire_marks")
DAMAGE_TYPES = (*SURFACE_TYPES, "guard_rail")
LEVELS = (1, 2, 3, 4, 5)


def compiled(illusion: dict, **case_fields) -> CompiledScene:
    """The compiled scene of a case holding one illusion (no roadside props: faster)."""
    case_fields.setdefault("scene", {"density": 0.0})
    return compile_scene(Case(illusions=[illusion], **case_fields))


def lane_alpha(scene: CompiledScene, t_lo: float | None = None, t_hi: float | None = None) -> float:
    """Coverage-weighted area (m^2) of the illusion's layers over t in [t_lo, t_hi] (default: the carriageway)."""
    half = scene.network.main.half_width
    t_lo, t_hi = (-half if t_lo is None else t_lo), (half if t_hi is None else t_hi)
    area = 0.0
    for layer in scene.layers:
        t_road = layer.t0 + (np.arange(layer.rgba.shape[1]) + 0.5) * layer.texel
        inside = (t_road >= t_lo) & (t_road <= t_hi)
        area += float(layer.rgba[:, inside, 3].sum(dtype=np.float64)) * layer.texel**2
    return area


def rail_vertices(scene: CompiledScene) -> np.ndarray:
    meshes = [mesh.vertices for mesh in scene.meshes if mesh.source == 0]
    assert meshes, "the guard rail added no mesh"
    return np.concatenate(meshes)


@pytest.mark.parametrize("name", DAMAGE_TYPES)
def test_registered_with_a_monotone_five_row_table(name: str) -> None:
    cls = REGISTRY[name]
    assert cls.CATEGORY == "road_damage"
    rows = cls.SEVERITY
    assert len(rows) == 5 and all(type(row) is type(rows[0]) for row in rows)
    for key in (field.name for field in dataclasses.fields(rows[0])):
        values = [getattr(row, key) for row in rows]
        if key == "offset":  # the rail closes in on the lanes
            assert values == sorted(values, reverse=True)
        else:
            assert values == sorted(values), key


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("name", DAMAGE_TYPES)
def test_compiles_deterministically(name: str, level: int) -> None:
    spec = {"type": name, "severity": level, "extent": 20.0 if name in SURFACE_TYPES else 60.0}
    first, second = compiled(spec), compiled(spec)
    assert len(first.layers) == len(second.layers) and len(first.meshes) == len(second.meshes)
    assert first.layers or first.meshes
    for a, b in zip(first.layers, second.layers):
        assert (a.s0, a.t0, a.texel, a.over_paint) == (b.s0, b.t0, b.texel, b.over_paint)
        assert np.array_equal(a.rgba, b.rgba)
    for mesh_a, mesh_b in zip(first.meshes, second.meshes):
        assert np.array_equal(mesh_a.vertices, mesh_b.vertices) and np.array_equal(mesh_a.colors, mesh_b.colors)
    assert np.array_equal(first.env.sun_dir_world, second.env.sun_dir_world)
    other = compiled({**spec, "seed": 1})
    if name in SURFACE_TYPES:
        assert any(not np.array_equal(a.rgba, b.rgba) for a, b in zip(first.layers, other.layers))


@pytest.mark.parametrize("name", DAMAGE_TYPES)
def test_json_round_trip(name: str) -> None:
    case = Case(illusions=[{"type": name, "severity": 4, "seed": 3}])
    again = parse_case(case_json(case))
    assert again == case
    assert type(again.illusions[0]).__name__ == type(case.illusions[0]).__name__
    assert again.illusions[0].model_dump() == case.illusions[0].model_dump()


@pytest.mark.parametrize("spec, field", [
    ({"type": "road_crack", "darkness": 1.5}, "darkness"),
    ({"type": "road_repair", "patches": -1}, "patches"),
    ({"type": "tire_marks", "track_width": 2.0}, "track_width"),
    ({"type": "guard_rail", "side": "middle"}, "side"),
    ({"type": "guard_rail", "color": [0.5, 0.5, 3.0]}, "color"),
])
def test_bad_fields_are_named(spec: dict, field: str) -> None:
    with pytest.raises(CaseError, match=field):
        parse_case({"illusions": [spec]})


@pytest.mark.parametrize("name", SURFACE_TYPES)
def test_severity_ladder_strengthens_the_lane_region(name: str) -> None:
    coverage = [lane_alpha(compiled({"type": name, "severity": level, "extent": 50.0})) for level in LEVELS]
    assert all(a < b for a, b in zip(coverage, coverage[1:])), coverage
    assert coverage[-1] > 2.0 * coverage[0]


@pytest.mark.parametrize("name", SURFACE_TYPES)
def test_layers_cover_the_carriageway_in_view_from_the_first_frame(name: str) -> None:
    case_fields = {"road": {"lanes_per_direction": 3}, "ego": {"start_s": 30.0}}
    scene = compiled({"type": name, "margin": 0.5}, **case_fields)
    half = scene.network.main.half_width
    assert scene.layers
    for layer in scene.layers:
        assert layer.piece == 0 and layer.rgba.dtype == np.float32 and layer.rgba.shape[2] == 4
        assert layer.rgba.shape[0] * layer.rgba.shape[1] <= MAX_LAYER_TEXELS
        assert layer.t0 == pytest.approx(-half - 0.5)
        assert layer.t0 + layer.rgba.shape[1] * layer.texel >= half + 0.5 - 1e-9
        assert 0.02 <= layer.texel <= 0.04
    s_first = min(layer.s0 for layer in scene.layers)
    assert 30.0 <= s_first <= 30.0 + 10.0  # within the camera's first view of the road
    s_last = max(layer.s0 + layer.rgba.shape[0] * layer.texel for layer in scene.layers)
    assert s_last - s_first >= 60.0


def test_long_damage_is_split_into_layers_under_the_texel_budget() -> None:
    # Level 1 spreads its marks over the whole stretch (higher levels bunch them at its start).
    scene = compiled({"type": "tire_marks", "severity": 1, "extent": 300.0, "margin": 2.0, "straight": 6},
                     road={"lanes_per_direction": 4, "length": 800.0})
    assert len(scene.layers) >= 2
    assert all(layer.rgba.shape[0] * layer.rgba.shape[1] <= MAX_LAYER_TEXELS for layer in scene.layers)
    ends = sorted((layer.s0, layer.s0 + layer.rgba.shape[0] * layer.texel) for layer in scene.layers)
    assert all(b[0] >= a[1] - 1e-6 for a, b in zip(ends, ends[1:]))  # consecutive, never overlapping


def test_crack_stains_lie_under_the_paint_and_cracks_sealant_and_rubber_over_it() -> None:
    cracks = compiled({"type": "road_crack", "severity": 1}).layers
    assert {layer.name.rsplit(" ", 1)[0]: layer.over_paint for layer in cracks} == {"crack stains": False,
                                                                                    "cracks": True}
    worn = compiled({"type": "road_crack", "severity": 4}).layers
    assert {layer.name.rsplit(" ", 1)[0]: layer.over_paint for layer in worn} == {
        "crack stains": False, "cracks": True, "worn paint": True}
    repair = compiled({"type": "road_repair", "severity": 4}).layers
    assert {layer.name.rsplit(" ", 1)[0]: layer.over_paint for layer in repair} == {
        "repair patches": False, "unpainted patches": True, "sealant": True, "ghost markings": False}
    assert {layer.over_paint for layer in compiled({"type": "tire_marks"}).layers} == {True}


@pytest.mark.parametrize("name", ("road_crack", "road_repair"))
def test_level_five_runs_damage_right_beside_the_ego_lane_lines(name: str) -> None:
    def beside(level: int) -> float:
        scene = compiled({"type": name, "severity": level})
        # The ego (lane 0) sees the centre line at t = 0 and its lane line at t = -lane_width.
        lines = (0.0, -scene.network.lane_width)
        return sum(lane_alpha(scene, t + 0.1, t + 0.45) + lane_alpha(scene, t - 0.45, t - 0.1) for t in lines)
    assert beside(5) > 4.0 * beside(1)


def test_tire_marks_cross_lane_lines_at_level_five() -> None:
    def on_lines(spec: dict) -> float:
        scene = compiled(spec)
        lines = (0.0, -scene.network.lane_width)  # both lines of the ego's lane
        return sum(lane_alpha(scene, t - 0.05, t + 0.05) for t in lines)
    assert on_lines({"type": "tire_marks", "severity": 1}) == 0.0  # braking in lane
    assert on_lines({"type": "tire_marks", "severity": 5, "straight": 0, "yaw": 0}) > 0.2  # swerves cross


def test_guard_rail_closes_in_on_the_lanes_with_severity() -> None:
    ego_t = -1.75  # centre of lane 0 on the default straight road, where world y = t
    nearest = [np.abs(rail_vertices(compiled({"type": "guard_rail", "severity": level}))[:, 1] - ego_t).min()
               for level in LEVELS]
    assert all(a > b for a, b in zip(nearest, nearest[1:])), nearest


def test_guard_rail_sun_throws_its_shadow_across_the_lanes() -> None:
    suns = [compiled({"type": "guard_rail", "severity": level}).env.sun_dir_world for level in LEVELS]
    plain = compile_scene(Case(scene={"density": 0.0})).env.sun_dir_world
    assert suns[0] == pytest.approx(plain)  # level 1 keeps the case's sun
    # From level 2 one sun, wherever the level sets the rails: the rails change, not the light.
    assert np.ptp(suns[1:], axis=0).max() < 1e-12
    assert not np.allclose(suns[1], plain)
    assert compiled({"type": "guard_rail", "severity": 3, "shadow_m": 0}).env.sun_dir_world == pytest.approx(plain)
    # On a highway the rail stands on the asphalt shoulder, its top 0.75 m above the road.
    scene = compiled({"type": "guard_rail", "severity": 3, "side": "right"}, scene={"kind": "highway", "density": 0})
    sun = scene.env.sun_dir_world
    assert sun[1] < 0  # on the right of a road heading +X, so the shadow falls towards +t (onto the road)
    reach = 0.75 * (-sun[1]) / np.hypot(sun[0], sun[1]) / np.tan(np.arcsin(sun[2]))
    assert reach == pytest.approx(GuardRail.SEVERITY[2].shadow_m, rel=0.05)


def test_guard_rail_sun_is_one_over_a_lowered_verge() -> None:
    """Rails at offsets over verges of other heights (a rural verge 2 cm down beyond its 0.6 m shoulder) share
    one sun: it is solved for a rail top over the carriageway, not over the level's footing."""
    suns = [compiled({"type": "guard_rail", "severity": level}, scene={"kind": "rural", "density": 0.0}).env
            .sun_dir_world for level in LEVELS[1:]]
    assert np.ptp(suns, axis=0).max() < 1e-12


def test_guard_rail_fields_override_the_table() -> None:
    scene = compiled({"type": "guard_rail", "severity": 1, "side": "left", "offset": 0.5, "far_side": True,
                      "color": [0.7, 0.1, 0.1]})
    y = rail_vertices(scene)[:, 1]
    half = scene.network.main.half_width
    assert y.max() > half + 0.4 and y.min() < -half - 0.4  # both edges
    colors = np.concatenate([m.colors for m in scene.meshes if m.source == 0])
    assert np.isclose(colors[:, 0], 0.7).any()


def test_guard_rail_leaves_junction_mouths_open() -> None:
    scene = compiled({"type": "guard_rail", "severity": 5},
                     road={"type": "t_junction", "junction_s": 60.0}, ego={"start_s": 10.0})
    main = scene.network.main
    gap = next((g0, g1) for g0, g1, side in main.gaps if side < 0)
    x = rail_vertices(scene)[:, 0]  # the main road runs along +X from the origin: x = s
    y = rail_vertices(scene)[:, 1]
    right = y < -main.half_width
    assert right.any() and not ((x[right] > gap[0] + 0.5) & (x[right] < gap[1] - 0.5)).any()
    assert (x[right] > gap[1]).any() and (x[right] < gap[0]).any()  # the rail goes on beyond the mouth


def _over_paint_on_ego_lines(scene: CompiledScene, s_max: float | None = None) -> float:
    """Coverage-weighted area (m^2) of over-paint layers on the paint of the ego lane's two lines (t = 0 and
    t = -lane_width on the default road), up to ``s_max`` along the road if given."""
    area = 0.0
    for layer in (layer for layer in scene.layers if layer.over_paint):
        t_road = layer.t0 + (np.arange(layer.rgba.shape[1]) + 0.5) * layer.texel
        s_road = layer.s0 + (np.arange(layer.rgba.shape[0]) + 0.5) * layer.texel
        on_line = (np.abs(t_road) < 0.08) | (np.abs(t_road + scene.network.lane_width) < 0.08)
        rows = s_road < (np.inf if s_max is None else s_max)
        area += float(layer.rgba[rows][:, on_line, 3].sum(dtype=np.float64)) * layer.texel**2
    return area


@pytest.mark.parametrize("name", SURFACE_TYPES)
def test_level_five_breaks_the_paint_of_the_ego_lane_lines(name: str) -> None:
    weak, strong = (_over_paint_on_ego_lines(compiled({"type": name, "severity": level})) for level in (1, 5))
    assert strong > 0.5  # m^2 of cracks, unpainted patches or rubber over the lines' paint
    assert strong > 5.0 * weak


def test_tire_marks_bunch_in_the_first_view_at_level_five() -> None:
    # The default ego starts at s = 10 m and first sees the road about 6 m ahead.
    near = [_over_paint_on_ego_lines(compiled({"type": "tire_marks", "severity": level}), s_max=26.0)
            for level in (1, 5)]
    assert near[0] == 0.0 and near[1] > 0.3


def test_cracked_joints_and_inlays_follow_the_lines_nearest_the_ego() -> None:
    cracks = compiled({"type": "road_crack", "severity": 1, "joints": 2, "density": 0.0})
    repair = compiled({"type": "road_repair", "severity": 1, "trenches": 2, "patches": 0, "strips": 0})
    for scene in (cracks, repair):
        on_lines = lane_alpha(scene, -0.3, 0.3) + lane_alpha(scene, -3.8, -3.2)
        elsewhere = lane_alpha(scene, 1.2, 3.5) + lane_alpha(scene, -2.6, -1.0)
        assert on_lines > 10.0 * max(elsewhere, 1e-3), (on_lines, elsewhere)
