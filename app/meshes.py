"""User meshes for a vehicle's ``mesh_file``, kept in ``<data dir>/uploads``: the API (``POST /api/meshes``) and the
editor's upload button store them through ``store_mesh``, which takes only a model that loads (``load_obstacle``,
at most ``MAX_OBSTACLE_FACES`` triangles) under a checked plain name, written atomically. A name is never reused for
other bytes (409), so frames cached for a case that names it stay right.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

from lanevil_core.illusions.traffic import MESH_NAME_RULE, MESH_SUFFIXES, is_mesh_name, load_obstacle


class MeshUploadError(ValueError):
    """An upload that is not stored: ``status`` (409, 413, 415 or 422) and a message."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def mesh_name(filename: str) -> str:
    """The name an upload is stored under: its base name (no folders), other characters than letters, digits,
    ``.``, ``_``, ``-`` as ``_``, leading dots and dashes dropped."""
    base = PureWindowsPath(PurePosixPath(filename or "").name).name
    return re.sub(r"[^A-Za-z0-9._-]", "_", base).lstrip("._-")


def legacy_mesh_files(document: Any) -> Any:
    """A stored case document whose ``mesh_file`` paths (written before it became a name) are turned into names:
    the sanitised base name, ``.glb`` added when it names no model format. Such a case still opens; its frames
    answer 422 until a model of that name is uploaded."""
    if not isinstance(document, dict) or not isinstance(document.get("illusions"), list):
        return document
    illusions = []
    for illusion in document["illusions"]:
        name = illusion.get("mesh_file") if isinstance(illusion, dict) else None
        if isinstance(name, str) and not is_mesh_name(name):
            fixed = mesh_name(name).replace("..", "_") or "mesh"
            illusion = {**illusion, "mesh_file": fixed if is_mesh_name(fixed) else f"{fixed[:95]}.glb"}
        illusions.append(illusion)
    return {**document, "illusions": illusions}


def list_meshes(uploads: Path) -> list[str]:
    """Names of the stored meshes, sorted."""
    if not uploads.is_dir():
        return []
    return sorted(path.name for path in uploads.iterdir() if path.is_file() and is_mesh_name(path.name))


def store_mesh(uploads: Path, filename: str, data: bytes, max_bytes: int) -> str:
    """Check ``data`` and store it in ``uploads`` as ``mesh_name(filename)``; return that name."""
    name = mesh_name(filename)
    suffix = name.rpartition(".")[2].lower() if "." in name else ""
    if suffix not in MESH_SUFFIXES:
        raise MeshUploadError(415, f"{filename!r}: send a {', '.join('.' + s for s in MESH_SUFFIXES)} model")
    if not is_mesh_name(name):
        raise MeshUploadError(422, f"{filename!r} {MESH_NAME_RULE}")
    if len(data) > max_bytes:
        raise MeshUploadError(413, f"{name} is over {max_bytes} bytes")
    if suffix == "gltf":
        _check_embedded(data, name)
    target = uploads / name
    if target.exists():
        if target.read_bytes() == data:
            return name
        raise MeshUploadError(409, f"a different mesh is stored as {name}: upload it under another name")
    uploads.mkdir(parents=True, exist_ok=True)
    _write_checked(uploads, target, data)
    return name


def _check_embedded(data: bytes, name: str) -> None:
    """A ``.gltf`` must carry its buffers and images inline (``data:`` URIs): it is read alone, never with files it
    names on the server."""
    try:
        document = json.loads(data)
    except (UnicodeDecodeError, ValueError):
        raise MeshUploadError(422, f"{name} is not glTF JSON") from None
    parts = [*document.get("buffers", []), *document.get("images", [])] if isinstance(document, dict) else []
    if any(isinstance(part, dict) and not str(part.get("uri", "data:")).startswith("data:") for part in parts):
        raise MeshUploadError(422, f"{name} refers to other files: embed its buffers and images (or upload a .glb)")


def _write_checked(uploads: Path, target: Path, data: bytes) -> None:
    """Write ``data`` beside ``target``, load it as an obstacle, then rename it into place (or remove it)."""
    handle, temp_name = tempfile.mkstemp(dir=uploads, prefix=".upload-", suffix=target.suffix)
    temp = Path(temp_name)
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        try:
            load_obstacle(temp)
        except Exception as error:  # trimesh raises many kinds for a file that is not a model  # noqa: BLE001
            message = str(error).replace(str(temp), target.name)
            raise MeshUploadError(422, f"{target.name} is not a usable model: {message}") from None
        os.replace(temp, target)
    finally:
        temp.unlink(missing_ok=True)
