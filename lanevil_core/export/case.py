"""Export a case's frames with lane labels (TuSimple, CULane) and its 3D scene (glTF binary).

Layout of an export folder ``DIR``::

    DIR/case.json                  the case, canonical JSON
    DIR/000000.png ...             1280x720 frames (TuSimple)
    DIR/labels.json                TuSimple JSON lines, ``raw_file`` relative to DIR
    DIR/culane/000000.png ...      1640x590 frames (CULane)
    DIR/culane/000000.lines.txt    CULane lanes of each frame
    DIR/scene.glb                  road surface, paint and objects (glTF, +Y up)

Every file is written atomically and byte-for-byte deterministically (PNG without timestamps or text chunks).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Collection, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh

from ..case import Case, case_json
from ..files import write_atomic
from ..images import png_bytes
from ..labels.lanes import CULANE_SIZE, TUSIMPLE_SIZE, culane_lines, tusimple_record
from ..pipeline.compile import compile_scene
from ..render import render_frame
from ..typed import Float32Array, FloatArray, IntArray
from ..world.paint import road_albedo
from ..world.primitives import flat_trimesh
from ..world.road_mesh import road_surface
from ..world.scene import CompiledScene

FORMATS: tuple[str, ...] = ("tusimple", "culane")
# glTF is +Y up: world (x, y, z) -> glTF (x, z, -y).
R_GLTF_WORLD = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

Progress = Callable[[int, int], None]


@dataclass
class ExportResult:
    """What an export wrote (paths relative to its folder)."""

    out_dir: Path
    files: list[str] = field(default_factory=list)


def _check_formats(formats: Collection[str]) -> None:
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown:
        raise ValueError(f"unknown export format {unknown[0]!r} (choose from {', '.join(FORMATS)})")


def _check_frames(case: Case, frames: Iterable[int]) -> list[int]:
    chosen = list(frames)
    bad = [n for n in chosen if not 0 <= n < case.ego.frames]
    if bad:
        raise ValueError(f"frame {bad[0]} is outside 0..{case.ego.frames - 1}")
    return chosen


def _write(result: ExportResult, relative: str, data: bytes) -> None:
    write_atomic(result.out_dir / relative, data)
    result.files.append(relative)


def _export_tusimple(scene: CompiledScene, frame_index: int, result: ExportResult) -> str:
    """Render and write one 1280x720 frame; return its TuSimple JSON line."""
    frame = render_frame(scene, frame_index, TUSIMPLE_SIZE)
    name = f"{frame_index:06d}.png"
    _write(result, name, png_bytes(frame.rgb))
    return json.dumps(tusimple_record(scene, frame_index, frame, name))


def _export_culane(scene: CompiledScene, frame_index: int, result: ExportResult) -> None:
    frame = render_frame(scene, frame_index, CULANE_SIZE)
    stem = f"culane/{frame_index:06d}"
    _write(result, f"{stem}.png", png_bytes(frame.rgb))
    _write(result, f"{stem}.lines.txt", culane_lines(scene, frame).encode("utf-8"))


def export_case(
    case: Case,
    out_dir: str | Path,
    frames: Iterable[int] | None = None,
    formats: Collection[str] = frozenset({"tusimple", "culane"}),
    glb: bool = False,
    progress: Progress | None = None,
    meshes_dir: Path | None = None,
) -> ExportResult:
    """Render ``frames`` (default: all) of ``case`` into ``out_dir`` with labels in ``formats``.

    ``progress(done, total)`` is called after every frame; a vehicle's ``mesh_file`` is read from ``meshes_dir``.
    """
    _check_formats(formats)
    chosen = _check_frames(case, range(case.ego.frames) if frames is None else frames)
    result = ExportResult(Path(out_dir))
    scene = compile_scene(case, meshes_dir=meshes_dir)
    _write(result, "case.json", case_json(case).encode("utf-8"))
    records = []
    for done, frame_index in enumerate(chosen, start=1):
        if "tusimple" in formats:
            records.append(_export_tusimple(scene, frame_index, result))
        if "culane" in formats:
            _export_culane(scene, frame_index, result)
        if progress is not None:
            progress(done, len(chosen))
    if "tusimple" in formats:
        _write(result, "labels.json", "".join(line + "\n" for line in records).encode("utf-8"))
    if glb:
        _write(result, "scene.glb", scene_glb(scene))
    return result


def _gltf(vertices: FloatArray, faces: IntArray, colors: Float32Array) -> trimesh.Trimesh:
    """A flat-coloured mesh in glTF axes."""
    return flat_trimesh(np.asarray(vertices, np.float64) @ R_GLTF_WORLD.T, faces, colors)


def scene_glb(scene: CompiledScene) -> bytes:
    """The compiled 3D scene (road surface, paint, visible objects) as glTF binary bytes, +Y up."""
    gltf_scene = trimesh.Scene()
    road = road_surface(scene.network)
    gltf_scene.add_geometry(_gltf(road.vertices, road.faces, road_albedo(scene.network)[road.material]),
                            geom_name="road", node_name="road")
    paint = scene.paint.mesh(scene.network)
    if len(paint[1]):
        gltf_scene.add_geometry(_gltf(*paint), geom_name="paint", node_name="paint")
    for index, mesh in enumerate(scene.meshes):
        if mesh.visible and len(mesh.faces):
            name = f"{index:04d}_{mesh.name}"
            gltf_scene.add_geometry(_gltf(mesh.vertices, mesh.faces, mesh.colors),
                                    geom_name=name, node_name=name)
    return gltf_scene.export(file_type="glb")
