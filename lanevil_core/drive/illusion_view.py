"""Where along the road a case's illusions lie, and when a drive first has them in view.

An illusion's span is the stretch of the main road its scene elements cover: its surface layers, its meshes (the
stations of their vertices) and its lamps. An illusion that only changes the environment (sun, wetness) spans the
whole road. It is in view once the camera is within ``VIEW_RANGE_M`` of the span's start (beyond that it covers
a few pixel rows near the horizon).
"""

from __future__ import annotations

import numpy as np

from ..typed import FloatArray
from ..world.scene import CompiledScene

VIEW_RANGE_M = 50.0
VERTICES_PER_MESH = 64  # vertices sampled per mesh for its stations


def _stations(scene: CompiledScene, p_world: FloatArray) -> list[float]:
    line = scene.network.main.line
    return [line.station(point)[0] for point in p_world]


def illusion_span(scene: CompiledScene) -> tuple[float, float] | None:
    """(s_start, s_end) of the main road covered by the case's illusions, None for a case without any."""
    if not scene.case.illusions:
        return None
    stations: list[float] = []
    for layer in scene.layers:
        if layer.source >= 0 and layer.piece == 0:
            stations += [layer.s0, layer.s0 + layer.rgba.shape[0] * layer.texel]
    for mesh in scene.meshes:
        if mesh.source >= 0 and len(mesh.vertices):
            step = max(1, len(mesh.vertices) // VERTICES_PER_MESH)
            stations += _stations(scene, mesh.vertices[::step])
    for light in scene.lights:
        if light.source >= 0:
            stations += _stations(scene, np.asarray(light.p_world)[None])
    if not stations:
        return 0.0, float(scene.network.main.line.length)
    return float(min(stations)), float(max(stations))


def in_view(span: tuple[float, float], s_camera: float) -> bool:
    """Whether an illusion spanning ``span`` is in view of a camera at station ``s_camera``."""
    return span[0] - VIEW_RANGE_M <= s_camera <= span[1]
