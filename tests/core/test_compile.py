"""compile_scene with ``reuse``: the road and roadside of an earlier scene are taken only when they still apply."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from lanevil_core.case import Case, parse_case
from lanevil_core.illusions import REGISTRY
from lanevil_core.pipeline.compile import compile_scene, roadside_key
from lanevil_core.render import render_frame
from lanevil_core.world.scene import array_bytes


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


class _NoCase:
    """Stands in for ``scene.case``: any read fails, naming what was read."""

    def __getattr__(self, name: str) -> None:
        raise AssertionError(f"a later stage read scene.case.{name}")


def test_renderer_labels_and_exporter_read_nothing_of_the_case(make_case) -> None:
    from lanevil_core.export.case import scene_glb
    from lanevil_core.labels.lanes import culane_lines, tusimple_record
    from lanevil_core.render import render_frame

    types = ("white_solid", "white_dashed", "yellow_double_solid", "none", "white_solid")
    case = make_case(road={"type": "t_junction", "markings": [{"type": kind} for kind in types]},
                     illusions=[{"type": "streetlight_shadow", "severity": 3}])
    scene = compile_scene(case)
    assert scene.paint.line_types == types
    assert scene.ego.frames == case.ego.frames and scene.ego.mount == case.camera
    scene.case = _NoCase()  # type: ignore[assignment]
    frame = render_frame(scene, 5, size=(160, 90))
    assert len(tusimple_record(scene, 5, frame, raw_file="000005.png")["lanes"]) >= 2
    assert isinstance(culane_lines(scene, frame), str)
    assert scene_glb(scene)[:4] == b"glTF"


def test_the_scene_says_which_illusions_set_the_sun() -> None:
    clean = parse_case({"road": {"type": "straight"}})
    assert compile_scene(clean).env.sun_set_by == ()
    both = parse_case({"road": {"type": "straight"}, "illusions": [
        {"type": "fence_shadow", "severity": 3}, {"type": "road_crack", "severity": 2},
        {"type": "sunlight_reflection", "severity": 3}]})
    assert compile_scene(both).env.sun_set_by == (0, 2)  # the crack leaves the sun alone; the last one's is shown
    assert [type(i).SETS_SUN for i in both.illusions] == [True, False, True]


@pytest.mark.parametrize("illusion_type", sorted(REGISTRY))
def test_an_illusion_beyond_the_end_of_the_drive_compiles_and_renders(illusion_type: str) -> None:
    """``s`` may lie anywhere on the road (0..3000 m), past the drive's end or the road's: nothing to see there."""
    case = Case.model_validate({"illusions": [{"type": illusion_type, "s": 2999.0, "severity": 4}]})
    frame = render_frame(compile_scene(case), 0, (64, 64))
    assert frame.rgb.shape == (64, 64, 3)


def test_scene_bytes_count_arrays_a_numba_kernel_allocated() -> None:
    """Such an array's base is numba's MemInfo, not an array: it owns its data (the crack layers' 100s of MB)."""
    ones = numba.njit(lambda n: np.ones((n, 4), np.float32))(1000)
    assert not isinstance(ones.base, np.ndarray)
    assert array_bytes([ones[:10], ones[10:20]]) == ones.nbytes == 16_000
    assert array_bytes([np.zeros(8)[2:]]) == 64
