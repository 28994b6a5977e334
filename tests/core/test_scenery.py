"""Roadside scenery: nothing on any carriageway, shoulder or sidewalk, modest triangle counts, deterministic."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from lanevil_core.case import Case
from lanevil_core.pipeline.compile import roadside_inputs
from lanevil_core.typed import SCENE_KINDS, SceneKind
from lanevil_core.world.road_layout import RoadNetwork, RoadPiece, build_network
from lanevil_core.world.scene import Mesh
from lanevil_core.world.scenery import corridor_half_width, roadside_meshes

OVERHEAD_CLEARANCE_M = 4.5  # what is this high above the road (a lamp arm, a tunnel lintel) may span it
# Structures allowed inside the roadside strips (but never on the carriageway).
ON_VERGE = {"barrier", "pole", "street_furniture", "pedestrian"}  # lamp posts, furniture and people on sidewalks


def road_frame(piece: RoadPiece, p_world: np.ndarray) -> tuple[np.ndarray, ...]:
    """s, t and height above the road surface of world points (n, 3) in ``piece``'s road frame (nearest
    sample every 4 m, then two projections on the local tangent)."""
    line = piece.line
    coarse = slice(None, None, 40)
    near = np.argmin(((p_world[:, None, :2] - line.xy[coarse][None]) ** 2).sum(-1), axis=1)
    s = line.s[coarse][near]
    for _ in range(2):
        origin, tangent, _ = line.frame(s)
        flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
        s = s + ((p_world[:, :2] - origin[:, :2]) * flat).sum(1)
    origin, _, left = line.frame(np.clip(s, 0.0, line.length))
    return s, ((p_world - origin) * left).sum(1), p_world[:, 2] - origin[:, 2]


def intrusions(network: RoadNetwork, meshes: list[Mesh], reach: Callable[[RoadPiece], float]) -> set[str]:
    """Names of meshes with a vertex (or face centre) within ``reach(piece)`` of some piece's centre line,
    inside its length, lower than the overhead clearance."""
    if not meshes:
        return set()
    per_mesh = [np.concatenate([m.vertices, m.vertices[m.faces].mean(1)]) for m in meshes]
    owner = np.concatenate([np.full(len(p), i) for i, p in enumerate(per_mesh)])
    probes = np.concatenate(per_mesh)
    bad: set[str] = set()
    for piece in network.pieces:
        s, t, h = road_frame(piece, probes)
        inside = (s > 0.5) & (s < piece.line.length - 0.5) & (np.abs(t) < reach(piece)) & (h < OVERHEAD_CLEARANCE_M)
        bad |= {meshes[i].name for i in np.unique(owner[inside])}
    return bad


def scenery(kind: SceneKind, road: str = "straight", density: float = 1.0,
            seed: int = 0) -> tuple[RoadNetwork, list[Mesh]]:
    case = Case.model_validate({"scene": {"kind": kind, "density": density}, "road": {"type": road}})
    network = build_network(case.road, kind)
    return network, roadside_meshes(roadside_inputs(case), network, np.random.default_rng(seed))


@pytest.mark.parametrize("road", ["straight", "bend", "crossroad"])
@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_nothing_stands_on_the_road(kind: SceneKind, road: str) -> None:
    network, meshes = scenery(kind, road)
    assert meshes
    # Every prop clears the carriageway of every piece (main road and junction arms) ...
    assert intrusions(network, meshes, lambda piece: piece.half_width) == set()
    # ... and, but for barriers and lamp posts, the shoulders, kerbs and sidewalks too.
    props = [mesh for mesh in meshes if mesh.kind not in ON_VERGE]
    assert intrusions(network, props, lambda piece: corridor_half_width(piece) - 0.05) == set()


TRIANGLE_BUDGET = 36_000  # the roadside of a crossroad at density 1 (twice that at 3): the people on a town's
# sidewalks (200 faces each) took it past the 30 000 it was before, the suburbs' garden trees behind the first row
# (trees of about 200 faces, no longer 8-face lumps) past 32 000, parked cars' octagonal wheels with hubs (no longer
# hexagons) to 35 240


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_triangle_budget(kind: SceneKind) -> None:
    for density in (1.0, 3.0):
        _, meshes = scenery(kind, "crossroad", density)
        faces = sum(len(mesh.faces) for mesh in meshes)
        assert faces < (TRIANGLE_BUDGET if density == 1.0 else 2 * TRIANGLE_BUDGET), (kind, density, faces)


@pytest.mark.parametrize("kind", SCENE_KINDS)
@pytest.mark.parametrize("density", [5e-324, 1e-300, 1e-9])
def test_a_density_of_next_to_nothing_places_next_to_nothing(kind: SceneKind, density: float) -> None:
    # the props' spacings divide by the density: a subnormal one makes them infinite, which must mean "none"
    _, meshes = scenery(kind, "crossroad", density)
    rows = [mesh.name for mesh in meshes if mesh.name.split()[0] in ("building", "house", "farmhouse")]
    assert not rows, (kind, density, rows)


def test_scenery_is_deterministic_and_seeded() -> None:
    _, a = scenery("suburban", "bend", seed=4)
    _, b = scenery("suburban", "bend", seed=4)
    _, c = scenery("suburban", "bend", seed=5)
    assert [m.name for m in a] == [m.name for m in b]
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x.vertices, y.vertices)
        np.testing.assert_array_equal(x.colors, y.colors)
    assert sum(len(m.faces) for m in a) != sum(len(m.faces) for m in c) or not np.array_equal(
        a[0].vertices, c[0].vertices)


@pytest.mark.parametrize("kind", ["urban", "suburban", "rural"])
def test_density_scales_the_props(kind: SceneKind) -> None:
    """More props at a higher density: the faces of the grouped ones (trees, barriers, lamps), and buildings by
    their count (their faces depend on their sizes and windows, drawn anew when the rows change)."""
    def amount(meshes: list) -> int:
        return sum(len(m.faces) if m.kind != "building" else 500 for m in meshes)

    faces = [amount(scenery(kind, density=d)[1]) for d in (0.0, 1.0, 3.0)]
    assert faces[0] < faces[1] < faces[2] and faces[0] < faces[2] / 2


def test_scenes_differ_by_kind() -> None:
    kinds = {kind: {m.kind for m in scenery(kind)[1]} for kind in SCENE_KINDS}
    assert "building" in kinds["urban"] and "pole" in kinds["urban"]
    assert {"building", "tree"} <= kinds["suburban"]
    assert "barrier" in kinds["highway"] and "building" not in kinds["highway"]
    assert "tree" in kinds["rural"]
    assert "tunnel" in kinds["tunnel_approach"]


def test_props_cover_the_whole_road() -> None:
    network, meshes = scenery("rural", "bend")
    s, _, _ = road_frame(network.main, np.concatenate([m.vertices for m in meshes if m.kind == "tree"]))
    inside = s[(s > 0) & (s < network.main.line.length)]
    assert inside.min() < 40.0 and inside.max() > network.main.line.length - 40.0


def test_highway_barriers_line_both_edges_beyond_the_shoulder() -> None:
    network, meshes = scenery("highway", "bend")
    barriers = np.concatenate([m.vertices for m in meshes if m.kind == "barrier"])
    s, t, h = road_frame(network.main, barriers)
    shoulder = network.main.half_width + network.main.strips[0].width
    assert np.all(np.abs(t) > shoulder) and np.all(np.abs(t) < corridor_half_width(network.main) + 0.5)
    assert (t > 0).any() and (t < 0).any()
    assert np.all(np.abs(h) < 0.9)  # standing on the verge, not floating


def test_tunnel_portal_spans_the_road_ahead_of_the_ego() -> None:
    case = Case.model_validate({"scene": {"kind": "tunnel_approach"}})
    network = build_network(case.road, "tunnel_approach")
    meshes = roadside_meshes(roadside_inputs(case), network, np.random.default_rng(0))
    portal = next(m for m in meshes if m.name == "tunnel portal")
    s, t, h = road_frame(network.main, portal.vertices[portal.faces].mean(1))
    lintel = (np.abs(t) < network.main.half_width) & (h > 5.0)
    assert lintel.any()
    s_face = s[lintel].min()
    assert case.ego.start_s + 145.0 < s_face < case.ego.start_s + 255.0


@pytest.mark.parametrize("kind", ["urban", "suburban"])
def test_parked_cars_line_the_street_beyond_the_sidewalk(kind: SceneKind) -> None:
    """Rows of parked vehicles (kind ``vehicle``: test_nothing_stands_on_the_road keeps them off the carriageway
    and the sidewalk), more at a higher density, none at 0, none in the junction's mouth."""
    def parked(density: float) -> list[Mesh]:
        return [m for m in scenery(kind, "crossroad", density)[1] if m.name.startswith("parked cars")]

    counts = [sum(len(m.faces) for m in parked(d)) for d in (0.0, 1.0, 3.0)]
    assert counts[0] == 0 < counts[1] < counts[2], counts
    network, _ = scenery(kind, "crossroad", 3.0)
    points = np.concatenate([m.vertices for m in parked(3.0) if " piece 0 " in m.name])  # along the main road
    for arm in network.pieces[1:]:
        s, t, _ = road_frame(arm, points)
        near_arm = (s > -5.0) & (s < arm.line.length) & (np.abs(t) < corridor_half_width(arm) + 5.0)
        assert not near_arm.any()  # a gap where the crossing road meets the street
    assert {m.kind for m in parked(1.0)} == {"vehicle"}


