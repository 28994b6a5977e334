"""Compile a case into the scene the renderer draws: road, roadside, illusions, lights, environment."""

from __future__ import annotations

import numpy as np

from .case import Case
from .environment import environment_for
from .illusions import CompileContext
from .road_layout import build_network
from .scene import CompiledScene
from .scenery import roadside_meshes


def compile_scene(case: Case) -> CompiledScene:
    """Build the network, the roadside props and every illusion's scene elements."""
    network = build_network(case.road, case.scene.kind)
    ctx = CompileContext(case=case, network=network, env=environment_for(case))
    ctx.meshes.extend(roadside_meshes(case, network, np.random.default_rng([case.seed, 0])))
    for index, illusion in enumerate(case.illusions):
        ctx.source = index
        illusion.compile(ctx)
    return CompiledScene(case=case, network=network, env=ctx.env, meshes=ctx.meshes, layers=ctx.layers,
                         lights=ctx.lights)
