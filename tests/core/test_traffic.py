"""Traffic illusions: deterministic compile, more participants and more hidden paint with severity, a free ego
path, JSON round trips and user obstacle models."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
from pydantic import ValidationError

from lanevil_core.camera import ego_camera
from lanevil_core.case import Case, case_meshes_dir, parse_case
from lanevil_core.illusions import REGISTRY, CompileContext, MeshFileError
from lanevil_core.illusions.traffic import EGO_CLEAR_M, Footprints, Slot, load_obstacle, srgb_to_linear
from lanevil_core.pipeline.compile import case_environment, ego_drive, load_user_meshes
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.scene import Mesh

TRAFFIC = ("pedestrian", "vehicle", "bicycle")


def compiled(spec: dict, meshes_dir: Path | None = None, **case: object) -> tuple[Case, CompileContext]:
    """Compile one illusion on its own (no roadside) into a fresh context."""
    model = Case.model_validate({"illusions": [spec], **case})
    network = build_network(model.road, model.scene.kind)
    ctx = CompileContext(seed=model.seed, drive=ego_drive(model), network=network, env=case_environment(model),
                         source=0, user_meshes=load_user_meshes(model, meshes_dir))
    model.illusions[0].compile(ctx)
    return model, ctx


def hidden_share(case: Case, ctx: CompileContext, frame: int = 0) -> float:
    """Share of the lane lines' image rows (every 4 px below the horizon) hidden behind the participants,
    by casting rays from the camera to the paint."""
    network = ctx.network
    camera = ego_camera(case, network, frame)
    rows = np.arange(372.0, 720.0, 4.0)
    s = case.ego_s(frame) + case.camera.x + case.camera.z * camera.intrinsics.fy / (rows - camera.intrinsics.cy)
    paint = network.main.line.to_world(s[:, None], network.main.boundaries_t[None, :], 0.01).reshape(-1, 3)
    uv, depth = camera.project(paint)
    k = camera.intrinsics
    seen = (depth > 0.5) & (uv[:, 0] >= 0) & (uv[:, 0] < k.width) & (uv[:, 1] < k.height)
    paint = paint[seen]
    tris = np.concatenate([m.vertices[m.faces] for m in ctx.meshes])
    origin = camera.p_world_camera
    ray = paint - origin
    reach = np.linalg.norm(ray, axis=1)
    ray /= reach[:, None]
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    to_origin = origin - tris[:, 0]
    q = np.cross(to_origin, e1)
    hidden = np.zeros(len(paint), bool)
    for start in range(0, len(paint), 128):
        d = ray[start:start + 128, None, :]
        p = np.cross(d, e2[None])
        det = (e1[None] * p).sum(-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            u = (to_origin[None] * p).sum(-1) * inv
            v = (d * q[None]).sum(-1) * inv
            t = (e2 * q).sum(-1)[None] * inv
        hit = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0) & (t < reach[start:start + 128, None] - 0.05)
        hidden[start:start + 128] = hit.any(1)
    return float(hidden.mean())


def road_st(ctx: CompileContext, p_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    line = ctx.network.main.line
    near = np.argmin(((p_world[:, None, :2] - line.xy[None, ::5]) ** 2).sum(-1), axis=1)
    s = line.s[::5][near]
    for _ in range(2):
        origin, tangent, _ = line.frame(s)
        flat = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
        s = s + ((p_world[:, :2] - origin[:, :2]) * flat).sum(1)
    origin, _, left = line.frame(s)
    return s, ((p_world - origin) * left).sum(1)


def test_traffic_types_are_registered() -> None:
    for name in TRAFFIC:
        assert REGISTRY[name].CATEGORY == "traffic"
        rows: Sequence[Any] = REGISTRY[name].SEVERITY  # each family its own row type
        assert len(rows) == 5 and all(type(row) is type(rows[0]) for row in rows)
        counts = [row.count for row in rows]
        distances = [row.distance for row in rows]
        assert counts == sorted(counts) and distances == sorted(distances, reverse=True)


@pytest.mark.parametrize("name", TRAFFIC)
def test_each_severity_compiles_deterministically(name: str) -> None:
    for severity in range(1, 6):
        _, a = compiled({"type": name, "severity": severity, "seed": 3})
        _, b = compiled({"type": name, "severity": severity, "seed": 3})
        assert a.meshes and len(a.meshes) == len(b.meshes)
        for x, y in zip(a.meshes, b.meshes):
            np.testing.assert_array_equal(x.vertices, y.vertices)
            np.testing.assert_array_equal(x.colors, y.colors)
            assert x.source == 0 and x.name.startswith(name)
    _, other = compiled({"type": name, "severity": 5, "seed": 4})
    assert not all(np.array_equal(x.vertices, y.vertices) for x, y in zip(a.meshes, other.meshes))


@pytest.mark.parametrize("name", TRAFFIC)
def test_severity_adds_participants_and_hides_more_paint(name: str) -> None:
    counts, hidden = [], []
    for severity in (1, 3, 5):
        case, ctx = compiled({"type": name, "severity": severity})
        counts.append(len(ctx.meshes))
        hidden.append(hidden_share(case, ctx))
    assert counts[0] < counts[1] < counts[2]
    assert hidden[0] <= hidden[1] < hidden[2]
    assert hidden[2] > (0.15 if name == "vehicle" else 0.04)  # level 5 clearly covers paint in the first frame


@pytest.mark.parametrize("name", TRAFFIC)
@pytest.mark.parametrize("road", ["straight", "bend"])
def test_participants_stay_on_the_road_and_off_the_ego_path(name: str, road: str) -> None:
    case, ctx = compiled({"type": name, "severity": 5}, road={"type": road, "radius": 120.0})
    t_ego = ctx.network.lane_center_t(case.ego.lane)
    end_s = case.ego_s(case.ego.frames - 1)
    for mesh in ctx.meshes:
        s, t = road_st(ctx, mesh.vertices)
        low = mesh.vertices[:, 2] - ctx.network.main.line.to_world(s, 0.0)[:, 2] < 3.0
        on_path = (s > case.ego.start_s) & (s < end_s + 5.0) & (np.abs(t - t_ego) < EGO_CLEAR_M - 0.02)
        assert not np.any(on_path & low), mesh.name
        assert np.all(np.abs(t) < ctx.network.main.half_width + 1.1), mesh.name
        assert abs(mesh.vertices[:, 2].min() - ctx.network.main.line.to_world(s.mean(), 0.0)[2]) < 0.3


@pytest.mark.parametrize("name", TRAFFIC)
def test_first_and_last_frames_see_participants(name: str) -> None:
    for severity in (2, 5):
        case, ctx = compiled({"type": name, "severity": severity})
        for frame in (0, case.ego.frames - 1):
            camera = ego_camera(case, ctx.network, frame)
            centres = np.array([m.vertices.mean(0) for m in ctx.meshes])
            uv, depth = camera.project(centres)
            k = camera.intrinsics
            visible = (depth > 3.0) & (depth < 80.0) & (uv[:, 0] > 0) & (uv[:, 0] < k.width)
            assert visible.any(), (severity, frame)


def test_explicit_fields_override_the_table() -> None:
    _, ctx = compiled({"type": "pedestrian", "severity": 1, "count": 7, "group": 7, "distance": 20.0,
                       "shirt_colors": [[0.9, 0.0, 0.0]]})
    assert len(ctx.meshes) == 7
    s, _ = road_st(ctx, np.array([m.vertices.mean(0) for m in ctx.meshes]))
    assert s.min() == pytest.approx(10.0 + 20.0, abs=0.5)
    assert all(np.any(np.all(np.isclose(m.colors, (0.9, 0.0, 0.0)), axis=1)) for m in ctx.meshes)
    _, trucks = compiled({"type": "vehicle", "kind": "truck", "count": 3, "spacing": 25.0})
    assert len(trucks.meshes) == 3
    assert all(np.ptp(m.vertices[:, 2]) > 3.2 for m in trucks.meshes)


def test_vehicle_lights_and_colours() -> None:
    _, ctx = compiled({"type": "vehicle", "severity": 3, "kind": "car", "lights_on": True,
                       "colors": [[0.1, 0.2, 0.7]]})
    for mesh in ctx.meshes:
        assert mesh.emission is not None and mesh.emission.max() > 1.0
        assert np.any(np.all(np.isclose(mesh.colors, (0.1, 0.2, 0.7)), axis=1))


@pytest.mark.parametrize("name", TRAFFIC)
def test_json_round_trip(name: str) -> None:
    cls = REGISTRY[name]
    spec = {"type": name, "severity": 4, "seed": 9, "count": 5, "distance": 15.0}
    model = cls.model_validate(spec)
    again = cls.model_validate_json(model.model_dump_json())
    assert again == model
    case = parse_case({"illusions": [spec]})
    reread = parse_case(case.model_dump_json())
    assert reread.illusions[0] == case.illusions[0]
    assert json.loads(reread.model_dump_json())["illusions"][0]["type"] == name


def test_bad_fields_name_the_field() -> None:
    with pytest.raises(ValidationError, match="count"):
        REGISTRY["pedestrian"].model_validate({"type": "pedestrian", "count": 0})
    with pytest.raises(ValidationError, match="colors"):
        REGISTRY["vehicle"].model_validate({"type": "vehicle", "colors": [[2.0, 0.0, 0.0]]})
    with pytest.raises(ValidationError, match="motion"):
        REGISTRY["bicycle"].model_validate({"type": "bicycle", "motion": "flying"})


def _two_part_glb(path: Path) -> None:
    """A red box 4 m long along glTF +Z (forward) and a green-material cylinder on top, as a GLB."""
    body = trimesh.creation.box((2.0, 1.0, 4.0))
    body.unmerge_vertices()
    body.visual.vertex_colors = np.tile([200, 30, 30, 255], (len(body.vertices), 1))
    mast = trimesh.creation.cylinder(0.2, 1.0, sections=8)
    mast.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, (1, 0, 0)))
    mast.apply_translation((0.0, 1.0, 0.0))
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[20, 200, 30, 255])
    mast.visual = trimesh.visual.TextureVisuals(material=material)
    trimesh.Scene([body, mast]).export(path)


def test_load_obstacle_glb_converts_axes_and_colours(tmp_path: Path) -> None:
    path = tmp_path / "thing.glb"
    _two_part_glb(path)
    mesh = load_obstacle(path)
    size = mesh.vertices.max(0) - mesh.vertices.min(0)
    np.testing.assert_allclose(size, (4.0, 2.0, 2.0), atol=1e-5)  # glTF +Z forward -> +X, +Y up -> +Z
    assert mesh.vertices[:, 2].min() == pytest.approx(0.0)
    np.testing.assert_allclose(mesh.vertices.min(0)[:2] + mesh.vertices.max(0)[:2], 0.0, atol=1e-6)
    red, green = srgb_to_linear(np.array([200.0, 30, 30])), srgb_to_linear(np.array([20.0, 200, 30]))
    assert np.any(np.all(np.isclose(mesh.colors, red, atol=1e-3), axis=1))
    assert np.any(np.all(np.isclose(mesh.colors, green, atol=1e-3), axis=1))
    assert load_obstacle(path, up="z").vertices[:, 2].max() == pytest.approx(4.0)


def test_load_obstacle_obj_and_errors(tmp_path: Path) -> None:
    cube = trimesh.creation.box((1.0, 1.0, 1.0))
    cube.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.SimpleMaterial(diffuse=[30, 30, 200, 255]))
    cube.export(tmp_path / "cube.obj")
    mesh = load_obstacle(tmp_path / "cube.obj")
    assert isinstance(mesh, Mesh) and len(mesh.faces) == 12
    assert mesh.colors[:, 2].min() > 5 * mesh.colors[:, 0].max()
    with pytest.raises(FileNotFoundError):
        load_obstacle(tmp_path / "missing.glb")
    with pytest.raises(ValueError, match="triangles"):
        load_obstacle(tmp_path / "cube.obj", max_faces=4)


def test_vehicle_mesh_file_replaces_the_bodies(tmp_path: Path) -> None:
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    _two_part_glb(meshes / "thing.glb")
    _, ctx = compiled({"type": "vehicle", "severity": 2, "kind": "van", "mesh_file": "thing.glb"}, meshes)
    for mesh in ctx.meshes:
        assert len(mesh.faces) == 12 + 32  # the loaded model, not the procedural van
        size = np.sort(mesh.vertices.max(0) - mesh.vertices.min(0))
        assert size.max() <= 5.2 + 1e-6 and size.max() > 2.5


@pytest.mark.parametrize("name", ["/etc/passwd", "/proc/self/environ", "../../etc/hostname", "a/b.glb", "x.txt",
                                  ".hidden.glb", "a..glb", "C:\\x.glb"])
def test_mesh_file_is_a_plain_model_name(name: str) -> None:
    with pytest.raises(ValidationError, match="must be a file name in the uploads folder"):
        Case.model_validate({"illusions": [{"type": "vehicle", "mesh_file": name}]})


def test_a_mesh_file_outside_or_missing_from_the_folder_is_refused(tmp_path: Path) -> None:
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    _two_part_glb(tmp_path / "elsewhere.glb")
    (meshes / "link.glb").symlink_to(tmp_path / "elsewhere.glb")
    for name, says in (("link.glb", "outside"), ("missing.glb", "not in the meshes folder")):
        with pytest.raises(MeshFileError, match=says) as error:
            compiled({"type": "vehicle", "mesh_file": name}, meshes)
        assert error.value.field == "illusions.0.vehicle.mesh_file"
    with pytest.raises(MeshFileError, match="no meshes folder"):
        compiled({"type": "vehicle", "mesh_file": "elsewhere.glb"})


def test_the_cli_reads_meshes_beside_the_case_file(tmp_path: Path) -> None:
    assert case_meshes_dir(tmp_path / "cases" / "a.json") == tmp_path / "cases" / "meshes"


def test_someone_on_an_edge_line_stands_just_inside_the_paved_edge() -> None:
    case = Case()
    free = Footprints(ego_drive(case), t_ego=-1.75)
    placed = free.place(Slot(40.0, -7.0, 0.0), 0.3, 0.4, reach=7.2)
    assert placed is not None and placed.t == pytest.approx(-6.8)  # squeezed in, still on the edge line
    assert free.place(Slot(60.0, -7.5, 0.0), 0.3, 0.4, reach=7.2) is None  # standing off the road: dropped


@pytest.mark.parametrize("name", ["pedestrian", "bicycle"])
def test_level_five_crowds_the_ego_lines_in_the_first_frame(name: str) -> None:
    case, ctx = compiled({"type": name, "severity": 5})
    t_ego = ctx.network.lane_center_t(case.ego.lane)
    ego_lines = (t_ego - ctx.network.lane_width / 2, t_ego + ctx.network.lane_width / 2)
    s, t = road_st(ctx, np.array([m.vertices.mean(0) for m in ctx.meshes]))
    near = s < case.ego.start_s + 20.0  # the first group stands 14-19 m ahead
    on_ego_lines = near & np.any([np.abs(t - line) < 0.3 for line in ego_lines], axis=0)
    assert near.sum() >= 6 and on_ego_lines.sum() >= 2


@pytest.mark.parametrize("name", ["pedestrian", "bicycle"])
def test_every_level_is_the_level_five_crowd_thinned_out(name: str) -> None:
    positions = []
    for severity in range(1, 6):
        _, ctx = compiled({"type": name, "severity": severity})
        positions.append({tuple(np.round(m.vertices.mean(0), 3)) for m in ctx.meshes})
    for lower, higher in zip(positions, positions[1:]):
        assert lower < higher  # a higher level only adds participants
