"""Compiled scenes for the editor, reusing the roadside while only illusions, sun or weather change.

``compile_scene`` spends most of its time on the roadside props (``scenery.roadside_meshes``), which depend only on
the road, the scene kind and density, the seed, the ego's start and whether it is night (``roadside_key``).
Scrubbing a severity or the sun changes none of those, so the editor keeps the last scene and passes it to
``compile_scene(case, reuse=...)``, which compiles only the environment and the illusions anew.
Every scene is put into the frame service's scene cache, where the REST API finds it too.
"""

from __future__ import annotations

import threading

from lanevil_core.case import Case
from lanevil_core.compile import compile_scene, roadside_key
from lanevil_core.scene import CompiledScene

from ..frames import FrameService, case_hash


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
        reuse = previous[1] if previous is not None and previous[0] == side_key else None
        scene = compile_scene(case, reuse=reuse)
        if reuse is None:
            self.full_compiles += 1
        else:
            self.partial_compiles += 1
        with self._lock:
            self._roadside = (side_key, scene)
        return scene

