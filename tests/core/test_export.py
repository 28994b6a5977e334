"""Dataset export: folder layout, TuSimple / CULane files, deterministic bytes, the glTF scene."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from lanevil_core.case import Case, load_case
from lanevil_core.export.case import export_case
from lanevil_core.images import png_bytes
from lanevil_core.world.paint import dash_spans, paint_mesh
from lanevil_core.world.road_layout import build_network

CASE = Case.model_validate({"ego": {"frames": 50}, "scene": {"density": 0.3}})


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("export")
    export_case(CASE, out, frames=[3], formats={"tusimple", "culane"}, glb=True)
    return out


def test_layout(exported):
    names = sorted(str(p.relative_to(exported)) for p in exported.rglob("*") if p.is_file())
    assert names == ["000003.png", "case.json", "culane/000003.lines.txt", "culane/000003.png", "labels.json",
                     "scene.glb"]
    assert Image.open(exported / "000003.png").size == (1280, 720)
    assert Image.open(exported / "culane/000003.png").size == (1640, 590)
    assert load_case(exported / "case.json") == CASE


def test_tusimple_labels_file(exported):
    lines = (exported / "labels.json").read_text().splitlines()
    assert len(lines) == 1
    record = json.loads(lines[0])
    assert record["raw_file"] == "000003.png" and record["frame"] == 3
    assert record["h_samples"] == list(range(160, 720, 10))
    assert 2 <= len(record["lanes"]) <= 5
    assert all(len(lane) == 56 for lane in record["lanes"])


def test_culane_lines_file(exported):
    text = (exported / "culane/000003.lines.txt").read_text()
    lanes = [[float(v) for v in line.split()] for line in text.splitlines()]
    assert 2 <= len(lanes) <= 4
    for lane in lanes:
        xs, ys = np.array(lane[0::2]), np.array(lane[1::2])
        assert ys[0] <= 590 and np.all(np.diff(ys) == -10)
        assert np.all((xs >= 0) & (xs < 1640))


def _png_chunks(data: bytes) -> list[bytes]:
    chunks, pos = [], 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunks.append(kind)
        pos += 12 + length
    return chunks


def test_png_has_no_metadata():
    data = png_bytes(np.zeros((4, 5, 3), np.uint8))
    assert _png_chunks(data) == [b"IHDR", b"IDAT", b"IEND"]
    assert data == png_bytes(np.zeros((4, 5, 3), np.uint8))


def test_export_is_deterministic(exported, tmp_path):
    export_case(CASE, tmp_path, frames=[3], formats={"tusimple"}, glb=True)
    for name in ("000003.png", "labels.json", "case.json", "scene.glb"):
        assert (tmp_path / name).read_bytes() == (exported / name).read_bytes(), name
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files left behind


def test_glb_scene_is_y_up_with_road_paint_and_objects(exported):
    scene = trimesh.load(exported / "scene.glb")
    assert {"road", "paint"} <= set(scene.geometry)
    assert len(scene.geometry) > 2  # roadside objects too
    paint = scene.geometry["paint"]
    # Paint lies on the flat road: glTF y (up) is the lift; the road runs along +x, its width along glTF z = -y.
    assert np.allclose(paint.vertices[:, 1], 0.01, atol=1e-6)
    assert paint.bounds[1, 0] > 300 and np.all(np.abs(paint.vertices[:, 2]) <= 7.2)
    colors = paint.visual.vertex_colors[:, :3]
    assert {tuple(c) for c in colors} == {(178, 178, 171), (184, 117, 10)}  # white and yellow paint albedo


def test_dash_spans_follow_the_marking_period():
    spans = dash_spans(0.0, 100.0, 1, 3.0, 12.0)
    assert spans[:2] == [(0.0, 3.0), (12.0, 15.0)] and spans[-1] == (96.0, 99.0) and len(spans) == 9
    assert dash_spans(5.0, 50.0, 0, 3.0, 12.0) == [(5.0, 50.0)]


def test_paint_mesh_covers_every_stripe():
    case = Case.model_validate({"road": {"lanes_per_direction": 1}})
    vertices, faces, colors = paint_mesh(build_network(case.road, case.scene.kind), case.road.markings)
    # Edge lines and the double centre line are solid: 4 stripes of 400 quads (800 triangles) at 1 m steps.
    # The lanes_per_direction=1 road has no dashed line.
    assert len(faces) == 4 * 800 and len(colors) == len(faces)
    assert faces.max() < len(vertices)


def test_bad_arguments_are_rejected(tmp_path):
    with pytest.raises(ValueError, match="format"):
        export_case(CASE, tmp_path, frames=[0], formats={"kitti"})
    with pytest.raises(ValueError, match="frame 50"):
        export_case(CASE, tmp_path, frames=[50], formats={"tusimple"})
