"""Compile a case into the scene the renderer draws: road, roadside, illusions, lights, environment."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ..camera import ego_path
from ..case import Case
from ..illusions import CompileContext, EgoDrive, MeshFileError
from ..illusions.traffic import mesh_path
from ..world.environment import environment_for, in_proportion, is_night
from ..world.paint import road_paint
from ..world.road_layout import RoadNetwork, build_network
from ..world.scene import CompiledScene, Mesh
from ..world.scenery import roadside_meshes, street_lamps


def roadside_key(case: Case) -> str:
    """Identity of what the road network and the roadside props depend on (road, scene, seed, ego, day/night).

    Two cases with the same key differ only in environment and illusions (a scrubbed severity, a moved sun)."""
    data = {"road": case.road.model_dump(mode="json"), "scene": case.scene.model_dump(mode="json"),
            "seed": case.seed, "ego": case.ego.model_dump(mode="json"), "night": is_night(case.sun.altitude)}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode("utf-8")).hexdigest()


def _roadside(case: Case, reuse: CompiledScene | None) -> tuple[RoadNetwork, list[Mesh]]:
    if reuse is not None and roadside_key(reuse.case) == roadside_key(case):
        return reuse.network, [mesh for mesh in reuse.meshes if mesh.source < 0]
    network = build_network(case.road, case.scene.kind)
    return network, roadside_meshes(case, network, np.random.default_rng([case.seed, 0]))


def mesh_files(case: Case) -> list[tuple[str, str]]:
    """(field path, file name) of every user mesh the case names (``illusions.N.vehicle.mesh_file``, the path
    pydantic's errors give)."""
    named = [(f"illusions.{index}.{illusion.type}.mesh_file", getattr(illusion, "mesh_file", None))
             for index, illusion in enumerate(case.illusions)]
    return [(field, name) for field, name in named if name]


def check_mesh_files(case: Case, meshes_dir: Path | None) -> None:
    """``MeshFileError`` naming the first ``mesh_file`` that is not a file in ``meshes_dir`` (without loading it)."""
    for field, name in mesh_files(case):
        try:
            mesh_path(meshes_dir, name)
        except ValueError as error:
            raise MeshFileError(field, str(error)) from None


def ego_drive(case: Case) -> EgoDrive:
    """What the illusions read of the case's ego: its lane and its drive along the main road."""
    return EgoDrive(lane=case.ego.lane, start_s=case.ego.start_s, end_s=case.ego_s(case.ego.frames - 1),
                    road_length=case.road.length)


def compile_scene(case: Case, reuse: CompiledScene | None = None, *, meshes_dir: Path | None = None) -> CompiledScene:
    """Build the network, the roadside props and every illusion's scene elements.

    ``meshes_dir`` is the folder a vehicle's ``mesh_file`` is read from (``case_meshes_dir`` of a case file; the
    server's uploads folder); a case naming a mesh file without one raises ``MeshFileError``.

    With ``reuse`` (an earlier scene whose ``roadside_key`` matches), its network and roadside meshes are taken
    as they are and only the environment and illusions are compiled anew; the result equals a full compile.
    """
    network, roadside = _roadside(case, reuse)
    ctx = CompileContext(seed=case.seed, drive=ego_drive(case), network=network, env=environment_for(case),
                         meshes_dir=meshes_dir)
    ctx.meshes.extend(roadside)
    ctx.lights.extend(street_lamps(case, network))  # lit at night only
    case_sun = ctx.env.sun_intensity
    for index, illusion in enumerate(case.illusions):
        ctx.source = index
        illusion.compile(ctx)
    if case.camera.sensor is not None:  # a photograph: sun and sky in daylight's proportion for the final sun
        in_proportion(ctx.env, air_mass=ctx.env.sun_intensity == case_sun)
    return CompiledScene(case=case, network=network, env=ctx.env, paint=road_paint(case.road),
                         ego=ego_path(case, network), meshes=ctx.meshes, layers=ctx.layers, lights=ctx.lights)
