"""Leaves lit as a volume: wrapped sunlight past a crown's terminator, light through the leaves, sky from all round."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lanevil_core.case import parse_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.foliage import LEAF_WRAP, leaf_cosine, leaf_sky, leaf_transmission
from lanevil_core.world import facade
from lanevil_core.world.scene import FIRST_OBJECT_ID


def test_leaves_take_the_sun_past_the_outline_and_through_themselves() -> None:
    cosines = np.linspace(-1.0, 1.0, 41)
    lit = np.array([leaf_cosine(float(c)) for c in cosines])
    through = np.array([leaf_transmission(float(c)) for c in cosines])
    assert leaf_cosine(1.0) == pytest.approx(1.0) and (np.diff(lit) >= 0).all()
    assert (lit[cosines <= -LEAF_WRAP] == 0).all() and (lit[(cosines > -LEAF_WRAP) & (cosines < 0)] > 0).all()
    assert (through[cosines >= 0] == 0).all() and (np.diff(through[cosines <= 0]) <= 0).all()
    assert 0.0 < leaf_sky(-1.0) < leaf_sky(0.0) < leaf_sky(1.0) == pytest.approx(1.0)


def _crowns(leaves: bool, azimuth: float) -> tuple[float, float]:
    """(mean luma, mean green minus red) of the leaves in frame 10 of a rural road at a low sun from ``azimuth``,
    with the crowns marked as leaves or left plain."""
    case = parse_case({"road": {"type": "straight"}, "scene": {"kind": "rural"},
                       "sun": {"altitude": 25.0, "azimuth": azimuth}, "camera": {"width": 320, "height": 180}})
    scene = compile_scene(case)
    marked = np.zeros(len(scene.meshes), bool)
    for index, mesh in enumerate(scene.meshes):
        if mesh.finish is not None and (mesh.finish == facade.LEAVES).any():
            marked[index] = True
            if not leaves:
                scene.meshes[index] = dataclasses.replace(mesh, finish=np.zeros_like(mesh.finish))
    frame = render_frame(scene, 10)
    crown = np.isin(frame.object_id, FIRST_OBJECT_ID + np.flatnonzero(marked))
    assert crown.sum() > 300
    rgb = frame.rgb[crown].astype(np.float64)
    return float((rgb @ (0.299, 0.587, 0.114)).mean()), float((rgb[:, 1] - rgb[:, 0]).mean())


@pytest.mark.parametrize("azimuth", [0.0, 180.0])
def test_crowns_are_lit_as_leaves_not_as_dark_shells(azimuth: float) -> None:
    luma, green = _crowns(True, azimuth)
    shell_luma, shell_green = _crowns(False, azimuth)
    assert luma > 1.05 * shell_luma  # light past the terminator and through the leaves (measured 1.07-1.14x)
    assert green > shell_green > 0.0  # and greener: lit leaves, not a shell in the blue sky's light
