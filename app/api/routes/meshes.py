"""``/api/meshes``: upload a glTF/GLB/OBJ model for a vehicle's ``mesh_file`` and list the uploaded ones."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Request
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel
from starlette.datastructures import UploadFile

from lanevil_core.illusions.traffic import MAX_OBSTACLE_FACES

from ...meshes import MAX_GLTF_DEPTH, MeshUploadError, list_meshes, store_mesh
from ..deps import StateDep
from ..errors import ERROR_RESPONSES, ApiError, ApiRoute, ErrorBody
from ..forms import read_form


class MeshList(BaseModel):
    """The uploaded models' names."""

    data: list[str]
    count: int


class MeshStored(BaseModel):
    """The name a model was stored under, and every uploaded name."""

    name: str
    meshes: list[str]


router = APIRouter(prefix="/meshes", tags=["meshes"], route_class=ApiRoute, responses=ERROR_RESPONSES)

# The file's name says its format (``.glb``, ``.gltf``, ``.obj``; any other is a 415), its part's media type is
# not read; the example file name is what clients generated from the description send.
MODEL_MEDIA_TYPES = "model/gltf-binary, model/gltf+json, model/obj, application/octet-stream"
UPLOAD_BODY: dict[str, Any] = {"requestBody": {"required": True, "content": {"multipart/form-data": {
    "schema": {"type": "object", "required": ["file"], "additionalProperties": False, "properties": {"file": {
        "type": "string", "format": "binary", "contentMediaType": "model/gltf-binary",
        "description": f"a model that loads, at most {MAX_OBSTACLE_FACES} triangles, whose file name ends .glb, "
                       ".gltf (buffers and images embedded) or .obj; a .gltf/.glb's JSON at most "
                       f"{MAX_GLTF_DEPTH} levels deep"}}},
    "encoding": {"file": {"contentType": MODEL_MEDIA_TYPES, "headers": {"Content-Disposition": {
        "schema": {"type": "string"}, "example": 'form-data; name="file"; filename="model.glb"'}}}}}}}}


@router.get("", summary="List uploaded meshes")
def get_meshes(state: StateDep) -> MeshList:
    """Names of the uploaded meshes: what a vehicle's ``mesh_file`` may name."""
    names = list_meshes(state.meshes_dir)
    return MeshList(data=names, count=len(names))


@router.post("", status_code=201, summary="Upload a mesh", openapi_extra=UPLOAD_BODY,
             responses={status: {"model": ErrorBody, "description": description} for status, description in (
                 (409, "another mesh is stored under that name"), (413, "the file is over the upload limit"),
                 (415, "not a .glb, .gltf or .obj file"))})
async def upload_mesh(request: Request, state: StateDep) -> MeshStored:
    """Store a model (multipart field ``file``) in the uploads folder under a checked name; a vehicle's
    ``mesh_file`` may then name it. The model must load and have at most 60,000 triangles."""
    form = await read_form(request, max_files=1)
    upload = form.get("file")
    if not isinstance(upload, UploadFile):
        raise ApiError(422, "send the model as the multipart file field 'file'", "file")
    limit = state.settings.max_upload_bytes
    data = await upload.read(limit + 1)
    try:
        name = await run_in_threadpool(store_mesh, state.meshes_dir, upload.filename or "", data, limit)
    except MeshUploadError as error:
        raise ApiError(error.status, str(error), "file") from None
    return MeshStored(name=name, meshes=list_meshes(state.meshes_dir))
