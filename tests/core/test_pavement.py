"""Concrete pavement: the carriageway's material, its slabs and sealed joints, and what stays the same (the labels,
the paint, the paved reach the illusions use)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.case import Case
from lanevil_core.dataset.plan import train_variation
from lanevil_core.labels import lanes as L
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.materials import JOINT_SPACING_M, SEALANT_ALBEDO, slab_joints
from lanevil_core.typed import MATERIALS, SCENE_KINDS, SceneKind
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.road_mesh import road_surface
from lanevil_core.world.scene import ID_ROAD

GREY = 0.21


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_concrete_paves_the_carriageway_and_its_flush_shoulder(make_case: Callable[..., Case], kind: SceneKind) -> None:
    asphalt = build_network(make_case(scene={"kind": kind}).road, kind)
    concrete = build_network(make_case(scene={"kind": kind}, road={"pavement": "concrete"}).road, kind)
    assert asphalt.main.carriageway == "asphalt" and concrete.main.carriageway == "slab"
    assert concrete.main.paved_reach == asphalt.main.paved_reach  # illusions keep their room on the road
    assert [s.material for s in concrete.main.strips[1:]] == [s.material for s in asphalt.main.strips[1:]]
    surface = road_surface(concrete)
    assert set(surface.material[surface.carriageway]) == {MATERIALS.index("slab")}
    assert MATERIALS.index("asphalt") not in surface.material


def test_a_joint_darkens_the_slab_and_mid_slab_keeps_its_tone() -> None:
    footprint = 0.005
    on_joint = slab_joints(2 * JOINT_SPACING_M, 1.7, footprint, footprint, 3.5, 0.0, GREY, GREY, GREY)
    mid_slab = slab_joints(2.5 * JOINT_SPACING_M, 1.7, footprint, footprint, 3.5, 0.0, GREY, GREY, GREY)
    on_line = slab_joints(2.5 * JOINT_SPACING_M, 3.5, footprint, footprint, 3.5, 0.0, GREY, GREY, GREY)
    assert on_joint[0] == pytest.approx(SEALANT_ALBEDO, abs=1e-6)
    assert on_line[0] == pytest.approx(SEALANT_ALBEDO, abs=1e-6)  # longitudinal joints on the lane boundaries
    assert mid_slab[0] > 0.7 * GREY


@settings(max_examples=200, deadline=None)
@given(s=st.floats(0.0, 400.0), t=st.floats(-10.0, 10.0), stain=st.floats(-1.0, 1.0))
def test_far_away_the_joints_are_an_even_shade(s: float, t: float, stain: float) -> None:
    """A footprint of many slabs averages the joints, the slabs' tones and the drip instead of aliasing them: the
    same shade wherever it falls."""
    here = slab_joints(s, t, 2 * JOINT_SPACING_M, 7.0, 3.5, stain, GREY, GREY, GREY)
    there = slab_joints(s + 1.3, t + 0.9, 2 * JOINT_SPACING_M, 7.0, 3.5, stain, GREY, GREY, GREY)
    assert here[0] == here[1] == here[2]
    assert 0.9 * GREY < here[0] < GREY
    assert abs(here[0] - there[0]) < 0.01 * GREY


@settings(deadline=None)
@given(s=st.floats(0.0, 400.0), t=st.floats(-10.0, 10.0), fs=st.floats(1e-3, 20.0), ft=st.floats(1e-3, 20.0),
       stain=st.floats(-1.0, 1.0))
def test_slab_colour_stays_between_sealant_and_the_brightest_slab(s: float, t: float, fs: float, ft: float,
                                                                 stain: float) -> None:
    r, _, _ = slab_joints(s, t, fs, ft, 3.5, stain, GREY, GREY, GREY)
    assert min(SEALANT_ALBEDO, 0.7 * GREY) - 1e-9 <= r <= 1.08 * GREY + 1e-9


def test_concrete_keeps_the_labels_and_shows_the_slabs(make_case: Callable[..., Case]) -> None:
    frames, records = {}, {}
    for pavement in ("asphalt", "concrete"):
        scene = compile_scene(make_case(road={"pavement": pavement}))
        frame = render_frame(scene, 5)
        frames[pavement] = frame
        records[pavement] = L.tusimple_record(scene, 5, frame, "a.png")
    assert records["concrete"]["lanes"] == records["asphalt"]["lanes"]
    road = (frames["asphalt"].object_id == ID_ROAD) & (frames["concrete"].object_id == ID_ROAD)
    lower = np.zeros_like(road)
    lower[frames["asphalt"].rgb.shape[0] * 3 // 4:] = True
    grey = {name: frame.rgb[road & lower].astype(float).mean() for name, frame in frames.items()}
    assert grey["concrete"] > grey["asphalt"] + 40  # concrete is far paler than asphalt
    # Transverse joints: dark rows across the slabs in the near field (asphalt varies by a few levels only).
    height, width = frames["concrete"].rgb.shape[:2]
    dips = {}
    for name, frame in frames.items():
        near = frame.rgb[height * 3 // 4:, width // 2 + 40].astype(float).mean(axis=1)
        dips[name] = np.median(near) - near.min()
    assert dips["concrete"] > 6.0 and dips["concrete"] > 2 * dips["asphalt"], dips


def test_the_randomised_split_paves_some_roads_with_concrete(make_case: Callable[..., Case]) -> None:
    base = make_case()
    drawn = [train_variation(base, 0, index, vary_camera=True)[1]["pavement"] for index in range(40)]
    assert 4 <= drawn.count("concrete") <= 24
    plain = {train_variation(base, 0, index)[1]["pavement"] for index in range(20)}
    assert plain == {"asphalt"}  # the diversified split is unchanged
