"""Compiled scenes for the editor, reusing the roadside while only illusions, sun or weather change.

``compile_scene`` spends most of its time on the roadside props (``scenery.roadside_meshes``), which depend only on
the road, the scene kind and density, the seed, the ego's start and whether it is night. Scrubbing a severity or
the sun changes none of those, so the editor keeps the last network and roadside and re-runs only the
environment and the illusions, in the same order as ``compile_scene`` (so the result is the same scene).
Every scene is put into the frame service's scene cache, where the REST API finds it too.
"""

from __future__ import annotations

import hashlib
import json
import threading

from lanevil_core.case import Case
from lanevil_core.compile import compile_scene
from lanevil_core.environment import environment_for
from lanevil_core.illusions import CompileContext
from lanevil_core.scene import CompiledScene, Mesh

from ..frames import FrameService, case_hash

NIGHT_ALTITUDE_DEG = -2.0  # matches environment_for: lamps glow at or below this sun altitude


def roadside_key(case: Case) -> str:
    """Identity of what the roadside props depend on."""
    data = {"road": case.road.model_dump(mode="json"), "scene": case.scene.model_dump(mode="json"),
            "seed": case.seed, "ego": case.ego.model_dump(mode="json"),
            "night": case.sun.altitude <= NIGHT_ALTITUDE_DEG}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode("utf-8")).hexdigest()


class SceneCompiler:
    """Compiles cases for the editor's preview and 3D view (thread-safe)."""

    def __init__(self, frames: FrameService) -> None:
        self.frames = frames
        self._lock = threading.Lock()
        self._roadside: tuple[str, CompiledScene] | None = None
        self.full_compiles = 0
        self.partial_compiles = 0

    def scene(self, case: Case) -> CompiledScene:
        """The compiled scene of ``case``, from the frame service's cache or compiled (partly) here."""
        key = case_hash(case)
        cached = self.frames.scenes.get(key)
        if cached is None:
            cached = self._compile(case)
            self.frames.scenes.put(key, cached)
        return cached

    def _compile(self, case: Case) -> CompiledScene:
        side_key = roadside_key(case)
        with self._lock:
            previous = self._roadside
        if previous is None or previous[0] != side_key:
            scene = compile_scene(case)
            self.full_compiles += 1
        else:
            scene = _recompile_illusions(case, previous[1])
            self.partial_compiles += 1
        with self._lock:
            self._roadside = (side_key, scene)
        return scene


def _roadside_meshes(scene: CompiledScene) -> list[Mesh]:
    return [mesh for mesh in scene.meshes if mesh.source < 0]


def _recompile_illusions(case: Case, base: CompiledScene) -> CompiledScene:
    """``compile_scene(case)`` for a case whose roadside equals ``base``'s: the environment and illusions anew."""
    ctx = CompileContext(case=case, network=base.network, env=environment_for(case))
    ctx.meshes.extend(_roadside_meshes(base))
    for index, illusion in enumerate(case.illusions):
        ctx.source = index
        illusion.compile(ctx)
    return CompiledScene(case=case, network=base.network, env=ctx.env, meshes=ctx.meshes, layers=ctx.layers,
                         lights=ctx.lights)

