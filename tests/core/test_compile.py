"""compile_scene with ``reuse``: the road and roadside of an earlier scene are taken only when they still apply."""

from __future__ import annotations

import numpy as np

from lanevil_core.case import parse_case
from lanevil_core.compile import compile_scene, roadside_key


def _assert_same(a, b) -> None:
    assert len(a.meshes) == len(b.meshes) and len(a.layers) == len(b.layers) and len(a.lights) == len(b.lights)
    for mesh_a, mesh_b in zip(a.meshes, b.meshes):
        np.testing.assert_array_equal(mesh_a.vertices, mesh_b.vertices)
        np.testing.assert_array_equal(mesh_a.colors, mesh_b.colors)
    np.testing.assert_allclose(a.env.sun_dir_world, b.env.sun_dir_world)


def test_reuse_with_the_same_roadside_equals_a_full_compile() -> None:
    base = compile_scene(parse_case({"scene": {"kind": "urban"}, "illusions": [{"type": "fence_shadow"}]}))
    case = parse_case({"scene": {"kind": "urban"}, "sun": {"azimuth": 100},
                       "illusions": [{"type": "vehicle", "severity": 4}]})
    assert roadside_key(case) == roadside_key(base.case)
    reused = compile_scene(case, reuse=base)
    assert reused.network is base.network
    _assert_same(reused, compile_scene(case))


def test_reuse_is_ignored_when_the_roadside_changed() -> None:
    base = compile_scene(parse_case({"scene": {"kind": "urban"}}))
    night = parse_case({"scene": {"kind": "urban"}, "sun": {"altitude": -10}})  # lamps glow at night
    assert roadside_key(night) != roadside_key(base.case)
    scene = compile_scene(night, reuse=base)
    assert scene.network is not base.network
    _assert_same(scene, compile_scene(night))
