"""User meshes: a case's ``vehicle.mesh_file`` read from a meshes folder (glTF, GLB, OBJ) as a local-frame ``Mesh``.

``mesh_file`` is a file NAME, never a path: ``mesh_path`` looks it up in the meshes folder the compile is given (a
case file's ``meshes/`` folder for the library and CLI, the server's uploads folder for the app) and refuses
anything else. ``pipeline.compile`` loads the meshes a case names before its illusions compile, so the illusions
read no files.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np
import trimesh

from .. import images
from ..typed import FloatArray
from .primitives import to_mesh
from .scene import Mesh

GREY = (0.3, 0.3, 0.3)  # albedo of a model's faces that carry no colour
# What a ``mesh_file`` may be: a plain file name of a model format ``load_obstacle`` reads (no folder, no "..").
MESH_SUFFIXES = ("glb", "gltf", "obj")
MESH_NAME = re.compile(rf"^[A-Za-z0-9][A-Za-z0-9._-]{{0,99}}\.({'|'.join(MESH_SUFFIXES)})$")
MESH_NAME_RULE = (f"must be a file name in the uploads folder (letters, digits, '.', '_', '-'; ending "
                  f"{', '.join('.' + suffix for suffix in MESH_SUFFIXES)}), not a path")
MAX_OBSTACLE_FACES = 60_000


def srgb_to_linear(rgb8: FloatArray) -> FloatArray:
    """(..., 3) sRGB 0-255 -> linear [0, 1]."""
    return images.srgb_to_linear(np.asarray(rgb8, np.float64) / 255.0)


def _face_colors(geometry: trimesh.Trimesh) -> FloatArray:
    """(m, 3) linear albedo per face from a loaded mesh's visual: face or vertex colours, the texture
    sampled at the vertices, the material's base colour, else grey."""
    visual: Any = geometry.visual  # one of several visual kinds, told apart by .kind
    faces = geometry.faces
    try:
        if visual.kind == "face":
            return srgb_to_linear(visual.face_colors[:, :3])
        if visual.kind == "vertex":
            return srgb_to_linear(visual.vertex_colors[faces][:, :, :3].mean(1))
        if visual.kind == "texture":
            material = getattr(visual, "material", None)
            if getattr(visual, "uv", None) is not None and getattr(material, "image", None) is not None:
                colors = visual.to_color().vertex_colors
                return srgb_to_linear(colors[faces][:, :, :3].mean(1))
            if material is not None:
                return np.broadcast_to(srgb_to_linear(np.asarray(material.main_color)[:3]), (len(faces), 3))
    except (AttributeError, ValueError, IndexError, ImportError):
        pass
    return np.broadcast_to(np.asarray(GREY, np.float64), (len(faces), 3))


def is_mesh_name(name: str) -> bool:
    """Whether ``name`` is an acceptable ``mesh_file``: a plain model file name (``MESH_NAME``, no "..")."""
    return bool(MESH_NAME.match(name)) and ".." not in name


def mesh_path(meshes_dir: Path | None, name: str) -> Path:
    """The file ``name`` in ``meshes_dir``; ``ValueError`` for a name that is no plain model name, no folder, a
    path resolving outside the folder (a link pointing away) or a missing file."""
    if not is_mesh_name(name):
        raise ValueError(f"{name!r} {MESH_NAME_RULE}")
    if meshes_dir is None:
        raise ValueError(f"{name!r}: no meshes folder to read it from")
    folder = Path(meshes_dir).resolve()
    path = (folder / name).resolve()
    if not path.is_relative_to(folder):
        raise ValueError(f"{name!r} resolves outside the meshes folder")
    if not path.is_file():
        raise ValueError(f"{name!r} is not in the meshes folder (upload it first)")
    return path


def load_obstacle(path: str | Path, *, up: Literal["y", "z"] = "y", max_faces: int = MAX_OBSTACLE_FACES,
                  name: str | None = None) -> Mesh:
    """A user's glTF/GLB/OBJ model as a local-frame ``Mesh``: footprint centred on the origin, resting on z = 0,
    +X forward.

    ``up="y"`` converts glTF's convention (+Y up, +Z forward) to this frame; ``up="z"`` keeps the axes. Colours
    come per face from the file (sRGB converted to linear), grey where it has none.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"obstacle model not found: {path.name}")
    parts = _model_parts(path)
    if not parts:
        raise ValueError(f"{path.name}: no triangles in the model")
    faces = sum(len(g.faces) for g in parts)
    if faces > max_faces:
        raise ValueError(f"{path.name}: {faces} triangles, more than the {max_faces} the renderer takes per obstacle")
    vertices, tris, colors, offset = [], [], [], 0
    for g in parts:
        vertices.append(np.asarray(g.vertices, np.float64))
        tris.append(np.asarray(g.faces, np.int64) + offset)
        colors.append(_face_colors(g))
        offset += len(g.vertices)
    p = np.concatenate(vertices)
    if up == "y":  # (x, y, z) glTF -> +X forward (glTF +Z), +Y left (glTF +X), +Z up (glTF +Y)
        p = np.stack([p[:, 2], p[:, 0], p[:, 1]], axis=1)
    lo, hi = p.min(0), p.max(0)
    p = p - [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]]
    mesh = to_mesh(trimesh.Trimesh(p, np.concatenate(tris), process=False), np.concatenate(colors),
                   name=name or path.stem, kind="obstacle", gloss=0.3)
    return mesh


def _model_parts(path: Path) -> list[trimesh.Trimesh]:
    """The triangle meshes of a model file; ``ValueError`` naming the file (by its base name, never its folder)
    for anything trimesh cannot read. trimesh's own messages are not passed on: they quote folders and its API."""
    try:
        scene = cast(trimesh.Scene, trimesh.load(str(path), force="scene"))
        return [g for g in scene.dump(concatenate=False) if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    except Exception as error:  # trimesh raises many kinds (KeyError, IndexError, RecursionError ...)  # noqa: BLE001
        raise ValueError(f"{path.name}: not a readable {path.suffix.lstrip('.')} model") from error