@pytest.mark.parametrize("kind", ["urban", "suburban"])
def test_people_walk_and_stand_on_the_sidewalks_of_towns(kind: SceneKind) -> None:
    def people(density: float) -> tuple[RoadNetwork, list[Mesh]]:
        network, meshes = scenery(kind, "straight", density)
        return network, [m for m in meshes if m.name.startswith("passers-by")]

    counts = [sum(len(m.faces) for m in people(d)[1]) for d in (0.0, 1.0, 3.0)]
    assert counts[0] == 0 < counts[1] < counts[2], counts
    network, found = people(3.0)
    assert {m.kind for m in found} == {"pedestrian"}
    main = network.main
    kerb = main.half_width + sum(strip.width for strip in main.strips[:1])  # the kerb side of the sidewalk
    back = kerb + sum(strip.width for strip in main.strips[1:-1])
    points = np.concatenate([m.vertices for m in found])
    _, t, _ = road_frame(main, points)
    assert (np.abs(t) > kerb + 0.5).all() and (np.abs(t) < back).all()  # on the sidewalk, clear of the kerb
    assert (t > 0).any() and (t < 0).any()  # both sides
    _, again = people(3.0)
    assert all(np.array_equal(a.vertices, b.vertices) for a, b in zip(found, again, strict=True))


