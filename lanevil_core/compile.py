"""Compile a case into the scene the renderer draws: road, roadside, illusions, lights, environment."""

from __future__ import annotations

import hashlib
import json

import numpy as np

from .camera import ego_path
from .case import Case
from .environment import environment_for, is_night
from .illusions import CompileContext
from .paint import road_paint
from .road_layout import RoadNetwork, build_network
from .scene import CompiledScene, Mesh
from .scenery import roadside_meshes


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


def compile_scene(case: Case, reuse: CompiledScene | None = None) -> CompiledScene:
    """Build the network, the roadside props and every illusion's scene elements.

    With ``reuse`` (an earlier scene whose ``roadside_key`` matches), its network and roadside meshes are taken
    as they are and only the environment and illusions are compiled anew; the result equals a full compile.
    """
    network, roadside = _roadside(case, reuse)
    ctx = CompileContext(case=case, network=network, env=environment_for(case))
    ctx.meshes.extend(roadside)
    for index, illusion in enumerate(case.illusions):
        ctx.source = index
        illusion.compile(ctx)
    return CompiledScene(case=case, network=network, env=ctx.env, paint=road_paint(case.road),
                         ego=ego_path(case, network), meshes=ctx.meshes, layers=ctx.layers, lights=ctx.lights)
