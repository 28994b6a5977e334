"""User meshes for a vehicle's ``mesh_file``, kept in ``<data dir>/uploads``: the API (``POST /api/meshes``) and the
editor's upload button store them through ``store_mesh``, which takes only a model that loads (``load_obstacle``,
at most ``MAX_OBSTACLE_FACES`` triangles) under a checked plain name, written atomically. A name is never reused for
other bytes (409), so frames cached for a case that names it stay right.
"""

from __future__ import annotations

import os
import re
import struct
import tempfile
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

from lanevil_core.illusions.traffic import MESH_NAME_RULE, MESH_SUFFIXES, is_mesh_name, load_obstacle

GLTF_SUFFIXES = ("gltf", "glb")
MAX_GLTF_DEPTH = 64  # exporters write glTF JSON a handful of levels deep (its ``extras`` a few more)
GLB_HEADER = struct.Struct("<4sIIII")  # magic, version, total length; the first chunk's length and type
GLB_JSON_CHUNK = 0x4E4F534A  # "JSON" as a little-endian uint32


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
    if suffix in GLTF_SUFFIXES:
        _check_embedded(gltf_document(data, suffix, name), name)
    target = uploads / name
    if target.exists():
        if target.read_bytes() == data:
            return name
        raise MeshUploadError(409, f"a different mesh is stored as {name}: upload it under another name")
    uploads.mkdir(parents=True, exist_ok=True)
    _write_checked(uploads, target, data)
    return name


def gltf_document(data: bytes, suffix: str, name: str) -> Any:
    """The JSON document of a ``.gltf`` file or of a ``.glb``'s first chunk, read strictly (UTF-8, at most
    ``MAX_GLTF_DEPTH`` levels deep, no NaN): a 422 ``MeshUploadError`` for anything else, before the model loader
    sees it (Python's ``json`` recurses once per level, so a deeply nested document would exhaust the stack)."""
    from .api.json_body import BodyError, parse_json  # the api package imports this module

    text = data
    if suffix == "glb":
        magic, _, _, length, kind = struct.unpack_from("<4sIIII", data.ljust(GLB_HEADER.size, b"\0"))
        if magic != b"glTF" or kind != GLB_JSON_CHUNK or length > len(data) - GLB_HEADER.size:
            raise MeshUploadError(422, f"{name} is not a binary glTF (GLB) file: no glTF header and JSON chunk")
        text = data[GLB_HEADER.size:GLB_HEADER.size + length]
    try:
        return parse_json(text, name, max_depth=MAX_GLTF_DEPTH)
    except BodyError as error:
        raise MeshUploadError(422, f"{name} is not usable glTF JSON: {error}") from None


def _check_embedded(document: Any, name: str) -> None:
    """A glTF must carry its buffers and images inline (``data:`` URIs, or a ``.glb``'s own binary chunk): it is
    read alone, never with files it names on the server."""
    if not isinstance(document, dict):
        raise MeshUploadError(422, f"{name}: its glTF JSON is not an object")
    parts = [part for key in ("buffers", "images") for part in _as_list(document.get(key))]
    if any(not isinstance(part, dict) or not str(part.get("uri", "data:")).startswith("data:") for part in parts):
        raise MeshUploadError(422, f"{name} refers to other files: embed its buffers and images (or upload a .glb)")


def _as_list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else [] if value is None else [value]


def _write_checked(uploads: Path, target: Path, data: bytes) -> None:
    """Write ``data`` beside ``target``, load it as an obstacle, then rename it into place (or remove it)."""
    handle, temp_name = tempfile.mkstemp(dir=uploads, prefix=".upload-", suffix=target.suffix)
    temp = Path(temp_name)
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        try:
            load_obstacle(temp, name=target.stem)
        except ValueError as error:  # its message names the file by its base name alone, never the folder
            message = str(error).replace(temp.name, target.name)
            raise MeshUploadError(422, f"{target.name} is not a usable model: {message}") from None
        os.replace(temp, target)
    finally:
        temp.unlink(missing_ok=True)