def test_parked_cars_only_in_towns() -> None:
    for kind in ("highway", "rural", "tunnel_approach"):
        assert not [m for m in scenery(kind, "crossroad", 3.0)[1] if m.name.startswith("parked")], kind


@pytest.mark.parametrize(("road", "approaches"), [("crossroad", 4), ("t_junction", 3), ("straight", 0)])
def test_a_traffic_signal_at_each_approach_to_a_town_junction(road: str, approaches: int) -> None:
    for kind in ("urban", "suburban"):
        network, meshes = scenery(kind, road)
        signals = [m for m in meshes if m.name.startswith("traffic signal")]
        assert len(signals) == approaches, (kind, road)
        for signal in signals:
            assert signal.emission is not None
            lit = signal.emission.max(1) > 0
            lamps = np.unique(signal.emission[lit].round(4), axis=0)
            assert len(lamps) == 1 and lit.sum() == 12  # one lamp (a box) lit, the housing dark
            s, t, _ = road_frame(network.main, signal.vertices)
            foot = np.argmin(signal.vertices[:, 2])
            kerb = network.main.half_width + sum(strip.width for strip in network.main.strips[:2])
            assert abs(t[foot]) > kerb or any(  # beyond the kerb of the main road or of an arm
                abs(road_frame(arm, signal.vertices[foot:foot + 1])[1][0]) > kerb for arm in network.pieces[1:])
    _, rural = scenery("rural", road)
    assert not [m for m in rural if m.name.startswith("traffic signal")]


UTILITY_KINDS = {"rural", "suburban"}


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_utility_poles_and_wires_line_rural_and_suburban_roads_only(kind: SceneKind) -> None:
    network, meshes = scenery(kind, "straight")
    lines = [mesh for mesh in meshes if mesh.name == "utility lines"]
    assert len(lines) == (1 if kind in UTILITY_KINDS else 0)
    if not lines:
        return
    _, t, h = road_frame(network.main, lines[0].vertices)
    row = np.median(t)
    assert abs(row) > corridor_half_width(network.main)  # beside the verge, one side
    assert np.all(np.sign(t) == np.sign(row))
    poles = lines[0].vertices[(h < 0.0)]  # only the poles' footings go below the ground
    s_feet = np.unique(road_frame(network.main, poles)[0].round(0))
    gaps = np.diff(s_feet[np.diff(np.concatenate([[-99.0], s_feet])) > 2.0])
    assert len(gaps) >= 3 and np.all((gaps > 30.0) & (gaps < 52.0))  # 35-50 m apart
    assert 9.0 <= h.max() <= 12.5  # 9-12 m poles


def test_utility_wires_sag_between_poles() -> None:
    network, meshes = scenery("rural", "straight")
    line = next(mesh for mesh in meshes if mesh.name == "utility lines")
    s, _, h = road_frame(network.main, line.vertices)
    high = h > 7.0
    wire_top, wire_low = np.percentile(h[high], 95), np.percentile(h[high], 2)
    assert wire_top - wire_low > 0.5  # a catenary dips mid-span


def test_the_roadside_moves_no_lane_label(make_case: Callable[..., Case]) -> None:
    from lanevil_core.labels import lanes
    from lanevil_core.pipeline.compile import compile_scene
    from lanevil_core.render import render_frame

    records = []
    for density in (0.0, 2.0):
        case = make_case(scene={"kind": "rural", "density": density}, road={"type": "s_curve"})
        scene = compile_scene(case)
        records.append(lanes.tusimple_record(scene, 5, render_frame(scene, 5), "a.png"))
    assert any(mesh.name == "utility lines" for mesh in scene.meshes)
    assert records[0]["lanes"] == records[1]["lanes"] and records[0]["line_types"] == records[1]["line_types"]
