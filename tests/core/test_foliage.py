"""Leaves lit as a volume: wrapped sunlight past a crown's terminator, light through the leaves, sky from all round;
clumps of leaves drawn in world space and filtered over the pixel's footprint."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lanevil_core.case import parse_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.foliage import (
    LEAF_MASS_M,
    LEAF_RESOLVED_PX,
    LEAF_WRAP,
    leaf_clumps,
    leaf_cosine,
    leaf_sky,
    leaf_transmission,
)
from lanevil_core.render.textures import value_noise
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


def _clumps_on_a_plane(foot_m: float, normal: tuple[float, float, float] = (0.6, 0.0, 0.8),
                       points: int = 4000) -> np.ndarray:
    """(points, 6) ``leaf_clumps`` over random points of a tilted crown face, seen over ``foot_m`` metres."""
    rng = np.random.default_rng(7)
    nx, ny, nz = normal
    u = np.array([-nz, 0.0, nx])  # two directions across the face
    v = np.cross(normal, u)
    out = np.empty((points, 6))
    for index, (a, b) in enumerate(rng.uniform(-40.0, 40.0, (points, 2))):
        px, py, pz = 120.0 + a * u + b * v
        out[index] = leaf_clumps(px, py, pz, nx, ny, nz, foot_m)
    return out


def test_value_noise_is_repeatable_bounded_and_its_gradient_exact() -> None:
    rng = np.random.default_rng(3)
    step = 1e-5
    for x, y, z in rng.uniform(-500.0, 500.0, (200, 3)):
        value, gx, gy, gz = value_noise(x, y, z)
        assert value_noise(x, y, z) == (value, gx, gy, gz) and -1.0 <= value <= 1.0
        numeric = [(value_noise(x + dx, y + dy, z + dz)[0] - value_noise(x - dx, y - dy, z - dz)[0]) / (2 * step)
                   for dx, dy, dz in ((step, 0, 0), (0, step, 0), (0, 0, step))]
        assert np.allclose((gx, gy, gz), numeric, atol=1e-4)


def test_leaf_clumps_vary_across_a_face_about_its_own_tone() -> None:
    near = _clumps_on_a_plane(0.01)  # a crown a few metres away: clumps of 45 pixels
    assert (near == _clumps_on_a_plane(0.01)).all()  # the same world point, the same clump
    luma = near[:, :3] @ (0.299, 0.587, 0.114)
    assert luma.std() > 0.15  # lit clumps and dark gaps, not one flat tone
    assert abs(near[:, :3].mean(axis=0) - 1.0).max() < 0.03  # ... about the face's own colour
    assert (near[:, 0] - near[:, 2])[luma > 1.1].mean() > 0.0  # the outer clumps yellower (red over blue)
    tilt = near[:, 3:] @ np.array((0.6, 0.0, 0.8))
    assert np.allclose(np.linalg.norm(near[:, 3:], axis=1), 1.0) and tilt.min() < 0.95 and tilt.min() > 0.0


@pytest.mark.parametrize("foot_m", [1.01 * LEAF_MASS_M / LEAF_RESOLVED_PX, 2.0, 25.0])
def test_leaf_clumps_fade_to_their_mean_over_a_large_footprint(foot_m: float) -> None:
    far = _clumps_on_a_plane(foot_m, points=200)
    assert (far[:, :3] == 1.0).all() and (far[:, 3:] == (0.6, 0.0, 0.8)).all()
    spread = [float(_clumps_on_a_plane(foot, points=600)[:, 1].std()) for foot in (0.01, 0.1, 0.3, 0.6)]
    assert spread == sorted(spread, reverse=True) and spread[-1] < 0.5 * spread[0]


def test_the_clumps_touch_only_the_leaves_own_pixels() -> None:
    case = parse_case({"road": {"type": "straight"}, "scene": {"kind": "suburban"},
                       "camera": {"width": 320, "height": 180}})
    scene = compile_scene(case)
    plain = compile_scene(case)
    leafy = np.zeros(len(scene.meshes), bool)
    for index, mesh in enumerate(plain.meshes):
        if mesh.finish is not None and (mesh.finish == facade.LEAVES).any():
            leafy[index] = True
            plain.meshes[index] = dataclasses.replace(mesh, finish=np.zeros_like(mesh.finish))
    assert scene.meshes is not plain.meshes
    lit, flat = render_frame(scene, 10), render_frame(plain, 10)
    crown = np.isin(lit.object_id, FIRST_OBJECT_ID + np.flatnonzero(leafy))
    assert crown.sum() > 300 and (lit.object_id == flat.object_id).all()
    near = crown.copy()  # the edges' anti-aliasing blends a crown into the pixels next to it
    for down in (-1, 0, 1):
        for across in (-1, 0, 1):
            near |= np.roll(crown, (down, across), axis=(0, 1))
    assert (lit.rgb[~near] == flat.rgb[~near]).all()  # road, paint, walls, sky: the same bytes
    assert (lit.rgb[crown] != flat.rgb[crown]).any(axis=1).mean() > 0.25  # (the meshes hold their trunks too)
