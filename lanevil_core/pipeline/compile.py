"""Compile a case into the scene the renderer draws: road, roadside, illusions, lights, environment."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ..camera import ego_path
from ..case import Case
from ..illusions import CompileContext, EgoDrive, MeshFileError
from ..world.environment import environment_for, in_proportion, is_night
from ..world.paint import road_paint
from ..world.road_layout import RoadNetwork, build_network
from ..world.scene import CompiledScene, Environment, Mesh
from ..world.scenery import RoadsideInputs, roadside_meshes, street_lamps
from ..world.user_meshes import load_obstacle, mesh_path


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
    return network, roadside_meshes(roadside_inputs(case), network, np.random.default_rng([case.seed, 0]))


def _named_meshes(case: Case) -> list[tuple[int, str, str]]:
    """(illusion index, field path, file name) of every user mesh the case names."""
    named = [(index, f"illusions.{index}.{illusion.type}.mesh_file", getattr(illusion, "mesh_file", None))
             for index, illusion in enumerate(case.illusions)]
    return [(index, field, name) for index, field, name in named if name]


def mesh_files(case: Case) -> list[tuple[str, str]]:
    """(field path, file name) of every user mesh the case names (``illusions.N.vehicle.mesh_file``, the path
    pydantic's errors give)."""
    return [(field, name) for _index, field, name in _named_meshes(case)]


def check_mesh_files(case: Case, meshes_dir: Path | None) -> None:
    """``MeshFileError`` naming the first ``mesh_file`` that is not a file in ``meshes_dir`` (without loading it)."""
    load_user_meshes(case, meshes_dir, read=False)


def load_user_meshes(case: Case, meshes_dir: Path | None, read: bool = True) -> dict[int, Mesh]:
    """Illusion index -> the model its ``mesh_file`` names, read from ``meshes_dir`` (``world.user_meshes``);
    ``MeshFileError`` naming the field of the first that is missing or unreadable. With ``read=False`` the files
    are only looked up (and the dict stays empty)."""
    meshes: dict[int, Mesh] = {}
    for index, field, name in _named_meshes(case):
        try:
            path = mesh_path(meshes_dir, name)
            if read:
                meshes[index] = load_obstacle(path)
        except (OSError, ValueError) as error:
            raise MeshFileError(field, str(error)) from None
    return meshes


def ego_drive(case: Case) -> EgoDrive:
    """What the illusions read of the case's ego: its lane and its drive along the main road."""
    return EgoDrive(lane=case.ego.lane, start_s=case.ego.start_s, end_s=case.ego_s(case.ego.frames - 1),
                    road_length=case.road.length)


def roadside_inputs(case: Case) -> RoadsideInputs:
    """What the roadside reads of the case: its scene, night or day, the ego's drive, the junction (every one of
    them is part of ``roadside_key``)."""
    drive = ego_drive(case)
    return RoadsideInputs(kind=case.scene.kind, density=case.scene.density, night=is_night(case.sun.altitude),
                          start_s=drive.start_s, end_s=drive.end_s, junction_s=case.road.junction_s)


def case_environment(case: Case) -> Environment:
    """The case's sun, sky, wetness and fog before its illusions change them; photographed when its camera has a
    sensor."""
    return environment_for(case.weather, case.sun, photographed=case.camera.sensor is not None)


def _sun_of(env: Environment) -> tuple[float, ...]:
    """What an illusion may do to the sun: its direction, its strength, night."""
    return (*(float(v) for v in env.sun_dir_world), float(env.sun_intensity), float(env.night))


def compile_scene(case: Case, reuse: CompiledScene | None = None, *, meshes_dir: Path | None = None) -> CompiledScene:
    """Build the network, the roadside props and every illusion's scene elements.

    ``meshes_dir`` is the folder a vehicle's ``mesh_file`` is read from (``case_meshes_dir`` of a case file; the
    server's uploads folder); a case naming a mesh file without one raises ``MeshFileError``.

    With ``reuse`` (an earlier scene whose ``roadside_key`` matches), its network and roadside meshes are taken
    as they are and only the environment and illusions are compiled anew; the result equals a full compile.
    """
    network, roadside = _roadside(case, reuse)
    ctx = CompileContext(seed=case.seed, drive=ego_drive(case), network=network, env=case_environment(case),
                         user_meshes=load_user_meshes(case, meshes_dir), case_sun_altitude=case.sun.altitude)
    ctx.meshes.extend(roadside)
    ctx.lights.extend(street_lamps(roadside_inputs(case), network))  # lit at night only
    case_sun = ctx.env.sun_intensity
    for index, illusion in enumerate(case.illusions):
        ctx.source = index
        sun_before = _sun_of(ctx.env)
        illusion.compile(ctx)
        if _sun_of(ctx.env) != sun_before:
            ctx.env.sun_set_by = (*ctx.env.sun_set_by, index)
    if case.camera.sensor is not None:  # a photograph: sun and sky in daylight's proportion for the final sun
        in_proportion(ctx.env, air_mass=ctx.env.sun_intensity == case_sun)
    return CompiledScene(case=case, network=network, env=ctx.env, paint=road_paint(case.road, case.seed),
                         ego=ego_path(case, network), meshes=ctx.meshes, layers=ctx.layers, lights=ctx.lights)
